// Promises of bind() and grow(): guides reproduced at their roots, rigid motion, scale, thread-count
// and batch independence, no crossings and no points in the skin on hard scenes (tests/interp/
// hard_scenes.h) and on random non-crossing guide sets, coherence, no NaN.
#include <catch2/catch.hpp>
#include <omp.h>

#include <algorithm>
#include <cstring>

#include "check/check.h"
#include "exact/exact_planar.h"
#include "interp/interp_fixtures.h"
#include "interp/interpolate.h"
#include "interp/scene_measures.h"

using namespace plume;
using namespace plume::test;
using Method = InterpolationSettings::Method;

namespace {

InterpolationSettings settings_for(Method method, int k = 4, float margin = -1.0f) {
  InterpolationSettings settings;
  settings.method = method;
  settings.k = k;
  settings.skin_margin = margin;
  return settings;
}

const char *name_of(Method method) {
  return method == Method::fur ? "fur" : method == Method::linear ? "linear" : "streamline";
}

/// Point at arc length s along a polyline (its last point past the end).
Eigen::Vector3f point_at_arc(std::span<const Eigen::Vector3f> points, float s) {
  for (size_t j = 0; j + 1 < points.size(); ++j) {
    const float length = (points[j + 1] - points[j]).norm();
    if (s <= length) return points[j] + (length > 0.0f ? s / length : 0.0f) * (points[j + 1] - points[j]);
    s -= length;
  }
  return points.back();
}

/// Largest distance from strand points to the guide's points at the same arc length.
float deviation_by_arc(std::span<const Eigen::Vector3f> strand, std::span<const Eigen::Vector3f> guide) {
  float worst = 0.0f, s = 0.0f;
  for (size_t i = 0; i < strand.size(); ++i) {
    if (i > 0) s += (strand[i] - strand[i - 1]).norm();
    worst = std::max(worst, (strand[i] - point_at_arc(guide, s)).norm());
  }
  return worst;
}

/// Arcs over the northern cap of the unit sphere, bending in various directions; `points` samples.
struct CapScene {
  Mesh mesh = make_sphere(1.0f, 32, 64, PoleAxis::z, false);
  MeshQuery query{mesh};
  Guides guides;
  Roots roots;

  /// `combed`: shapes are given in a frame whose tangent follows the global x axis (so every guide
  /// curls in phase, like a combed ringlet groom) rather than in the root's own surface frame.
  CapScene(const std::function<std::function<Eigen::Vector3f(float)>(int)> &shape_of, int points,
           const std::function<float(int)> &length_of, int root_count, bool combed = false) {
    StrandSet strands;
    int index = 0;
    for (float theta : {0.0f, 0.3f, 0.6f, 0.9f})
      for (int phi_step = 0; phi_step < (theta == 0.0f ? 1 : 8); ++phi_step) {
        const float phi = 2.0f * float(M_PI) * float(phi_step) / 8.0f + theta;
        const Eigen::Vector3f near(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
        std::vector<Eigen::Vector3f> curve = guide_curve(mesh, query, near, length_of(index), points, shape_of(index));
        if (combed) {
          SurfaceFrame frame = surface_frame(mesh, query.closest(near));
          const Eigen::Vector3f n = frame.normal();
          const Eigen::Vector3f x = Eigen::Vector3f::UnitX() - n * n.x();
          frame.basis.col(0) = x.squaredNorm() > 1e-6f ? x.normalized() : Eigen::Vector3f::UnitY();
          frame.basis.col(1) = n.cross(frame.basis.col(0));
          const auto shape = shape_of(index);
          for (int i = 0; i < points; ++i)
            curve[size_t(i)] = frame.to_world(shape(length_of(index) * float(i) / float(points - 1)));
        }
        strands.append(curve, uint64_t(index));
        ++index;
      }
    guides = bind_guides(query, strands, "cap");
    std::vector<bool> cap(mesh.triangle_count());
    for (size_t f = 0; f < mesh.triangle_count(); ++f)
      cap[f] = mesh.positions[size_t(mesh.triangles[f][0])].z() > std::cos(0.85f);
    roots = scatter_roots(mesh, root_count, 11, cap);
  }
};

size_t checker_inside(const MeshQuery &query, const StrandSet &strands) {
  std::vector<uint64_t> examples;
  return check::count_points_inside(strands, query, 0.0f, 0, examples);
}

StrandSet grow_all(const interp::Binding &binding, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
                   const StrandSet &guides, int points = 32) {
  interp::GrowOptions options;
  options.points_per_strand = points;
  StrandSet strands;
  interp::grow(binding, mesh, query, roots, guides, options, strands);
  return strands;
}

}  // namespace

TEST_CASE("binding: k nearest guides, weights sum to 1, an exact hit takes all the weight", "[interp]") {
  CapScene scene([](int) { return arc_shape(1.0f); }, 32, [](int) { return 0.8f; }, 200);
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::fur, 4));
  REQUIRE(binding.root_count() == scene.roots.size());
  for (size_t r = 0; r < binding.root_count(); ++r) {
    float total = 0.0f;
    for (int s = 0; s < 4; ++s) total += binding.weights[r * 4 + size_t(s)];
    CHECK(total == Approx(1.0f).margin(1e-5));
    // The guide with the largest weight is the nearest one.
    const Eigen::Vector3f root = surface_position(scene.mesh, scene.roots.points[r]);
    size_t nearest = 0;
    for (size_t g = 1; g < scene.guides.size(); ++g)
      if ((surface_position(scene.mesh, scene.guides.roots[g]) - root).norm() <
          (surface_position(scene.mesh, scene.guides.roots[nearest]) - root).norm())
        nearest = g;
    CHECK(binding.guide_ids[r * 4] == int32_t(nearest));
  }
  const interp::Binding at_guides =
      interp::bind(scene.mesh, scene.guides, roots_of(scene.guides), settings_for(Method::fur, 4));
  for (size_t g = 0; g < scene.guides.size(); ++g) {
    CHECK(at_guides.guide_ids[g * 4] == int32_t(g));
    CHECK(at_guides.weights[g * 4] == 1.0f);
    CHECK(at_guides.guide_ids[g * 4 + 1] == -1);
  }
  CHECK_THROWS_AS(interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::fur, 0)), InputError);
}


TEST_CASE("binding: the groom's length unit, the skin margin and the step follow the guides' median segment",
          "[interp]") {
  CapScene scene([](int) { return arc_shape(1.0f); }, 32, [](int i) { return 0.6f + 0.1f * float(i % 3); }, 50);
  std::vector<float> segments;
  for (size_t g = 0; g < scene.guides.size(); ++g)
    for (size_t j = 0; j + 1 < 32; ++j)
      segments.push_back((scene.guides.strands.points(g)[j + 1] - scene.guides.strands.points(g)[j]).norm());
  std::nth_element(segments.begin(), segments.begin() + ptrdiff_t(segments.size() / 2), segments.end());
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline));
  CHECK(binding.length_unit == segments[segments.size() / 2]);
  CHECK(binding.skin_margin == Approx(interp::default_margin_fraction * binding.length_unit));
  CHECK(binding.step == Approx(interp::step_fraction * binding.length_unit));
  // An explicit margin is kept as given (scene units).
  const interp::Binding given = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline, 4, 0.003f));
  CHECK(given.skin_margin == 0.003f);
}

TEST_CASE("a strand rooted at a guide's root is that guide, within 0.1% of its length", "[interp]") {
  // At the guide's own point count: fur and linear copy it; streamline follows its C1 curve and is
  // cut at its length.
  std::vector<Scene> scenes;
  scenes.push_back(planar_s_curves(32, 2));
  scenes.push_back(combed_layers(32, 2));
  scenes.push_back(ringlets(64, 2));
  scenes.push_back(draped_sphere(48, 2));
  scenes.push_back(random_flow(7, 32, 20, 2));
  for (const Scene &scene : scenes)
    for (const Method method : {Method::streamline, Method::fur, Method::linear}) {
      const Roots at_guides = roots_of(scene.guides);
      const StrandSet strands =
          grow_scene(scene, at_guides, settings_of(method), int(scene.guides.strands.points_in(0)));
      float worst = 0.0f;
      for (size_t g = 0; g < scene.guides.size(); ++g)
        worst = std::max(worst, guide_deviation(strands.points(g), scene.guides.strands.points(g)));
      INFO(scene.name << ", " << name_of(method) << ": largest deviation " << 100.0f * worst << "% of the guide's length");
      CHECK(worst < (method == Method::streamline ? 1e-3f : 2e-5f));
    }
  // Other point counts: the strand's points lie on the guide up to the chords' sag.
  CapScene cap([](int i) { return arc_shape(0.6f + 0.1f * float(i % 5)); }, 57, [](int i) { return 0.6f + 0.05f * float(i % 4); }, 1);
  const Roots at_guides = roots_of(cap.guides);
  for (const Method method : {Method::fur, Method::streamline, Method::linear}) {
    const interp::Binding binding = interp::bind(cap.mesh, cap.guides, at_guides, settings_for(method));
    const StrandSet strands = grow_all(binding, cap.mesh, cap.query, at_guides, cap.guides.strands, 32);
    float worst = 0.0f;
    for (size_t g = 0; g < cap.guides.size(); ++g)
      worst = std::max(worst, deviation_by_arc(strands.points(g), cap.guides.strands.points(g)) /
                                  float(cap.guides.strands.length(g)));
    INFO(name_of(method) << ": relative deviation at 32 points from guides of 57 " << worst);
    CHECK(worst < 2e-3f);
  }
}

TEST_CASE("a root within the checker's root tolerance of a guide root grows as that guide, from its own place",
          "[interp]") {
  // plume check holds every strand rooted within 1e-4 of the emitter's diagonal of a guide root to
  // that guide (0.1% of its length). Grown by the field from a root that near, a strand strays by a
  // multiple of the offset where neighbouring curves part (0.197% on Sintel at 100,000 roots, from
  // 0.003): so growth treats such a root as at the guide root, and the strand is the guide's own
  // curve after its first point, which is moved by the root's offset on the skin. Three times the
  // tolerance away (beyond twice it, the hit distance) a root is grown by the field again.
  std::vector<Scene> scenes;
  scenes.push_back(ringlets(64, 2));
  scenes.push_back(draped_sphere(48, 2));
  scenes.push_back(scaled(random_flow(8, 32, 20, 2), 100.0f));
  for (const Scene &scene : scenes) {
    Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
    for (const Eigen::Vector3f &p : scene.mesh.positions) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
    const float tolerance = float(check::kRootToleranceOfDiagonal) * (hi - lo).norm();
    const Roots at_guides = roots_of(scene.guides);
    const int n = int(scene.guides.strands.points_in(0));
    const StrandSet exact = grow_scene(scene, at_guides, settings_of(Method::streamline), n);
    for (const float times : {0.5f, 0.95f, 3.0f}) {
      std::vector<Eigen::Vector3f> places;
      for (size_t g = 0; g < scene.guides.size(); ++g) {
        const SurfaceFrame frame = surface_frame(scene.mesh, scene.guides.roots[g]);
        places.push_back(frame.origin + times * tolerance * frame.basis.col(0));
      }
      const Roots beside = roots_at(*scene.query, places);
      const StrandSet strands = grow_scene(scene, beside, settings_of(Method::streamline), n);
      for (size_t g = 0; g < scene.guides.size(); ++g) {
        bool same_after_root = true;
        for (int j = 1; j < n; ++j) same_after_root = same_after_root && strands.points(g)[j] == exact.points(g)[j];
        const float moved = (strands.points(g)[0] - exact.points(g)[0]).norm();
        INFO(scene.name << ", guide " << g << ", root " << times << " root tolerances away: first point moved "
                        << moved / tolerance << " tolerances");
        if (times < 2.0f) {
          CHECK(same_after_root);
          CHECK(moved <= 1.01f * times * tolerance);
          CHECK(moved >= 0.5f * times * tolerance);
          CHECK(curve_deviation(scene.guides, g, strands.points(g)) < 1e-3);
        } else {
          CHECK_FALSE(same_after_root);
        }
      }
    }
  }
}

TEST_CASE("a streamline strand at a guide's root lies on the guide's curve and ends at its tip, at fewer points",
          "[interp]") {
  // The checker's measure (check::guide_deviation) against the guide's curve (groom/guide_curve.h),
  // at 12 and 7 points from guides of 32 to 64: the strand's curve is as long as the guide's, so its
  // tip is the guide's. (Cutting the curve where the resampled polyline reached the guide's length
  // carried it past the tip by the chords' shortfall: 1% and more on the ringlets.)
  std::vector<Scene> scenes;
  scenes.push_back(planar_s_curves(32, 2));
  scenes.push_back(ringlets(64, 2));
  scenes.push_back(draped_sphere(48, 2));
  scenes.push_back(random_flow(7, 32, 20, 2));
  scenes.push_back(scaled(random_flow(8, 32, 20, 2), 100.0f));
  for (const Scene &scene : scenes)
    for (const int points : {12, 7}) {
      const Roots at_guides = roots_of(scene.guides);
      const StrandSet strands = grow_scene(scene, at_guides, settings_of(Method::streamline), points);
      double worst = 0.0, worst_tip = 0.0;
      for (size_t g = 0; g < scene.guides.size(); ++g) {
        double length = 0.0;
        worst = std::max(worst, curve_deviation(scene.guides, g, strands.points(g), &length));
        worst_tip = std::max(worst_tip, double((strands.points(g).back() - scene.guides.strands.points(g).back()).norm()) / length);
      }
      INFO(scene.name << " at " << points << " points: largest deviation " << 100.0 * worst << "%, tip " << 100.0 * worst_tip
                      << "% of the guide's length");
      CHECK(worst < 1e-3);
      CHECK(worst_tip < 1e-3);
    }
}

TEST_CASE("strands are the same to the bit whichever strands are grown with them, and for any thread count",
          "[interp]") {
  std::vector<Scene> scenes;
  scenes.push_back(ringlets(64, 40));
  scenes.push_back(combed_layers(32, 40));
  const int threads = omp_get_max_threads();
  for (const Scene &scene : scenes)
    for (const Method method : {Method::streamline, Method::fur, Method::linear}) {
      omp_set_num_threads(1);
      const StrandSet one = grow_scene(scene, scene.roots, settings_of(method), 32);
      omp_set_num_threads(2);
      const StrandSet all = grow_scene(scene, scene.roots, settings_of(method), 32);
      omp_set_num_threads(threads);
      REQUIRE(one.positions.size() == all.positions.size());
      CHECK(std::memcmp(one.positions.data(), all.positions.data(), all.positions.size() * sizeof(Eigen::Vector3f)) == 0);
      for (size_t r = 0; r < scene.roots.size(); r += 3) {
        Roots alone;
        alone.points = {scene.roots.points[r]};
        alone.ids = {scene.roots.ids[r]};
        // Binding one root alone gives it the same guides and weights; the length unit comes from
        // the guides.
        const StrandSet strand = grow_scene(scene, alone, settings_of(method), 32);
        const std::span<const Eigen::Vector3f> in_all = all.points(r);
        REQUIRE(strand.positions.size() == in_all.size());
        INFO(scene.name << ", " << name_of(method) << ", root " << r);
        CHECK(std::memcmp(strand.positions.data(), in_all.data(), in_all.size() * sizeof(Eigen::Vector3f)) == 0);
      }
    }
}

TEST_CASE("planar guides: streamline strands never intersect (exact 2-D test) and keep their order", "[interp]") {
  // S-curves of different lengths, amplitudes and phases, roots between and outside them; the
  // strands lie in the guides' plane, so an exact orientation test decides every intersection.
  const Scene scene = planar_s_curves(32, 50);
  REQUIRE(planar_intersections(scene.guides.strands) == 0);
  const StrandSet strands = grow_scene(scene, scene.roots, settings_of(Method::streamline), 32);
  for (const Eigen::Vector3f &p : strands.positions) REQUIRE(p.y() == 0.0f);
  CHECK(planar_intersections(strands) == 0);
  // Order: every point of strand i + 1 stays on the same side of strand i (roots go along +x).
  size_t out_of_order = 0;
  for (size_t s = 0; s + 1 < strands.strand_count(); ++s)
    for (const Eigen::Vector3f &q : strands.points(s + 1).subspan(1)) {
      float best = INFINITY;
      double side = 0.0;
      const auto line = strands.points(s);
      for (size_t u = 0; u + 1 < line.size(); ++u) {
        const float d = segment_distance(line[u], line[u + 1], q, q);
        if (d < best) {
          best = d;
          side = orient_xz(line[u], line[u + 1], q);
        }
      }
      out_of_order += side >= 0.0;
    }
  CHECK(out_of_order == 0);
  std::vector<uint64_t> examples;
  CHECK(check::count_points_inside(strands, *scene.query, 0.0f, 0, examples) == 0);
  // Linear blending, the baseline, crosses here.
  CHECK(planar_intersections(grow_scene(scene, scene.roots, settings_of(Method::linear), 32)) > 0);
}

TEST_CASE("the planar arch: bunched streamline strands intersect in no more pairs than measured (a known failure)",
          "[interp]") {
  // Guide A (1.5 long) and guide B (3.6 long) rising beside it, arching over A's tip and curling back
  // down on A's far side; roots between them and outside. The promise is 0 intersecting pairs (exact
  // 2-D test) at any written point count; the field still brings strands rooted between the guides
  // together inside B's arch until their curves coincide, and their polylines, sampling one curve at
  // staggered arc lengths, cross (docs/interpolation.md, "What is guaranteed" and "Bunching"). The
  // bounds are the counts measured on 2026-11-28: a change to the field must not raise them, and
  // one that solves the arch brings them to 0.
  struct Case {
    int roots, points;
    size_t measured;
  };
  for (const Case &c : {Case{40, 24, 24}, Case{40, 32, 10}, Case{40, 48, 5}, Case{60, 24, 54}, Case{60, 32, 30},
                        Case{60, 48, 13}, Case{100, 24, 185}, Case{100, 32, 111}, Case{100, 48, 66}}) {
    const Scene scene = planar_arch(32, c.roots);
    INFO(c.roots << " roots, " << c.points << " points");
    StrandSet strands = grow_scene(scene, scene.roots, settings_of(Method::streamline), c.points);
    std::vector<uint64_t> examples;
    CHECK(check::count_points_inside(strands, *scene.query, 0.0f, 0, examples) == 0);
    CHECK(all_finite(strands));
    size_t off_plane = 0;
    for (Eigen::Vector3f &p : strands.positions) {
      off_plane += p.y() != 0.0f;
      p = Eigen::Vector3f(p.x(), p.z(), 0.0f);  // the plane the exact test reads
    }
    REQUIRE(off_plane == 0);
    const size_t pairs = exact_intersecting_pairs(strands).size();
    INFO(pairs << " intersecting pairs");
    CHECK(pairs <= c.measured);
  }
}

TEST_CASE("hard scenes: streamline strands do not cross, no method leaves a point inside the skin or a NaN",
          "[interp]") {
  // Layered combed guides over a curved patch, ringlets of several turns and phases, guides of 1x to
  // 4x lengths draped over a closed sphere. Crossings as the checker counts them, at a thousandth of
  // the strands' median segment.
  std::vector<Scene> scenes;
  scenes.push_back(combed_layers(32, 300));
  scenes.push_back(ringlets(64, 200));
  scenes.push_back(draped_sphere(48, 400));
  for (const Scene &scene : scenes) {
    std::vector<uint64_t> examples;
    REQUIRE(check::count_points_inside(scene.guides.strands, *scene.query, 0.0f, 0, examples) == 0);
    for (const Method method : {Method::streamline, Method::fur, Method::linear}) {
      const StrandSet strands =
          grow_scene(scene, scene.roots, settings_of(method), int(scene.guides.strands.points_in(0)));
      INFO(scene.name << ", " << name_of(method));
      CHECK(all_finite(strands));
      CHECK(check::count_points_inside(strands, *scene.query, 0.0f, 0, examples) == 0);
      if (method == Method::streamline)
        CHECK(check::count_crossings(strands, 1e-3f * median_segment(strands), 0).pairs == 0);
    }
  }
}

TEST_CASE("random non-crossing guide sets: streamline strands never cross and never enter the skin", "[interp]") {
  // Guides traced through one smooth random rising field (so they never meet), of lengths varying
  // 3x, from random roots; many seeds.
  for (uint64_t seed = 100; seed < 112; ++seed) {
    const Scene scene = random_flow(seed, 32, 16, 80);
    const StrandSet strands = grow_scene(scene, scene.roots, settings_of(Method::streamline), 32);
    std::vector<uint64_t> examples;
    INFO("seed " << seed);
    CHECK(all_finite(strands));
    CHECK(check::count_crossings(strands, 1e-3f * median_segment(strands), 0).pairs == 0);
    CHECK(check::count_points_inside(strands, *scene.query, 0.0f, 0, examples) == 0);
  }
}

TEST_CASE("partings: with a hard or a partial parting, no crossings, no point inside, strands comb away on each side",
          "[interp]") {
  for (const bool hard : {true, false}) {
    PartingSettings parting_settings;
    const Scene scene = parted_sphere(hard, parting_settings);
    const partings::PartingField field(scene.mesh, scene.guides, parting_settings);
    const StrandSet strands = grow_scene(scene, scene.roots, settings_of(Method::streamline), 32, nullptr, &field);
    std::vector<uint64_t> examples;
    INFO(scene.name);
    CHECK(all_finite(strands));
    CHECK(check::count_points_inside(strands, *scene.query, 0.0f, 0, examples) == 0);
    CHECK(check::count_crossings(strands, 1e-3f * median_segment(strands), 0).pairs == 0);
    // Every strand rooted within 0.15 of the parting, and not past a partial line's ends, goes the
    // way its side combs: its tip is farther from the parting than its root, on the same side.
    size_t wrong_way = 0, near_line = 0;
    for (size_t r = 0; r < strands.strand_count(); ++r) {
      const auto points = strands.points(r);
      if (std::abs(points[0].y()) > 0.15f || std::abs(points[0].x()) > 0.3f) continue;
      ++near_line;
      wrong_way += !(points.back().y() * points[0].y() > 0.0f && std::abs(points.back().y()) > std::abs(points[0].y()));
    }
    INFO(wrong_way << " of " << near_line << " strands beside the parting go the wrong way");
    CHECK(near_line > 20);
    CHECK(wrong_way == 0);
  }
}

TEST_CASE("growth's clearance is a lower bound of every point's signed distance, at least the margin past the root",
          "[interp]") {
  const Scene scene = combed_layers(32, 150);
  for (const Method method : {Method::streamline, Method::fur, Method::linear}) {
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_of(method));
    interp::GrowOptions options;
    StrandSet strands;
    std::vector<float> clearance;
    interp::grow(binding, scene.mesh, *scene.query, scene.roots, scene.guides.strands, options, strands, &clearance);
    REQUIRE(clearance.size() == strands.positions.size());
    size_t above = 0, below_margin = 0;
    for (size_t j = 0; j < strands.positions.size(); ++j) {
      above += clearance[j] > scene.query->signed_distance(strands.positions[j]) + 1e-5f;
      below_margin += j % 32 != 0 && scene.query->signed_distance(strands.positions[j]) < 0.5f * binding.skin_margin;
    }
    INFO(name_of(method));
    CHECK(above == 0);
    if (method == Method::streamline) CHECK(below_margin == 0);
  }
}

TEST_CASE("a rigid motion of emitter and guides moves every strand rigidly", "[interp]") {
  CapScene scene([](int i) { return arc_shape(0.5f + 0.2f * float(i % 3)); }, 24, [](int) { return 0.7f; }, 300);
  const Eigen::Affine3f motion =
      Eigen::Translation3f(0.3f, -0.2f, 0.5f) * Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized());
  Mesh moved_mesh = scene.mesh;
  for (Eigen::Vector3f &p : moved_mesh.positions) p = motion * p;
  moved_mesh.compute_normals();
  const MeshQuery moved_query(moved_mesh);
  StrandSet moved_guides = scene.guides.strands;
  for (Eigen::Vector3f &p : moved_guides.positions) p = motion * p;

  for (const Method method : {Method::fur, Method::streamline, Method::linear}) {
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(method));
    const StrandSet rest = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    const StrandSet moved = grow_all(binding, moved_mesh, moved_query, scene.roots, moved_guides);
    float worst = 0.0f;
    for (size_t s = 0; s < rest.strand_count(); ++s)
      for (int64_t p = 0; p < rest.points_in(s); ++p)
        worst = std::max(worst, (motion * rest.points(s)[p] - moved.points(s)[p]).norm() / float(rest.length(s)));
    INFO(name_of(method) << ": worst deviation / strand length " << worst);
    // Float rounding, and the discrete choices it can flip where a test sits on its threshold (a
    // streamline step accepted or redone shorter, a fur or linear segment walked in one step or in
    // sub-steps near the skin): the rest of that strand then moves by the integration's own error,
    // a few 1e-4 of its length at most. A frame or rotation error would show at 1e-2.
    CHECK(worst <= 1e-3f);
  }
}

TEST_CASE("a groom scaled by 0.01 or by 100 gives the same strands, scaled: no default is in absolute units",
          "[interp]") {
  // Curls and arcs that lean onto the skin, so that the skin margin acts on the strands.
  CapScene scene([](int i) { return arc_shape(i % 2 ? 2.5f : 0.9f + 0.1f * float(i % 3)); }, 32,
                 [](int i) { return 0.5f + 0.15f * float(i % 4); }, 400);
  for (const Method method : {Method::fur, Method::streamline, Method::linear}) {
    const InterpolationSettings settings = settings_for(method, 4, -1.0f);  // the automatic margin
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings);
    const StrandSet unit = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    for (const float scale : {0.01f, 100.0f}) {
      Mesh mesh = scene.mesh;
      for (Eigen::Vector3f &p : mesh.positions) p *= scale;
      mesh.compute_normals();
      const MeshQuery query(mesh);
      Guides guides = scene.guides;
      for (Eigen::Vector3f &p : guides.strands.positions) p *= scale;
      const interp::Binding scaled_binding = interp::bind(mesh, guides, scene.roots, settings);
      CHECK(scaled_binding.skin_margin == Approx(scale * binding.skin_margin).epsilon(1e-5));
      const StrandSet scaled = grow_all(scaled_binding, mesh, query, scene.roots, guides.strands);
      REQUIRE(scaled.positions.size() == unit.positions.size());
      float worst = 0.0f;
      for (size_t s = 0; s < unit.strand_count(); ++s)
        for (int64_t p = 0; p < unit.points_in(s); ++p)
          worst = std::max(worst, (scale * unit.points(s)[p] - scaled.points(s)[p]).norm() /
                                      (scale * float(unit.length(s))));
      INFO(name_of(method) << " scaled by " << scale << ": worst deviation / strand length " << worst);
      // Float rounding, and the discrete choices rounding may flip: streamline's accepted or rejected
      // steps, fur's and linear's sub-steps through the skin band (see the rigid-motion test). A
      // length kept in scene units (a margin of 0.005 on strands of 0.5 to 1.0) would move points by
      // about 1e-2 of the length at 100x and far more at 0.01x.
      CHECK(worst <= (method == Method::streamline ? 1e-3f : 1e-4f));
      CHECK(checker_inside(query, scaled) == 0);
    }
  }
}

TEST_CASE("fur where the skin turns sharply (an ear below the scalp's guides): guides are turned by at most 30 degrees",
          "[interp]") {
  // A plane folded down along x = 0 (a 90-degree edge): guides stand on the flat part, leaning a
  // little towards the edge; roots on the wall below the edge take them. Carried whole, the guides
  // would turn with the skin's normal by 90 degrees and stick straight out of the wall.
  Mesh mesh = make_plane(2.0f, 40);
  for (Eigen::Vector3f &p : mesh.positions)
    if (p.x() > 0.0f) p = Eigen::Vector3f(0.0f, p.y(), -p.x());
  mesh.compute_normals();
  const MeshQuery query(mesh);
  StrandSet strands;
  const Eigen::Vector3f lean = Eigen::Vector3f(0.3f, 0.0f, 1.0f).normalized();
  for (int i = 0; i < 9; ++i) {
    const Eigen::Vector3f root(-0.15f - 0.1f * float(i % 3), -0.3f + 0.3f * float(i / 3), 0.0f);
    std::vector<Eigen::Vector3f> curve;
    for (int j = 0; j < 16; ++j) curve.push_back(root + 0.04f * float(j) * lean);
    strands.append(curve, uint64_t(i));
  }
  const Guides guides = bind_guides(query, strands, "flat");
  std::vector<Eigen::Vector3f> places;
  for (int i = 0; i < 60; ++i) places.emplace_back(0.0f, -0.3f + 0.01f * float(i), -0.05f - 0.002f * float(i % 7));
  const Roots roots = roots_at(query, places);
  const interp::Binding binding = interp::bind(mesh, guides, roots, settings_for(Method::fur));
  const StrandSet grown = grow_all(binding, mesh, query, roots, guides.strands, 16);
  float worst = 0.0f;
  for (size_t s = 0; s < grown.strand_count(); ++s) {
    const Eigen::Vector3f first = (grown.points(s)[1] - grown.points(s)[0]).normalized();
    worst = std::max(worst, std::acos(std::clamp(first.dot(lean), -1.0f, 1.0f)) * 180.0f / float(M_PI));
  }
  INFO("largest turn of a strand's first segment from the guides' " << worst << " degrees");
  CHECK(worst <= 30.5f);
  CHECK(worst >= 20.0f);  // the wall's strands do turn with the skin, as far as the cap lets them
  CHECK(checker_inside(query, grown) == 0);
}

TEST_CASE("the thread count does not change binding or strands", "[interp]") {
  CapScene scene([](int i) { return arc_shape(0.5f + 0.2f * float(i % 3)); }, 24, [](int) { return 0.7f; }, 500);
  const int threads = omp_get_max_threads();
  for (const Method method : {Method::fur, Method::streamline, Method::linear}) {
    omp_set_num_threads(1);
    const interp::Binding one = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(method));
    const StrandSet a = grow_all(one, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    omp_set_num_threads(2);
    const interp::Binding two = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(method));
    const StrandSet b = grow_all(two, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    CHECK(one.guide_ids == two.guide_ids);
    CHECK(one.weights == two.weights);
    REQUIRE(a.positions.size() == b.positions.size());
    CHECK(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Eigen::Vector3f)) == 0);
  }
  omp_set_num_threads(threads);
}

TEST_CASE("near a guide, the deviation from it shrinks to 0 as the root approaches the guide root", "[interp]") {
  CapScene scene([](int i) { return arc_shape(0.5f + 0.3f * float(i % 3)); }, 32, [](int) { return 0.8f; }, 1);
  const size_t guide = 9;  // on the ring theta = 0.3
  const SurfaceFrame frame = surface_frame(scene.mesh, scene.guides.roots[guide]);
  for (const Method method : {Method::streamline, Method::fur}) {
    float previous = INFINITY;
    for (const float distance : {0.1f, 0.03f, 0.01f, 0.003f, 0.001f}) {
      const Roots roots = roots_at(scene.query, {frame.origin + distance * frame.basis.col(1)});
      const interp::Binding binding = interp::bind(scene.mesh, scene.guides, roots, settings_for(method));
      const StrandSet strands = grow_all(binding, scene.mesh, scene.query, roots, scene.guides.strands);
      const float deviation = max_point_distance(strands, 0, scene.guides.strands, guide);
      INFO(name_of(method) << " at " << distance << ": deviation " << deviation);
      CHECK(deviation < previous);
      CHECK(deviation < 3.0f * distance);
      previous = deviation;
    }
  }
}

TEST_CASE("frame coherence: a small guide motion moves no strand point more than 1.5x the guides' motion", "[interp]") {
  CapScene scene([](int i) { return arc_shape(0.5f + 0.2f * float(i % 3)); }, 32, [](int) { return 0.8f; }, 300);
  // Each guide turns a little about its root, about an axis of its own.
  StrandSet moved = scene.guides.strands;
  for (size_t g = 0; g < moved.strand_count(); ++g) {
    const Eigen::Vector3f axis = Eigen::Vector3f(std::sin(1.7f * float(g)), std::cos(2.3f * float(g)), 0.5f).normalized();
    const Eigen::Matrix3f turn = Eigen::AngleAxisf(0.01f, axis).toRotationMatrix();
    const Eigen::Vector3f root = moved.points(g)[0];
    for (Eigen::Vector3f &p : moved.points_for_write(g)) p = root + turn * (p - root);
  }
  for (const Method method : {Method::streamline, Method::fur}) {
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(method));
    const StrandSet before = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    const StrandSet after = grow_all(binding, scene.mesh, scene.query, scene.roots, moved);
    float worst_ratio = 0.0f;
    for (size_t s = 0; s < before.strand_count(); ++s)
      for (int64_t p = 1; p < before.points_in(s); ++p) {
        float guide_motion = 0.0f;
        for (int slot = 0; slot < binding.k; ++slot) {
          const int32_t g = binding.guide_ids[s * size_t(binding.k) + size_t(slot)];
          if (g >= 0)
            guide_motion = std::max(guide_motion, (moved.points(size_t(g))[p] - scene.guides.strands.points(size_t(g))[p]).norm());
        }
        const float motion = (after.points(s)[p] - before.points(s)[p]).norm();
        worst_ratio = std::max(worst_ratio, motion / (guide_motion + 1e-6f));
      }
    INFO(name_of(method) << ": largest strand motion / guide motion " << worst_ratio);
    CHECK(worst_ratio <= 1.5f);
  }
}

TEST_CASE("degenerate guides and far roots give finite strands, out of the skin", "[interp]") {
  const Mesh mesh = make_plane(4.0f, 8);
  const MeshQuery query(mesh);
  StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}}, 0);  // 2 points
  strands.append(std::vector<Eigen::Vector3f>{{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 1.0f}}, 1);  // coincident
  strands.append(std::vector<Eigen::Vector3f>{{0.5f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.0f}, {0.5f, 0.0f, 0.5f},
                                              {0.5f, 0.0f, 0.5f}, {0.6f, 0.0f, 0.9f}},
                 2);  // zero-length segments
  strands.append(std::vector<Eigen::Vector3f>{{-0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}, {-0.5f, 0.5f, 0.0f}},
                 3);  // zero length
  // Two guides meeting at their tips (the paper's singular case), and one lying into the skin.
  strands.append(std::vector<Eigen::Vector3f>{{-0.3f, -0.5f, 0.0f}, {-0.15f, -0.5f, 0.5f}, {0.0f, -0.5f, 1.0f}}, 4);
  strands.append(std::vector<Eigen::Vector3f>{{0.3f, -0.5f, 0.0f}, {0.15f, -0.5f, 0.5f}, {0.0f, -0.5f, 1.0f}}, 5);
  strands.append(std::vector<Eigen::Vector3f>{{1.0f, 1.0f, 0.0f}, {1.5f, 1.0f, -0.3f}, {2.0f, 1.0f, -0.2f}}, 6);
  const Guides guides = bind_guides(query, strands, "degenerate");
  const Roots roots = roots_at(query, {{0.0f, 0.0f, 0.0f},   {0.5f, 0.0f, 0.0f},  {-0.5f, 0.5f, 0.0f},
                                       {0.0f, -0.5f, 0.0f},  {-0.1f, -0.5f, 0.0f}, {0.25f, 0.0f, 0.0f},
                                       {1.9f, -1.9f, 0.0f},  {1.2f, 1.0f, 0.0f},   {-1.9f, 1.9f, 0.0f}});
  for (const Method method : {Method::fur, Method::streamline, Method::linear})
    for (const int points : {2, 3, 32}) {
      const interp::Binding binding = interp::bind(mesh, guides, roots, settings_for(method));
      const StrandSet grown = grow_all(binding, mesh, query, roots, guides.strands, points);
      INFO(name_of(method) << ", " << points << " points per strand");
      CHECK(all_finite(grown));
      CHECK(count_inside(query, grown) == 0);
    }
  // Roots on the far side of a sphere from every guide.
  CapScene scene([](int) { return arc_shape(1.0f); }, 16, [](int) { return 0.8f; }, 1);
  const Roots far = roots_at(scene.query, {{0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, -0.2f}, {-1.0f, 0.0f, 0.0f}});
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, far, settings_for(Method::streamline));
  const StrandSet grown = grow_all(binding, scene.mesh, scene.query, far, scene.guides.strands);
  CHECK(all_finite(grown));
  CHECK(count_inside(scene.query, grown) == 0);
}

TEST_CASE("binding with hard zones: no influence across zones, a zone without guides is an error", "[interp]") {
  Mesh mesh = make_plane(4.0f, 8);
  mesh.group_names = {"left", "right"};
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::Vector3i &t = mesh.triangles[f];
    const float x = (mesh.positions[size_t(t[0])].x() + mesh.positions[size_t(t[1])].x() + mesh.positions[size_t(t[2])].x()) / 3.0f;
    mesh.triangle_groups[f] = x < 0.0f ? 0 : 1;
  }
  const MeshQuery query(mesh);
  StrandSet strands;
  for (int i = 0; i < 6; ++i) {
    const float x = -1.25f + 0.5f * float(i), y = 0.3f * float(i % 3) - 0.3f;
    strands.append(std::vector<Eigen::Vector3f>{{x, y, 0.0f}, {x, y, 0.5f}, {x + 0.2f, y, 1.0f}}, uint64_t(i));
  }
  const Guides guides = bind_guides(query, strands, "zones");
  PartingSettings zones;
  zones.zone_source = PartingSettings::ZoneSource::face_groups;
  const partings::PartingField field(mesh, guides, zones);
  const Roots roots = scatter_roots(mesh, 400, 3);
  for (const Method method : {Method::streamline, Method::fur}) {
    const interp::Binding binding = interp::bind(mesh, guides, roots, settings_for(method), &field);
    size_t across = 0;
    for (size_t r = 0; r < roots.size(); ++r)
      for (int s = 0; s < binding.k; ++s) {
        const int32_t g = binding.guide_ids[r * size_t(binding.k) + size_t(s)];
        if (g >= 0) across += field.guide_zone(size_t(g)) != field.zone_of(roots.points[r]);
      }
    CHECK(across == 0);
    const StrandSet grown = grow_all(binding, mesh, query, roots, guides.strands);
    CHECK(all_finite(grown));
  }
  // Guides only on the left: the right zone's roots have no guide.
  StrandSet left;
  for (size_t g = 0; g < 3; ++g) left.append(strands.points(g), g);
  const Guides left_guides = bind_guides(query, left, "left");
  const partings::PartingField left_field(mesh, left_guides, zones);
  CHECK_THROWS_AS(interp::bind(mesh, left_guides, roots, settings_for(Method::streamline), &left_field), InputError);
}
