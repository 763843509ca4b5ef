// `plume check` on feather frames, between two frames: the layer order, order flips, popping and
// shape drift measured on the shipped bird's frames 23 and 24 (24 is the README's picture), with what
// holds there asserted; a frame against itself neither flips nor pops, a planted pop is found and
// fails --strict past its bound; layer-order violations fail --strict; bad uses exit 2.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

const std::string kBirdDir = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
const std::string kBird = kBirdDir + "bird.groom.yaml";

/// The number after "key": in the object "section": {...} of a one-line JSON report.
double field(const std::string &json, const std::string &section, const std::string &key) {
  const size_t at = json.find("\"" + section + "\": {");
  REQUIRE(at != std::string::npos);
  const size_t k = json.find("\"" + key + "\": ", at);
  REQUIRE(k != std::string::npos);
  return std::stod(json.substr(k + key.size() + 4));
}

/// The bird's groom with its layering pass on (`layers`: the groom's layers map), its files named
/// from `dir`.
std::string layered_bird(const ScratchDir &scratch, const std::string &layers = "{enabled: true}") {
  std::string text = read_text(kBird);
  const auto replace = [&](const std::string &from, const std::string &to) {
    const size_t at = text.find(from);
    REQUIRE(at != std::string::npos);
    text.replace(at, from.size(), to);
  };
  replace("mesh: bird.obj", "mesh: " + kBirdDir + "bird.obj");
  replace("sequence: anim/", "sequence: " + kBirdDir + "anim/");
  replace("file: stems.obj", "file: " + kBirdDir + "stems.obj");
  replace("template_files: [bird.feathers.yaml]", "template_files: [" + kBirdDir + "bird.feathers.yaml]");
  replace("  detail:", "  layers: " + layers + "\n  detail:");
  const std::string path = (scratch / "layered.groom.yaml");
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("plume check measures order, flips, popping and drift on the bird's frames 23 and 24", "[feathers][cli]") {
  ScratchDir scratch("feather_check_bird");
  const RunResult run = run_plume("regrow " + quoted(kBird) + " --frames 23-24 --no-preview --vanes " +
                                      quoted(scratch / "v.####.obj"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const RunResult check = run_plume("check " + quoted(scratch / "v.0024.obj") + " --groom " + quoted(kBird) +
                                        " --frame 24 --previous " + quoted(scratch / "v.0023.obj") +
                                        " --max-pop 0.25 --strict --json",
                                    scratch);
  INFO(check.out << check.err);
  REQUIRE(check.out.find("\"layer_order\"") != std::string::npos);
  const std::string &json = check.out;
  // What holds on the shipped coat (its groom does not turn the layering pass on): no vertex below
  // the skin, every feather ranked, no covering broken at rest, the shapes within 2% of their rest
  // shape on average, fewer than 1% of the pairs overlapping in both frames flipping.
  CHECK(field(json, "inside_skin", "points") == 0);
  CHECK(field(json, "layer_order", "overlapping_pairs") > 1000);
  CHECK(field(json, "layer_order", "unranked_pairs") == 0);
  CHECK(field(json, "layer_order", "broken_at_rest") == 0);
  CHECK(field(json, "shape_drift", "mean_percent") < 2.0);
  CHECK(field(json, "shape_drift", "max_percent") < 100.0);
  const double both = field(json, "order_flips", "pairs_in_both"), flips = field(json, "order_flips", "flips");
  CHECK(both > 1000);
  CHECK(flips < 0.01 * both);
  CHECK(field(json, "popping", "largest_rachis_widths") > 0.0);
  CHECK(field(json, "popping", "mean_rachis_widths") < 1.0);
  // What does not hold without layering: vanes through each other, and so --strict fails.
  CHECK(field(json, "vane_pairs", "feather_pairs") > 0);
  CHECK(check.exit_code == 3);
  CHECK(json.find("\"clean\": false") != std::string::npos);
}

TEST_CASE("a feather frame against itself neither flips nor pops; a planted pop is found and fails --strict",
          "[feathers][cli]") {
  ScratchDir scratch("feather_check_pop");
  const std::string groom = layered_bird(scratch);
  const RunResult run = run_plume("regrow " + quoted(groom) + " --strands 600 --frames 24 --no-preview --vanes " +
                                      quoted(scratch / "v.####.obj"),
                                  scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  // The feathers the pass leaves under a lower one are announced (the violations below come from them).
  CHECK(run.err.find("feathers are left under a feather the layer order puts below them") != std::string::npos);
  const std::string frame = scratch / "v.0024.obj";
  const std::string same = "check " + quoted(frame) + " --groom " + quoted(groom) + " --frame 24 --previous-frame 24 ";
  const RunResult itself = run_plume(same + "--previous " + quoted(frame) + " --max-pop 0 --strict --json", scratch);
  INFO(itself.out << itself.err);
  CHECK(field(itself.out, "order_flips", "flips") == 0);
  CHECK(field(itself.out, "popping", "largest_rachis_widths") == 0.0);
  CHECK(itself.out.find("\"over_bound\": false") != std::string::npos);
  // The layered proxy's vanes meet nowhere and stay out of the skin, yet the layering pass cannot
  // turn every higher feather out from under the lower ones it overlaps (layering_test.cpp names
  // which): layer-order violations, and --strict fails on them alone.
  CHECK(field(itself.out, "vane_pairs", "feather_pairs") == 0);
  CHECK(field(itself.out, "inside_skin", "points") == 0);
  CHECK(field(itself.out, "layer_order", "violations") > 0);
  CHECK(itself.out.find("layer-order violations\"") != std::string::npos);
  CHECK(itself.exit_code == 3);
  // The text report names the same measures.
  const RunResult report = run_plume(same + "--previous " + quoted(frame), scratch);
  CHECK(report.exit_code == 0);
  CHECK(report.out.find("layer order (frozen at rest") != std::string::npos);
  CHECK(report.out.find(": 0 order flips of") != std::string::npos);
  CHECK(report.out.find("popping: largest 0 rachis widths") != std::string::npos);
  CHECK(report.out.find("shape drift from the rest shape: mean") != std::string::npos);

  // One vane vertex of the first feather (the file's first vertex line) moved by 0.05 units.
  std::string text = read_text(frame);
  const size_t v = text.find("\nv ") + 1, end = text.find('\n', v);
  std::istringstream line(text.substr(v + 2, end - v - 2));
  double x = 0, y = 0, z = 0;
  line >> x >> y >> z;
  std::ostringstream moved;
  moved.precision(9);
  moved << "v " << x + 0.05 << " " << y << " " << z;
  text.replace(v, end - v, moved.str());
  const std::string popped = scratch / "popped.obj";
  std::ofstream(popped) << text;
  const std::string first_group = text.substr(text.find("\ng feather_") + 11, 20);
  const std::string first_id = first_group.substr(0, first_group.find('\n'));
  const RunResult pop = run_plume("check " + quoted(popped) + " --groom " + quoted(groom) +
                                      " --frame 24 --previous-frame 24 --previous " + quoted(frame) +
                                      " --max-pop 0.1 --strict --json",
                                  scratch);
  INFO(pop.out << pop.err);
  CHECK(field(pop.out, "popping", "largest_distance") == Approx(0.05).epsilon(1e-4));
  CHECK(pop.out.find("\"worst_feather\": " + first_id + ",", pop.out.find("\"popping\"")) != std::string::npos);
  CHECK(field(pop.out, "popping", "largest_rachis_widths") > 0.1);
  CHECK(pop.out.find("\"over_bound\": true") != std::string::npos);
  CHECK(pop.out.find("rachis widths over the bound 0.1\"") != std::string::npos);
  CHECK(pop.exit_code == 3);
  const RunResult lenient = run_plume("check " + quoted(popped) + " --groom " + quoted(groom) +
                                          " --frame 24 --previous-frame 24 --previous " + quoted(frame) +
                                          " --max-pop 1000 --json",
                                      scratch);
  CHECK(lenient.out.find("\"over_bound\": false") != std::string::npos);
  CHECK(lenient.exit_code == 0);

  // Bad uses: no groom, a bound without a previous frame, another coat's frame (its first: the frame
  // number is given on the command line, and the feathers a file holds are the same on every frame).
  const RunResult no_groom = run_plume("check " + quoted(frame) + " --mesh " + quoted(kBirdDir + "bird.obj") +
                                           " --previous " + quoted(frame),
                                       scratch);
  CHECK(no_groom.exit_code == 2);
  CHECK(no_groom.err.find("--previous: needs --groom") != std::string::npos);
  const RunResult no_previous = run_plume("check " + quoted(frame) + " --groom " + quoted(groom) + " --max-pop 1", scratch);
  CHECK(no_previous.exit_code == 2);
  CHECK(no_previous.err.find("--max-pop: needs --previous") != std::string::npos);
  const RunResult other = run_plume("regrow " + quoted(groom) + " --strands 300 --frames 1 --no-preview --vanes " +
                                        quoted(scratch / "w.####.obj"),
                                    scratch);
  REQUIRE(other.exit_code == 0);
  const RunResult mismatch = run_plume(same + "--previous " + quoted(scratch / "w.0001.obj"), scratch);
  CHECK(mismatch.exit_code == 2);
  CHECK(mismatch.err.find("holds other feathers than") != std::string::npos);
}

TEST_CASE("plume regrow and plume check follow the groom's layer order: front tracts above what covers them",
          "[feathers][cli]") {
  ScratchDir scratch("feather_check_front");
  const auto order_of = [&](const std::string &layers, const std::string &name) {
    const std::string groom = layered_bird(scratch, layers);
    const std::string vanes = scratch / (name + ".####.obj"), frame = scratch / (name + ".0001.obj");
    const RunResult run = run_plume("regrow " + quoted(groom) + " --strands 400 --frames 1 --no-preview --vanes " +
                                        quoted(vanes), scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    const RunResult check = run_plume("check " + quoted(frame) + " --groom " + quoted(groom) + " --frame 1 --json", scratch);
    INFO(check.out << check.err);
    REQUIRE(check.exit_code == 0);
    REQUIRE(check.out.find("\"broken_examples\": [") != std::string::npos);
    return std::pair{field(check.out, "layer_order", "overridden_at_rest"), field(check.out, "layer_order", "violations")};
  };
  // The flight feathers put above the coverts that cover their bases at rest: those coverings are
  // reversed, and the order the check judges by is the one the layering pass followed.
  const auto [front_reversed, front_violations] = order_of("{enabled: true, front: [left_flight, right_flight]}", "front");
  const double plain_reversed = order_of("{enabled: true}", "plain").first;
  CHECK(front_reversed > 0);
  CHECK(plain_reversed == 0);
  // Judged by the coverage order instead, the flights over the coverts would count as violations.
  const std::string plain_groom = layered_bird(scratch, "{enabled: true}");
  const RunResult against = run_plume("check " + quoted(scratch / "front.0001.obj") + " --groom " + quoted(plain_groom) +
                                          " --frame 1 --json", scratch);
  REQUIRE(against.exit_code == 0);
  CHECK(field(against.out, "layer_order", "violations") > front_violations);
}

TEST_CASE("a bad layer map or an unknown front tract exits 2 naming the key, and writes nothing", "[feathers][cli]") {
  ScratchDir scratch("feather_bad_layers");
  std::ofstream(scratch / "short_map.txt") << "0.5\n0.2\n";
  const std::string map = scratch / "short_map.txt";
  for (const auto &[layers, expected] :
       {std::pair{"{enabled: true, map: " + map + "}", std::string("values (one per emitter vertex), got 2")},
        std::pair{std::string("{enabled: true, front: [tail, wingz]}"), std::string("no face group \"wingz\"")}}) {
    const std::string groom = layered_bird(scratch, layers);
    const RunResult run = run_plume("regrow " + quoted(groom) + " --strands 50 --frames 1 --no-preview --vanes " +
                                        quoted(scratch / "v.####.obj"), scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find(expected) != std::string::npos);
    const std::string key = layers.find("map") != std::string::npos ? "feathers.layers.map" : "feathers.layers.front";
    CHECK(run.err.find(key) != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(scratch / "v.0001.obj"));
  }
}

TEST_CASE("plume check --frames compares each feather frame with the one before it in the range", "[feathers][cli]") {
  ScratchDir scratch("feather_check_frames");
  const RunResult run = run_plume("regrow " + quoted(kBird) + " --strands 300 --frames 22-24 --no-preview --vanes " +
                                      quoted(scratch / "v.####.obj"), scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const RunResult range = run_plume("check " + quoted(scratch / "v.####.obj") + " --groom " + quoted(kBird) +
                                        " --frames 22-24 --max-pop 1000 --json", scratch);
  INFO(range.err);
  REQUIRE(range.exit_code == 0);
  const RunResult alone = run_plume("check " + quoted(scratch / "v.0024.obj") + " --groom " + quoted(kBird) +
                                        " --frame 24 --previous " + quoted(scratch / "v.0023.obj") +
                                        " --max-pop 1000 --json", scratch);
  REQUIRE(alone.exit_code == 0);
  // The range's reports, one per line, in frame order; the third is the single check of frame 24
  // against 23, file names aside.
  std::vector<std::string> reports;
  std::istringstream lines(range.out);
  for (std::string line; std::getline(lines, line);)
    if (line.rfind("{\"file\": ", 0) == 0) reports.push_back(line);
  REQUIRE(reports.size() == 3);
  const auto without_files = [](std::string text) {
    for (size_t at = text.find("\"file\": \""); at != std::string::npos; at = text.find("\"file\": \"", at + 1))
      text.erase(at + 9, text.find('"', at + 9) - (at + 9));
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    return text;
  };
  CHECK(without_files(reports[2]) == without_files(alone.out));
  // The first frame of the range has nothing before it; the second is against the first.
  CHECK(reports[0].find("\"previous\"") == std::string::npos);
  CHECK(reports[1].find("\"previous\": {\"file\": \"" + (scratch / "v.0022.obj") + "\", \"frame\": 22") != std::string::npos);
  CHECK(field(range.out, "order_flips", "pairs_in_both") > 100);
  CHECK(range.out.find("\"frames_checked\": 3") != std::string::npos);
}
