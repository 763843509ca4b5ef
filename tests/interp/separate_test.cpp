// The separation pass (interp/separate.h): streamline strands' written polylines keep apart where
// their exact curves do, on scenes where the field bunches strands closer than the chords' sag: the
// planar arch (checked with the exact 2-D test), bunched bundles, random flows over many seeds, a
// scaled copy, thread counts, subsets of roots.
#include <omp.h>

#include <catch2/catch.hpp>
#include <cstring>
#include <memory>

#include "exact/exact_planar.h"
#include "interp/hard_scenes.h"
#include "interp/scene_measures.h"
#include "interp/separate.h"
#include "skin/skin_grid.h"

using namespace plume;
using namespace plume::test;
using Method = InterpolationSettings::Method;

namespace {

struct Grown {
  StrandSet strands;
  interp::GrowStats stats;
};

Grown grow_with(const Scene &scene, const Roots &roots, int points, bool separate) {
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, roots, settings_of(Method::streamline));
  interp::GrowOptions options;
  options.points_per_strand = points;
  options.separate = separate;
  Grown grown;
  options.r_stats = &grown.stats;
  interp::grow(binding, scene.mesh, *scene.query, roots, scene.guides.strands, options, grown.strands);
  return grown;
}

/// The planar scene's strands (in the XZ plane) mapped to the XY plane the exact test reads.
StrandSet to_xy(const StrandSet &strands) {
  StrandSet out = strands;
  for (Eigen::Vector3f &p : out.positions) p = Eigen::Vector3f(p.x(), p.z(), 0.0f);
  return out;
}

size_t transversal(const StrandSet &strands) {
  return check::count_crossings(strands, 1e-3f * median_segment(strands), 0).transversal_pairs;
}

size_t inside(const Scene &scene, const StrandSet &strands) {
  std::vector<uint64_t> examples;
  return check::count_points_inside(strands, *scene.query, 0.0f, 0, examples);
}

/// The largest distance between corresponding points of two strand sets of equal shape.
[[maybe_unused]] float largest_difference(const StrandSet &a, const StrandSet &b) {
  float worst = 0.0f;
  for (size_t k = 0; k < a.positions.size(); ++k) worst = std::max(worst, (a.positions[k] - b.positions[k]).norm());
  return worst;
}

}  // namespace

TEST_CASE("separation: planar strands stay in their plane; S-curves at few points never intersect (exact 2-D test)",
          "[interp][separate]") {
  // S-curves of different lengths and phases at 8 to 12 points per strand: the chords' sag is large
  // against the strands' spacing. The pass moves points only in the plane of the difference of the
  // exact curves, so the strands stay in the guides' plane, where an exact test decides.
  size_t before = 0;
  for (const auto &[points, roots] : {std::pair{12, 50}, std::pair{8, 120}, std::pair{10, 200}}) {
    const Scene scene = planar_s_curves(32, roots);
    INFO(points << " points, " << roots << " roots");
    const Grown without = grow_with(scene, scene.roots, points, false);
    const Grown with = grow_with(scene, scene.roots, points, true);
    for (const Eigen::Vector3f &p : with.strands.positions) REQUIRE(p.y() == 0.0f);
    before += exact_intersecting_pairs(to_xy(without.strands)).size();
    CHECK(exact_intersecting_pairs(to_xy(with.strands)).empty());
    CHECK(planar_intersections(with.strands) == 0);
    CHECK(transversal(with.strands) == 0);
    CHECK(inside(scene, with.strands) == 0);
    CHECK(all_finite(with.strands));
  }
  INFO(before << " intersecting pairs without the pass");
  CHECK(before > 0);
}

TEST_CASE("separation: the planar arch stays in its plane and out of the skin (its bunched strands are a known failure)",
          "[interp][separate]") {
  // Strands rooted between a short guide and a long one arching over it converge on one curve inside
  // the arch, until their fine curves coincide in float: there is no side left to tell, and the pass
  // cannot part them within its largest move (docs/interpolation.md, "Bunching"). What it must keep:
  // the plane, the skin, finite points, and no more intersecting pairs than without it.
  for (const auto &[points, roots] : {std::pair{32, 40}, std::pair{16, 40}, std::pair{12, 100}}) {
    const Scene scene = planar_arch(32, roots);
    INFO(points << " points, " << roots << " roots");
    const Grown without = grow_with(scene, scene.roots, points, false);
    const Grown with = grow_with(scene, scene.roots, points, true);
    for (const Eigen::Vector3f &p : with.strands.positions) REQUIRE(p.y() == 0.0f);
    const size_t after = exact_intersecting_pairs(to_xy(with.strands)).size();
    const size_t before = exact_intersecting_pairs(to_xy(without.strands)).size();
    INFO(before << " intersecting pairs without the pass, " << after << " with it");
    CHECK(after <= before);
    CHECK(inside(scene, with.strands) == 0);
    CHECK(all_finite(with.strands));
  }
}

namespace {

/// The scene's roots followed by its guides' roots: strands at guide roots grown among the others.
Roots with_guide_roots(const Scene &scene) {
  Roots roots = scene.roots;
  const Roots at_guides = roots_of(scene.guides);
  roots.points.insert(roots.points.end(), at_guides.points.begin(), at_guides.points.end());
  for (size_t g = 0; g < at_guides.size(); ++g) roots.ids.push_back(uint64_t(1u << 30) + g);
  return roots;
}

/// The largest deviation, in fractions of the guide's length, of the strands grown at the guide
/// roots (the last #guides strands) from their guides' curves, as the checker measures it.
float worst_guide_deviation(const Scene &scene, const StrandSet &strands) {
  const size_t first = strands.strand_count() - scene.guides.size();
  double worst = 0.0;
  for (size_t g = 0; g < scene.guides.size(); ++g)
    worst = std::max(worst, curve_deviation(scene.guides, g, strands.points(first + g)));
  return float(worst);
}

/// The random flow (1,500 roots, 8 points) of the first seed on which the pass moves points, and
/// its strands grown with the pass on 2 threads: grown once, read by every case that needs them.
struct BusyFlow {
  Scene scene;
  Grown grown;
};

const BusyFlow &busy_flow() {
  static const std::unique_ptr<BusyFlow> found = [] {
    const int threads = omp_get_max_threads();
    omp_set_num_threads(2);
    std::unique_ptr<BusyFlow> busy;
    for (uint64_t seed = 200; seed < 216; ++seed) {
      busy.reset(new BusyFlow{random_flow(seed, 32, 16, 1500), {}});
      busy->grown = grow_with(busy->scene, busy->scene.roots, 8, true);
      if (busy->grown.stats.separation_points_moved > 0) break;
    }
    omp_set_num_threads(threads);
    return busy;
  }();
  return *found;
}

}  // namespace

TEST_CASE("separation: random flows over many seeds at 8 points per strand leave no transversal pair",
          "[interp][separate]") {
  // Guides traced through one smooth random rising field, strands at 8 points,
  // far below the guides' 32: the chords' sag is large against the strands' spacing. Strands at the
  // guide roots grown among the others stay within 0.1% of their guides.
  size_t before = 0, moved_seeds = 0;
  for (uint64_t seed = 200; seed < 212; ++seed) {
    const Scene scene = random_flow(seed, 32, 16, 1500);
    const Roots roots = with_guide_roots(scene);
    const Grown without = grow_with(scene, roots, 8, false);
    const Grown with = grow_with(scene, roots, 8, true);
    const size_t transversal_without = transversal(without.strands);
    INFO("seed " << seed << ": " << transversal_without << " transversal pairs without the pass");
    before += transversal_without;
    moved_seeds += with.stats.separation_points_moved > 0;
    CHECK(transversal(with.strands) == 0);
    CHECK(with.stats.unseparated_pairs == 0);
    CHECK(inside(scene, with.strands) == 0);
    CHECK(all_finite(with.strands));
    CHECK(worst_guide_deviation(scene, with.strands) < 1e-3f);
    // No point moved farther than the pass allows: a strand at a guide root (the last #guides)
    // 0.02 of the median segment, another 0.1 of its own segment within 0.02 and 0.1 of the median.
    const float median = median_segment(without.strands);
    const size_t first_at_guide = with.strands.strand_count() - scene.guides.size();
    for (size_t r = 0; r < with.strands.strand_count(); ++r) {
      const auto moved = with.strands.points(r), grown = without.strands.points(r);
      float length = 0.0f, worst = 0.0f;
      for (size_t j = 0; j < grown.size(); ++j) {
        if (j > 0) length += (grown[j] - grown[j - 1]).norm();
        worst = std::max(worst, (moved[j] - grown[j]).norm());
      }
      const float own = interp::separation_largest_move * length / float(grown.size() - 1);
      const float allowed = r >= first_at_guide ? interp::separation_largest_move_at_guide * median
                                                : std::clamp(own, interp::separation_largest_move_at_guide * median,
                                                             interp::separation_largest_move * median);
      INFO("strand " << r);
      if (worst > allowed * 1.01f) CHECK(worst <= allowed * 1.01f);
    }
  }
  INFO(before << " transversal pairs over the seeds without the pass");
  CHECK(moved_seeds > 0);  // the pass had work to do
}

TEST_CASE("separation: a bunched bundle (many strands drawn onto one curve) leaves no transversal pair",
          "[interp][separate]") {
  // Dense roots under combed layers and ringlets: the field draws strands together over the guides.
  std::vector<Scene> scenes;
  scenes.push_back(combed_layers(32, 1500));
  scenes.push_back(ringlets(64, 600));
  for (const Scene &scene : scenes)
    for (const int points : {12, 24}) {
      const Grown with = grow_with(scene, scene.roots, points, true);
      INFO(scene.name << ", " << points << " points: " << with.stats.separated_pairs << " segment pairs found, "
                      << with.stats.unseparated_pairs << " left");
      CHECK(transversal(with.strands) == 0);
      CHECK(inside(scene, with.strands) == 0);
    }
}

TEST_CASE("separation: the same bytes for 1 and 2 threads; a scaled groom gives the same strands scaled",
          "[interp][separate]") {
  const Scene &scene = busy_flow().scene;
  const Grown &two = busy_flow().grown;  // grown on 2 threads
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const Grown one = grow_with(scene, scene.roots, 8, true);
  omp_set_num_threads(threads);
  REQUIRE(one.stats.separation_points_moved > 0);
  REQUIRE(one.strands.positions.size() == two.strands.positions.size());
  CHECK(std::memcmp(one.strands.positions.data(), two.strands.positions.data(),
                    two.strands.positions.size() * sizeof(Eigen::Vector3f)) == 0);
  for (const float factor : {0.01f, 100.0f}) {
    const Scene big = scaled(scene, factor);
    const Grown grown = grow_with(big, big.roots, 8, true);
    INFO("scaled by " << factor);
    CHECK(transversal(grown.strands) == 0);
    float worst = 0.0f;
    for (size_t k = 0; k < grown.strands.positions.size(); ++k)
      worst = std::max(worst, (factor * one.strands.positions[k] - grown.strands.positions[k]).norm());
    // Float rounding, and the discrete choices it may flip (an integration step, a pair found or not
    // at the pass's distance): within the pass's largest move.
    CHECK(worst <= factor * interp::separation_largest_move * median_segment(one.strands) * 1.5f);
  }
}

TEST_CASE("separation: a subset of roots grown alone gives each strand's exact curve; the pass moves it by at most "
          "its largest move",
          "[interp][separate]") {
  // What a strand is, whichever strands are grown with it: its exact curve resampled (the pass off,
  // or a root grown alone, which has no neighbour), to the bit. The pass moves its points from there
  // by at most separation_largest_move of the strands' median segment, and only where a neighbour
  // grown with it came near.
  const Scene &scene = busy_flow().scene;
  const Grown &all = busy_flow().grown;
  const Grown exact = grow_with(scene, scene.roots, 8, false);
  REQUIRE(all.stats.separation_points_moved > 0);
  const float allowed = interp::separation_largest_move * median_segment(exact.strands) * 1.01f;
  size_t identical = 0;
  for (size_t r = 0; r < scene.roots.size(); r += 7) {
    Roots alone;
    alone.points = {scene.roots.points[r]};
    alone.ids = {scene.roots.ids[r]};
    const Grown one = grow_with(scene, alone, 8, true);
    REQUIRE(one.strands.positions.size() == 8);
    CHECK(std::memcmp(one.strands.positions.data(), exact.strands.points(r).data(), 8 * sizeof(Eigen::Vector3f)) == 0);
    float worst = 0.0f;
    for (int j = 0; j < 8; ++j) worst = std::max(worst, (all.strands.points(r)[j] - one.strands.positions[size_t(j)]).norm());
    CHECK(worst <= allowed);
    identical += worst == 0.0f;
  }
  CHECK(identical > 0);
}

TEST_CASE("separation: tips ended at the skin and meeting there move back along their strands, never into it",
          "[interp][separate]") {
  // Strands that come down onto the skin and end on it at one point (a sink of the field at the
  // skin), on a flat skin and in the crease of a valley: a tip that cannot move aside (the skin below,
  // the margin round it; in the crease the other face) moves back along its own last segment. Exact
  // curves that meet at the tips give no side to tell. Scaled by 1e-3 and 1e3: the same, scaled.
  size_t retracted = 0;
  for (const bool valley : {false, true})
  for (const float scale : {1.0f, 1e-3f, 1e3f}) {
    INFO((valley ? "valley" : "flat") << ", scale " << scale);
    Mesh mesh;
    const float rim = valley ? 3.0f : 0.0f;  // the valley's faces rise 3 over 4 from its crease (x = 0)
    mesh.positions = {scale * Eigen::Vector3f(-4, -4, rim), scale * Eigen::Vector3f(0, -4, 0), scale * Eigen::Vector3f(4, -4, rim),
                      scale * Eigen::Vector3f(-4, 4, rim), scale * Eigen::Vector3f(0, 4, 0), scale * Eigen::Vector3f(4, 4, rim)};
    mesh.triangles = {Eigen::Vector3i(0, 1, 4), Eigen::Vector3i(0, 4, 3), Eigen::Vector3i(1, 2, 5), Eigen::Vector3i(1, 5, 4)};
    mesh.triangle_groups = {0, 0, 0, 0};
    mesh.group_names = {"default"};
    mesh.compute_normals();
    const MeshQuery query(mesh);
    const skin::SkinGrid grid(mesh, query);
    const int n = 4, count = 6;
    const float tip_height = 1e-5f * scale, margin = 0.02f * scale;
    std::vector<Eigen::Vector3f> positions;
    std::vector<float> lower;
    interp::ExactCurves curves;
    curves.offsets.push_back(0);
    for (int c = 0; c < count; ++c) {
      // Azimuths 0, 25, 50, ... degrees: the last segments meet at 25 to 125 degrees.
      const float phi = float(c) * 25.0f * float(M_PI) / 180.0f;
      const Eigen::Vector3f out(std::cos(phi), std::sin(phi), 0.0f);
      const auto skin_z = [&](const Eigen::Vector3f &p) { return rim / 4.0f * std::abs(p.x()); };
      Eigen::Vector3f points[n] = {scale * (1.5f * out), scale * (1.0f * out + Eigen::Vector3f(0, 0, 1.2f)),
                                   scale * (0.5f * out + Eigen::Vector3f(0, 0, 1.2f)), Eigen::Vector3f(0, 0, tip_height)};
      for (int j = 0; j + 1 < n; ++j) points[j].z() += skin_z(points[j]);
      for (const Eigen::Vector3f &p : points) {
        positions.push_back(p);
        SurfacePoint closest;
        lower.push_back(grid.signed_distance(p, -1, closest));
        curves.points.push_back(p);
      }
      curves.offsets.push_back(curves.points.size());
      float length = 0.0f;
      for (int j = 1; j < n; ++j) length += (points[j] - points[j - 1]).norm();
      curves.cuts.push_back(length);
    }
    StrandSet before;
    before.resize_uniform(count, n, false);
    before.positions = positions;
    const float tolerance = 1e-3f * median_segment(before);
    REQUIRE(check::count_crossings(before, tolerance, 0).transversal_pairs > 0);
    const interp::SeparationStats stats =
        interp::separate_strands(positions, n, curves, tolerance, margin, mesh, grid, lower);
    StrandSet after = before;
    after.positions = positions;
    INFO(stats.pairs_found << " pairs found, " << stats.retracted << " tips retracted, " << stats.pairs_left << " left");
    retracted += size_t(stats.retracted);
    CHECK(stats.pairs_left == 0);
    CHECK(check::count_crossings(after, tolerance, 0).transversal_pairs == 0);
    for (int c = 0; c < count; ++c) {
      const size_t first = size_t(c * n);
      CHECK(positions[first] == before.positions[first]);  // roots never move
      // Within the largest move; every point out of the skin by its floor: the margin, or half its
      // distance where growth left it nearer.
      for (int j = 0; j < n; ++j) {
        const size_t k = first + size_t(j);
        CHECK((positions[k] - before.positions[k]).norm() <= interp::separation_largest_move * median_segment(before) * 1.01f);
        if (j == 0) continue;  // a root on the skin (checked above: it never moves)
        SurfacePoint closest;
        const float was = grid.signed_distance(before.positions[k], -1, closest);
        REQUIRE(was > 0.0f);
        CHECK(grid.signed_distance(positions[k], -1, closest) >= 0.5f * std::min(margin, was) * 0.999f);
      }
    }
  }
  CHECK(retracted > 0);  // in the crease, tips went back along their strands
}
