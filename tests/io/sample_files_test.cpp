// The sample strand files of tests/data/strands (also the fuzzers' seeds): each format's variants
// read to the same two strands, and numbers at the edges of float range read as the nearest float.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <limits>

#include "groom/error.h"
#include "io/point_list.h"
#include "io/strand_file.h"
#include "scratch_dir.h"

namespace {

const std::string kStrands = PLUME_TEST_DATA "/strands/";

/// The samples' strands: (0,0,0) (0,0.5,0.1) (0,1,0.3), then (1,0,0) (1,1,0).
void check_two_strands(const plume::StrandSet &strands) {
  REQUIRE(strands.offsets == std::vector<int64_t>{0, 3, 5});
  CHECK(strands.positions[1] == Eigen::Vector3f(0.0f, 0.5f, 0.1f));
  CHECK(strands.positions[2] == Eigen::Vector3f(0.0f, 1.0f, 0.3f));
  CHECK(strands.positions[4] == Eigen::Vector3f(1.0f, 1.0f, 0.0f));
}

}  // namespace

TEST_CASE("every sample strand file reads to its strands, widths and ids", "[io]") {
  for (const char *name : {"two_strands.hair", "two_strands_ascii.ply", "two_strands_binary.ply", "two_strands.usda",
                           "two_strands.obj", "strand_ids_ascii.ply", "strand_ids_binary.ply"}) {
    INFO(name);
    const plume::StrandSet strands = plume::io::read_strands(kStrands + name);
    check_two_strands(strands);
    const std::string file(name);
    if (file.find("two_strands") == 0 && file != "two_strands.obj")
      CHECK(strands.widths == std::vector<float>{0.02f, 0.015f, 0.01f, 0.02f, 0.01f});
    if (file == "two_strands.usda") CHECK(strands.ids == std::vector<uint64_t>{16777216, 16777217});
  }
  // Another tool's layer: a default value, a constant width, ids as groom_id, a mesh beside.
  const plume::StrandSet other = plume::io::read_strands(kStrands + "constant_widths.usda");
  CHECK(other.offsets == std::vector<int64_t>{0, 2, 5});
  CHECK(other.widths == std::vector<float>(5, 0.1f));
  CHECK(other.ids == std::vector<uint64_t>{4, 5});
  // Polylines of several indices, negative and with /vt parts.
  const plume::StrandSet polylines = plume::io::read_strands(kStrands + "polylines.obj");
  CHECK(polylines.offsets == std::vector<int64_t>{0, 3, 5});
  const std::vector<Eigen::Vector3f> roots = plume::io::read_points(kStrands + "roots.txt");
  REQUIRE(roots.size() == 3);
  CHECK(roots[2] == Eigen::Vector3f(-1e3f, 2.5e-3f, 7.0f));
}

TEST_CASE("a binary PLY element of a trillion items of no bytes is read at once, not walked", "[io]") {
  const plume::StrandSet strands = plume::io::read_strands(kStrands + "empty_element_binary.ply");
  CHECK(strands.offsets == std::vector<int64_t>{0, 2});
}

TEST_CASE("a number too small for a float reads as zero; the largest float reads as itself", "[io]") {
  plume::test::ScratchDir dir("float_edges");
  std::ofstream(dir.file("tiny.txt")) << "1e-50 -1e-400 0\n";
  const std::vector<Eigen::Vector3f> tiny = plume::io::read_points(dir.file("tiny.txt"));
  REQUIRE(tiny.size() == 1);
  CHECK(tiny[0] == Eigen::Vector3f::Zero());
  // The shortest text of the largest float is above it as a double (3.4028235e38 > 3.40282346e38):
  // it still names that float, in a double PLY and in a .usda.
  const float largest = std::numeric_limits<float>::max();
  std::ofstream(dir.file("largest.usda")) << "#usda 1.0\ndef BasisCurves \"c\" {\n  int[] curveVertexCounts = [2]\n"
                                             "  point3f[] points = [(0, 0, 0), (3.4028235e38, -3.4028235e+38, 1e-320)]\n}\n";
  const plume::StrandSet usda = plume::io::read_strands(dir.file("largest.usda"));
  CHECK(usda.positions[1] == Eigen::Vector3f(largest, -largest, 0.0f));
  std::ofstream(dir.file("largest.ply")) << "ply\nformat ascii 1.0\nelement vertex 2\nproperty double x\nproperty double y\n"
                                            "property double z\nproperty int strand\nend_header\n0 0 0 1\n"
                                            "3.4028235e38 1e-50 0 1\n";
  const plume::StrandSet ply = plume::io::read_strands(dir.file("largest.ply"));
  CHECK(ply.positions[1] == Eigen::Vector3f(largest, 0.0f, 0.0f));
  // Just beyond it: infinity, refused.
  std::ofstream(dir.file("beyond.usda")) << "#usda 1.0\ndef BasisCurves \"c\" {\n  int[] curveVertexCounts = [2]\n"
                                            "  point3f[] points = [(0, 0, 0), (3.5e38, 0, 0)]\n}\n";
  CHECK_THROWS_WITH(plume::io::read_strands(dir.file("beyond.usda")),
                    Catch::Contains("beyond.usda:4:35: points: expected a number within float range"));
}
