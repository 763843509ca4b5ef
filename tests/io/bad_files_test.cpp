// Every reader against the broken files in tests/data/bad/: each must throw InputError whose
// message names the file, the place (line or byte) and what was expected.
#include <catch2/catch.hpp>

#include <string>
#include <vector>

#include "groom/error.h"
#include "io/obj_mesh.h"
#include "io/point_list.h"
#include "io/strand_file.h"

namespace {

enum class Reader { Strands, Mesh, Points };

struct BadFile {
  const char *name;
  Reader reader;
  std::vector<std::string> message_parts;  // each must appear in the message
};

std::string message_of(const BadFile &bad) {
  const std::string path = std::string(PLUME_TEST_DATA "/bad/") + bad.name;
  try {
    switch (bad.reader) {
      case Reader::Strands: plume::io::read_strands(path); break;
      case Reader::Mesh: plume::io::read_obj_mesh(path); break;
      case Reader::Points: plume::io::read_points(path); break;
    }
  } catch (const plume::InputError &error) {
    return error.what();
  }
  return "(no error)";
}

void check_bad_files(const std::vector<BadFile> &files) {
  for (const BadFile &bad : files) {
    const std::string message = message_of(bad);
    INFO(bad.name << " -> " << message);
    CHECK(message.find(bad.name) != std::string::npos);
    for (const std::string &part : bad.message_parts) {
      INFO("expected part: " << part);
      CHECK(message.find(part) != std::string::npos);
    }
  }
}

}  // namespace

TEST_CASE("a broken .hair file is rejected with its byte offset and what was expected", "[io]") {
  check_bad_files({
      {"hair_truncated.hair", Reader::Strands, {"@byte 584", "points: expected 7296 x 12 bytes, file ends after 400"}},
      {"hair_huge_count.hair", Reader::Strands, {"@byte 128", "segments: expected 4000000000 x 2 bytes, file ends after 72"}},
      {"hair_nan.hair", Reader::Strands, {"@byte 146", "points[1].y: expected a finite number"}},
      {"hair_bad_magic.hair", Reader::Strands, {"@byte 0", "magic: expected \"HAIR\", got \"HAIX\""}},
      {"hair_segments_mismatch.hair", Reader::Strands, {"@byte 128", "expected to add up to the point count 5", "got 6"}},
      {"hair_no_points.hair", Reader::Strands, {"@byte 12", "expected the points bit (2) to be set, got 1"}},
  });
}

TEST_CASE("a broken .ply file is rejected with its line or byte offset and what was expected", "[io]") {
  check_bad_files({
      {"ply_missing_edges.ply", Reader::Strands, {":7:", "expected an edge element (vertex1, vertex2) or a per-vertex strand/curve property"}},
      {"ply_truncated.ply", Reader::Strands, {"@byte 175", "element vertex: expected 100 x 12 bytes, file ends after 24"}},
      {"ply_huge_count.ply", Reader::Strands, {":10:", "expected 4000000001 lines of data", "the file has 3"}},
      {"ply_huge_count_binary.ply", Reader::Strands, {"@byte 181", "element vertex: expected 4000000000 x 12 bytes, file ends after 32"}},
      {"ply_nan.ply", Reader::Strands, {":12:", "vertex 1: y: expected a finite number, got \"nan\""}},
      {"ply_bad_edge_index.ply", Reader::Strands, {":15", "edge 1: vertex2: expected a vertex index 0..2, got 7"}},
      {"ply_bad_edge_index_binary.ply", Reader::Strands, {"@byte 200", "edge 0: vertex2: expected a vertex index 0..1, got -5"}},
      {"ply_bad_magic.ply", Reader::Strands, {":1", "magic: expected \"ply\", got \"plx\""}},
      {"ply_big_endian.ply", Reader::Strands, {":2:8", "expected ascii or binary_little_endian, got \"binary_big_endian\""}},
      {"ply_loop.ply", Reader::Strands, {"lies on a closed loop; expected open chains"}},
  });
}

TEST_CASE("a broken OBJ strand file is rejected with file:line:column and what was expected", "[io]") {
  check_bad_files({
      {"obj_lines_bad_index.obj", Reader::Strands, {":5:5", "l: vertex index 9 out of range, expected 1..3", "(vertices read so far: 3)"}},
      {"obj_lines_nan.obj", Reader::Strands, {":2:5", "v: y: expected a finite number, got \"NaN\""}},
      {"obj_lines_single.obj", Reader::Strands, {":3", "l: expected at least 2 vertex indices, got 1"}},
  });
}

TEST_CASE("a broken OBJ mesh is rejected with file:line:column and what was expected", "[io]") {
  check_bad_files({
      {"obj_face_bad_index.obj", Reader::Mesh, {":4:7", "f: vertex index 7 out of range, expected 1..3", "(vertices read so far: 3)"}},
      {"obj_face_bad_uv_index.obj", Reader::Mesh, {":5:7", "f: uv index 2 out of range, expected 1..1", "(uvs read so far: 1)"}},
      {"obj_mesh_inf.obj", Reader::Mesh, {":2:5", "v: y: expected a finite number, got \"inf\""}},
      {"obj_face_two_corners.obj", Reader::Mesh, {":4", "f: expected at least 3 corners, got 2"}},
      {"obj_mesh_all_degenerate.obj", Reader::Mesh, {"every triangle is degenerate"}},
      {"obj_mesh_bad_number.obj", Reader::Mesh, {":2:5", "v: y: expected a number, got \"abc\""}},
      // Finite floats whose edge cross product overflows: root scattering used to hang on them.
      {"obj_mesh_huge.obj", Reader::Mesh, {":2:", "v: vertex 2: expected coordinates within [-1e+06, 1e+06], got (1e+20, 0, 0)"}},
  });
  // A frame of an emitter sequence goes through the same reader.
  const plume::Mesh rest = plume::io::read_obj_mesh(PLUME_TEST_DATA "/groom_file/head.obj");
  CHECK_THROWS_WITH(plume::io::read_obj_pose(PLUME_TEST_DATA "/bad/obj_mesh_huge.obj", rest),
                    Catch::Contains("obj_mesh_huge.obj:2:") && Catch::Contains("v: vertex 2: expected coordinates within"));
}

TEST_CASE("a broken .usda file is rejected with file:line:column and what was expected", "[io]") {
  check_bad_files({
      {"usda_bad_header.usda", Reader::Strands, {":1:1", "first line: expected \"#usda 1.0\", got \"#usda 2.0\""}},
      {"usda_counts_mismatch.usda", Reader::Strands, {":11:", "curveVertexCounts: expected to add up to the 4 points, got 5"}},
      {"usda_huge_count.usda", Reader::Strands, {":11:", "curveVertexCounts[0]: expected an integer >= 2 (linear curves) that fits int, got 4000000000"}},
      {"usda_nan.usda", Reader::Strands, {":12:44", "points: expected a number, got \"nan\""}},
      {"usda_syntax.usda", Reader::Strands, {":12:9", "curveVertexCounts: expected ',' or ']', got \"point3f\""}},
      {"usda_no_curves.usda", Reader::Strands, {"expected a BasisCurves prim, found none"}},
      {"usda_bad_widths.usda", Reader::Strands, {":13:", "widths: expected 1 (constant), 1 (uniform) or 2 (vertex) values", "got 3"}},
      {"usda_bad_tuple.usda", Reader::Strands, {":12:", "points: a tuple of 3: expected ','"}},
  });
}

TEST_CASE("a value beyond float range is refused with its place, not read as an infinite point", "[io]") {
  check_bad_files({
      {"usda_point_1e300.usda", Reader::Strands, {":12:41", "points: expected a number within float range (magnitude at most 3.4028235e+38), got 1e+300"}},
      {"usda_width_1e300.usda", Reader::Strands, {":13:32", "widths: expected a finite number >= 0 within float range, got 1e+300"}},
      {"ply_binary_double_1e300.ply", Reader::Strands, {"@byte 199", "vertex 1: x: expected a number within float range", "got 1e+300"}},
  });
  // The same points through the roots reader, which reads strand files too.
  check_bad_files({{"usda_point_1e300.usda", Reader::Points, {":12:41", "got 1e+300"}}});
}

TEST_CASE("a number no integer of its field holds is refused with its place, not converted", "[io]") {
  check_bad_files({
      {"usda_counts_1e30.usda", Reader::Strands, {":11:36", "curveVertexCounts: expected an integer, got \"1e30\""}},
      {"ply_strand_id_7e31.ply", Reader::Strands, {":9", "vertex 0: strand: expected an integer id, got 7e+31"}},
      {"ply_binary_strand_id_nan.ply", Reader::Strands, {"@byte 169", "vertex 1: curve: expected an integer id, got nan"}},
      {"ply_edge_index_1e30.ply", Reader::Strands, {"@byte 210", "edge 0: vertex2: expected a vertex index 0..1, got 1e+30"}},
      {"ply_float_list_count.ply", Reader::Strands, {":7:", "property list: expected an integer count type (uchar, int, ...), got \"float\""}},
      // Element counts that add up to 2^64 + 1: a sum that wrapped let the reader allocate 2^63 vertices.
      {"ply_count_wraps.ply", Reader::Strands, {":12:", "elements: expected 18446744073709551615 lines of data", "the file has 1"}},
  });
}

TEST_CASE("a broken root point list is rejected with file:line and what was expected", "[io]") {
  check_bad_files({
      {"points_missing_z.txt", Reader::Points, {":3:", "z: expected a number, got the end of the line"}},
      {"points_nan.txt", Reader::Points, {":3:3", "y: expected a finite number, got \"nan\""}},
      {"points_huge.txt", Reader::Points, {":2:1", "point 1: expected coordinates within [-1e+06, 1e+06], got (4, 5e+30, 6)"}},
  });
}

TEST_CASE("a missing file is an input error that names the file", "[io]") {
  const std::string missing = PLUME_TEST_DATA "/bad/no_such_file";
  for (const char *ext : {".hair", ".ply", ".usda", ".obj"}) {
    try {
      plume::io::read_strands(missing + ext);
      FAIL("no error for a missing " << ext);
    } catch (const plume::InputError &error) {
      CHECK_THAT(error.what(), Catch::Contains("no_such_file" + std::string(ext)) && Catch::Contains("cannot open file"));
    }
  }
  CHECK_THROWS_WITH(plume::io::read_obj_mesh(missing + ".obj"), Catch::Contains("no_such_file.obj: cannot open file"));
  CHECK_THROWS_WITH(plume::io::read_points(missing + ".txt"), Catch::Contains("no_such_file.txt: cannot open file"));
}

TEST_CASE("an unknown strand file extension is an input error naming the accepted ones", "[io]") {
  CHECK_THROWS_WITH(plume::io::read_strands(PLUME_TEST_DATA "/bad/points_nan.txt"),
                    Catch::Contains("points_nan.txt: strand file: expected extension .hair, .ply, .usda or .obj, got \".txt\""));
  CHECK_THROWS_WITH(plume::io::read_points(PLUME_TEST_DATA "/bad/roots.yaml"),
                    Catch::Contains("roots.yaml: point list: expected extension .txt, .hair, .ply, .usda or .obj, got \".yaml\""));
}
