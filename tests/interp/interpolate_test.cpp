// Promises of bind() and grow(): guides reproduced at their roots, rigid motion, thread-count
// independence, no crossings and no points in the skin for streamline-ratio, coherence, no NaN.
#include <catch2/catch.hpp>
#include <omp.h>

#include <algorithm>
#include <cstring>

#include "check/check.h"
#include "interp/interp_fixtures.h"
#include "interp/interpolate.h"

using namespace plume;
using namespace plume::test;
using Method = InterpolationSettings::Method;

namespace {

InterpolationSettings settings_for(Method method, int k = 4, float margin = 0.005f) {
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

// The checker's counts (check/check.h), as `plume check` reports them.
size_t checker_crossings(const StrandSet &strands) { return check::count_crossings(strands, 2e-4f, 0).pairs; }
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

TEST_CASE("a strand rooted at a guide's root is that guide", "[interp]") {
  for (const int guide_points : {32, 20, 57}) {
    CapScene scene([](int i) { return arc_shape(0.6f + 0.1f * float(i % 5)); }, guide_points,
                   [](int i) { return 0.6f + 0.05f * float(i % 4); }, 10);
    const Roots at_guides = roots_of(scene.guides);
    for (const Method method : {Method::fur, Method::streamline, Method::linear}) {
      const interp::Binding binding = interp::bind(scene.mesh, scene.guides, at_guides, settings_for(method));
      const StrandSet strands = grow_all(binding, scene.mesh, scene.query, at_guides, scene.guides.strands);
      float worst = 0.0f;
      for (size_t g = 0; g < scene.guides.size(); ++g)
        worst = std::max(worst, deviation_by_arc(strands.points(g), scene.guides.strands.points(g)) /
                                    float(scene.guides.strands.length(g)));
      INFO(name_of(method) << ", guides of " << guide_points << " points: relative deviation " << worst);
      // Same point count: the guide itself. Other counts: the strand's points lie on the guide up to
      // the chord of one step across a guide vertex.
      CHECK(worst < (guide_points == 32 ? 2e-5f : 2e-3f));
    }
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
    // Float rounding alone: 1e-6. Streamline growth also makes discrete choices per step (substeps
    // near a guide, a predicted or a full midpoint step), and rounding can flip one where its test sits
    // on the threshold; the rest of that strand then moves by the steps' local error, about 2e-5 of
    // its length. A frame or rotation error would show at 1e-2.
    CHECK(worst <= (method == Method::streamline ? 1e-4f : 1e-5f));
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
      // Float rounding, and for streamline a discrete choice per step that rounding may flip (see the
      // rigid-motion test). A length kept in scene units (a margin of 0.005 on strands of 0.5 to 1.0)
      // would move points by about 1e-2 of the length at 100x and far more at 0.01x.
      CHECK(worst <= (method == Method::streamline ? 1e-4f : 1e-5f));
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

TEST_CASE("a streamline strand is the same to the bit whichever strands are grown with it", "[interp]") {
  // A strand must not depend on the strands grown in the same call (their order, their count, what
  // a thread grows before it): gentle arcs and tight curls (where the pace term acts), guides of
  // several lengths (so neighbours step differently), and k = 5 and 6: a full and a partial group of
  // four guides, and (where growth searches two guide slots side by side) an odd last slot. Roots at
  // the guides' own roots too, whose strands hit their guide (distance 0) from the first step on.
  const auto helix = [](int i) {
    const float radius = 0.04f, rise = 0.02f, phase = 0.5f * float(i);
    return std::function<Eigen::Vector3f(float)>([=](float s) {
      const float turn = s / std::sqrt(radius * radius + rise * rise);
      return Eigen::Vector3f(radius * (std::cos(turn + phase) - std::cos(phase)),
                             radius * (std::sin(turn + phase) - std::sin(phase)), rise * turn);
    });
  };
  const CapScene arcs([](int i) { return arc_shape(0.5f + 0.2f * float(i % 3)); }, 24,
                      [](int i) { return 0.5f + 0.1f * float(i % 4); }, 41);
  const CapScene curls(helix, 64, [](int i) { return 0.8f + 0.1f * float(i % 4); }, 41, true);
  for (const CapScene *scene : {&arcs, &curls}) {
    const Roots at_guides = roots_of(scene->guides);
    for (const int k : {4, 5, 6})
      for (const Roots *roots : {&scene->roots, &at_guides}) {
        const InterpolationSettings settings = settings_for(Method::streamline, k);
        const interp::Binding binding = interp::bind(scene->mesh, scene->guides, *roots, settings);
        const StrandSet all = grow_all(binding, scene->mesh, scene->query, *roots, scene->guides.strands);
        for (size_t r = 0; r < roots->size(); r += roots == &at_guides ? 1 : 3) {
          Roots alone;
          alone.points = {roots->points[r]};
          alone.ids = {roots->ids[r]};
          const interp::Binding single = interp::bind(scene->mesh, scene->guides, alone, settings);
          const StrandSet strand = grow_all(single, scene->mesh, scene->query, alone, scene->guides.strands);
          const std::span<const Eigen::Vector3f> in_all = all.points(r);
          REQUIRE(strand.positions.size() == in_all.size());
          CHECK(std::memcmp(strand.positions.data(), in_all.data(), in_all.size() * sizeof(Eigen::Vector3f)) == 0);
        }
      }
  }
}

namespace {

/// Paper, Figure 4: two guides in the plane y = 0 over the skin z = 0. Guide A rises straight up;
/// guide B leans low towards A, then rises beside it, so the channel between them narrows.
struct PlanarScene {
  Mesh mesh = make_plane(4.0f, 8);
  MeshQuery query{mesh};
  Guides guides;
  Roots roots;

  PlanarScene() {
    StrandSet strands;
    std::vector<Eigen::Vector3f> a, b;
    const int n = 32;
    const float length = 1.5f;
    for (int i = 0; i < n; ++i) a.emplace_back(-0.5f, 0.0f, length * float(i) / float(n - 1));
    const float lean = 20.0f * float(M_PI) / 180.0f;
    const float lean_length = 0.8f / std::cos(lean);
    const std::vector<Eigen::Vector3f> corner{{0.5f, 0.0f, 0.0f},
                                              {-0.3f, 0.0f, lean_length * std::sin(lean)},
                                              {-0.3f, 0.0f, lean_length * std::sin(lean) + length - lean_length}};
    for (int i = 0; i < n; ++i) b.push_back(point_at_arc(corner, length * float(i) / float(n - 1)));
    strands.append(a, 0);
    strands.append(b, 1);
    guides = bind_guides(query, strands, "planar");
    for (int i = 1; i < 20; ++i) {
      roots.points.push_back(query.closest(Eigen::Vector3f(-0.5f + float(i) / 20.0f, 0.0f, 0.0f)));
      roots.ids.push_back(uint64_t(i));
    }
  }
};

float cross2(const Eigen::Vector3f &u, const Eigen::Vector3f &v) { return u.x() * v.z() - u.z() * v.x(); }

/// Pairs of strands (in the XZ plane) whose segments properly intersect.
size_t planar_crossings(const StrandSet &strands) {
  size_t pairs = 0;
  for (size_t i = 0; i < strands.strand_count(); ++i)
    for (size_t j = i + 1; j < strands.strand_count(); ++j) {
      const auto a = strands.points(i), b = strands.points(j);
      bool crossed = false;
      for (size_t u = 0; u + 1 < a.size() && !crossed; ++u)
        for (size_t v = 0; v + 1 < b.size() && !crossed; ++v) {
          const float d1 = cross2(a[u + 1] - a[u], b[v] - a[u]), d2 = cross2(a[u + 1] - a[u], b[v + 1] - a[u]);
          const float d3 = cross2(b[v + 1] - b[v], a[u] - b[v]), d4 = cross2(b[v + 1] - b[v], a[u + 1] - b[v]);
          crossed = ((d1 > 0) != (d2 > 0)) && ((d3 > 0) != (d4 > 0)) && d1 != 0 && d2 != 0 && d3 != 0 && d4 != 0;
        }
      pairs += crossed;
    }
  return pairs;
}

/// Side of q relative to a polyline in the XZ plane (sign of the cross product with its closest segment).
float side_of(std::span<const Eigen::Vector3f> line, const Eigen::Vector3f &q) {
  float best = INFINITY, side = 0.0f;
  for (size_t u = 0; u + 1 < line.size(); ++u) {
    const float distance = segment_distance(line[u], line[u + 1], q, q);
    if (distance < best) {
      best = distance;
      side = cross2(line[u + 1] - line[u], q - line[u]);
    }
  }
  return side;
}

}  // namespace

TEST_CASE("planar two-guide problem: streamline keeps the strands apart and in order, linear crosses", "[interp]") {
  PlanarScene scene;
  REQUIRE(planar_crossings(scene.guides.strands) == 0);

  const interp::Binding streamline = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline, 2));
  const StrandSet strands = grow_all(streamline, scene.mesh, scene.query, scene.roots, scene.guides.strands);
  CHECK(planar_crossings(strands) == 0);
  // Order: every point of strand i + 1 stays on the same side (towards guide B) of strand i.
  size_t out_of_order = 0;
  for (size_t s = 0; s + 1 < strands.strand_count(); ++s)
    for (const Eigen::Vector3f &q : strands.points(s + 1).subspan(1)) out_of_order += side_of(strands.points(s), q) >= 0.0f;
  CHECK(out_of_order == 0);
  for (const Eigen::Vector3f &p : strands.positions) CHECK(std::abs(p.y()) < 1e-6f);
  CHECK(count_inside(scene.query, strands) == 0);

  const interp::Binding linear = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::linear, 2));
  const StrandSet blended = grow_all(linear, scene.mesh, scene.query, scene.roots, scene.guides.strands);
  CHECK(planar_crossings(blended) > 0);
}

TEST_CASE("streamline over a curved patch: no crossing pairs and no point inside the skin", "[interp]") {
  SECTION("layered arcs combed one way") {
    CapScene scene([](int) { return arc_shape(1.2f); }, 32, [](int) { return 1.0f; }, 120);
    REQUIRE(count_inside(scene.query, scene.guides.strands) == 0);
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline));
    const StrandSet strands = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    CHECK(checker_crossings(strands) == 0);
    CHECK(checker_inside(scene.query, strands) == 0);
  }
  SECTION("guides of unequal length and point count") {
    CapScene scene([](int i) { return arc_shape(0.4f + 0.15f * float(i % 4)); }, 24,
                   [](int i) { return 0.5f + 0.25f * float(i % 4); }, 120);
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline));
    const StrandSet strands = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    CHECK(checker_crossings(strands) == 0);
    CHECK(checker_inside(scene.query, strands) == 0);
  }
}

// Away from the root the guides' own clearances bound each point where the field is evaluated, so
// growth proves points far from the skin without a query, and hands the effects stack bounds nearer
// the true distances. On these arcs the skin checks alone prove a median of about 0.22 of the
// distance over the outer halves of the strands (10th percentile 0.05); with the guides' bounds
// about 0.37 (0.16).
TEST_CASE("streamline growth's clearance: a lower bound, and the guides' bounds tighten it away from the root", "[interp]") {
  CapScene scene([](int) { return arc_shape(1.2f); }, 32, [](int) { return 1.0f; }, 300);
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline));
  interp::GrowOptions options;
  options.points_per_strand = 32;
  StrandSet strands;
  std::vector<float> clearance;
  interp::grow(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands, options, strands, &clearance);
  REQUIRE(clearance.size() == strands.positions.size());
  std::vector<float> ratios;
  for (size_t r = 0; r < strands.strand_count(); ++r)
    for (int64_t j = strands.offsets[r]; j < strands.offsets[r + 1]; ++j) {
      const float exact = scene.query.signed_distance(strands.positions[size_t(j)]);
      CHECK(clearance[size_t(j)] <= exact + 1e-5f);
      if (j - strands.offsets[r] >= 16) ratios.push_back(clearance[size_t(j)] / exact);
    }
  std::sort(ratios.begin(), ratios.end());
  INFO("clearance / distance over the outer halves: 10th percentile " << ratios[ratios.size() / 10] << ", median "
                                                                       << ratios[ratios.size() / 2]);
  CHECK(ratios[ratios.size() / 10] > 0.1f);
  CHECK(ratios[ratios.size() / 2] > 0.3f);
}

// Ringlets combed in phase, with coils (radius 0.04) far tighter than the guide spacing: the closest
// point on a far guide must keep pace along its coils instead of jumping round them.
TEST_CASE("streamline over curly guides: no crossing pairs and no point inside the skin", "[interp]") {
    const auto helix = [](int) {
      const float radius = 0.04f, rise = 0.02f, phase = 0.0f;
      return std::function<Eigen::Vector3f(float)>([=](float s) {
        const float turn = s / std::sqrt(radius * radius + rise * rise);
        return Eigen::Vector3f(radius * (std::cos(turn + phase) - std::cos(phase)),
                               radius * (std::sin(turn + phase) - std::sin(phase)), rise * turn);
      });
    };
    CapScene scene(helix, 64, [](int) { return 1.0f; }, 120, true);
    REQUIRE(count_inside(scene.query, scene.guides.strands) == 0);
    const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline));
    const StrandSet strands = grow_all(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands);
    CHECK(checker_crossings(strands) == 0);
    CHECK(checker_inside(scene.query, strands) == 0);
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

TEST_CASE("near a guide, steps are split only where the field turns: not along guides that run alike, where guides meet at an angle",
          "[interp]") {
  // Roots within half a step of a guide root (h = 0.8 / 31), eight around each guide of the cap.
  CapScene scene([](int i) { return arc_shape(0.5f + 0.3f * float(i % 3)); }, 32, [](int) { return 0.8f; }, 1);
  std::vector<Eigen::Vector3f> near_roots;
  for (size_t g = 0; g < scene.guides.size(); ++g) {
    const SurfaceFrame frame = surface_frame(scene.mesh, scene.guides.roots[g]);
    for (const float distance : {0.002f, 0.005f, 0.01f})
      for (int a = 0; a < 8; ++a) {
        const float angle = 2.0f * float(M_PI) * float(a) / 8.0f;
        near_roots.push_back(frame.origin + distance * (std::cos(angle) * frame.basis.col(0) + std::sin(angle) * frame.basis.col(1)));
      }
  }
  auto stats_of = [](const Mesh &mesh, const MeshQuery &query, const Guides &guides, const Roots &roots, int k) {
    const interp::Binding binding = interp::bind(mesh, guides, roots, settings_for(Method::streamline, k));
    interp::GrowOptions options;
    interp::GrowStats stats;
    options.r_stats = &stats;
    StrandSet strands;
    interp::grow(binding, mesh, query, roots, guides.strands, options, strands);
    return stats;
  };
  const interp::GrowStats alike = stats_of(scene.mesh, scene.query, scene.guides, roots_at(scene.query, near_roots), 4);
  INFO("guides alike: " << alike.steps << " steps, " << alike.predicted_steps << " predicted, " << alike.substepped_steps
                        << " substepped, " << alike.evaluations << " evaluations");
  REQUIRE(alike.steps == int64_t(near_roots.size()) * 30);
  CHECK(alike.substepped_steps == 0);
  CHECK(alike.predicted_steps >= alike.steps * 9 / 10);
  CHECK(alike.evaluations < alike.steps * 11 / 10);

  // Two straight guides from roots 0.02 apart, 53 degrees between them (a V), and roots beside one.
  const Mesh plane = make_plane(2.0f, 20);
  const MeshQuery plane_query(plane);
  StrandSet vee;
  for (const float side : {-1.0f, 1.0f}) {
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 32; ++i) {
      const float s = 0.8f * float(i) / 31.0f;
      points.emplace_back(side * (0.01f + 0.5f * s), 0.0f, s);
    }
    vee.append(points, side < 0.0f ? 0 : 1);
  }
  const Guides vee_guides = bind_guides(plane_query, vee, "vee");
  std::vector<Eigen::Vector3f> beside;
  for (int i = 1; i < 10; ++i) beside.emplace_back(-0.01f + 0.0005f * float(i), 0.0f, 0.0f);
  const interp::GrowStats meeting = stats_of(plane, plane_query, vee_guides, roots_at(plane_query, beside), 2);
  INFO("guides at an angle: " << meeting.steps << " steps, " << meeting.substepped_steps << " substepped");
  CHECK(meeting.substepped_steps >= meeting.steps / 10);
}

// A strand's first point is the one its own skin guard cannot bound (the root is on the skin):
// growth proves it from the balls round earlier strands' first points, which hold no skin, and
// searches only where none of them reaches it by the margin.
TEST_CASE("a strand's first point is proven outside from earlier strands' first points, never inside the margin",
          "[interp]") {
  CapScene scene([](int) { return arc_shape(1.0f); }, 32, [](int) { return 1.0f; }, 6000);
  auto grow_with = [&](float margin, interp::GrowStats &r_stats) {
    const interp::Binding binding =
        interp::bind(scene.mesh, scene.guides, scene.roots, settings_for(Method::streamline, 4, margin));
    interp::GrowOptions options;
    options.r_stats = &r_stats;
    StrandSet strands;
    interp::grow(binding, scene.mesh, scene.query, scene.roots, scene.guides.strands, options, strands);
    return strands;
  };
  std::vector<uint64_t> examples;
  // Steps of 1/31 leave the skin along the normal: an earlier first point a root or two away proves
  // most of them (a single thread, so that each strand follows the one before it).
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  interp::GrowStats rising;
  const StrandSet strands = grow_with(0.005f, rising);
  omp_set_num_threads(threads);
  INFO("first points proven: " << rising.first_points_proven << " of " << rising.first_points);
  CHECK(rising.first_points == int64_t(scene.roots.size()));
  CHECK(rising.first_points_proven >= rising.first_points / 2);
  CHECK(check::count_points_inside(strands, scene.query, 0.005f, 0, examples) == 0);
  // A margin above the first step's rise: every first point is pushed out to it, and no earlier one
  // may spare a later one its push.
  interp::GrowStats pushed;
  const StrandSet kept_out = grow_with(0.05f, pushed);
  CHECK(check::count_points_inside(kept_out, scene.query, 0.05f, 0, examples) == 0);
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
      if (method == Method::streamline) CHECK(count_inside(query, grown) == 0);
    }
  // Roots on the far side of a sphere from every guide.
  CapScene scene([](int) { return arc_shape(1.0f); }, 16, [](int) { return 0.8f; }, 1);
  const Roots far = roots_at(scene.query, {{0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, -0.2f}, {-1.0f, 0.0f, 0.0f}});
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, far, settings_for(Method::streamline));
  const StrandSet grown = grow_all(binding, scene.mesh, scene.query, far, scene.guides.strands);
  CHECK(all_finite(grown));
  CHECK(count_inside(scene.query, grown) == 0);
}

TEST_CASE("push_out_of_skin leaves no point inside and keeps roots", "[interp]") {
  const Mesh mesh = make_sphere(1.0f, 24, 48, PoleAxis::z, false);
  const MeshQuery query(mesh);
  StrandSet strands;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3f root = Eigen::Vector3f(std::cos(0.3f * float(i)), std::sin(0.3f * float(i)), 0.1f * float(i - 10)).normalized();
    std::vector<Eigen::Vector3f> points{surface_position(mesh, query.closest(root))};
    // Strands that dive through the sphere.
    for (int p = 1; p < 16; ++p) points.push_back(points[0] * (1.0f - 0.15f * float(p)) + Eigen::Vector3f(0.05f * float(p), 0.0f, 0.0f));
    strands.append(points, uint64_t(i));
  }
  const StrandSet before = strands;
  REQUIRE(count_inside(query, strands) > 0);
  interp::push_out_of_skin(query, 0.01f, strands);
  CHECK(count_inside(query, strands) == 0);
  for (size_t s = 0; s < strands.strand_count(); ++s) CHECK(strands.points(s)[0] == before.points(s)[0]);
  CHECK(all_finite(strands));
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
