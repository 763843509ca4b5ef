// Round trips through every strand format, the real Sintel guides, and root point lists.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <limits>

#include "groom/error.h"
#include "io/point_list.h"
#include "io/strand_file.h"
#include "scratch_dir.h"

namespace {

using plume::StrandSet;

/// Strands with awkward floats (not short decimals, tiny, huge, negative) and uneven lengths.
StrandSet awkward_strands(bool with_widths, bool sequential_ids) {
  StrandSet strands;
  uint64_t state = 12345;
  auto next_float = [&](float scale) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return scale * (float(int64_t(state >> 33) % 2000001 - 1000000) / 999983.0f);
  };
  for (int s = 0; s < 37; ++s) {
    const int point_num = 2 + (s * 7) % 13;
    std::vector<Eigen::Vector3f> points;
    std::vector<float> widths;
    for (int p = 0; p < point_num; ++p) {
      points.emplace_back(next_float(1.0f), next_float(1e3f), next_float(1e-4f));
      widths.push_back(std::abs(next_float(0.1f)) + 1e-7f);
    }
    const uint64_t id = sequential_ids ? uint64_t(s) : (uint64_t(s) * 5952u << 24) | uint64_t(s);
    strands.append(points, id, with_widths ? std::span<const float>(widths) : std::span<const float>());
  }
  strands.positions[3] = Eigen::Vector3f(0.1f, 1.0f / 3.0f, std::numeric_limits<float>::min());
  strands.positions[4] = Eigen::Vector3f(-0.0f, 3.4e38f, 1e-38f);
  return strands;
}

void check_same_strands(const StrandSet &read, const StrandSet &written, bool widths, bool ids) {
  REQUIRE(read.offsets == written.offsets);
  REQUIRE(read.positions.size() == written.positions.size());
  for (size_t p = 0; p < read.positions.size(); ++p) {
    INFO("point " << p);
    REQUIRE(read.positions[p] == written.positions[p]);  // bit-exact: floats are written shortest round-trip
  }
  if (widths) CHECK(read.widths == written.widths);
  if (ids) CHECK(read.ids == written.ids);
  read.check_invariants();
}

}  // namespace

TEST_CASE("writing then reading .hair, .ply, .usda and .obj gives back exactly the same strands", "[io]") {
  plume::test::ScratchDir dir("strand_round_trip");
  for (const bool with_widths : {true, false}) {
    const StrandSet sequential = awkward_strands(with_widths, true);
    const StrandSet stable = awkward_strands(with_widths, false);
    SECTION(std::string(".hair") + (with_widths ? " with widths" : "")) {
      plume::io::write_strands(dir.file("s.hair"), sequential, {});
      const StrandSet read = plume::io::read_strands(dir.file("s.hair"));
      check_same_strands(read, sequential, with_widths, true);
      CHECK(read.widths.empty() == !with_widths);
    }
    SECTION(std::string(".ply") + (with_widths ? " with widths" : "")) {
      plume::io::write_strands(dir.file("s.ply"), sequential, {});
      const StrandSet read = plume::io::read_strands(dir.file("s.ply"));
      check_same_strands(read, sequential, with_widths, true);
      CHECK(read.widths.empty() == !with_widths);
    }
    SECTION(std::string(".obj") + (with_widths ? " with widths" : "")) {
      plume::io::write_strands(dir.file("s.obj"), sequential, {});
      check_same_strands(plume::io::read_strands(dir.file("s.obj")), sequential, false, true);
    }
    SECTION(std::string(".usda with stable 64-bit ids and hair groups") + (with_widths ? " and widths" : "")) {
      // Ids a double cannot hold exactly (2^53 + 1, 2^63 - 1) must still come back bit for bit.
      StrandSet wide = stable;
      wide.ids[0] = (uint64_t(1) << 53) + 1;
      wide.ids[1] = uint64_t(std::numeric_limits<int64_t>::max());
      plume::io::StrandWriteOptions options;
      options.constant_width = 0.25f;
      // Group ids differ from the stable ids: the reader must take the ids from plume_id.
      for (size_t s = 0; s < wide.strand_count(); ++s) options.group_ids.push_back(int32_t(s % 3));
      plume::io::write_strands(dir.file("s.usda"), wide, options);
      const StrandSet read = plume::io::read_strands(dir.file("s.usda"));
      check_same_strands(read, wide, with_widths, true);
      if (!with_widths) CHECK(read.widths == std::vector<float>(read.point_count(), 0.25f));
    }
    SECTION(std::string(".usda with a time code and root uvs") + (with_widths ? " and widths" : "")) {
      plume::io::StrandWriteOptions options;
      options.time_code = 7.0;
      for (size_t s = 0; s < sequential.strand_count(); ++s) options.root_uvs.emplace_back(float(s) / 37.0f, 0.5f);
      plume::io::write_strands(dir.file("t.usda"), sequential, options);
      check_same_strands(plume::io::read_strands(dir.file("t.usda")), sequential, with_widths, true);
    }
  }
}

TEST_CASE("the .usda writer lays out the file as FORMATS.md says", "[io]") {
  plume::test::ScratchDir dir("usda_layout");
  StrandSet strands;
  const std::vector<Eigen::Vector3f> a = {{0, 0, 0}, {0, 1, 0}, {0, 2, 0.5f}};
  const std::vector<Eigen::Vector3f> b = {{1, 0, 0}, {1, 1, 0}};
  strands.append(a, 10, std::vector<float>{0.2f, 0.1f, 0.05f});
  strands.append(b, 11, std::vector<float>{0.4f, 0.2f});
  plume::io::StrandWriteOptions options;
  options.root_uvs = {{0.25f, 0.75f}, {0.5f, 0.125f}};
  options.group_ids = {3, 7};
  options.time_code = 12;
  options.fps = 30;
  options.meters_per_unit = 1;
  options.comment = "Plume \"test\"";
  plume::io::write_strands(dir.file("layout.usda"), strands, options);
  std::ifstream in(dir.file("layout.usda"));
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  CHECK(text.rfind("#usda 1.0\n", 0) == 0);
  for (const char *expected : {
           "doc = \"Plume \\\"test\\\"\"", "defaultPrim = \"Groom\"", "metersPerUnit = 1\n", "upAxis = \"Y\"",
           "startTimeCode = 12\n", "endTimeCode = 12\n", "timeCodesPerSecond = 30\n",
           "def Xform \"Groom\" (\n    kind = \"component\"\n    prepend apiSchemas = [\"GroomAPI\"]\n)",
           "def BasisCurves \"hair\"", "uniform token type = \"linear\"", "int[] curveVertexCounts = [3, 2]",
           "point3f[] points.timeSamples = {\n            12: [(0, 0, 0), (0, 1, 0), (0, 2, 0.5), (1, 0, 0), (1, 1, 0)],",
           "float[] widths = [0.2, 0.1, 0.05, 0.4, 0.2] (\n            interpolation = \"vertex\"",
           // extent padded by half the largest width (0.4)
           "float3[] extent.timeSamples = {\n            12: [(-0.2, -0.2, -0.2), (1.2, 2.2, 0.7)],",
           // Unreal keeps only primvars named groom_*: the hair group and the root UV; the stable ids
           // are always int64, as plume_id
           "int[] primvars:groom_group_id = [3, 7] (\n            interpolation = \"uniform\"",
           "int64[] primvars:plume_id = [10, 11] (\n            interpolation = \"uniform\"",
           "texCoord2f[] primvars:groom_root_uv = [(0.25, 0.75), (0.5, 0.125)] (\n            interpolation = \"uniform\""}) {
    INFO(expected);
    CHECK(text.find(expected) != std::string::npos);
  }
  SECTION("without a time code, widths or groups: plain points, constant width, default metersPerUnit, no time metadata, group 0") {
    StrandSet plain = strands;
    plain.widths.clear();
    plume::io::StrandWriteOptions defaults;
    defaults.constant_width = 0.5f;
    plume::io::write_strands(dir.file("plain.usda"), plain, defaults);
    std::ifstream plain_in(dir.file("plain.usda"));
    const std::string plain_text((std::istreambuf_iterator<char>(plain_in)), std::istreambuf_iterator<char>());
    CHECK(plain_text.find("metersPerUnit = 0.01\n") != std::string::npos);
    CHECK(plain_text.find("TimeCode") == std::string::npos);
    CHECK(plain_text.find("point3f[] points = [(0, 0, 0),") != std::string::npos);
    CHECK(plain_text.find("float[] widths = [0.5] (\n            interpolation = \"constant\"") != std::string::npos);
    CHECK(plain_text.find("float3[] extent = [(-0.25, -0.25, -0.25), (1.25, 2.25, 0.75)]") != std::string::npos);
    CHECK(plain_text.find("upAxis = \"Y\"\n") != std::string::npos);
    CHECK(plain_text.find("groom_root_uv") == std::string::npos);
    CHECK(plain_text.find("primvars:groom_id") == std::string::npos);
    CHECK(plain_text.find("primvars:st") == std::string::npos);
    CHECK(plain_text.find("int[] primvars:groom_group_id = [0, 0] (\n            interpolation = \"uniform\"") != std::string::npos);
    CHECK(plain_text.find("int64[] primvars:plume_id = [10, 11] (\n            interpolation = \"uniform\"") != std::string::npos);
  }
  SECTION("up axis Z") {
    plume::io::StrandWriteOptions z_up;
    z_up.up_axis = "Z";
    plume::io::write_strands(dir.file("z.usda"), strands, z_up);
    std::ifstream z_in(dir.file("z.usda"));
    const std::string z_text((std::istreambuf_iterator<char>(z_in)), std::istreambuf_iterator<char>());
    CHECK(z_text.find("upAxis = \"Z\"\n") != std::string::npos);
  }
  SECTION("group ids must be empty or one per strand") {
    plume::io::StrandWriteOptions one_group;
    one_group.group_ids = {1};
    CHECK_THROWS_WITH(plume::io::write_strands(dir.file("groups.usda"), strands, one_group),
                      Catch::Contains("group_ids must be empty or one per strand (2), got 1"));
  }
}

TEST_CASE(".usda ids come from primvars:plume_id, else primvars:groom_id, else 0..n-1", "[io]") {
  plume::test::ScratchDir dir("usda_ids");
  const std::string head = "#usda 1.0\n\ndef BasisCurves \"hair\"\n{\n    int[] curveVertexCounts = [2, 2]\n"
                           "    point3f[] points = [(0, 0, 0), (0, 1, 0), (1, 0, 0), (1, 1, 0)]\n";
  const std::string tail = "}\n";
  SECTION("a file from another tool with groom_id only") {
    std::ofstream(dir.file("g.usda")) << head << "    int[] primvars:groom_id = [4, 9] (interpolation = \"uniform\")\n" << tail;
    CHECK(plume::io::read_strands(dir.file("g.usda")).ids == std::vector<uint64_t>{4, 9});
  }
  SECTION("both: plume_id wins, wherever it appears") {
    std::ofstream(dir.file("b.usda")) << head << "    int64[] primvars:plume_id = [+99857989967872, 5]\n"
                                      << "    int[] primvars:groom_id = [0, 0]\n" << tail;
    CHECK(plume::io::read_strands(dir.file("b.usda")).ids == std::vector<uint64_t>{99857989967872ull, 5});
  }
  SECTION("neither") {
    std::ofstream(dir.file("n.usda")) << head << tail;
    CHECK(plume::io::read_strands(dir.file("n.usda")).ids == std::vector<uint64_t>{0, 1});
  }
  SECTION("a plume_id per curve, integers >= 0") {
    std::ofstream(dir.file("c.usda")) << head << "    int64[] primvars:plume_id = [7]\n" << tail;
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("c.usda")),
                      Catch::Contains("c.usda:7:") && Catch::Contains("primvars:plume_id: expected one per curve (2), got 1"));
    std::ofstream(dir.file("f.usda")) << head << "    int64[] primvars:plume_id = [7, 1.5]\n" << tail;
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("f.usda")),
                      Catch::Contains("f.usda:7:") && Catch::Contains("primvars:plume_id: expected an integer, got \"1.5\""));
    std::ofstream(dir.file("m.usda")) << head << "    int[] primvars:groom_id = [-1, 2]\n" << tail;
    CHECK_THROWS_WITH(plume::io::read_strands(dir.file("m.usda")),
                      Catch::Contains("primvars:groom_id[0]: expected an integer >= 0, got -1"));
  }
}

TEST_CASE("the .ply and .obj writers put one edge or two-index l per segment", "[io]") {
  plume::test::ScratchDir dir("segments");
  StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{0, 0, 0}, {0, 1, 0}, {0, 2, 0}}, 0);
  strands.append(std::vector<Eigen::Vector3f>{{1, 0, 0}, {1, 1, 0}}, 1);
  plume::io::write_strands(dir.file("s.obj"), strands, {});
  std::ifstream obj(dir.file("s.obj"));
  const std::string obj_text((std::istreambuf_iterator<char>(obj)), std::istreambuf_iterator<char>());
  CHECK(obj_text.find("v 0 2 0\nv 1 0 0\nv 1 1 0\nl 1 2\nl 2 3\nl 4 5\n") != std::string::npos);
  plume::io::write_strands(dir.file("s.ply"), strands, {});
  std::ifstream ply(dir.file("s.ply"), std::ios::binary);
  const std::string ply_text((std::istreambuf_iterator<char>(ply)), std::istreambuf_iterator<char>());
  CHECK(ply_text.rfind("ply\nformat binary_little_endian 1.0\nelement vertex 5\nproperty float x\nproperty float y\n"
                       "property float z\nelement edge 3\nproperty int vertex1\nproperty int vertex2\nend_header\n", 0) == 0);
}

TEST_CASE("PLY strands come from edges (following their direction when consistent) or from a per-vertex strand id, ascii or binary", "[io]") {
  plume::test::ScratchDir dir("ply_variants");
  const std::string head = "ply\nformat ascii 1.0\nelement vertex 5\nproperty double x\nproperty float y\nproperty float z\n";
  SECTION("edges that all point one way: each chain starts where its edges start") {
    std::ofstream(dir.file("e.ply")) << head << "element edge 3\nproperty uint vertex1\nproperty uint vertex2\nend_header\n"
                                     << "0 0 0\n0 1 0\n0 2 0\n5 0 0\n5 1 0\n4 3\n2 1\n1 0\n";
    const StrandSet read = plume::io::read_strands(dir.file("e.ply"));
    REQUIRE(read.offsets == std::vector<int64_t>{0, 3, 5});
    CHECK(read.positions[0] == Eigen::Vector3f(0, 2, 0));
    CHECK(read.positions[2] == Eigen::Vector3f(0, 0, 0));
    CHECK(read.positions[3] == Eigen::Vector3f(5, 1, 0));
  }
  SECTION("edges in mixed directions: each chain starts at its lower-index end") {
    std::ofstream(dir.file("m.ply")) << head << "element edge 3\nproperty int vertex1\nproperty int vertex2\nend_header\n"
                                     << "0 0 0\n0 1 0\n0 2 0\n5 0 0\n5 1 0\n4 3\n1 0\n1 2\n";
    const StrandSet read = plume::io::read_strands(dir.file("m.ply"));
    REQUIRE(read.offsets == std::vector<int64_t>{0, 3, 5});
    CHECK(read.positions[0] == Eigen::Vector3f(0, 0, 0));
    CHECK(read.positions[2] == Eigen::Vector3f(0, 2, 0));
    CHECK(read.positions[3] == Eigen::Vector3f(5, 0, 0));
  }
  SECTION("a strand id per vertex, with a face element to skip") {
    std::ofstream(dir.file("c.ply")) << head << "property int strand\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
                                     << "0 0 0 7\n0 1 0 7\n5 0 0 9\n5 1 0 9\n5 2 0 9\n3 0 1 2\n";
    const StrandSet read = plume::io::read_strands(dir.file("c.ply"));
    REQUIRE(read.offsets == std::vector<int64_t>{0, 2, 5});
    CHECK(read.positions[4] == Eigen::Vector3f(5, 2, 0));
  }
}

TEST_CASE("OBJ l lines of any length chain into strands; negative indices count back", "[io]") {
  plume::test::ScratchDir dir("obj_lines");
  std::ofstream(dir.file("l.obj")) << "v 0 0 0\nv 0 1 0\nv 0 2 0\nl 1 2 3\nv 4 0 0\nv 4 1 0\nv 4 2 0\nl -3 -2\nl -2 -1\n";
  const StrandSet read = plume::io::read_strands(dir.file("l.obj"));
  REQUIRE(read.offsets == std::vector<int64_t>{0, 3, 6});
  CHECK(read.positions[5] == Eigen::Vector3f(4, 2, 0));
  CHECK(read.ids == std::vector<uint64_t>{0, 1});
}

TEST_CASE("the real Sintel guides load: 228 strands of 32 points", "[io]") {
  const StrandSet guides = plume::io::read_strands(PLUME_SOURCE_DIR "/grooms/sintel/sintel_guides.hair");
  CHECK(guides.strand_count() == 228);
  CHECK(guides.point_count() == 228 * 32);
  for (size_t s = 0; s < guides.strand_count(); ++s) CHECK(guides.points_in(s) == 32);
  guides.check_invariants();
  SECTION("and survive every format") {
    plume::test::ScratchDir dir("sintel_formats");
    for (const char *ext : {".hair", ".ply", ".usda", ".obj"}) {
      const std::string path = dir.file(std::string("guides") + ext);
      plume::io::write_strands(path, guides, {});
      const StrandSet read = plume::io::read_strands(path);
      INFO(ext);
      CHECK(read.offsets == guides.offsets);
      CHECK(read.positions == guides.positions);
    }
  }
}

TEST_CASE("root points come from a text list or the first point of each strand", "[io]") {
  plume::test::ScratchDir dir("points");
  std::ofstream(dir.file("roots.txt")) << "# x y z\n1 2 3\n\n  -4.5\t5e-1 6  # trailing comment\n";
  const std::vector<Eigen::Vector3f> listed = plume::io::read_points(dir.file("roots.txt"));
  REQUIRE(listed.size() == 2);
  CHECK(listed[1] == Eigen::Vector3f(-4.5f, 0.5f, 6.0f));
  const std::vector<Eigen::Vector3f> roots = plume::io::read_points(PLUME_SOURCE_DIR "/grooms/sintel/sintel_guides.hair");
  const StrandSet guides = plume::io::read_strands(PLUME_SOURCE_DIR "/grooms/sintel/sintel_guides.hair");
  REQUIRE(roots.size() == 228);
  for (size_t s = 0; s < 228; ++s) CHECK(roots[s] == guides.points(s)[0]);
}

TEST_CASE("a strand a format cannot hold is refused before any file appears", "[io]") {
  plume::test::ScratchDir dir("refuse");
  StrandSet too_long;
  too_long.append(std::vector<Eigen::Vector3f>(65537, Eigen::Vector3f::Zero()), 0);
  CHECK_THROWS_WITH(plume::io::write_strands(dir.file("long.hair"), too_long, {}),
                    Catch::Contains("long.hair") && Catch::Contains("at most 65,535 segments per strand, got 65536"));
  CHECK_FALSE(std::filesystem::exists(dir.file("long.hair")));
  StrandSet single;
  single.append(std::vector<Eigen::Vector3f>{Eigen::Vector3f::Zero()}, 0);
  CHECK_THROWS_WITH(plume::io::write_strands(dir.file("single.usda"), single, {}),
                    Catch::Contains("single.usda") && Catch::Contains("expected at least 2 points, got 1"));
  CHECK(std::filesystem::is_empty(dir.path()));
}
