// The skin pass of the effects stack on strands whose last batch of four points is partial: it
// reads no point beyond the strand (checked by AddressSanitizer in the sanitizer build,
// tests/sanitize.sh) and leaves every point outside the skin.
#include <catch2/catch.hpp>

#include "effects/effects.h"
#include "effects/effects_fixtures.h"

using namespace plume;

TEST_CASE("the skin pass reads no point past a strand whose last batch holds fewer than four points", "[effects]") {
  const Mesh mesh = test::make_sphere(1.0f, 24, 48);
  const MeshQuery query(mesh);
  const Roots roots = scatter_roots(mesh, 64, 3);
  const Guides guides = test::make_guides(mesh, query, 8, 0.5f, 0.0f);
  const std::vector<int32_t> nearest = test::nearest_guides(mesh, roots, guides);
  EffectDesc wave;
  wave.type = EffectType::wave;
  wave.frequency = 3.0f;
  wave.amplitude = 0.001f;  // far less than any point's distance to the skin: every point is proven
  const float margin = 0.005f;
  // 2 to 9 points: partial last batches of 1, 2 and 3 points (2-4, 6-8 points) and whole ones. The
  // last strand of the set ends the stack's buffer of grown points, so a read past it leaves the
  // buffer; a new stack each time, so the buffer is allocated to that size. At amount 0 no point
  // moves, so every point is proven at its grown place even without clearances, the lanes past a
  // strand's end included when they are left unset.
  for (const float amount : {0.0f, 1.0f}) {
    wave.amount = amount;
    for (int points = 2; points <= 9; ++points) {
      INFO(points << " points per strand, amount " << amount);
      const StrandSet grown = test::grow_straight(mesh, roots, 0.5f, points);
      StrandSet strands = grown;
      std::vector<float> clearance;
      if (amount > 0.0f)
        for (const Eigen::Vector3f &p : grown.positions) clearance.push_back(std::max(0.0f, query.signed_distance(p)));
      const effects::EffectStack stack({wave}, mesh, roots, guides, nearest);
      stack.apply(mesh, query, guides.strands, margin, strands, clearance);
      for (size_t s = 0; s < strands.strand_count(); ++s)
        for (int64_t j = 1; j < strands.points_in(s); ++j) {
          CHECK(query.signed_distance(strands.points(s)[j]) >= margin);
          if (amount == 0.0f) CHECK(strands.points(s)[j] == grown.points(s)[j]);
        }
    }
  }
}
