#include <catch2/catch.hpp>

#include <Eigen/Geometry>
#include <map>
#include <random>
#include <set>

#include "groom/error.h"
#include "groom/guide_curve.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/strand_set.h"
#include "test_fixtures.h"

using namespace plume;

namespace {
Mesh transformed(const Mesh &mesh, const Eigen::Affine3f &xf) {
  Mesh out = mesh;
  for (Eigen::Vector3f &p : out.positions) p = xf * p;
  out.compute_normals();
  return out;
}
}  // namespace

TEST_CASE("a StrandSet keeps offsets, points, widths and ids consistent", "[groom]") {
  StrandSet set;
  const std::vector<Eigen::Vector3f> a{{0, 0, 0}, {0, 1, 0}, {0, 3, 0}};
  const std::vector<Eigen::Vector3f> b{{1, 0, 0}, {1, 0, 2}};
  set.append(a, 7, std::vector<float>{0.1f, 0.1f, 0.05f});
  set.append(b, 9, std::vector<float>{0.2f, 0.1f});
  REQUIRE(set.strand_count() == 2);
  REQUIRE(set.point_count() == 5);
  REQUIRE(set.offsets == std::vector<int64_t>{0, 3, 5});
  REQUIRE(set.ids == std::vector<uint64_t>{7, 9});
  REQUIRE(set.points(1)[1] == Eigen::Vector3f(1, 0, 2));
  REQUIRE(set.length(0) == Approx(3.0));
  REQUIRE_NOTHROW(set.check_invariants());

  set.positions[4].x() = std::numeric_limits<float>::quiet_NaN();
  REQUIRE_THROWS_AS(set.check_invariants(), InternalError);

  StrandSet uniform;
  uniform.resize_uniform(3, 4, true);
  REQUIRE(uniform.offsets == std::vector<int64_t>{0, 4, 8, 12});
  REQUIRE(uniform.widths.size() == 12);
  REQUIRE_NOTHROW(uniform.check_invariants());
}

TEST_CASE("the closest point on the surface lies on the surface and has valid barycentrics", "[groom]") {
  const Mesh sphere = test::make_sphere(2.0f, 16, 32);
  const MeshQuery query(sphere);
  for (const Eigen::Vector3f &p : {Eigen::Vector3f(3, 0.5f, 0.2f), Eigen::Vector3f(0.3f, -0.9f, 1.5f),
                                   Eigen::Vector3f(0, 5, 0), Eigen::Vector3f(-1.2f, 1.0f, 1.4f)}) {
    const SurfacePoint sp = query.closest(p);
    REQUIRE(sp.triangle >= 0);
    REQUIRE(sp.bary.sum() == Approx(1.0f).margin(1e-5));
    REQUIRE(sp.bary.minCoeff() >= -1e-6f);
    // On a finely tessellated sphere the closest point is near the radial projection.
    REQUIRE((surface_position(sphere, sp) - 2.0f * p.normalized()).norm() < 0.1f);
    const float sd = query.signed_distance(p);
    REQUIRE(sd == Approx(p.norm() - 2.0f).margin(0.05f));
  }
}

TEST_CASE("a surface frame is orthonormal, normal-aligned and turns rigidly with the skin", "[groom]") {
  const Mesh sphere = test::make_sphere(1.5f, 12, 24);
  Mesh no_uv = sphere;
  no_uv.uvs.clear();
  no_uv.triangle_uvs.clear();
  const Eigen::Affine3f motion = Eigen::Translation3f(3, -1, 2) * Eigen::AngleAxisf(0.7f, Eigen::Vector3f(1, 2, 3).normalized());
  for (const Mesh *mesh : std::vector<const Mesh *>{&sphere, &no_uv}) {
    const Mesh moved = transformed(*mesh, motion);
    for (int f = 0; f < int(mesh->triangle_count()); f += 37) {
      if (mesh->triangle_area(f) <= 0.0) continue;
      const SurfacePoint sp{f, Eigen::Vector3f(0.2f, 0.3f, 0.5f)};
      const SurfaceFrame frame = surface_frame(*mesh, sp);
      REQUIRE((frame.basis.transpose() * frame.basis - Eigen::Matrix3f::Identity()).norm() < 1e-5f);
      REQUIRE(frame.basis.determinant() == Approx(1.0f).margin(1e-5));
      REQUIRE(frame.normal().dot(surface_normal(*mesh, sp)) == Approx(1.0f).margin(1e-5));
      const SurfaceFrame moved_frame = surface_frame(moved, sp);
      INFO("triangle " << f << (mesh->has_uvs() ? " with uvs" : " without uvs"));
      REQUIRE((moved_frame.basis - motion.linear() * frame.basis).norm() < 1e-4f);
      REQUIRE((moved_frame.origin - motion * frame.origin).norm() < 1e-4f);
    }
  }
}

TEST_CASE("scattered roots lie on the surface, follow area, and are stable", "[groom]") {
  const Mesh sphere = test::make_sphere(1.0f, 10, 20);
  const Roots a = scatter_roots(sphere, 2000, 42);
  const Roots b = scatter_roots(sphere, 2000, 42);
  REQUIRE(a.size() == 2000);
  REQUIRE(a.ids == b.ids);
  for (size_t i = 0; i < a.size(); ++i) {
    REQUIRE(a.points[i].triangle == b.points[i].triangle);
    REQUIRE(a.points[i].bary == b.points[i].bary);
    REQUIRE(a.points[i].bary.minCoeff() >= 0.0f);
    REQUIRE(a.points[i].bary.sum() == Approx(1.0f).margin(1e-5));
    // On the surface: the point is on its triangle, so within tessellation error of the sphere.
    REQUIRE(surface_position(sphere, a.points[i]).norm() == Approx(1.0f).margin(0.05));
  }
  REQUIRE(std::set<uint64_t>(a.ids.begin(), a.ids.end()).size() == a.size());

  SECTION("a higher count keeps every existing root where it was") {
    const Roots more = scatter_roots(sphere, 3500, 42);
    REQUIRE(more.size() == 3500);
    std::map<uint64_t, size_t> where;
    for (size_t i = 0; i < more.size(); ++i) where[more.ids[i]] = i;
    for (size_t i = 0; i < a.size(); ++i) {
      REQUIRE(where.count(a.ids[i]) == 1);
      const size_t j = where[a.ids[i]];
      REQUIRE(more.points[j].triangle == a.points[i].triangle);
      REQUIRE(more.points[j].bary == a.points[i].bary);
    }
  }
  SECTION("another seed gives other roots") {
    const Roots c = scatter_roots(sphere, 2000, 43);
    size_t same = 0;
    for (size_t i = 0; i < a.size(); ++i) same += (c.points[i].bary == a.points[i].bary);
    REQUIRE(same < 20);
  }
  SECTION("roots are spread in proportion to area") {
    // Upper half of the sphere vs lower half: equal areas, so nearly equal counts.
    size_t upper = 0;
    for (const SurfacePoint &sp : a.points) upper += surface_position(sphere, sp).y() > 0.0f;
    REQUIRE(std::abs(double(upper) - 1000.0) < 100.0);
  }
  SECTION("a face mask restricts the roots to the chosen faces") {
    std::vector<bool> mask(sphere.triangle_count(), false);
    for (size_t f = 0; f < mask.size(); f += 3) mask[f] = true;
    const Roots masked = scatter_roots(sphere, 500, 42, mask);
    REQUIRE(masked.size() == 500);
    for (const SurfacePoint &sp : masked.points) REQUIRE(mask[sp.triangle]);
  }
}

TEST_CASE("guides carried by the skin move rigidly with a rigid emitter", "[groom]") {
  const Mesh sphere = test::make_sphere(1.0f, 12, 24);
  const MeshQuery query(sphere);
  StrandSet strands;
  for (int g = 0; g < 5; ++g) {
    const Eigen::Vector3f root = Eigen::Vector3f(std::cos(g * 1.1f), 0.4f * g - 0.8f, std::sin(g * 1.1f)).normalized();
    std::vector<Eigen::Vector3f> pts;
    for (int i = 0; i < 6; ++i) pts.push_back(root * (1.0f + 0.2f * i) + Eigen::Vector3f(0, -0.05f * i * i, 0));
    strands.append(pts, uint64_t(g));
  }
  const Guides guides = bind_guides(query, strands, "test");
  const Eigen::Affine3f motion = Eigen::Translation3f(-2, 1, 0.5f) * Eigen::AngleAxisf(1.2f, Eigen::Vector3f::UnitY());
  const Mesh moved = transformed(sphere, motion);
  const StrandSet carried = carry_guides(sphere, moved, guides);
  for (size_t p = 0; p < strands.point_count(); ++p)
    REQUIRE((carried.positions[p] - motion * strands.positions[p]).norm() < 1e-4f);
}

TEST_CASE("a guide with fewer than two points is rejected with its index", "[groom]") {
  const Mesh sphere = test::make_sphere(1.0f, 6, 12);
  const MeshQuery query(sphere);
  StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{1, 0, 0}, {2, 0, 0}}, 0);
  strands.append(std::vector<Eigen::Vector3f>{{0, 1, 0}}, 1);
  REQUIRE_THROWS_WITH(bind_guides(query, strands, "g.hair"), Catch::Contains("g.hair") && Catch::Contains("guide 1"));
}

TEST_CASE("a mesh with only degenerate triangles or bad indices is rejected", "[groom]") {
  Mesh flat;
  flat.positions = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  flat.triangles = {{0, 1, 2}};
  flat.triangle_groups = {0};
  flat.group_names = {"default"};
  REQUIRE_THROWS_WITH(flat.validate("flat.obj"), Catch::Contains("flat.obj") && Catch::Contains("degenerate"));
  flat.triangles = {{0, 1, 5}};
  REQUIRE_THROWS_WITH(flat.validate("bad.obj"), Catch::Contains("bad.obj") && Catch::Contains("vertex 6"));
}

TEST_CASE("a hinted closest-point query finds the same point as an unhinted one", "[groom]") {
  const Mesh sphere = test::make_sphere(2.0f, 16, 32);
  const MeshQuery full(sphere);
  const MeshQuery light(sphere, MeshQuery::Start::hint_only);
  const SurfacePoint far_hint{40, Eigen::Vector3f(0.2f, 0.3f, 0.5f)};
  for (const Eigen::Vector3f &p : {Eigen::Vector3f(3, 0.5f, 0.2f), Eigen::Vector3f(0.3f, -0.9f, 1.5f),
                                   Eigen::Vector3f(-1.2f, 1.0f, 1.4f), Eigen::Vector3f(0.1f, -2.5f, -0.3f)}) {
    const SurfacePoint expected = full.closest(p);
    for (const SurfacePoint &hint : {expected, far_hint, SurfacePoint{}}) {
      SurfacePoint found;
      const double d = light.signed_distance(p.cast<double>(), hint, found);
      REQUIRE((surface_position(sphere, found) - surface_position(sphere, expected)).norm() < 1e-5f);
      REQUIRE(d == Approx(full.signed_distance(p)).margin(1e-5));
    }
  }
}

TEST_CASE("the surface point below a point lies on that point's normal line, where the closest one misses it",
          "[groom]") {
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), height(0.01f, 0.4f);
  for (const float scale : {0.01f, 1.0f, 100.0f})
    for (const int rings : {6, 16}) {
      // Facets lean from the interpolated normals by up to half a facet's angle. On the coarse
      // sphere the normals' lines leave gaps above some edges (no surface point's line passes
      // through such a point), and a few on the finer one: there the miss only has to shrink.
      const Mesh sphere = transformed(test::make_sphere(1.0f, rings, 2 * rings - 2), Eigen::Affine3f(Eigen::Scaling(scale)));
      const MeshQuery query(sphere);
      int closest_missed = 0, exact = 0;
      double closest_total = 0.0, below_total = 0.0;
      for (int i = 0; i < 200; ++i) {
        const Eigen::Vector3f direction = Eigen::Vector3f(unit(random), unit(random), unit(random)).normalized();
        const Eigen::Vector3f p = scale * (1.0f + height(random)) * direction;
        const auto miss = [&](const SurfacePoint &sp) {
          const Eigen::Vector3f d = p - surface_position(sphere, sp), n = surface_normal(sphere, sp);
          return (d - d.dot(n) * n).norm();
        };
        const SurfacePoint below = surface_point_below(query, p), closest = query.closest(p);
        INFO("scale " << scale << ", rings " << rings << ", point " << i);
        CHECK(miss(below) <= miss(closest));
        CHECK((p - surface_position(sphere, below)).dot(surface_normal(sphere, below)) > 0.0f);
        closest_total += miss(closest);
        below_total += miss(below);
        if (miss(closest) > 1e-3f * scale) ++closest_missed;
        if (miss(below) <= 1e-5f * scale) ++exact;
      }
      INFO("scale " << scale << ", rings " << rings << ": " << exact << " of 200 exact; misses " << closest_total
                    << " -> " << below_total);
      CHECK(closest_missed > 100);  // scenes where it matters
      CHECK(exact >= 190);
      CHECK(below_total < 0.05 * closest_total);
    }
  // On or below the skin it is the closest point.
  const Mesh sphere = test::make_sphere(1.0f, 6, 10);
  const MeshQuery query(sphere);
  for (const Eigen::Vector3f &p : {Eigen::Vector3f(0.3f, 0.2f, 0.1f), Eigen::Vector3f(0.0f, 0.0f, 0.0f)}) {
    const SurfacePoint below = surface_point_below(query, p), closest = query.closest(p);
    CHECK(below.triangle == closest.triangle);
    CHECK((surface_position(sphere, below) - surface_position(sphere, closest)).norm() == 0.0f);
  }
}

TEST_CASE("a guide's curve passes through its points with continuous tangents, and measures its length",
          "[groom]") {
  // A circle's arc sampled at 9 points: the curve's length is the arc's to well within the chords'.
  std::vector<Eigen::Vector3f> points;
  const float radius = 2.0f, angle = 1.5f;
  for (int i = 0; i < 9; ++i) {
    const float a = angle * float(i) / 8.0f;
    points.emplace_back(radius * std::cos(a), radius * std::sin(a), 0.0f);
  }
  points.insert(points.begin() + 4, points[4]);  // a repeated point is left out
  std::vector<CurvePiece> pieces;
  guide_curve(points, 1e-6f, pieces);
  REQUIRE(pieces.size() == 8);
  double chords = 0.0;
  for (size_t j = 0; j < pieces.size(); ++j) {
    chords += double((pieces[j].end - pieces[j].a).norm());
    CHECK((pieces[j].at(1.0f) - pieces[j].end).norm() < 1e-5f);
    if (j + 1 < pieces.size()) {
      CHECK((pieces[j].end - pieces[j + 1].a).norm() == 0.0f);
      CHECK(pieces[j].derivative(1.0f).normalized().dot(pieces[j + 1].derivative(0.0f).normalized()) > 1.0f - 1e-5f);
    }
  }
  const double arc = double(radius) * double(angle);
  CHECK(std::abs(curve_length(pieces) - arc) < 0.05 * (arc - chords));
  const std::vector<Eigen::Vector3f> samples = sample_curve(pieces, 8);
  CHECK(samples.size() == 8 * 8 + 1);
  for (const Eigen::Vector3f &s : samples) CHECK(std::abs(s.norm() - radius) < 1e-3f * radius);
  // Fewer than two distinct points: no curve.
  guide_curve(std::vector<Eigen::Vector3f>{points[0], points[0]}, 1e-6f, pieces);
  CHECK(pieces.empty());
}
