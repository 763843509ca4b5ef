// OBJ emitter meshes: face forms, polygons, groups, UVs, the real Sintel head, and pose frames.
#include <catch2/catch.hpp>

#include <fstream>

#include "groom/error.h"
#include "io/obj_mesh.h"
#include "scratch_dir.h"

namespace {

const char *kQuadWithGroups =
    "# a unit square as a quad, then a triangle in another group\n"
    "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
    "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvt 0.5 0.5\n"
    "vn 0 0 1\n"
    "g scalp\n"
    "f 1/1/1 2/2/1 3/3/1 4/4/1\n"
    "g body\n"
    "f -4/-4 -1/-1 -3/-3\n";

}  // namespace

TEST_CASE("an OBJ mesh reads every face form, fan-triangulates polygons and keeps UVs and g groups", "[io]") {
  plume::test::ScratchDir dir("obj_mesh");
  std::ofstream(dir.file("m.obj")) << kQuadWithGroups;
  const plume::Mesh mesh = plume::io::read_obj_mesh(dir.file("m.obj"));
  REQUIRE(mesh.vertex_count() == 5);
  REQUIRE(mesh.triangle_count() == 3);
  CHECK(mesh.triangles[0] == Eigen::Vector3i(0, 1, 2));
  CHECK(mesh.triangles[1] == Eigen::Vector3i(0, 2, 3));
  CHECK(mesh.triangles[2] == Eigen::Vector3i(1, 4, 2));  // -4, -1, -3 of five vertices
  REQUIRE(mesh.has_uvs());
  CHECK(mesh.triangle_uvs[2] == Eigen::Vector3i(1, 4, 2));
  CHECK(mesh.group_names == std::vector<std::string>{"scalp", "body"});
  CHECK(mesh.triangle_groups == std::vector<int>{0, 0, 1});
  REQUIRE(mesh.vertex_normals.size() == 5);
  CHECK(mesh.vertex_normals[0].isApprox(Eigen::Vector3f(0, 0, 1)));
}

TEST_CASE("usemtl names the face groups when a file has both usemtl and g; unnamed faces go to default", "[io]") {
  plume::test::ScratchDir dir("obj_groups");
  std::ofstream(dir.file("m.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n"
                                   << "f 1//1 2//1 3//1\ng a\nusemtl skin\nf 2 4 3\ng b\nf 1 2 4\n" << "vn 0 0 1\n";
  // `vn` after use is out of order: the face's normal index is checked when the face is read.
  CHECK_THROWS_WITH(plume::io::read_obj_mesh(dir.file("m.obj")), Catch::Contains("m.obj:5:") &&
                                                                     Catch::Contains("f: normal index 1 out of range"));
  std::ofstream(dir.file("n.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nvn 0 0 1\n"
                                   << "f 1//1 2//1 3//1\ng a\nusemtl skin\nf 2 4 3\ng b\nf 1 2 4\n";
  const plume::Mesh mesh = plume::io::read_obj_mesh(dir.file("n.obj"));
  CHECK_FALSE(mesh.has_uvs());
  CHECK(mesh.group_names == std::vector<std::string>{"skin", "default"});
  CHECK(mesh.triangle_groups == std::vector<int>{1, 0, 0});
}

TEST_CASE("the real Sintel head loads: 5952 triangles", "[io]") {
  const plume::Mesh mesh = plume::io::read_obj_mesh(PLUME_SOURCE_DIR "/grooms/sintel/sintel.obj");
  CHECK(mesh.triangle_count() == 5952);
  CHECK(mesh.vertex_count() == 3046);
  CHECK(mesh.vertex_normals.size() == 3046);
  CHECK(mesh.group_names.size() == 1);  // one `o`, no g or usemtl
}

TEST_CASE("an OBJ pose keeps the rest topology and takes the frame's positions", "[io]") {
  plume::test::ScratchDir dir("obj_pose");
  std::ofstream(dir.file("rest.obj")) << kQuadWithGroups;
  std::ofstream(dir.file("frame.obj")) << "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nv 2 0 1\n"
                                       << "f 1 2 3 4\nf 2 5 3\n";
  const plume::Mesh rest = plume::io::read_obj_mesh(dir.file("rest.obj"));
  const plume::Mesh posed = plume::io::read_obj_pose(dir.file("frame.obj"), rest);
  CHECK(posed.triangles == rest.triangles);
  CHECK(posed.triangle_uvs == rest.triangle_uvs);
  CHECK(posed.group_names == rest.group_names);
  CHECK(posed.positions[4] == Eigen::Vector3f(2, 0, 1));
  CHECK(posed.vertex_normals.size() == 5);
}

TEST_CASE("an OBJ pose with another vertex count or other triangles is refused, naming what differs", "[io]") {
  plume::test::ScratchDir dir("obj_pose_bad");
  std::ofstream(dir.file("rest.obj")) << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n";
  const plume::Mesh rest = plume::io::read_obj_mesh(dir.file("rest.obj"));
  CHECK_THROWS_WITH(plume::io::read_obj_pose(PLUME_TEST_DATA "/bad/obj_pose_fewer_vertices.obj", rest),
                    Catch::Contains("obj_pose_fewer_vertices.obj: vertex count: expected 4 as in the rest mesh, got 3"));
  CHECK_THROWS_WITH(plume::io::read_obj_pose(PLUME_TEST_DATA "/bad/obj_pose_other_triangles.obj", rest),
                    Catch::Contains("obj_pose_other_triangles.obj: triangle 2: expected vertices 2 4 3 as in the rest mesh, got 2 3 4"));
}
