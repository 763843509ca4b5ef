// The checker's crossing count against an exact 2-D test (tests/exact/exact_planar.h, CGAL exact
// predicates and constructions) on random planar strand sets: many seeds, crossing and
// non-crossing sets, near-parallel touching and small-angle crossings planted, and the same scenes
// scaled by 0.01 and 100 with the default tolerance.
#include <catch2/catch.hpp>

#include <array>
#include <cmath>
#include <random>

#include "check/check.h"
#include "exact/exact_planar.h"

using namespace plume;
using namespace plume::check;

namespace {

using Points = std::vector<Eigen::Vector3f>;
constexpr float kPi = 3.14159265f;

/// A random planar scene (z = 0). `walkers`: random walks of fixed step that cross each other and
/// everything else; the combed strands (wavy rows of one shape) never cross each other. Then copies
/// of some strands are planted beside them (moved sideways by a fraction or a multiple of the
/// default tolerance: touching or clear) and turned about their middle by a few degrees (crossing
/// at small angles, under and over the 10 degree threshold). A `clean` scene has no walker, and its
/// plants are 4 tolerances beside their strand: nothing crosses, though neighbours are close.
StrandSet random_scene(uint64_t seed, bool clean) {
  const int walkers = clean ? 0 : 12;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  StrandSet strands;
  uint64_t id = 0;
  const float step = 0.25f;
  const float turn = (seed % 3 == 0 ? 3.0f : seed % 3 == 1 ? 15.0f : 60.0f) * kPi / 180.0f;
  for (int w = 0; w < walkers; ++w) {
    Eigen::Vector3f p(4.0f * unit(random), 4.0f * unit(random), 0.0f);
    float heading = 2.0f * kPi * unit(random);
    Points points{p};
    for (int j = 0; j < 24; ++j) {
      heading += turn * (2.0f * unit(random) - 1.0f);
      p += step * Eigen::Vector3f(std::cos(heading), std::sin(heading), 0.0f);
      points.push_back(p);
    }
    strands.append(points, id++);
  }
  const float phase = 2.0f * kPi * unit(random), amplitude = 0.1f * unit(random);
  for (int row = 0; row < 10; ++row) {
    Points points;
    for (int j = 0; j <= 16; ++j) {
      const float x = 0.25f * float(j);
      points.emplace_back(x, 0.2f + 0.37f * float(row) + amplitude * std::sin(1.3f * x + phase), 0.0f);
    }
    strands.append(points, id++);
  }
  // The default tolerance of the scene so far: 1e-3 of its median segment length (the plants below
  // copy existing segments, so they hardly move it).
  const float tolerance = float(kToleranceOfMedianSegment * median_segment_length(strands));
  const size_t originals = strands.strand_count();
  for (int plant = 0; plant < 6; ++plant) {
    const size_t source = clean ? size_t(plant) : size_t(random() % originals);  // clean: each row once
    Points copy(strands.points(source).begin(), strands.points(source).end());
    const Eigen::Vector3f along = (copy[1] - copy[0]).normalized();
    if (clean) {
      for (Eigen::Vector3f &q : copy) q += 4.0f * tolerance * Eigen::Vector3f(-along.y(), along.x(), 0.0f);
    } else if (plant < 3) {
      // Beside it: 0.3, 0.7 and 0.97 tolerances (touching where the strand is straight enough),
      // 1.03, 1.6 or 4 (clear, unless the strand bends back toward its copy).
      const float gap = std::array<float, 6>{0.3f, 0.7f, 0.97f, 1.03f, 1.6f, 4.0f}[random() % 6] * tolerance;
      for (Eigen::Vector3f &q : copy) q += gap * Eigen::Vector3f(-along.y(), along.x(), 0.0f);
    } else {
      // Turned about its middle point: crossing the original there at the turn's angle.
      const float angle = std::array<float, 5>{3.0f, 8.0f, 9.9f, 12.0f, 25.0f}[random() % 5] * kPi / 180.0f;
      const Eigen::Vector3f centre = copy[copy.size() / 2];
      for (Eigen::Vector3f &q : copy) {
        const Eigen::Vector3f d = q - centre;
        q = centre + Eigen::Vector3f(std::cos(angle) * d.x() - std::sin(angle) * d.y(),
                                     std::sin(angle) * d.x() + std::cos(angle) * d.y(), 0.0f);
      }
    }
    strands.append(copy, id++);
  }
  return strands;
}

StrandSet scaled(const StrandSet &strands, float scale) {
  StrandSet result = strands;
  for (Eigen::Vector3f &p : result.positions) p *= scale;
  return result;
}

}  // namespace

TEST_CASE("the checker's crossing count agrees with an exact 2-D test on random planar strand sets", "[check]") {
  size_t exact_pairs = 0, transversal = 0, touching = 0, intersecting = 0, uncertain = 0, clean_scenes = 0;
  size_t scaled_compared = 0;
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    INFO("seed " << seed);
    // Every fourth scene is clean: combed rows and copies beside them, nothing crossing.
    const StrandSet strands = random_scene(seed, seed % 4 == 0);
    const float tolerance = crossing_tolerance_for(strands, CheckOptions{});
    const CrossingCount count = count_crossings(strands, tolerance, 4);
    const test::ExactCrossings exact = test::exact_crossings(strands, tolerance, kTransversalDegrees);
    INFO("checker " << count.pairs << " (" << count.transversal_pairs << " transversal), exact " << exact.pairs << " ("
                    << exact.transversal_pairs << " transversal), uncertain " << exact.uncertain_pairs);
    CHECK(count.pairs >= exact.pairs);
    CHECK(count.pairs <= exact.pairs + exact.uncertain_pairs);
    CHECK(count.transversal_pairs >= exact.transversal_pairs);
    CHECK(count.transversal_pairs <= exact.transversal_pairs + exact.uncertain_pairs);
    CHECK(count.touching_pairs >= exact.touching_pairs);
    CHECK(count.touching_pairs <= exact.touching_pairs + exact.uncertain_pairs);
    // Strands that share a point are within any tolerance.
    CHECK(exact.pairs + exact.uncertain_pairs >= exact.intersecting_pairs);
    exact_pairs += exact.pairs;
    transversal += exact.transversal_pairs;
    touching += exact.touching_pairs;
    intersecting += exact.intersecting_pairs;
    uncertain += exact.uncertain_pairs;
    clean_scenes += exact.pairs + exact.uncertain_pairs == 0;

    // The same scene at another scale, with its own default tolerance: the same counts. Scaling
    // rounds the float coordinates (by up to about 2.5e-3 of the tolerance here), so the scenes are
    // compared where no pair comes within 0.5% of the tolerance or the angle threshold (78 of the
    // 120 scaled scenes; each is still compared with the exact test above and below).
    const bool clear_of_rounding =
        test::exact_crossings(strands, tolerance, kTransversalDegrees, 5e-3).uncertain_pairs == 0;
    for (const float scale : {0.01f, 100.0f}) {
      INFO("scale " << scale);
      const StrandSet other = scaled(strands, scale);
      const float other_tolerance = crossing_tolerance_for(other, CheckOptions{});
      CHECK(other_tolerance == Approx(scale * tolerance).epsilon(1e-5));
      const CrossingCount other_count = count_crossings(other, other_tolerance, 4);
      const test::ExactCrossings other_exact = test::exact_crossings(other, other_tolerance, kTransversalDegrees);
      // The checker agrees with the exact test on the scaled scene too.
      CHECK(other_count.pairs >= other_exact.pairs);
      CHECK(other_count.pairs <= other_exact.pairs + other_exact.uncertain_pairs);
      CHECK(other_count.transversal_pairs >= other_exact.transversal_pairs);
      CHECK(other_count.transversal_pairs <= other_exact.transversal_pairs + other_exact.uncertain_pairs);
      if (clear_of_rounding) {
        ++scaled_compared;
        CHECK(other_count.pairs == count.pairs);
        CHECK(other_count.transversal_pairs == count.transversal_pairs);
        CHECK(other_count.touching_pairs == count.touching_pairs);
      }
    }
  }
  // The scenes hold all the cases: transversal crossings, near-parallel touching, and sets with
  // nothing crossing; an uncertain pair (a distance within 1e-6 of the tolerance) is rare.
  INFO(exact_pairs << " pairs, " << transversal << " transversal, " << touching << " touching, " << intersecting
                   << " intersecting, " << uncertain << " uncertain, " << clean_scenes << " scenes without a crossing");
  CHECK(transversal > 200);
  CHECK(touching > 20);
  CHECK(clean_scenes == 15);
  CHECK(uncertain <= 2);
  // Most scenes are clear of the rounding band and compared across scales.
  INFO(scaled_compared << " scaled scenes compared");
  CHECK(scaled_compared >= 60);
}

TEST_CASE("the exact 2-D test itself: known intersections, touching and near misses", "[check]") {
  StrandSet strands;
  strands.append(Points{{0, 0, 0}, {1, 1, 0}}, 0);
  strands.append(Points{{0, 1, 0}, {1, 0, 0}}, 1);          // crosses strand 0 at (0.5, 0.5)
  strands.append(Points{{1, 1, 0}, {2, 1, 0}}, 2);          // touches strand 0 at its tip (1, 1)
  strands.append(Points{{0, 2, 0}, {1, 2, 0}, {2, 2, 0}}, 3);                 // clear of all
  strands.append(Points{{0, 2.001f, 0}, {1, 2.001f, 0}, {2, 2.001f, 0}}, 4);  // 0.001 beside strand 3
  // (their roots are closer than the tolerances below: their first segments are ignored, the
  // second ones touch)
  const auto pairs = test::exact_intersecting_pairs(strands);
  CHECK(pairs == std::vector<std::pair<uint32_t, uint32_t>>{{0, 1}, {0, 2}});
  // Within 0.002: 0-1 and 0-2 at 90 and 45 degrees (transversal), 3-4 side by side (touching).
  test::ExactCrossings exact = test::exact_crossings(strands, 0.002, 10.0);
  CHECK(exact.pairs == 3);
  CHECK(exact.transversal_pairs == 2);
  CHECK(exact.touching_pairs == 1);
  CHECK(exact.intersecting_pairs == 2);
  CHECK(exact.uncertain_pairs == 0);
  // At 0.0005 strands 3 and 4 are apart.
  exact = test::exact_crossings(strands, 0.0005, 10.0);
  CHECK(exact.pairs == 2);
  CHECK(exact.touching_pairs == 0);
  // A distance equal to the tolerance, to the last bit, is uncertain (float 2.001 - 2 is not 0.001).
  const double gap = double(2.001f) - 2.0;
  exact = test::exact_crossings(strands, gap, 10.0);
  CHECK(exact.uncertain_pairs == 1);
}
