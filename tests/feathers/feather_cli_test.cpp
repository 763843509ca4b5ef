// Feather grooms through the `plume` command: the same promises as hair (any frame regrown alone is
// the same bytes as in a full run, for any thread count), bad templates exit 2 naming the file and
// line, vane meshes are described and checked, and the bird's files are what make_bird writes.
#include <catch2/catch.hpp>

#include <sstream>

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

TEST_CASE("plume simulate writes the skin pass's lifts beside the guide cache: a frame regrown alone from it is the "
          "frame of a sequential run; a missing or malformed lifts file exits 2 naming it", "[feathers][cli]") {
  ScratchDir scratch("feather_lifts");
  // The cache, written with 1 and with 2 threads: the same bytes, a lifts file per frame.
  for (const int threads : {1, 2}) {
    const std::string dir = "cache" + std::to_string(threads) + "/";
    const RunResult run = run_plume("simulate " + quoted(kBird) + " --frames 1-5 --threads " + std::to_string(threads) +
                                        " --cache " + quoted(scratch / (dir + "stems.####.hair")),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    CHECK(run.out.find("feather lifts") != std::string::npos);
  }
  for (int frame = 1; frame <= 5; ++frame) {
    const std::string name = "stems.000" + std::to_string(frame) + ".lifts";
    const std::string one = read_text(scratch / ("cache1/" + name));
    CHECK(one.rfind("plume feather lifts 4\nframe " + std::to_string(frame) + "\nfeathers ", 0) == 0);
    CHECK(one.find("\nlayers 0\n") != std::string::npos);
    CHECK(one == read_text(scratch / ("cache2/" + name)));
  }
  // The lifts differ between frames (the bird moves) and some feathers are lifted.
  CHECK(read_text(scratch / "cache1/stems.0001.lifts") != read_text(scratch / "cache1/stems.0005.lifts"));
  const auto regrow = [&](const std::string &frames, const std::string &name, const std::string &extra) {
    return run_plume("regrow " + quoted(kBird) + " --frames " + frames + " --strands 300 --no-preview --out " +
                         quoted(scratch / (name + ".####.usda")) + " --vanes " +
                         quoted(scratch / (name + "_vanes.####.obj")) + extra,
                     scratch);
  };
  const std::string cache = " --guides-cache " + quoted(scratch / "cache1/stems.####.hair");
  RunResult run = regrow("1-5", "simulated", "");
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  run = regrow("1-5", "sequence", cache);
  REQUIRE(run.exit_code == 0);
  for (const int threads : {1, 2}) {
    const std::string name = "alone" + std::to_string(threads);
    run = regrow("4", name, cache + " --threads " + std::to_string(threads));
    REQUIRE(run.exit_code == 0);
    CHECK(read_text(scratch / (name + "_vanes.0004.obj")) == read_text(scratch / "sequence_vanes.0004.obj"));
    CHECK(read_text(scratch / (name + ".0004.usda")) == read_text(scratch / "sequence.0004.usda"));
  }
  for (int frame = 1; frame <= 5; ++frame) {
    INFO("frame " << frame);
    const std::string name = "_vanes.000" + std::to_string(frame) + ".obj";
    CHECK(read_text(scratch / ("sequence" + name)) == read_text(scratch / ("simulated" + name)));
  }
  // Frame 1, the cache's first, has no frame before, and no frame reads the last frame's lifts.
  fs::remove(scratch / "cache1/stems.0005.lifts");
  CHECK(regrow("1", "first", cache).exit_code == 0);
  // A missing lifts file beside a cache frame, and malformed ones: exit 2, the file and line named.
  fs::remove(scratch / "cache1/stems.0003.lifts");
  run = regrow("4", "missing", cache);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("stems.0003.lifts") != std::string::npos);
  CHECK(!fs::exists(scratch / "missing.0004.usda"));
  const std::string lifts = scratch / "cache1/stems.0003.lifts";
  const std::string valid = read_text(scratch / "cache2/stems.0003.lifts");
  const size_t body = valid.find("\n", valid.find("# id")) + 1;
  const size_t second_line = valid.find("\n", body) + 1;
  for (const auto &[text, expected] : std::vector<std::pair<std::string, std::string>>{
           {"plume feather lifts 5\n", "stems.0003.lifts:1: header"},
           {"plume feather lifts 2\nframe 3\nfeathers 0\nlayers 2\n", "stems.0003.lifts:4: layers: expected 0 or 1"},
           {"plume feather lifts 2\nframe 3\nfeathers 1\nlayers 1\n7 0 1\n", "layer_turn"},
           {"plume feather lifts 3\nframe 3\nfeathers 1\nlayers 1\n7 0 1 0 1\n", "layer_yaw"},
           {"plume feather lifts 3\nframe 3\nfeathers 1\nlayers 1\n7 0 1 0 1 4\n", "layer_yaw: expected radians"},
           {"plume feather lifts 4\nframe 3\nfeathers 1\nlayers 1\n7 0 1 0 1 0\n", "layer_bend"},
           {"plume feather lifts 4\nframe 3\nfeathers 1\nlayers 1\n7 0 1 0 1 0 4 0\n", "layer_bend: expected radians"},
           {"plume feather lifts 4\nframe 3\nfeathers 1\nlayers 1\n7 0 1 0 1 0 0.2 2\n", "layer_bend_start: expected"},
           {"plume feather lifts 1\nframe 2\nfeathers 0\n", "stems.0003.lifts:2: frame: expected 3"},
           {valid.substr(0, body) + "7 nan 1\n" + valid.substr(second_line), ":6:"},
           {valid.substr(0, body) + "7 0.5 2\n" + valid.substr(second_line), "scale"},
           {valid.substr(0, second_line), "expected"},
           {"plume feather lifts 1\nframe 3\nfeathers 99999999\n1 0 1\n", "expected 99999999 feathers, got 1"},
           {"plume feather lifts 1\nframe 3\nfeathers 1\n1 0 1\n", "no feather id"},
       }) {
    std::ofstream(lifts, std::ios::binary) << text;
    run = regrow("4", "bad", cache);
    INFO(text.substr(0, 60) << "\n" << run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find(expected) != std::string::npos);
    CHECK(run.err.find("stems.0003.lifts") != std::string::npos);
  }
  // A file of version 1 (no layers line) reads as before: the same frame.
  std::string version1 = valid;
  version1.replace(0, version1.find('\n'), "plume feather lifts 1");
  const size_t layers_line = version1.find("layers 0\n");
  REQUIRE(layers_line != std::string::npos);
  version1.erase(layers_line, 9);
  std::ofstream(lifts, std::ios::binary) << version1;
  run = regrow("4", "version1", cache);
  REQUIRE(run.exit_code == 0);
  CHECK(read_text(scratch / "version1_vanes.0004.obj") == read_text(scratch / "sequence_vanes.0004.obj"));
  // A groom without feathers: its cache as before, no lifts.
  const std::string hair = write_sintel_groom(scratch, "hair", "dynamics: {substeps: 2}\n");
  run = run_plume("simulate " + quoted(hair) + " --frames 1-2 --cache " + quoted(scratch / "hair/g.####.hair"), scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(fs::exists(scratch / "hair/g.0002.hair"));
  CHECK(!fs::exists(scratch / "hair/g.0002.lifts"));
  CHECK(run.out.find("feather lifts") == std::string::npos);
}

TEST_CASE("with layers, the layering pass's state is carried like the skin pass's: a frame regrown alone, with or "
          "without the cache, is the frame of a sequential run, for 1 and 2 threads", "[feathers][cli]") {
  ScratchDir scratch("feather_layers_state");
  // The bird with 300 feathers (the whole coat, so plume simulate's cache holds this coat's state) in
  // layers, its files named absolutely.
  std::string text = read_text(kBird);
  const std::string bird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  for (const std::string name : {"bird.obj", "anim/bird.####.obj", "stems.obj", "bird.feathers.yaml"}) {
    size_t at = text.find(" " + name);
    if (at == std::string::npos) at = text.find("[" + name);
    REQUIRE(at != std::string::npos);
    text.replace(at + 1, name.size(), bird + name);
  }
  const size_t count = text.find("count: 5000");
  REQUIRE(count != std::string::npos);
  text.replace(count, 11, "count: 300");
  text.replace(text.find("feathers:\n") + 10, 0, "  layers: {enabled: true}\n");
  const std::string groom = scratch / "layered.groom.yaml";
  std::ofstream(groom) << text;
  const auto regrow = [&](const std::string &frames, const std::string &name, const std::string &extra) {
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames " + frames + " --no-preview --out " +
                                        quoted(scratch / (name + ".####.usda")) + " --vanes " +
                                        quoted(scratch / (name + "_vanes.####.obj")) + extra,
                                    scratch);
    INFO(run.err);
    CHECK(run.exit_code == 0);
    return run;
  };
  const auto same = [&](const std::string &a, const std::string &b) { return read_text(scratch / a) == read_text(scratch / b); };
  regrow("1-4", "sequence", "");
  // Alone without a cache: frames 1-3 replayed (the stems simulated, the coat grown and layered).
  for (const int threads : {1, 2}) {
    const std::string name = "alone" + std::to_string(threads);
    regrow("4", name, " --threads " + std::to_string(threads));
    CHECK(same(name + "_vanes.0004.obj", "sequence_vanes.0004.obj"));
    CHECK(same(name + ".0004.usda", "sequence.0004.usda"));
  }
  // From plume simulate's cache (1 and 2 threads write the same bytes, layers included).
  for (const int threads : {1, 2}) {
    const std::string dir = "cache" + std::to_string(threads) + "/";
    const RunResult run = run_plume("simulate " + quoted(groom) + " --frames 1-4 --threads " + std::to_string(threads) +
                                        " --cache " + quoted(scratch / (dir + "stems.####.hair")),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
  }
  for (int frame = 1; frame <= 4; ++frame) {
    const std::string name = "stems.000" + std::to_string(frame) + ".lifts";
    const std::string one = read_text(scratch / ("cache1/" + name));
    CHECK(one.find("\nlayers 1\n") != std::string::npos);
    CHECK(one == read_text(scratch / ("cache2/" + name)));
  }
  // Frame 4 regrown alone reads frame 3's state: some feathers there are turned aside (a yaw, the last
  // column), so the carried yaw is what makes it the sequential frame.
  int yawed = 0;
  {
    std::istringstream lines(read_text(scratch / "cache1/stems.0003.lifts"));
    std::string line;
    while (std::getline(lines, line)) {
      std::istringstream values(line);
      double id = 0, lift = 0, scale = 0, turn = 0, size = 0, yaw = 0;
      if (values >> id >> lift >> scale >> turn >> size >> yaw && yaw != 0.0) ++yawed;
    }
  }
  CHECK(yawed > 0);
  const std::string cache = " --guides-cache " + quoted(scratch / "cache1/stems.####.hair");
  regrow("1-4", "cached_sequence", cache);
  for (int frame = 1; frame <= 4; ++frame) {
    INFO("frame " << frame);
    const std::string name = "_vanes.000" + std::to_string(frame) + ".obj";
    CHECK(same("cached_sequence" + name, "sequence" + name));
  }
  for (const int threads : {1, 2}) {
    const std::string name = "cached" + std::to_string(threads);
    regrow("4", name, cache + " --threads " + std::to_string(threads));
    CHECK(same(name + "_vanes.0004.obj", "sequence_vanes.0004.obj"));
  }
  // A lifts file without the layering pass's state (version 1, or written for the groom without
  // layers) exits 2 naming the file and the field.
  const std::string lifts = scratch / "cache1/stems.0003.lifts";
  const RunResult plain = run_plume("simulate " + quoted(kBird) + " --frames 1-3 --cache " +
                                        quoted(scratch / "plain/stems.####.hair"),
                                    scratch);
  REQUIRE(plain.exit_code == 0);
  std::string version1 = read_text(scratch / "plain/stems.0003.lifts");
  version1.replace(0, version1.find('\n'), "plume feather lifts 1");
  version1.erase(version1.find("layers 0\n"), 9);
  for (const std::string &bad : {read_text(scratch / "plain/stems.0003.lifts"), version1}) {
    std::ofstream(lifts, std::ios::binary) << bad;
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 4 --no-preview --out " +
                                        quoted(scratch / "bad.####.usda") + cache,
                                    scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find("stems.0003.lifts") != std::string::npos);
    CHECK(run.err.find("layers") != std::string::npos);
    CHECK(!fs::exists(scratch / "bad.0004.usda"));
  }
  // A layered file of version 3 (no bend columns) exits 2 naming the file and the bend; one of
  // version 2 (no yaw either), the yaw.
  const std::string valid_layered = read_text(scratch / "cache2/stems.0003.lifts");
  for (const auto &[version, field] : std::vector<std::pair<int, std::string>>{{3, "layer_bend"}, {2, "layer_yaw"}}) {
    std::string older;
    std::istringstream lines(valid_layered);
    std::string line;
    bool body = false;
    while (std::getline(lines, line)) {
      if (line.rfind("plume feather lifts", 0) == 0) line = "plume feather lifts " + std::to_string(version);
      if (body)
        for (int column = 0; column < (version == 3 ? 2 : 3); ++column) line.erase(line.rfind(' '));
      body = body || line.rfind("# id", 0) == 0;
      older += line + "\n";
    }
    std::ofstream(lifts, std::ios::binary) << older;
    const RunResult old = run_plume("regrow " + quoted(groom) + " --frames 4 --no-preview --out " +
                                        quoted(scratch / "old.####.usda") + cache,
                                    scratch);
    INFO(old.err);
    CHECK(old.exit_code == 2);
    CHECK(old.err.find("stems.0003.lifts") != std::string::npos);
    CHECK(old.err.find(field) != std::string::npos);
    CHECK(!fs::exists(scratch / "old.0004.usda"));
  }
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
