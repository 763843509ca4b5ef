// The USD outputs a studio pipeline opens: hair groups as BasisCurves prims of one layer, and the
// top-level stage that composes per-frame layers as value clips.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>

#include "groom/error.h"
#include "io/scratch_dir.h"
#include "io/strand_file.h"
#include "io/usda_stage.h"

namespace fs = std::filesystem;
using plume::StrandSet;

namespace {

std::string read_text(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

StrandSet strands_at(float x, int count, uint64_t first_id) {
  StrandSet strands;
  for (int s = 0; s < count; ++s) {
    const std::vector<Eigen::Vector3f> points = {{x + float(s), 0, 0}, {x + float(s), 1, 0}, {x + float(s), 2, 0.5f}};
    strands.append(points, first_id + uint64_t(s), std::vector<float>{0.02f, 0.01f, 0.005f});
  }
  return strands;
}

}  // namespace

TEST_CASE("hair groups are BasisCurves prims of one .usda, read back group by group", "[io]") {
  plume::test::ScratchDir dir("usda_groups");
  const StrandSet scalp = strands_at(0, 3, 100), brows = strands_at(10, 2, 100);
  std::vector<plume::io::StrandGroup> groups(2);
  groups[0] = {"scalp", &scalp, {{0.1f, 0.2f}, {0.3f, 0.4f}, {0.5f, 0.6f}}, 0};
  groups[1] = {"brows", &brows, {}, 1};
  plume::io::StrandWriteOptions options;
  options.time_code = 7;
  options.meters_per_unit = 1;
  options.up_axis = "Z";
  plume::io::write_strand_groups(dir.file("g.usda"), groups, options);
  const std::string text = read_text(dir.file("g.usda"));
  for (const char *expected :
       {"metersPerUnit = 1\n", "upAxis = \"Z\"\n", "def BasisCurves \"scalp\"\n", "def BasisCurves \"brows\"\n",
        "int[] primvars:groom_group_id = [0, 0, 0] (", "int[] primvars:groom_group_id = [1, 1] (",
        "texCoord2f[] primvars:groom_root_uv = [(0.1, 0.2), (0.3, 0.4), (0.5, 0.6)] (",
        "int64[] primvars:plume_id = [100, 101] ("}) {
    INFO(expected);
    CHECK(text.find(expected) != std::string::npos);
  }
  // One Groom Xform holds both, scalp first.
  CHECK(text.find("def Xform \"Groom\"") == text.rfind("def Xform \"Groom\""));
  CHECK(text.find("\"scalp\"") < text.find("\"brows\""));

  const auto read = plume::io::read_strand_groups(dir.file("g.usda"));
  REQUIRE(read.size() == 2);
  CHECK(read[0].first == "scalp");
  CHECK(read[1].first == "brows");
  CHECK(read[0].second.positions == scalp.positions);
  CHECK(read[1].second.positions == brows.positions);
  CHECK(read[1].second.ids == brows.ids);
  // read_strands gives every group's strands, one prim after the other.
  const StrandSet all = plume::io::read_strands(dir.file("g.usda"));
  CHECK(all.strand_count() == 5);
  CHECK(all.positions.back() == brows.positions.back());
  CHECK(all.ids[3] == 100);

  SECTION("a single-group file reads as one group named after its prim; other formats as one unnamed group") {
    plume::io::write_strands(dir.file("one.usda"), scalp);
    const auto one = plume::io::read_strand_groups(dir.file("one.usda"));
    REQUIRE(one.size() == 1);
    CHECK(one[0].first == "hair");
    plume::io::write_strands(dir.file("one.hair"), scalp);
    const auto hair = plume::io::read_strand_groups(dir.file("one.hair"));
    REQUIRE(hair.size() == 1);
    CHECK(hair[0].first.empty());
    CHECK(hair[0].second.strand_count() == 3);
  }
  SECTION("names must be USD prim names, unique; only .usda holds groups") {
    groups[1].name = "scalp";
    CHECK_THROWS_WITH(plume::io::write_strand_groups(dir.file("d.usda"), groups),
                      Catch::Contains("hair group \"scalp\": expected a name no other group has"));
    groups[1].name = "2brows";
    CHECK_THROWS_WITH(plume::io::write_strand_groups(dir.file("n.usda"), groups),
                      Catch::Contains("expected a USD prim name"));
    groups[1].name = "brows";
    CHECK_THROWS_WITH(plume::io::write_strand_groups(dir.file("g.ply"), groups),
                      Catch::Contains("expected a .usda"));
    CHECK_FALSE(fs::exists(dir.file("d.usda")));
  }
}

TEST_CASE("the USD stage composes frame layers as value clips, by relative paths, from the range alone", "[io]") {
  plume::test::ScratchDir dir("usd_stage");
  plume::io::UsdStageOptions options;
  options.time_codes = {1, 3, 5};
  options.frame_paths = {dir.file("frames/hair.0001.usda"), dir.file("frames/hair.0003.usda"),
                         dir.file("frames/hair.0005.usda")};
  options.curves_prims = {"scalp", "brows"};
  options.meters_per_unit = 0.001;
  options.up_axis.assign(1, 'Z');  // (= "Z" trips GCC 12's false -Wrestrict warning)
  options.fps = 30;
  options.comment = "test stage";
  plume::io::write_usd_stage(dir.file("hair.usda"), options);
  const std::string stage = read_text(dir.file("hair.usda"));
  INFO(stage);
  CHECK(stage.rfind("#usda 1.0\n", 0) == 0);
  for (const char *expected : {
           "doc = \"test stage\"", "defaultPrim = \"Groom\"", "metersPerUnit = 0.001\n", "upAxis = \"Z\"\n",
           "startTimeCode = 1\n", "endTimeCode = 5\n", "timeCodesPerSecond = 30\n",
           "def Xform \"Groom\" (\n    kind = \"component\"\n    prepend apiSchemas = [\"GroomAPI\"]\n",
           "prepend references = @./frames/hair.0001.usda@\n",
           "double2[] active = [(1, 0), (3, 1), (5, 2)]\n",
           "asset[] assetPaths = [@./frames/hair.0001.usda@, @./frames/hair.0003.usda@, @./frames/hair.0005.usda@]\n",
           "asset manifestAssetPath = @./hair.manifest.usda@\n", "string primPath = \"/Groom\"\n",
           "double2[] times = [(1, 1), (3, 3), (5, 5)]\n"}) {
    INFO(expected);
    CHECK(stage.find(expected) != std::string::npos);
  }
  // Nothing absolute: the stage moves with its frames.
  CHECK(stage.find(dir.path().string()) == std::string::npos);
  const std::string manifest = read_text(plume::io::usd_manifest_path(dir.file("hair.usda")));
  CHECK(plume::io::usd_manifest_path(dir.file("hair.usda")) == dir.file("hair.manifest.usda"));
  CHECK(manifest.find("over \"Groom\"\n{\n    over \"scalp\"\n    {\n        point3f[] points\n        float3[] extent\n    }\n"
                      "    over \"brows\"") != std::string::npos);

  SECTION("the same range gives the same bytes; a frame outside the stage's folder is named by ../") {
    plume::io::write_usd_stage(dir.file("again/hair.usda"), options);
    const std::string again = read_text(dir.file("again/hair.usda"));
    CHECK(again.find("@../frames/hair.0001.usda@") != std::string::npos);
    plume::io::write_usd_stage(dir.file("hair.usda"), options);
    CHECK(read_text(dir.file("hair.usda")) == stage);
  }
  SECTION("bad ranges and paths USD cannot name") {
    plume::io::UsdStageOptions bad = options;
    bad.time_codes = {1, 1, 2};
    CHECK_THROWS_AS(plume::io::write_usd_stage(dir.file("bad.usda"), bad), plume::InputError);
    bad = options;
    bad.frame_paths[1] = dir.file("a@b.usda");
    CHECK_THROWS_WITH(plume::io::write_usd_stage(dir.file("bad.usda"), bad), Catch::Contains("holds '@'"));
    bad = options;
    bad.time_codes.clear();
    bad.frame_paths.clear();
    CHECK_THROWS_WITH(plume::io::write_usd_stage(dir.file("bad.usda"), bad), Catch::Contains("at least one frame"));
    CHECK_FALSE(fs::exists(dir.file("bad.usda")));
  }
}
