// Out-of-range scene input is an InputError that names where it came from, never a hang or NaN.
#include <catch2/catch.hpp>

#include "groom/error.h"
#include "groom/guides.h"
#include "groom/limits.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "test_fixtures.h"

using namespace plume;
using Catch::Matchers::Contains;

namespace {
/// One triangle with the given corners, in one group.
Mesh one_triangle(const Eigen::Vector3f &a, const Eigen::Vector3f &b, const Eigen::Vector3f &c) {
  Mesh mesh;
  mesh.positions = {a, b, c};
  mesh.triangles = {Eigen::Vector3i(0, 1, 2)};
  mesh.triangle_groups = {0};
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}
}  // namespace

TEST_CASE("scatter_roots throws, never loops, when a triangle's float area overflows to inf", "[groom]") {
  // Finite 32-bit coordinates whose edge cross product (1e40) is not: the area is inf and the
  // normalised areas NaN, which made the search for the arrival time double forever.
  const Mesh mesh = one_triangle({0, 0, 0}, {1e20f, 0, 0}, {0, 0, 1e20f});
  REQUIRE(std::isinf(mesh.triangle_area(0)));
  const FileLoc roots_loc{"g.groom.yaml", 4, 1};
  REQUIRE_THROWS_AS(scatter_roots(mesh, 50, 1, {}, roots_loc), InputError);
  REQUIRE_THROWS_WITH(scatter_roots(mesh, 50, 1, {}, roots_loc),
                      Contains("g.groom.yaml:4:1: roots:") && Contains("infinite total area"));
}

TEST_CASE("scatter_roots names the groom's roots settings when the selected faces have no area", "[groom]") {
  const Mesh sphere = test::make_sphere(1.0f, 8, 12);
  const std::vector<bool> none(sphere.triangle_count(), false);
  REQUIRE_THROWS_WITH(scatter_roots(sphere, 10, 1, none, FileLoc{"h.groom.yaml", 4, 1}),
                      Contains("h.groom.yaml:4:1: roots:") && Contains("roots.groups, roots.near_guides") &&
                          Contains("no area"));
  // Without a location the message stands alone.
  REQUIRE_THROWS_WITH(scatter_roots(sphere, 10, 1, none), Catch::Matchers::StartsWith("roots: the selected faces"));
}

TEST_CASE("an InputError at a place prefixes what is known of it, and nothing when nothing is", "[groom]") {
  CHECK(std::string(InputError(FileLoc{}, "roots.count: expected a count").what()) == "roots.count: expected a count");
  CHECK(std::string(InputError(FileLoc{"", 3}, "x: bad").what()) == "<input>:3: x: bad");
  CHECK(std::string(InputError(FileLoc{"g.groom.yaml", 3, 7}, "x: bad").what()) == "g.groom.yaml:3:7: x: bad");
  FileLoc binary{"m.ply"};
  binary.byte_offset = 12;
  CHECK(std::string(InputError(binary, "x: bad").what()) == "m.ply@byte 12: x: bad");
}

TEST_CASE("scatter_roots still places every root on many faces for a small count", "[groom]") {
  // Few roots on many triangles need the arrival time to grow past count + 2: the bounded search
  // must still find it.
  const Mesh sphere = test::make_sphere(1.0f, 40, 80);
  for (int64_t count : {1, 3, 17}) REQUIRE(scatter_roots(sphere, count, 9).size() == size_t(count));
}

TEST_CASE("a mesh with a vertex beyond max_coordinate is rejected, naming the source and vertex", "[groom]") {
  Mesh mesh = one_triangle({0, 0, 0}, {1, 0, 0}, {0, 0, 1});
  REQUIRE_NOTHROW(mesh.validate("m.obj"));
  mesh.positions[1].x() = 1e20f;
  REQUIRE_THROWS_AS(mesh.validate("m.obj"), InputError);
  REQUIRE_THROWS_WITH(mesh.validate("m.obj"), Contains("m.obj: mesh: vertex 2: expected coordinates within"));
  mesh.positions[1].x() = max_coordinate;  // the bound itself is allowed
  REQUIRE_NOTHROW(mesh.validate("m.obj"));
}

TEST_CASE("a guide point beyond max_coordinate is rejected, naming the file, guide and point", "[groom]") {
  const Mesh sphere = test::make_sphere(1.0f, 8, 12);
  const MeshQuery query(sphere);
  StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{0, 1, 0}, {0, 2, 0}}, 0);
  strands.append(std::vector<Eigen::Vector3f>{{1, 0, 0}, {2, 0, 0}, {1e30f, 0, 0}}, 1);
  REQUIRE_THROWS_AS(bind_guides(query, strands, "g.hair"), InputError);
  REQUIRE_THROWS_WITH(bind_guides(query, strands, "g.hair"),
                      Contains("g.hair: guide 1, point 2: expected coordinates within"));
  strands.positions.back().x() = 3.0f;
  REQUIRE(bind_guides(query, strands, "g.hair").size() == 2);
}
