// The `plume` command end to end: every shipped groom runs, bad input gives exit 2 and leaves no
// file, output does not depend on the thread count or on which frames are computed together.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <fstream>

#include "cli/cli_fixtures.h"
#include "io/groom_file.h"
#include "io/point_list.h"

using namespace plume::cli_test;

namespace {

uint32_t big_endian_u32(const std::string &bytes, size_t offset) {
  return (uint32_t(uint8_t(bytes[offset])) << 24) | (uint32_t(uint8_t(bytes[offset + 1])) << 16) |
         (uint32_t(uint8_t(bytes[offset + 2])) << 8) | uint32_t(uint8_t(bytes[offset + 3]));
}

void require_png_of_size(const std::string &path, uint32_t size) {
  const std::string png = read_text(path);
  REQUIRE(png.size() > 33);
  REQUIRE(png.substr(0, 8) == std::string("\x89PNG\r\n\x1a\n", 8));
  REQUIRE(png.substr(12, 4) == "IHDR");
  CHECK(big_endian_u32(png, 16) == size);
  CHECK(big_endian_u32(png, 20) == size);
  CHECK(uint8_t(png[24]) == 8);  // bit depth
  CHECK(uint8_t(png[25]) == 2);  // RGB
}

}  // namespace

TEST_CASE("every groom in grooms/ regrows a frame, and info reads what it wrote", "[cli]") {
  const std::vector<std::string> grooms = shipped_grooms();
  REQUIRE(!grooms.empty());
  for (const std::string &groom : grooms) {
    INFO(groom);
    ScratchDir scratch("every_groom");
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 1 --strands 300 --out " +
                                        quoted(scratch / "hair.####.usda") + " --preview " +
                                        quoted(scratch / "preview.png"),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    CHECK(run.err.empty());  // not a terminal: no progress line
    REQUIRE(fs::exists(scratch / "hair.0001.usda"));
    require_png_of_size(scratch / "preview.png", 800);
    const RunResult info = run_plume("info " + quoted(scratch / "hair.0001.usda"), scratch);
    CHECK(info.exit_code == 0);
    // A feather groom's 300 follicles grow a rachis and barbs each: more curves than follicles.
    // --strands keeps at most the roots a groom has: a roots file may hold fewer than 300.
    // A groom of hair groups grows 300 in each group (info reads every group's BasisCurves prim).
    const plume::GroomDesc desc = plume::io::read_groom_file(groom);
    size_t expected = 0;
    for (const plume::GroomDesc &group : desc.groups.empty() ? std::vector<plume::GroomDesc>{desc} : desc.groups)
      expected += group.roots.source == plume::RootSettings::Source::file
                      ? std::min<size_t>(300, plume::io::read_points(group.roots.file).size())
                      : 300;
    if (read_text(groom).find("\nfeathers:") == std::string::npos)
      CHECK(info.out.find("strands    " + std::to_string(expected)) != std::string::npos);
    CHECK(info.out.find("points per strand") != std::string::npos);
  }
}

TEST_CASE("--help works on every command and --version prints the version", "[cli]") {
  ScratchDir scratch("help");
  for (const std::string command : {"", "regrow ", "simulate ", "preview ", "info ", "check "}) {
    INFO(command);
    const RunResult run = run_plume(command + "--help", scratch);
    CHECK(run.exit_code == 0);
    CHECK(run.out.find("Usage") != std::string::npos);
  }
  const RunResult version = run_plume("--version", scratch);
  CHECK(version.exit_code == 0);
  CHECK(version.out.find(std::string("plume ") + "0.") != std::string::npos);
  const RunResult none = run_plume("", scratch);
  CHECK(none.exit_code == 2);
  const RunResult unknown = run_plume("regrow --no-such-option", scratch);
  CHECK(unknown.exit_code == 2);
}

TEST_CASE("bad input exits with 2, says why on stderr and leaves no output file", "[cli]") {
  ScratchDir scratch("bad_input");
  const std::string out = scratch / "out";
  const std::string good = write_sintel_groom(scratch, "good", "");
  const std::string bad_data = PLUME_TEST_DATA "/bad/";

  // Guides with a NaN: copy the broken fixture next to a groom that uses it.
  fs::copy_file(bad_data + "hair_nan.hair", scratch / "nan_guides.hair");
  const std::string nan_groom = write_sintel_groom(scratch, "nan", "", scratch / "nan_guides.hair");
  // A malformed groom written here (a wrong type) and a mesh that does not exist.
  const std::string mistyped = write_sintel_groom(scratch, "mistyped", "interpolation: {k: four}\n");
  std::string text = read_text(good);
  text.replace(text.find("sintel.obj"), 10, "no_such_head.obj");
  const std::string no_mesh = scratch / "no_mesh.groom.yaml";
  std::ofstream(no_mesh) << text;

  struct Case {
    std::string what, args, message;
  };
  const std::string dest = " --out " + quoted(out + "/hair.####.usda") + " --preview " + quoted(out + "/p.png");
  const std::vector<Case> cases = {
      {"missing groom", "regrow " + quoted(scratch / "nope.groom.yaml") + " --frames 1" + dest, "nope.groom.yaml"},
      {"malformed groom (shipped fixture)", "regrow " + quoted(bad_data + "syntax_error.groom.yaml") + " --frames 1" + dest,
       "syntax_error.groom.yaml"},
      {"unknown key (shipped fixture)", "regrow " + quoted(bad_data + "unknown_top_key.groom.yaml") + " --frames 1" + dest,
       "unknown_top_key.groom.yaml"},
      {"mistyped value", "regrow " + quoted(mistyped) + " --frames 1" + dest, "interpolation.k"},
      {"missing mesh", "regrow " + quoted(no_mesh) + " --frames 1" + dest, "no_such_head.obj"},
      {"NaN in guides", "regrow " + quoted(nan_groom) + " --frames 1" + dest, "nan_guides.hair"},
      {"frames backwards", "regrow " + quoted(good) + " --frames 48-1" + dest, "--frames"},
      {"frames not a number", "regrow " + quoted(good) + " --frames one-two" + dest, "--frames"},
      {"frame step zero", "regrow " + quoted(good) + " --frames 1-10:0" + dest, "--frames"},
      {"range without a frame field", "regrow " + quoted(good) + " --frames 1-2 --out " + quoted(out + "/hair.usda"),
       "frame field"},
      {"unknown output format", "regrow " + quoted(good) + " --frames 1 --out " + quoted(out + "/hair.####.abc"),
       "--out"},
      {"missing guide cache", "regrow " + quoted(good) + " --frames 1" + dest, ""},
      {"preview of a missing groom", "preview " + quoted(scratch / "nope.groom.yaml") + " --out " + quoted(out + "/p.png"),
       "nope.groom.yaml"},
      {"simulate without dynamics", "simulate " + quoted(good) + " --frames 1-2 --cache " + quoted(out + "/g.####.hair"),
       "dynamics"},
      {"info on a broken file", "info " + quoted(bad_data + "hair_truncated.hair"), "hair_truncated.hair"},
      {"check without a mesh", "check " + quoted(bad_data + "hair_nan.hair"), "--mesh"},
  };
  for (const Case &c : cases) {
    if (c.what == "missing guide cache") continue;  // covered with dynamics below
    INFO(c.what << ": plume " << c.args);
    const RunResult run = run_plume(c.args, scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(!run.err.empty());
    if (!c.message.empty()) CHECK(run.err.find(c.message) != std::string::npos);
    CHECK(files_in(out).empty());
  }
}

TEST_CASE("preview writes an 800x800 PNG, and --size changes it", "[cli]") {
  ScratchDir scratch("preview");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  RunResult run = run_plume("preview " + quoted(groom) + " --frame 3 --guides --out " + quoted(scratch / "p.####.png"),
                            scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  require_png_of_size(scratch / "p.0003.png", 800);
  run = run_plume("preview " + quoted(groom) + " --size 64 --out " + quoted(scratch / "small.png"), scratch);
  REQUIRE(run.exit_code == 0);
  require_png_of_size(scratch / "small.png", 64);
}

TEST_CASE("the output does not depend on the thread count", "[cli]") {
  ScratchDir scratch("threads");
  const std::vector<std::string> grooms = shipped_grooms();
  for (const std::string &groom : grooms) {
    INFO(groom);
    for (const int threads : {1, 2}) {
      // Appended piece by piece: GCC 12 warns (-Wrestrict, falsely) on "t" + std::to_string(...) here.
      std::string pattern = "t";
      pattern += std::to_string(threads);
      pattern += ".####.ply";
      const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 2 --strands 300 --threads " +
                                          std::to_string(threads) + " --out " + quoted(scratch / pattern) +
                                          " --preview " + quoted(scratch / "p.####.png"),
                                      scratch);
      INFO(run.err);
      REQUIRE(run.exit_code == 0);
    }
    // A groom of hair groups writes a .ply per group: its first group's is compared.
    const plume::GroomDesc desc = plume::io::read_groom_file(groom);
    const std::string group = desc.groups.empty() ? "" : "." + desc.groups.front().group_name;
    const std::string one = read_text(scratch / ("t1" + group + ".0002.ply"));
    REQUIRE(!one.empty());
    CHECK(one == read_text(scratch / ("t2" + group + ".0002.ply")));
  }
}

TEST_CASE("a frame regrown alone is byte-identical to the same frame of a range", "[cli]") {
  ScratchDir scratch("frame_independence");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-4 --out " + quoted(scratch / "range.####.usda"), scratch)
              .exit_code == 0);
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 3 --out " + quoted(scratch / "alone.%04d.usda"), scratch)
              .exit_code == 0);
  const std::string from_range = read_text(scratch / "range.0003.usda");
  REQUIRE(!from_range.empty());
  CHECK(from_range == read_text(scratch / "alone.0003.usda"));
  // The head turns between keys: frames differ. Outside the keys the nearest key holds.
  CHECK(read_text(scratch / "range.0002.usda").find("points") != std::string::npos);
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 5-9:4 --out " + quoted(scratch / "late.####.hair"), scratch)
              .exit_code == 0);
  CHECK(!fs::exists(scratch / "late.0006.hair"));
  CHECK(read_text(scratch / "late.0005.hair") == read_text(scratch / "late.0009.hair"));
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1 --out " + quoted(scratch / "first.####.hair"), scratch)
              .exit_code == 0);
  CHECK(read_text(scratch / "first.0001.hair") != read_text(scratch / "late.0005.hair"));
}

TEST_CASE("with dynamics, chunks regrown from the guide cache match a full run", "[cli]") {
  ScratchDir scratch("dynamics_cache");
  const std::string groom = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 2}\noutput: {frames: 1-4}\n");
  // The whole range in one run, simulating as it goes.
  RunResult run = run_plume("regrow " + quoted(groom) + " --out " + quoted(scratch / "full.####.usda"), scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  // The simulation alone writes the cache; chunks are then regrown from it, in any order.
  run = run_plume("simulate " + quoted(groom) + " --frames 1-4 --cache " + quoted(scratch / "cache/guides.####.hair"),
                  scratch);
  REQUIRE(run.exit_code == 0);
  for (int frame = 1; frame <= 4; ++frame) CHECK(fs::exists(scratch / ("cache/guides.000" + std::to_string(frame) + ".hair")));
  const std::string cache = " --guides-cache " + quoted(scratch / "cache/guides.####.hair");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 3-4" + cache + " --out " + quoted(scratch / "chunk.####.usda"),
                    scratch)
              .exit_code == 0);
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 2" + cache + " --out " + quoted(scratch / "chunk.####.usda"),
                    scratch)
              .exit_code == 0);
  for (int frame = 2; frame <= 4; ++frame) {
    INFO("frame " << frame);
    const std::string name = ".000" + std::to_string(frame) + ".usda";
    const std::string full = read_text(scratch / ("full" + name));
    REQUIRE(!full.empty());
    CHECK(full == read_text(scratch / ("chunk" + name)));
  }
  // Without a cache, a frame regrown alone is simulated from the groom's first frame: same bytes.
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 3 --out " + quoted(scratch / "alone.####.usda"), scratch)
              .exit_code == 0);
  CHECK(read_text(scratch / "alone.0003.usda") == read_text(scratch / "full.0003.usda"));
  // The simulated guides move differently from the skin-carried ones.
  REQUIRE(run_plume("regrow " + quoted(write_sintel_groom(scratch, "still", "output: {frames: 1-4}\n")) +
                        " --frames 4 --out " + quoted(scratch / "still.####.usda"),
                    scratch)
              .exit_code == 0);
  CHECK(read_text(scratch / "still.0004.usda") != read_text(scratch / "full.0004.usda"));
  // A cache that lacks a frame is bad input, and nothing is written.
  run = run_plume("regrow " + quoted(groom) + " --frames 4-6" + cache + " --out " + quoted(scratch / "gap/h.####.usda"),
                  scratch);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("guides.0005.hair") != std::string::npos);
  CHECK(files_in(scratch.path / "gap").empty());
}

TEST_CASE("check exits with 3 under --strict when strands enter the skin, 0 otherwise", "[cli]") {
  ScratchDir scratch("check");
  const std::string mesh = sintel_dir() + "/sintel.obj";
  // One strand rising from above the head, one going from the scalp into the middle of the head.
  std::ofstream(scratch / "outside.obj") << "v 0 60 0\nv 0 61 0\nv 0 62 0\nl 1 2\nl 2 3\n";
  std::ofstream(scratch / "inside.obj") << "v 0 60 0\nv 0 61 0\nl 1 2\nv 0 45.5 0\nv 0 38 0\nl 3 4\n";
  RunResult run = run_plume("check " + quoted(scratch / "outside.obj") + " --mesh " + quoted(mesh) + " --strict", scratch);
  INFO(run.out << run.err);
  CHECK(run.exit_code == 0);
  CHECK(run.out.find("points inside the skin (margin 0): 0") != std::string::npos);
  run = run_plume("check " + quoted(scratch / "inside.obj") + " --mesh " + quoted(mesh) + " --strict", scratch);
  CHECK(run.exit_code == 3);
  CHECK(run.out.find("VIOLATIONS") != std::string::npos);
  run = run_plume("check " + quoted(scratch / "inside.obj") + " --mesh " + quoted(mesh), scratch);
  CHECK(run.exit_code == 0);
  // Regrown strands keep out of the skin.
  const std::string groom = write_sintel_groom(scratch, "g", "");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1 --out " + quoted(scratch / "h.####.hair"), scratch)
              .exit_code == 0);
  run = run_plume("check " + quoted(scratch / "h.0001.hair") + " --groom " + quoted(groom) + " --strict", scratch);
  INFO(run.out);
  CHECK(run.exit_code == 0);
  CHECK(run.out.find("influences across hard partings: 0") != std::string::npos);
}

TEST_CASE("info describes an emitter mesh and a groom", "[cli]") {
  ScratchDir scratch("info");
  RunResult run = run_plume("info " + quoted(sintel_dir() + "/sintel.obj"), scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find("vertices   3046") != std::string::npos);
  CHECK(run.out.find("triangles  5952") != std::string::npos);
  CHECK(run.out.find("groups     1") != std::string::npos);
  run = run_plume("info " + quoted(sintel_dir() + "/sintel_guides.hair"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find("strands    228") != std::string::npos);
  CHECK(run.out.find("points per strand  min 32  max 32") != std::string::npos);
  run = run_plume("info " + quoted(sintel_dir() + "/sintel.groom.yaml"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find("sintel_guides.hair") != std::string::npos);
  // An OBJ of `l` lines holds strands; a face indented by a tab makes it a mesh.
  std::ofstream(scratch / "lines.obj") << "v 0 0 0\nv 0 1 0\nv 0 2 0\nl 1 2\nl 2 3\n";
  run = run_plume("info " + quoted(scratch / "lines.obj"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find("lines.obj: strands") != std::string::npos);
  CHECK(run.out.find("points     3") != std::string::npos);
  std::ofstream(scratch / "face.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\n\tf 1 2 3\n";
  run = run_plume("info " + quoted(scratch / "face.obj"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find("face.obj: mesh") != std::string::npos);
  CHECK(run.out.find("triangles  1") != std::string::npos);
}

TEST_CASE("on a terminal regrow shows frames/s and an ETA on stderr", "[cli]") {
  ScratchDir scratch("progress");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  // script(1) (util-linux, always on Debian) runs the command on a pseudo-terminal.
  const std::string inner = quoted(PLUME_BINARY) + " regrow " + quoted(groom) + " --frames 1-3 --strands 50 --out " +
                            quoted(scratch / "h.####.hair");
  const std::string command = "script -qec \"" + inner + "\" /dev/null >" + quoted(scratch / "tty.txt") + " 2>&1";
  REQUIRE(std::system(command.c_str()) == 0);
  const std::string shown = read_text(scratch / "tty.txt");
  CHECK(shown.find("3/3 frames") != std::string::npos);
  CHECK(shown.find("frames/s") != std::string::npos);
  CHECK(shown.find("ETA") != std::string::npos);
  CHECK(fs::exists(scratch / "h.0003.hair"));
}

TEST_CASE("regrow writes each root's UV as primvars:groom_root_uv when the emitter has UVs", "[cli]") {
  ScratchDir scratch("uvs");
  // A unit square in the XZ plane with UVs = (x, z), and two upright guides on it.
  std::ofstream(scratch / "plane.obj") << "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\n"
                                          "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                          "f 1/1 4/4 3/3 2/2\n";
  std::ofstream(scratch / "guides.obj") << "v 0.2 0 0.2\nv 0.2 0.5 0.2\nv 0.2 1 0.2\nl 1 2\nl 2 3\n"
                                           "v 0.8 0 0.8\nv 0.8 0.5 0.8\nv 0.8 1 0.8\nl 4 5\nl 5 6\n";
  std::ofstream(scratch / "plane.groom.yaml") << "plume: 1\nemitter: {mesh: plane.obj}\nguides: {file: guides.obj}\n"
                                                 "roots: {count: 5}\nstrands: {points: 4}\n";
  const RunResult run = run_plume("regrow " + quoted(scratch / "plane.groom.yaml") + " --frames 1 --out " +
                                      quoted(scratch / "h.####.usda"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const std::string usda = read_text(scratch / "h.0001.usda");
  const size_t st = usda.find("texCoord2f[] primvars:groom_root_uv");
  REQUIRE(st != std::string::npos);
  // Five (u, v) pairs, each inside the unit square (the roots are on it).
  const size_t open = usda.find("= [", st) + 2, close = usda.find(']', open);
  REQUIRE(open != std::string::npos);
  const std::string values = usda.substr(open + 1, close - open - 1);
  CHECK(std::count(values.begin(), values.end(), '(') == 5);
  CHECK(values.find('-') == std::string::npos);
}
