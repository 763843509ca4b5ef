// Groom files with hair groups, and the output keys of a studio pipeline (units, up axis, stage):
// each group a full description sharing the emitter, every bad group a located, key-path message.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>

#include "io/groom_file.h"
#include "io/scratch_dir.h"

namespace fs = std::filesystem;
using plume::GroomDesc;
using plume::InputError;
using plume::io::read_groom_file;

namespace {

const fs::path fixtures = fs::path(PLUME_TEST_DATA) / "groom_file";

/// Writes `text` as a groom file in `dir` (emitter and guides by absolute paths through the
/// placeholders HEAD and GUIDES) and returns its path.
std::string write_groom(const plume::test::ScratchDir &dir, std::string text) {
  for (const auto &[key, value] : {std::pair<std::string, std::string>{"HEAD", (fixtures / "head.obj").string()},
                                   {"GUIDES", (fixtures / "guides.obj").string()}}) {
    for (size_t at = text.find(key); at != std::string::npos; at = text.find(key, at + value.size()))
      text.replace(at, key.size(), value);
  }
  const std::string path = dir.file("groups.groom.yaml");
  std::ofstream(path) << text;
  return path;
}

std::string error_of(const std::string &path) {
  try {
    read_groom_file(path);
  } catch (const InputError &e) {
    return e.what();
  }
  FAIL("reading " << path << " threw no InputError");
  return "";
}

const char *kTwoGroups =
    "plume: 1\n"
    "name: head\n"
    "emitter: {mesh: HEAD}\n"
    "groups:\n"
    "  - name: scalp\n"
    "    guides: {file: GUIDES}\n"
    "    roots: {count: 50, seed: 3}\n"
    "    strands: {points: 9}\n"
    "    effects: [{type: frizz, amount: 0.5}]\n"
    "  - name: brows\n"
    "    guides: {file: GUIDES}\n"
    "    roots: {density: 20}\n"
    "    interpolation: {method: fur, k: 2}\n"
    "    dynamics: {substeps: 2}\n"
    "output: {path: out/h.####.usda, frames: 1-4}\n";

}  // namespace

TEST_CASE("a groom of hair groups: each group a full description sharing the emitter and output", "[io]") {
  plume::test::ScratchDir dir("groom_groups");
  const GroomDesc g = read_groom_file(write_groom(dir, kTwoGroups));
  REQUIRE(g.groups.size() == 2);
  const GroomDesc &scalp = g.groups[0], &brows = g.groups[1];
  CHECK(scalp.group_name == "scalp");
  CHECK(brows.group_name == "brows");
  CHECK(scalp.group_index == 0);
  CHECK(brows.group_index == 1);
  CHECK(brows.group_loc.line == 10);
  for (const GroomDesc *group : {&scalp, &brows}) {
    CHECK(group->name == "head");
    CHECK(group->source == g.source);
    CHECK(group->emitter_path == fs::absolute(fixtures / "head.obj").lexically_normal().string());
    CHECK(group->output.path_pattern == (fs::path(g.source).parent_path() / "out/h.####.usda").string());
    CHECK(group->output.frames == "1-4");
    CHECK(group->groups.empty());
  }
  CHECK(scalp.roots.count == 50);
  CHECK(scalp.roots.seed == 3);
  CHECK(scalp.points_per_strand == 9);
  CHECK(scalp.effects.size() == 1);
  CHECK_FALSE(scalp.dynamics.enabled);
  CHECK(brows.roots.density == 20.0);
  CHECK(brows.interpolation.method == plume::InterpolationSettings::Method::fur);
  CHECK(brows.interpolation.k == 2);
  CHECK(brows.points_per_strand == 32);  // the default: nothing is inherited from another group
  CHECK(brows.effects.empty());
  CHECK(brows.dynamics.enabled);
  // The top level is the first group, for code that reads one.
  CHECK(g.group_name == "scalp");
  CHECK(g.roots.count == 50);

  const std::string text = plume::io::describe_groom(g);
  INFO(text);
  CHECK(text.find("groups: 2 (scalp, brows)\n") != std::string::npos);
  CHECK(text.find("group scalp (groom_group_id 0):\n  guides: ") != std::string::npos);
  CHECK(text.find("group brows (groom_group_id 1):\n") != std::string::npos);
  CHECK(text.find("  roots: 50 scattered, seed 3\n") != std::string::npos);
  CHECK(text.find("  interpolation: fur, k 2") != std::string::npos);
  CHECK(text.find("  dynamics: 2 substeps") != std::string::npos);
}

TEST_CASE("a groom without groups has none, and describes itself as before", "[io]") {
  const GroomDesc g = read_groom_file((fixtures / "minimal.groom.yaml").string());
  CHECK(g.groups.empty());
  CHECK(g.group_name.empty());
  const std::string text = plume::io::describe_groom(g);
  CHECK(text.find("groups:") == std::string::npos);
  CHECK(text.find("\nguides: ") != std::string::npos);
}

TEST_CASE("bad hair groups are errors at their file:line:column, naming the group's key path", "[io]") {
  plume::test::ScratchDir dir("groom_groups_bad");
  const std::string head = "plume: 1\nemitter: {mesh: HEAD}\n";
  const std::string scalp = "  - name: scalp\n    guides: {file: GUIDES}\n    roots: {count: 5}\n";
  struct Case {
    std::string text, where, message;
  };
  const std::vector<Case> cases = {
      {head + "groups:\n" + scalp + "  - name: brows\n    roots: {count: 5}\n", ":7:5: groups[1].guides:",
       "missing required key (a map with file)"},
      {head + "groups:\n" + scalp + "  - name: scalp\n    guides: {file: GUIDES}\n    roots: {count: 5}\n",
       ":7:11: groups[1].name:", "expected a name no other group has (groups[0] is \"scalp\"), got \"scalp\""},
      {head + "groups:\n  - guides: {file: GUIDES}\n    roots: {count: 5}\n", ":4:5: groups[0].name:",
       "missing required key"},
      {head + "groups:\n  - name: 2nd brows\n    guides: {file: GUIDES}\n    roots: {count: 5}\n",
       ":4:11: groups[0].name:", "a name of at most 64 ASCII letters, digits and _"},
      {head + "groups:\n" + scalp + "  - name: brows\n    guides: {file: GUIDES}\n", ":7:5: groups[1].roots:",
       "missing required key"},
      {head + "groups:\n" + scalp + "  - name: brows\n    guides: {file: GUIDES}\n    roots: {count: 0}\n",
       ":9:20: groups[1].roots.count:", "expected a whole number in [1, 100000000]"},
      {head + "groups:\n" + scalp + "    effects: [{type: clump, amout: 1}]\n", ":7:29: groups[0].effects[0].amout:",
       "unknown key"},
      {head + "roots: {count: 5}\ngroups:\n" + scalp, ":3:8: roots:", "not allowed beside groups"},
      {head + "groups: []\n", ":3:9: groups:", "expected a list of at least one hair group"},
      {head + "groups:\n" + scalp + "    feathers: {}\n", ":7:15: groups[0].feathers:", "not allowed in a hair group"},
      {head + "groups:\n" + scalp + "    colour: red\n", ":7:5: groups[0].colour:", "unknown key"},
  };
  for (const Case &c : cases) {
    const std::string path = write_groom(dir, c.text);
    const std::string message = error_of(path);
    INFO(c.text << "\n-> " << message);
    CHECK(message.rfind(path + c.where + " ", 0) == 0);
    CHECK(message.find(c.message) != std::string::npos);
  }
}

TEST_CASE("output.units, output.up_axis and output.stage reach the description, bad values are located", "[io]") {
  plume::test::ScratchDir dir("groom_units");
  const std::string head = "plume: 1\nemitter: {mesh: HEAD}\nguides: {file: GUIDES}\nroots: {count: 5}\n";
  SECTION("defaults: centimetres, Y up, no stage") {
    const GroomDesc g = read_groom_file(write_groom(dir, head));
    CHECK(g.output.meters_per_unit == 0.01);
    CHECK(g.output.up_axis == "Y");
    CHECK(g.output.stage_path.empty());
  }
  SECTION("named units, a number, Z up, a stage relative to the groom file") {
    for (const auto &[units, meters] : std::vector<std::pair<std::string, double>>{
             {"mm", 0.001}, {"cm", 0.01}, {"m", 1.0}, {"in", 0.0254}, {"ft", 0.3048}, {"0.5", 0.5}, {"2e-3", 0.002}}) {
      const GroomDesc g = read_groom_file(
          write_groom(dir, head + "output: {units: " + units + ", up_axis: Z, stage: shots/hair.usda}\n"));
      INFO(units);
      CHECK(g.output.meters_per_unit == Approx(meters));
      CHECK(g.output.up_axis == "Z");
      CHECK(g.output.stage_path == (dir.path() / "shots/hair.usda").string());
      CHECK(plume::io::describe_groom(g).find("up axis Z") != std::string::npos);
    }
  }
  SECTION("bad values") {
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"output: {units: furlong}\n", ":5:17: output.units: expected a length unit (mm, cm, dm, m, km, in, ft)"},
        {"output: {units: 0}\n", ":5:17: output.units: expected a length unit"},
        {"output: {units: -1}\n", ":5:17: output.units: expected a length unit"},
        {"output: {units: nan}\n", ":5:17: output.units: expected a length unit"},
        {"output: {units: [1]}\n", ":5:17: output.units: expected a length unit"},
        {"output: {up_axis: X}\n", ":5:19: output.up_axis: expected one of Y, Z"},
        {"output: {stage: hair.ply}\n", ":5:17: output.stage: expected a path ending in .usda"},
        {"output: {stage: hair.####.usda}\n", ":5:17: output.stage: expected a path without a frame field"},
    };
    for (const auto &[body, expected] : cases) {
      const std::string path = write_groom(dir, head + body);
      const std::string message = error_of(path);
      INFO(body << " -> " << message);
      CHECK(message.rfind(path + expected, 0) == 0);
    }
  }
}
