// Studio pipeline outputs: the top-level USD stage of a .usda sequence (value clips, the same bytes
// from every farm chunk), the groom's units and up axis, and grooms of several hair groups (one
// BasisCurves prim per group, one file per group in the other formats, checked group by group).
#include <catch2/catch.hpp>

#include <algorithm>

#include "cli/cli_fixtures.h"
#include "io/strand_file.h"

using namespace plume::cli_test;

namespace {

std::string groups_dir() { return std::string(PLUME_SOURCE_DIR) + "/grooms/sintel_groups"; }

/// A groom of two hair groups on the Sintel head turning (no dynamics): `scalp` from the shipped
/// scalp guides, `brows` from the example's brow guides. `extra` is appended to the scalp group.
std::string write_groups_groom(const ScratchDir &scratch, const std::string &name, const std::string &extra = "") {
  const std::string path = scratch / (name + ".groom.yaml");
  std::ofstream(path) << "plume: 1\n"
                      << "name: " << name << "\n"
                      << "emitter:\n"
                      << "  mesh: " << sintel_dir() << "/sintel.obj\n"
                      << "  animation:\n"
                      << "    pivot: [0, 24, -2]\n"
                      << "    keys: [{frame: 1, rotate: [0, 0, 0]}, {frame: 5, rotate: [0, 30, 0]}]\n"
                      << "groups:\n"
                      << "  - name: scalp\n"
                      << "    guides: {file: " << sintel_dir() << "/sintel_guides.hair}\n"
                      << "    roots: {count: 300, near_guides: 2.0, seed: 3}\n"
                      << "    strands: {points: 8}\n"
                      << extra
                      << "  - name: brows\n"
                      << "    guides: {file: " << groups_dir() << "/brows.hair}\n"
                      << "    roots: {count: 200, near_guides: 0.35, seed: 5}\n"
                      << "    strands: {points: 6, width: {root: 0.012, tip: 0.003}}\n"
                      << "    interpolation: {k: 3}\n";
  return path;
}

/// The names of the files in `dir`, sorted.
std::vector<std::string> names_in(const fs::path &dir) {
  std::vector<std::string> names;
  for (const std::string &path : files_in(dir)) names.push_back(fs::path(path).filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

size_t count_of(const std::string &text, const std::string &what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("a .usda sequence gets a stage of value clips, the same bytes from every farm chunk", "[cli]") {
  ScratchDir scratch("usd_stage");
  const std::string groom = write_sintel_groom(scratch, "turn", "");
  const RunResult full = run_plume("regrow " + quoted(groom) + " --frames 1-4 --strands 30 --out " +
                                       quoted(scratch / "full/hair.####.usda"),
                                   scratch);
  INFO(full.err);
  REQUIRE(full.exit_code == 0);
  const std::string stage = read_text(scratch / "full/hair.usda");
  INFO(stage);
  CHECK(stage.find("prepend references = @./hair.0001.usda@") != std::string::npos);
  CHECK(stage.find("asset[] assetPaths = [@./hair.0001.usda@, @./hair.0002.usda@, @./hair.0003.usda@, "
                   "@./hair.0004.usda@]") != std::string::npos);
  CHECK(stage.find("double2[] active = [(1, 0), (2, 1), (3, 2), (4, 3)]") != std::string::npos);
  CHECK(stage.find("startTimeCode = 1\n    endTimeCode = 4\n") != std::string::npos);
  CHECK(stage.find("metersPerUnit = 0.01\n    upAxis = \"Y\"") != std::string::npos);
  CHECK(stage.find(scratch.path.string()) == std::string::npos);  // no absolute path
  CHECK(read_text(scratch / "full/hair.manifest.usda").find("over \"hair\"") != std::string::npos);
  // Each frame is a layer of its own with its time sample, as before.
  CHECK(read_text(scratch / "full/hair.0003.usda").find("points.timeSamples = {\n            3: [") != std::string::npos);

  SECTION("farm chunks of the shot write the same stage, and the same frames") {
    for (const std::string chunk : {"1-2", "3-4"}) {
      const RunResult run = run_plume("regrow " + quoted(groom) + " --frames " + chunk + " --stage-frames 1-4 "
                                          "--strands 30 --out " + quoted(scratch / "chunk/hair.####.usda"),
                                      scratch);
      INFO(run.err);
      REQUIRE(run.exit_code == 0);
      CHECK(read_text(scratch / "chunk/hair.usda") == stage);
    }
    for (const char *name : {"hair.0001.usda", "hair.0004.usda", "hair.manifest.usda"})
      CHECK(read_text(scratch / (std::string("chunk/") + name)) == read_text(scratch / (std::string("full/") + name)));
  }
  SECTION("a groom's output.frames is the shot: a chunk's stage spans it") {
    const std::string shot = write_sintel_groom(scratch, "shot", "output: {frames: 1-4}\n");
    REQUIRE(run_plume("regrow " + quoted(shot) + " --frames 3 --strands 30 --out " + quoted(scratch / "shot/h_####.usda"),
                      scratch)
                .exit_code == 0);
    const std::string shot_stage = read_text(scratch / "shot/h.usda");
    CHECK(shot_stage.find("@./h_0001.usda@, @./h_0002.usda@, @./h_0003.usda@, @./h_0004.usda@]") != std::string::npos);
  }
  SECTION("--stage names it, --no-stage and other formats write none, a stage on a frame file is refused") {
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-2 --strands 30 --out " + quoted(scratch / "a/h.####.usda") +
                          " --stage " + quoted(scratch / "shots/turn.usda"),
                      scratch)
                .exit_code == 0);
    CHECK(read_text(scratch / "shots/turn.usda").find("@../a/h.0001.usda@, @../a/h.0002.usda@]") != std::string::npos);
    CHECK(fs::exists(scratch / "shots/turn.manifest.usda"));
    CHECK_FALSE(fs::exists(scratch / "a/h.usda"));
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-2 --strands 30 --no-stage --out " +
                          quoted(scratch / "b/h.####.usda"),
                      scratch)
                .exit_code == 0);
    CHECK(names_in(scratch.path / "b") == std::vector<std::string>{"h.0001.usda", "h.0002.usda"});
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-2 --strands 30 --out " + quoted(scratch / "c/h.####.ply"),
                      scratch)
                .exit_code == 0);
    CHECK(names_in(scratch.path / "c") == std::vector<std::string>{"h.0001.ply", "h.0002.ply"});
    const RunResult clash = run_plume("regrow " + quoted(groom) + " --frames 1-2 --strands 30 --out " +
                                          quoted(scratch / "d/h.####.usda") + " --stage " + quoted(scratch / "d/h.0002.usda"),
                                      scratch);
    CHECK(clash.exit_code == 2);
    CHECK(clash.err.find("--stage: the stage " + (scratch / "d/h.0002.usda") + " would be the file of frame 2") !=
          std::string::npos);
    CHECK_FALSE(fs::exists(scratch.path / "d"));
  }
}

TEST_CASE("the groom's output.units and output.up_axis are the USD layers' metersPerUnit and upAxis", "[cli]") {
  ScratchDir scratch("usd_units");
  const std::string groom = write_sintel_groom(scratch, "mm", "output: {units: mm, up_axis: Z}\n");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-2 --strands 20 --out " + quoted(scratch / "h.####.usda"),
                    scratch)
              .exit_code == 0);
  for (const char *name : {"h.0001.usda", "h.usda"}) {
    const std::string text = read_text(scratch / name);
    INFO(name);
    CHECK(text.find("metersPerUnit = 0.001\n") != std::string::npos);
    CHECK(text.find("upAxis = \"Z\"\n") != std::string::npos);
  }
  const std::string bad = write_sintel_groom(scratch, "bad", "output: {units: parsec}\n");
  const RunResult run = run_plume("regrow " + quoted(bad) + " --frames 1 --out " + quoted(scratch / "x.usda"), scratch);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find(bad + ":12:17: output.units: expected a length unit") != std::string::npos);
}

TEST_CASE("a groom of hair groups writes every group: one BasisCurves prim each, or one file each", "[cli]") {
  ScratchDir scratch("hair_groups");
  const std::string groom = write_groups_groom(scratch, "two");
  const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 1-2 --out " + quoted(scratch / "u/hair.####.usda"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const std::string text = read_text(scratch / "u/hair.0002.usda");
  CHECK(count_of(text, "def Xform \"Groom\"") == 1);
  CHECK(text.find("def BasisCurves \"scalp\"") < text.find("def BasisCurves \"brows\""));
  CHECK(count_of(text, "def BasisCurves") == 2);
  const auto groups = plume::io::read_strand_groups(scratch / "u/hair.0002.usda");
  REQUIRE(groups.size() == 2);
  CHECK(groups[0].second.strand_count() == 300);
  CHECK(groups[1].second.strand_count() == 200);
  CHECK(text.find("int[] primvars:groom_group_id = [1, 1, 1,") != std::string::npos);
  CHECK(text.find("int[] primvars:groom_group_id = [0, 0, 0,") != std::string::npos);
  const std::string manifest = read_text(scratch / "u/hair.manifest.usda");
  CHECK(manifest.find("over \"scalp\"") != std::string::npos);
  CHECK(manifest.find("over \"brows\"") != std::string::npos);

  SECTION("a group grows as the same description alone would: groups are independent") {
    const std::string alone = scratch / "scalp.groom.yaml";
    std::ofstream(alone) << "plume: 1\nemitter:\n  mesh: " << sintel_dir() << "/sintel.obj\n"
                         << "  animation:\n    pivot: [0, 24, -2]\n"
                         << "    keys: [{frame: 1, rotate: [0, 0, 0]}, {frame: 5, rotate: [0, 30, 0]}]\n"
                         << "guides: {file: " << sintel_dir() << "/sintel_guides.hair}\n"
                         << "roots: {count: 300, near_guides: 2.0, seed: 3}\nstrands: {points: 8}\n";
    REQUIRE(run_plume("regrow " + quoted(alone) + " --frames 2 --out " + quoted(scratch / "alone.####.usda"), scratch)
                .exit_code == 0);
    const plume::StrandSet single = plume::io::read_strands(scratch / "alone.0002.usda");
    CHECK(single.positions == groups[0].second.positions);
    CHECK(single.ids == groups[0].second.ids);
    // A groom without groups keeps its one prim "hair".
    CHECK(read_text(scratch / "alone.0002.usda").find("def BasisCurves \"hair\"") != std::string::npos);
  }
  SECTION(".ply: one file per group, the group's name before the frame field") {
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 2 --out " + quoted(scratch / "p/hair.####.ply"), scratch)
                .exit_code == 0);
    CHECK(names_in(scratch.path / "p") == std::vector<std::string>{"hair.brows.0002.ply", "hair.scalp.0002.ply"});
    CHECK(plume::io::read_strands(scratch / "p/hair.brows.0002.ply").positions == groups[1].second.positions);
  }
  SECTION("check --groom judges each group against its own description") {
    const std::string args = quoted(scratch / "u/hair.0002.usda") + " --groom " + quoted(groom) + " --frame 2";
    const RunResult text_run = run_plume("check " + args, scratch);
    INFO(text_run.out << text_run.err);
    CHECK(text_run.exit_code == 0);
    CHECK(text_run.out.find("(hair group scalp): 300 strands") != std::string::npos);
    CHECK(text_run.out.find("(hair group brows): 200 strands") != std::string::npos);
    CHECK(text_run.out.find("not the groom's") == std::string::npos);
    const RunResult json = run_plume("check " + args + " --json", scratch);
    CHECK(json.exit_code == 0);
    CHECK(json.out.rfind("[\n{", 0) == 0);
    CHECK(count_of(json.out, "\"group\":") == 2);
    CHECK(count_of(json.out, "\"strands_off_groom_roots\":0") == 2);
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 2 --out " + quoted(scratch / "p/hair.####.ply"), scratch)
                .exit_code == 0);
    const RunResult one = run_plume("check " + quoted(scratch / "p/hair.brows.0002.ply") + " --groom " + quoted(groom) +
                                        " --frame 2 --group brows --json",
                                    scratch);
    CHECK(one.exit_code == 0);
    CHECK(one.out.find("\"group\":\"brows\"") != std::string::npos);
    CHECK(one.out.find("\"strands_off_groom_roots\":0") != std::string::npos);
    // The scalp's strands checked as brows are not the brows' regrown strands.
    const RunResult wrong = run_plume("check " + quoted(scratch / "p/hair.scalp.0002.ply") + " --groom " +
                                          quoted(groom) + " --frame 2 --group brows --json",
                                      scratch);
    CHECK(wrong.out.find("\"strands_off_groom_roots\":0") == std::string::npos);
    for (const auto &[extra, message] : std::vector<std::pair<std::string, std::string>>{
             {" --group nope", "--group: no hair group \"nope\""},
             {"", "name the one"}}) {
      const RunResult bad = run_plume("check " + quoted(scratch / "p/hair.brows.0002.ply") + " --groom " + quoted(groom) +
                                          " --frame 2" + extra,
                                      scratch);
      INFO(bad.err);
      CHECK(bad.exit_code == 2);
      CHECK(bad.err.find(message) != std::string::npos);
    }
  }
  SECTION("info lists the groups; bad groups and a guide cache are refused with exit 2") {
    const RunResult info = run_plume("info " + quoted(groom), scratch);
    CHECK(info.out.find("groups: 2 (scalp, brows)") != std::string::npos);
    CHECK(info.out.find("group brows (groom_group_id 1):\n  guides: ") != std::string::npos);
    const RunResult json = run_plume("info " + quoted(groom) + " --json", scratch);
    CHECK(json.exit_code == 0);
    CHECK(json.out.find("\"groups\":[\"scalp\",\"brows\"]") != std::string::npos);
    CHECK(json.out.find("\"meters_per_unit\":0.01") != std::string::npos);
    CHECK(json.out.find("\"up_axis\":\"Y\"") != std::string::npos);
    const std::string twice = write_groups_groom(scratch, "twice", "  - name: brows\n    guides: {file: " +
                                                                       sintel_dir() + "/sintel_guides.hair}\n"
                                                                       "    roots: {count: 5}\n");
    const RunResult dup = run_plume("regrow " + quoted(twice) + " --frames 1 --out " + quoted(scratch / "x.usda"), scratch);
    CHECK(dup.exit_code == 2);
    CHECK(dup.err.find(twice + ":16:11: groups[2].name: expected a name no other group has (groups[1] is \"brows\")") != std::string::npos);
    const RunResult cache = run_plume("regrow " + quoted(groom) + " --frames 1 --guides-cache " +
                                          quoted(scratch / "g.####.hair") + " --out " + quoted(scratch / "x.usda"),
                                      scratch);
    CHECK(cache.exit_code == 2);
    CHECK(cache.err.find("--guides-cache: a guide cache holds one group's guides") != std::string::npos);
  }
}

TEST_CASE("the Sintel groups example: its brows and lashes pass check --strict on its first frame", "[cli]") {
  // The scalp group is the shipped Sintel groom's and shares its crossings (grooms/sintel_groups/README.md).
  // Its middle frame (24), every group, is in "every groom in grooms/ on the middle frame it renders".
  ScratchDir scratch("sintel_groups");
  const std::string groom = groups_dir() + "/sintel_groups.groom.yaml";
  const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 1 --no-stage --out " +
                                      quoted(scratch / "hair.####.usda") + " --preview " + quoted(scratch / "p.png"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  for (const std::string group : {"brows", "lashes"}) {
    const RunResult check = run_plume("check " + quoted(scratch / "hair.0001.usda") + " --groom " + quoted(groom) +
                                          " --frame 1 --group " + group + " --strict --json",
                                      scratch);
    INFO(group << " frame 1\n" << check.out << check.err);
    CHECK(check.exit_code == 0);
    CHECK(check.out.find("\"strands_off_groom_roots\":0") != std::string::npos);
    CHECK(check.out.find("\"clean\":true") != std::string::npos);
  }
}
