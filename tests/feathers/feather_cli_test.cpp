// Feather grooms through the `plume` command: the same promises as hair (any frame regrown alone is
// the same bytes as in a full run, for any thread count), bad templates exit 2 naming the file and
// line, vane meshes are described and checked, and the bird's files are what make_bird writes.
#include <catch2/catch.hpp>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

const std::string kBird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/bird.groom.yaml";

}  // namespace

TEST_CASE("a feather frame regrown alone is the same bytes as in a full run, for 1 and 2 threads", "[feathers][cli]") {
  ScratchDir scratch("feather_bytes");
  // With the stems simulated from frame 1: frame 4 alone simulates 1..4 again.
  const RunResult full = run_plume("regrow " + quoted(kBird) + " --frames 1-4 --strands 400 --threads 2 --out " +
                                       quoted(scratch / "full.####.usda") + " --vanes " + quoted(scratch / "vanes.####.obj"),
                                   scratch);
  INFO(full.err);
  REQUIRE(full.exit_code == 0);
  for (const int threads : {1, 2}) {
    std::string alone = "alone";
    alone += std::to_string(threads);
    const RunResult run = run_plume("regrow " + quoted(kBird) + " --frames 4 --strands 400 --threads " +
                                        std::to_string(threads) + " --out " + quoted(scratch / (alone + ".####.usda")) +
                                        " --vanes " + quoted(scratch / (alone + "_vanes.####.obj")),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    CHECK(read_text(scratch / (alone + ".0004.usda")) == read_text(scratch / "full.0004.usda"));
    CHECK(read_text(scratch / (alone + "_vanes.0004.obj")) == read_text(scratch / "vanes.0004.obj"));
  }
  // The frames differ from each other (the bird moves).
  CHECK(read_text(scratch / "full.0001.usda") != read_text(scratch / "full.0004.usda"));
  // Every other curve format, and the vanes as USD.
  for (const char *ext : {"hair", "ply", "obj"}) {
    const RunResult run = run_plume("regrow " + quoted(kBird) + " --frames 2 --strands 100 --out " +
                                        quoted(scratch / (std::string("c.####.") + ext)),
                                    scratch);
    CHECK(run.exit_code == 0);
    const RunResult info = run_plume("info " + quoted(scratch / (std::string("c.0002.") + ext)), scratch);
    CHECK(info.exit_code == 0);
    CHECK(info.out.find("points per strand") != std::string::npos);
  }
}

TEST_CASE("plume regrow grows feathers on the simulated stems, and the same from plume simulate's cache",
          "[feathers][cli]") {
  ScratchDir scratch("feather_dynamics");
  const auto regrow = [&](const std::string &groom, const std::string &frames, const std::string &name,
                          const std::string &extra) {
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames " + frames + " --strands 300 --no-preview --out " +
                                        quoted(scratch / (name + ".####.usda")) + " --vanes " +
                                        quoted(scratch / (name + "_vanes.####.obj")) + extra,
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
  };
  // The whole run simulates the stems from frame 1 (the left wing opening).
  regrow(kBird, "1-8", "full", "");
  // A farm task: the stems simulated once into a guide cache, a frame regrown alone from it.
  const RunResult simulate =
      run_plume("simulate " + quoted(kBird) + " --frames 1-8 --cache " + quoted(scratch / "stems.####.hair"), scratch);
  INFO(simulate.err);
  REQUIRE(simulate.exit_code == 0);
  regrow(kBird, "8", "cached", " --guides-cache " + quoted(scratch / "stems.####.hair"));
  CHECK(read_text(scratch / "cached.0008.usda") == read_text(scratch / "full.0008.usda"));
  CHECK(read_text(scratch / "cached_vanes.0008.obj") == read_text(scratch / "full_vanes.0008.obj"));
  // The same groom without dynamics (the stems carried by the skin alone) grows other feathers: the
  // simulated stems are what the feathers follow.
  std::string text = read_text(kBird);
  const size_t dynamics = text.find("\ndynamics:");
  REQUIRE(dynamics != std::string::npos);
  text.erase(dynamics + 1, text.find("\n\n", dynamics + 1) - dynamics);
  const std::string bird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  for (const std::string name : {"bird.obj", "anim/bird.####.obj", "stems.obj", "bird.feathers.yaml"}) {
    size_t at = text.find(" " + name);
    if (at == std::string::npos) at = text.find("[" + name);
    REQUIRE(at != std::string::npos);
    text.replace(at + 1, name.size(), bird + name);
  }
  const std::string still = scratch / "still.groom.yaml";
  std::ofstream(still) << text;
  const auto same = [&](const std::string &a, const std::string &b) { return read_text(scratch / a) == read_text(scratch / b); };
  regrow(still, "8", "still", "");
  CHECK_FALSE(same("still.0008.usda", "full.0008.usda"));
  CHECK_FALSE(same("still_vanes.0008.obj", "full_vanes.0008.obj"));
}

TEST_CASE("a feather frame passes plume check, curves and vane meshes", "[feathers][cli]") {
  ScratchDir scratch("feather_check");
  const RunResult run = run_plume("regrow " + quoted(kBird) + " --frames 13 --strands 1500 --out " +
                                      quoted(scratch / "f.####.ply") + " --vanes " + quoted(scratch / "v.####.usda"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const std::string mesh = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/anim/bird.0013.obj";
  const RunResult curves = run_plume("check " + quoted(scratch / "f.0013.ply") + " --groom " + quoted(kBird) +
                                         " --frame 13 --strict",
                                     scratch);
  INFO(curves.out << curves.err);
  CHECK(curves.exit_code == 0);
  CHECK(curves.out.find("feather curves") != std::string::npos);
  CHECK(curves.out.find("points below the skin (margin 0): 0") != std::string::npos);
  // The vanes: none below the skin; vane against vane is judged too (the bird's groom does not ask
  // for layers, so its vanes meet, and --strict would fail on them: layering_test.cpp proves layered
  // coats clean).
  const RunResult vanes = run_plume("check " + quoted(scratch / "v.0013.usda") + " --mesh " + quoted(mesh), scratch);
  INFO(vanes.out << vanes.err);
  CHECK(vanes.exit_code == 0);
  CHECK(vanes.out.find("points below the skin (margin 0): 0") != std::string::npos);
  CHECK(vanes.out.find("feather pairs whose vanes meet: ") != std::string::npos);
  const RunResult vanes_json = run_plume(
      "check " + quoted(scratch / "v.0013.usda") + " --mesh " + quoted(mesh) + " --strict --json", scratch);
  CHECK(vanes_json.out.find("\"vane_pairs\": {\"feather_pairs\": ") != std::string::npos);
  CHECK(vanes_json.exit_code == (vanes_json.out.find("\"feather_pairs\": 0,") != std::string::npos ? 0 : 3));
  // The same vanes against the rest pose, where the left wing is folded back along the body: the open
  // wing's vanes pass through the body there, and the check finds them.
  const RunResult rest = run_plume("check " + quoted(scratch / "v.0013.usda") + " --groom " + quoted(kBird) +
                                       " --frame 1 --strict --json",
                                   scratch);
  CHECK(rest.exit_code == 3);
  CHECK(rest.out.find("\"clean\": false") != std::string::npos);
  const RunResult info = run_plume("info " + quoted(scratch / "v.0013.usda"), scratch);
  CHECK(info.exit_code == 0);
  CHECK(info.out.find("vane mesh") != std::string::npos);
  CHECK(info.out.find("triangles") != std::string::npos);
  const RunResult groom = run_plume("info " + quoted(kBird), scratch);
  CHECK(groom.out.find("feathers: 6 templates") != std::string::npos);
}

TEST_CASE("bad feather templates exit 2 with the file, line and key", "[feathers][cli]") {
  ScratchDir scratch("feather_bad");
  for (const auto &[name, key] : std::vector<std::pair<std::string, std::string>>{
           {"feather_negative_length.groom.yaml", ":8:24: feathers.templates.contour.rachis.length: expected a number > 0"},
           {"feather_unsorted_key_barbs.groom.yaml", ":12:24: feathers.templates.contour.barbs.key_barbs[1].position"},
           {"feather_empty_silhouette.groom.yaml", ":10:29: feathers.templates.contour.barbs.right.silhouette"}}) {
    const std::string groom = std::string(PLUME_TEST_DATA) + "/bad/" + name;
    for (const std::string &command : {"regrow " + quoted(groom) + " --out " + quoted(scratch / "x.####.usda"),
                                      "info " + quoted(groom)}) {
      const RunResult run = run_plume(command, scratch);
      INFO(name << ": " << run.err);
      CHECK(run.exit_code == 2);
      CHECK(run.err.find(name + key) != std::string::npos);
    }
    CHECK(files_in(scratch.path).empty());
  }
  // A feather groom with nothing to write, and --vanes on a hair groom.
  const std::string quiet = scratch / "quiet.groom.yaml";
  {
    std::ofstream out(quiet);
    out << "plume: 1\nemitter: {mesh: " << PLUME_TEST_DATA << "/groom_file/head.obj}\nguides: {file: " << PLUME_TEST_DATA
        << "/groom_file/guides.obj}\nfeathers:\n  templates: {down: {rachis: {length: 0.2}}}\n"
        << "  key_feathers: [{template: down, groups: [scalp]}]\n  follicles: {count: 5}\n";
  }
  const RunResult none = run_plume("regrow " + quoted(quiet) + " --frames 1", scratch);
  CHECK(none.exit_code == 2);
  CHECK(none.err.find("expected an output for the feather curves") != std::string::npos);
  fs::remove(quiet);
  const RunResult vanes_on_hair = run_plume("regrow " + quoted(sintel_dir() + "/sintel.groom.yaml") + " --frames 1 --vanes " +
                                                quoted(scratch / "v.####.obj"),
                                            scratch);
  CHECK(vanes_on_hair.exit_code == 2);
  CHECK(vanes_on_hair.err.find("--vanes: expected a feather groom") != std::string::npos);
}

TEST_CASE("make_bird writes the bird's files kept in grooms/bird, byte for byte", "[feathers][cli]") {
  ScratchDir scratch("make_bird");
  const RunResult run = run_plume_command(quoted(PLUME_MAKE_BIRD) + " " + quoted(scratch.path.string()), scratch);
  REQUIRE(run.exit_code == 0);
  const fs::path kept = fs::path(PLUME_SOURCE_DIR) / "grooms" / "bird";
  const std::vector<std::string> written = files_in(scratch.path);
  REQUIRE(written.size() == 2 + 48);
  for (const std::string &file : written) {
    const std::string relative = fs::path(file).lexically_relative(scratch.path).string();
    INFO(relative);
    CHECK(read_text(file) == read_text((kept / relative).string()));
  }
}
