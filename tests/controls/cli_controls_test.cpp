// The plume command with controls: bad control input exits with 2, names the file, line and key,
// and writes nothing; plume info and plume simulate know the controls.
#include <catch2/catch.hpp>

#include <fstream>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

TEST_CASE("bad controls exit with 2, say where, and write nothing", "[controls][cli]") {
  ScratchDir scratch("controls_bad");
  const std::string bad = std::string(PLUME_TEST_DATA) + "/bad/controls_zero_radius.groom.yaml";
  RunResult run = run_plume("regrow " + quoted(bad) + " --out " + quoted(scratch / "h.####.usda"), scratch);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("controls_zero_radius.groom.yaml:8:54: controls.list[0].radius:") != std::string::npos);
  CHECK(files_in(scratch.path).empty());

  // A face group the emitter lacks is found when the groom is loaded, before anything is written.
  const std::string groom = scratch / "g.groom.yaml";
  std::ofstream(groom) << "plume: 1\n"
                       << "emitter: {mesh: " << PLUME_TEST_DATA << "/groom_file/head.obj}\n"
                       << "guides: {file: " << PLUME_TEST_DATA << "/groom_file/guides.obj}\n"
                       << "roots: {count: 10}\n"
                       << "controls:\n  list:\n    - {position: [0.5, 0, 0.5], groups: [tail], lift: 1}\n";
  run = run_plume("regrow " + quoted(groom) + " --out " + quoted(scratch / "out/h.####.usda"), scratch);
  CHECK(run.exit_code == 2);
  CHECK(
      run.err.find(
          "g.groom.yaml:7:41: controls.list[0].groups: no face group \"tail\" in the emitter (groups: scalp, face)") !=
      std::string::npos);
  CHECK_FALSE(fs::exists(scratch / "out"));
}

TEST_CASE("plume info lists the controls, and plume simulate caches the guides after them", "[controls][cli]") {
  ScratchDir scratch("controls_cli");
  const std::string cat = std::string(PLUME_SOURCE_DIR) + "/grooms/cat/cat.groom.yaml";
  const RunResult info = run_plume("info " + quoted(cat), scratch);
  CHECK(info.exit_code == 0);
  CHECK(info.out.find("controls: 4, blended binding") != std::string::npos);

  // The cache holds the guides growth reads: regrowing from it gives the bytes of a run that simulates.
  REQUIRE(run_plume("simulate " + quoted(cat) + " --frames 1-6 --cache " + quoted(scratch / "g.####.hair"), scratch)
              .exit_code == 0);
  REQUIRE(
      run_plume("regrow " + quoted(cat) + " --frames 6 --strands 500 --out " + quoted(scratch / "a.####.ply"), scratch)
          .exit_code == 0);
  REQUIRE(run_plume("regrow " + quoted(cat) + " --frames 6 --strands 500 --guides-cache " +
                        quoted(scratch / "g.####.hair") + " --out " + quoted(scratch / "b.####.ply"),
                    scratch)
              .exit_code == 0);
  const std::string simulated = read_text(scratch / "a.0006.ply"), cached = read_text(scratch / "b.0006.ply");
  REQUIRE_FALSE(simulated.empty());
  CHECK(simulated == cached);
}
