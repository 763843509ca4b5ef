// What a coat's frame reuses from barb to barb (feathers/build.h, VaneBarbs, the Bezier fast paths)
// gives the bits the plain computation gives: the frame's bytes do not depend on the order barbs
// are built in, nor on how many points a barb has.
#include <catch2/catch.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <span>
#include <vector>

#include "feather_fixtures.h"
#include "feathers/bezier.h"
#include "feathers/build.h"
#include "feathers/feather.h"

using namespace plume;
using namespace plume::feathers;
using plume::test::Draw;

namespace {

bool same_bits(const float *a, const float *b, size_t count) { return std::memcmp(a, b, count * sizeof(float)) == 0; }

bool same_barb(const Barb &a, const Barb &b) {
  return a.polygon.count == b.polygon.count &&
         same_bits(a.polygon.points[0].data(), b.polygon.points[0].data(), 3 * size_t(a.polygon.count)) &&
         same_bits(a.attach.data(), b.attach.data(), 3) && same_bits(a.frame.data(), b.frame.data(), 9) &&
         same_bits(&a.angle, &b.angle, 1) && same_bits(&a.plumulaceous, &b.plumulaceous, 1) &&
         same_bits(&a.length, &b.length, 1) && same_bits(a.attach_flat.data(), b.attach_flat.data(), 3) &&
         same_bits(a.frame_flat.data(), b.frame_flat.data(), 9);
}

/// de Casteljau as the general loop of bezier_point runs it.
Eigen::Vector3f de_casteljau(std::span<const Eigen::Vector3f> points, float u) {
  std::vector<Eigen::Vector3f> work(points.begin(), points.end());
  const float a = 1.0f - u;
  for (size_t level = work.size(); level > 1; --level)
    for (size_t i = 0; i + 1 < level; ++i) work[i] = a * work[i] + u * work[i + 1];
  return work[0];
}

}  // namespace

TEST_CASE("a vane's barbs built in turn, in any order, are build_barb's to the bit", "[feathers]") {
  Draw d(27);
  int compared = 0;
  for (uint64_t seed = 1; seed <= 120; ++seed) {
    const FeatherShape shape = make_shape(test::random_template(seed), seed, seed % 3 == 0 ? 0.85f : 1.0f);
    for (const bool after : {false, true}) {
      if (after && !shape.has_after) continue;
      const FeatherTemplate &f = after ? shape.after : shape.main;
      for (const Vane vane : {Vane::left, Vane::right}) {
        const std::vector<KeyBarb> &keys = (after ? shape.after_keys : shape.main_keys)[size_t(vane)];
        VaneBarbs barbs(f, keys, vane, shape.seed);
        // Positions in rachis order, at the key barbs themselves, at random, and going back: the
        // kept key-barb pair and mean polygon must never leak from one barb into another.
        std::vector<float> rps(shape.main_positions.begin(), shape.main_positions.end());
        for (const KeyBarb &key : keys) rps.push_back(key.position);
        for (int k = 0; k < 40; ++k) rps.push_back(d.unit());
        for (int k = 0; k < 20; ++k) rps.push_back(rps[size_t(d.integer(0, int(rps.size()) - 1))]);
        rps.push_back(0.0f);
        rps.push_back(1.0f);
        for (size_t k = 0; k < rps.size(); ++k) {
          const float rp = rps[k];
          const int index = k % 5 == 4 ? -1 : int(k);
          const Barb reused = barbs(rp, index, barb_attachment(f, rp));
          const Barb plain = build_barb(f, keys, vane, rp, index, shape.seed);
          INFO("seed " << seed << (after ? ", afterfeather" : "") << ", vane " << int(vane) << ", rp " << rp);
          REQUIRE(same_barb(reused, plain));
          ++compared;
        }
      }
    }
  }
  CHECK(compared > 10000);
}

TEST_CASE("Bezier points of 3 and 4 vertices are de Casteljau's loop to the bit", "[feathers]") {
  Draw d(28);
  for (int trial = 0; trial < 2000; ++trial) {
    const int count = 3 + trial % 2;
    std::array<Eigen::Vector3f, 4> points;
    for (int i = 0; i < count; ++i) points[size_t(i)] = Eigen::Vector3f(d.in(-9, 9), d.in(-9, 9), d.in(-9, 9));
    const std::span<const Eigen::Vector3f> view(points.data(), size_t(count));
    const float u = trial % 7 == 0 ? float(trial % 3) * 0.5f : d.unit();
    const Eigen::Vector3f fast = bezier_point(view, u), loop = de_casteljau(view, u);
    INFO("trial " << trial << ", " << count << " vertices, u " << u);
    REQUIRE(same_bits(fast.data(), loop.data(), 3));
  }
}

TEST_CASE("barbs of many points (weights kept a block at a time) follow their Bezier curves", "[feathers]") {
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const FeatherShape shape = make_shape(test::random_template(seed), seed);
    for (const int points : {2, 31, 32, 33, 70, 200}) {
      FeatherDetail detail;
      detail.barb_points = points;
      const FeatherGeometry g = build_feather(shape, detail);
      // The main feather's left barbs come right after its rachis; on the flat feather a barb's
      // point j is attach + frame * B(j / (points - 1)).
      int64_t point = detail.rachis_points + 1;
      VaneBarbs barbs(shape.main, shape.main_keys[size_t(Vane::left)], Vane::left, shape.seed);
      float worst = 0.0f;
      for (size_t b = 0; b < shape.main_positions.size(); ++b) {
        const float rp = shape.main_positions[b];
        const Barb barb = barbs(rp, int(b), barb_attachment(shape.main, rp));
        for (int j = 0; j < points; ++j, ++point) {
          const float u = float(j) / float(points - 1);
          const Eigen::Vector3f expected = barb.attach + barb.frame * bezier_point(barb.polygon.view(), u);
          worst = std::max(worst, (g.curves.positions[size_t(point)] - expected).norm() / std::max(barb.length, 1e-6f));
        }
      }
      INFO("seed " << seed << ", " << points << " points per barb");
      CHECK(worst <= 1e-5f);
    }
  }
}
