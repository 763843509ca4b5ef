// `plume check` end to end: the emitter posed at --frame (rigid keys, OBJ sequences), the guides of
// that frame (carried or simulated), the effects rule, requested roots, the strict verdicts, the
// JSON report read back by an independent parser, bad input, and the shipped grooms on the frames
// they render.
#include <catch2/catch.hpp>

#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

#include "cli/cli_fixtures.h"
#include "groom/mesh_query.h"
#include "interp/hard_scenes.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume::cli_test;

namespace {

/// Every leaf of a JSON text, path -> value as JSON text ("crossings.pairs" -> "3"), read by Node's
/// JSON.parse (tests/tools/json_leaves.mjs): strict, and written by nobody on Plume.
std::map<std::string, std::string> json_leaves(const std::string &json, const ScratchDir &scratch) {
  const std::string path = scratch / "report.json";
  std::ofstream(path) << json;
  const RunResult run = run_plume_command(
      "node " + quoted(std::string(PLUME_SOURCE_DIR) + "/tests/tools/json_leaves.mjs") + " " + quoted(path), scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  std::map<std::string, std::string> leaves;
  std::istringstream lines(run.out);
  for (std::string line; std::getline(lines, line);) {
    const size_t space = line.find(' ');
    if (space != std::string::npos) leaves[line.substr(0, space)] = line.substr(space + 1);
  }
  return leaves;
}

double number(const std::map<std::string, std::string> &leaves, const std::string &key) {
  const auto found = leaves.find(key);
  INFO(key);
  REQUIRE(found != leaves.end());
  REQUIRE(found->second != "null");
  return std::stod(found->second);
}

/// `plume check ARGS --json`, its exit code and its leaves.
struct JsonCheck {
  int exit_code = -1;
  std::map<std::string, std::string> leaves;
  double operator[](const std::string &key) const { return number(leaves, key); }
  const std::string &text(const std::string &key) const {
    INFO(key);
    REQUIRE(leaves.count(key));
    return leaves.at(key);
  }
};

JsonCheck check_json(const std::string &args, const ScratchDir &scratch) {
  const RunResult run = run_plume("check " + args + " --json", scratch);
  INFO(run.err);
  JsonCheck result;
  result.exit_code = run.exit_code;
  REQUIRE((run.exit_code == 0 || run.exit_code == 3));
  result.leaves = json_leaves(run.out, scratch);
  return result;
}

/// The Sintel head rotated by `degrees` about the y axis through (0, 24, -2), written as an OBJ of the
/// same topology (a frame of an emitter sequence).
void write_turned_head(const std::string &path, float degrees) {
  std::ifstream in(sintel_dir() + "/sintel.obj");
  std::ofstream out(path);
  const float a = degrees * 3.14159265f / 180.0f;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("v ", 0) == 0) {
      std::istringstream fields(line.substr(2));
      float x = 0, y = 0, z = 0;
      fields >> x >> y >> z;
      z += 2.0f;
      out << "v " << std::cos(a) * x + std::sin(a) * z << " " << y << " " << -std::sin(a) * x + std::cos(a) * z - 2.0f
          << "\n";
    } else {
      out << line << "\n";
    }
  }
}

}  // namespace

TEST_CASE("check poses the groom's emitter at --frame: an animated frame has no point inside the skin", "[cli]") {
  ScratchDir scratch("check_frame");
  // Rigid keys: the head turns 30 degrees and moves by 1 from frame 1 to 5.
  const std::string groom = write_sintel_groom(scratch, "rigid", "");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-5 --out " + quoted(scratch / "h.####.hair"), scratch)
              .exit_code == 0);
  for (const int frame : {1, 3, 5}) {
    INFO("frame " << frame);
    const std::string file = quoted(scratch / ("h.000" + std::to_string(frame) + ".hair"));
    const JsonCheck posed = check_json(file + " --groom " + quoted(groom) + " --frame " + std::to_string(frame) +
                                           " --strict",
                                       scratch);
    CHECK(posed.exit_code == 0);
    CHECK(posed["frame"] == frame);
    CHECK(posed["inside_skin.points"] == 0);
    CHECK(posed["strands_off_groom_roots"] == 0);
    CHECK(posed.text("clean") == "true");
  }
  // Frame 5 checked against the head at frame 1 (the rest pose), as the checker used to: thousands of
  // points "inside", and the roots are not the groom's there.
  const JsonCheck wrong = check_json(quoted(scratch / "h.0005.hair") + " --groom " + quoted(groom) + " --frame 1", scratch);
  CHECK(wrong["inside_skin.points"] > 500);
  CHECK(wrong["strands_off_groom_roots"] > 300);
  // Without --frame, the groom's first frame (1 here).
  CHECK(check_json(quoted(scratch / "h.0001.hair") + " --groom " + quoted(groom), scratch)["frame"] == 1);
  // A proxy run (--strands 150, a subset of the groom's roots) is the groom's too: its strands are
  // found among the groom's first 150 roots, in a format with ids and in one without.
  for (const std::string format : {"usda", "hair"}) {
    INFO(format);
    REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 5 --strands 150 --out " +
                          quoted(scratch / ("proxy.####." + format)),
                      scratch)
                .exit_code == 0);
    const JsonCheck proxy = check_json(quoted(scratch / ("proxy.0005." + format)) + " --groom " + quoted(groom) +
                                           " --frame 5 --strict",
                                       scratch);
    CHECK(proxy["strand_count"] == 150);
    CHECK(proxy["strands_off_groom_roots"] == 0);
    CHECK(proxy.exit_code == 0);
  }

  // An emitter sequence: the head turned by 20 degrees at frame 2, read from an OBJ.
  write_turned_head(scratch / "head.0001.obj", 0.0f);
  write_turned_head(scratch / "head.0002.obj", 20.0f);
  const std::string sequence = scratch / "sequence.groom.yaml";
  std::ofstream(sequence) << "plume: 1\n"
                          << "emitter:\n  mesh: " << sintel_dir() << "/sintel.obj\n"
                          << "  animation: {sequence: " << scratch.path.string() << "/head.####.obj}\n"
                          << "guides: {file: " << sintel_dir() << "/sintel_guides.hair}\n"
                          << "roots: {count: 400, near_guides: 2.0, seed: 3}\n"
                          << "strands: {points: 8}\n";
  REQUIRE(run_plume("regrow " + quoted(sequence) + " --frames 2 --out " + quoted(scratch / "s.####.hair"), scratch)
              .exit_code == 0);
  const JsonCheck sequenced =
      check_json(quoted(scratch / "s.0002.hair") + " --groom " + quoted(sequence) + " --frame 2 --strict", scratch);
  CHECK(sequenced.exit_code == 0);
  CHECK(sequenced["inside_skin.points"] == 0);
  CHECK(check_json(quoted(scratch / "s.0002.hair") + " --mesh " + quoted(sintel_dir() + "/sintel.obj"),
                   scratch)["inside_skin.points"] > 100);
  // A frame of the sequence that does not exist is bad input, named.
  const RunResult missing =
      run_plume("check " + quoted(scratch / "s.0002.hair") + " --groom " + quoted(sequence) + " --frame 3", scratch);
  CHECK(missing.exit_code == 2);
  CHECK(missing.err.find("head.0003.obj") != std::string::npos);
}

TEST_CASE("check measures strands at guide roots against the guides of the frame, simulated with dynamics", "[cli]") {
  ScratchDir scratch("check_frame_guides");
  // Linear blending reproduces a guide exactly at its root where the guide stays out of the skin
  // (growth keeps every point out of it): Sintel's guides but the 8 that run into the head. Roots at
  // every guide root; dynamics on, so the guides at frame 5 are the simulated ones (the head turns
  // under them).
  const plume::StrandSet all_guides = plume::io::read_strands(sintel_dir() + "/sintel_guides.hair");
  const plume::Mesh head = plume::io::read_obj_mesh(sintel_dir() + "/sintel.obj");
  const plume::MeshQuery head_query(head);
  plume::StrandSet outside;
  for (size_t g = 0; g < all_guides.strand_count(); ++g) {
    bool out = true;  // every point after the root farther from the skin than a few skin margins
    for (const Eigen::Vector3f &p : all_guides.points(g).subspan(1)) out = out && head_query.signed_distance(p) > 0.1f;
    if (out) outside.append(all_guides.points(g), all_guides.ids.empty() ? g : all_guides.ids[g]);
  }
  REQUIRE(outside.strand_count() >= 200);
  const int kept = int(outside.strand_count());
  plume::io::write_strands(scratch / "outside.hair", outside);
  const std::string guides_file = scratch / "outside.hair";
  const std::string groom = scratch / "g.groom.yaml";
  std::ofstream(groom) << "plume: 1\n"
                       << "emitter:\n  mesh: " << sintel_dir() << "/sintel.obj\n"
                       << "  animation:\n    pivot: [0, 24, -2]\n    keys:\n"
                       << "      - {frame: 1, rotate: [0, 0, 0]}\n      - {frame: 5, rotate: [0, 30, 0]}\n"
                       << "guides: {file: " << guides_file << "}\n"
                       << "roots: {file: " << guides_file << "}\n"
                       << "strands: {points: 32}\n"
                       << "interpolation: {method: linear}\n"
                       << "dynamics: {substeps: 2}\n";
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-5 --out " + quoted(scratch / "h.####.hair"), scratch)
              .exit_code == 0);
  const std::string args = quoted(scratch / "h.0005.hair") + " --groom " + quoted(groom) + " --frame 5";
  const JsonCheck at_frame = check_json(args, scratch);
  CHECK(at_frame["strands_off_groom_roots"] == 0);
  CHECK(at_frame["guides.strands_at_guide_roots"] == kept);
  CHECK(at_frame["guides.largest_deviation_percent"] < 1e-3);
  CHECK(at_frame["guides.over_limit"] == 0);
  // The same guides read from a cache of the simulation.
  REQUIRE(run_plume("simulate " + quoted(groom) + " --frames 1-5 --cache " + quoted(scratch / "c.####.hair"), scratch)
              .exit_code == 0);
  const JsonCheck cached = check_json(args + " --guides-cache " + quoted(scratch / "c.####.hair"), scratch);
  CHECK(cached["guides.largest_deviation_percent"] < 1e-3);
  // The same groom without dynamics carries its guides rigidly with the head: the simulated strands
  // of frame 5 are not those guides (they lag behind the turn), and the checker says so.
  const std::string still = scratch / "still.groom.yaml";
  {
    std::ifstream in(groom);
    std::ofstream out(still);
    for (std::string line; std::getline(in, line);)
      if (line.rfind("dynamics:", 0) != 0) out << line << "\n";
  }
  const JsonCheck carried = check_json(quoted(scratch / "h.0005.hair") + " --groom " + quoted(still) + " --frame 5",
                                       scratch);
  CHECK(carried["guides.strands_at_guide_roots"] == kept);
  CHECK(carried["guides.over_limit"] > 100);
  CHECK(carried.leaves.count("violations.0") == 1);
}

TEST_CASE("check judges crossings before the groom's effects, which bring strands together on purpose", "[cli]") {
  ScratchDir scratch("check_effects");
  // Strong clumps with a twist and frizz on every strand: the strands cross after the effects.
  const std::string groom = write_sintel_groom(
      scratch, "effects",
      "effects:\n"
      "  - {type: clump, seed: 1, radius: 3.0, amount: 1.0, ramp: [[0, 0], [1, 1]], twist: 0.5}\n"
      "  - {type: frizz, seed: 5, frequency: 1.5, amplitude: 0.5, fraction: 1.0, ramp: [[0, 0], [1, 1]]}\n");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 5 --out " + quoted(scratch / "h.####.usda"), scratch)
              .exit_code == 0);
  const std::string file = quoted(scratch / "h.0005.usda");
  const JsonCheck with_groom = check_json(file + " --groom " + quoted(groom) + " --frame 5 --strict", scratch);
  CHECK(with_groom.text("crossings_judged_on") == "\"strands before effects\"");
  CHECK(with_groom.text("groom_effects") == "true");
  CHECK(with_groom["crossings_after_effects.transversal_pairs"] > 0);
  CHECK(with_groom["crossings.transversal_pairs"] == 0);
  // Nothing crossed before the effects: every pair after them is theirs.
  CHECK(with_groom["crossings_after_effects.pairs_made_by_effects"] == with_groom["crossings_after_effects.pairs"]);
  CHECK(with_groom["crossings_after_effects.transversal_pairs_made_by_effects"] ==
        with_groom["crossings_after_effects.transversal_pairs"]);
  CHECK(with_groom["inside_skin.points"] == 0);
  CHECK(with_groom.exit_code == 0);
  // The same groom without effects grows exactly the strands the checker judged.
  const std::string plain = write_sintel_groom(scratch, "plain", "");
  REQUIRE(run_plume("regrow " + quoted(plain) + " --frames 5 --out " + quoted(scratch / "p.####.usda"), scratch)
              .exit_code == 0);
  const JsonCheck without = check_json(quoted(scratch / "p.0005.usda") + " --groom " + quoted(plain) + " --frame 5",
                                       scratch);
  CHECK(without.text("crossings_judged_on") == "\"strands\"");
  CHECK(without["crossings.pairs"] == with_groom["crossings.pairs"]);
  CHECK(without["crossings.tolerance"] > 0);
  // Without the groom nothing says which crossings the effects made: they are judged as they are.
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1 --out " + quoted(scratch / "h.####.usda"), scratch)
              .exit_code == 0);
  const JsonCheck alone =
      check_json(quoted(scratch / "h.0001.usda") + " --mesh " + quoted(sintel_dir() + "/sintel.obj") + " --strict",
                 scratch);
  CHECK(alone["crossings.transversal_pairs"] > 0);
  CHECK(alone.exit_code == 3);
  // Strands that are not the groom's (another seed's roots) cannot be regrown before the effects.
  const std::string reseeded = scratch / "reseeded.groom.yaml";
  {
    std::ifstream in(groom);
    std::ofstream out(reseeded);
    for (std::string line; std::getline(in, line);)
      out << (line.rfind("roots:", 0) == 0 ? "roots: {count: 400, near_guides: 2.0, seed: 4}" : line) << "\n";
  }
  const JsonCheck foreign = check_json(file + " --groom " + quoted(reseeded) + " --frame 5", scratch);
  CHECK(foreign["strands_off_groom_roots"] > 300);
  CHECK(foreign.text("crossings_judged_on") == "\"strands\"");
}

TEST_CASE("check --roots finds the strand of every requested root and names the missing ones", "[cli]") {
  ScratchDir scratch("check_roots");
  // Roots from a file: the guides' first points (228), snapped to the skin and lifted like them.
  // Without the separation pass, which would part the two strands that follow crossing guides.
  const std::string groom = write_sintel_groom(scratch, "g", "interpolation: {separate: false}\n");
  const std::string from_file = scratch / "file.groom.yaml";
  {
    std::ifstream in(groom);
    std::ofstream out(from_file);
    for (std::string line; std::getline(in, line);)
      out << (line.rfind("roots:", 0) == 0 ? "roots: {file: " + sintel_dir() + "/sintel_guides.hair}" : line) << "\n";
  }
  const std::string roots = quoted(sintel_dir() + "/sintel_guides.hair");
  REQUIRE(run_plume("regrow " + quoted(from_file) + " --frames 5 --out " + quoted(scratch / "all.####.hair"), scratch)
              .exit_code == 0);
  JsonCheck all = check_json(quoted(scratch / "all.0005.hair") + " --groom " + quoted(from_file) +
                                 " --frame 5 --guide-limit 100 --strict --roots " + roots,
                             scratch);
  CHECK(all["requested_roots.requested"] == 228);
  CHECK(all["requested_roots.missing"] == 0);
  // Strands at the guides' roots follow the guides, and two of Sintel's guides cross each other
  // (plume check on sintel_guides.hair finds the pair): that crossing is the only violation.
  CHECK(all["inside_skin.points"] == 0);
  CHECK(all["guides.over_limit"] == 0);
  CHECK(all["crossings.transversal_pairs"] == 1);
  CHECK(all.text("violations.0") == "\"1 transversal crossing pair\"");
  CHECK(all.exit_code == 3);
  // A proxy of the first 100 roots misses the other 128.
  REQUIRE(run_plume("regrow " + quoted(from_file) + " --frames 5 --strands 100 --out " + quoted(scratch / "some.####.hair"),
                    scratch)
              .exit_code == 0);
  const JsonCheck some = check_json(quoted(scratch / "some.0005.hair") + " --groom " + quoted(from_file) +
                                        " --frame 5 --guide-limit 100 --strict --roots " + roots,
                                    scratch);
  CHECK(some["requested_roots.missing"] == 128);
  CHECK(some["requested_roots.missing_examples.0"] == 100);
  CHECK(some["requested_roots.missing_examples.7"] == 107);
  CHECK(some.text("violations.0") == "\"128 requested roots without a strand\"");
  CHECK(some.exit_code == 3);
  // A text roots file with one point far from any strand (the chin) and one on a strand's root.
  std::ofstream(scratch / "roots.txt") << "# x y z\n0 22 9\n";
  const RunResult text = run_plume("check " + quoted(scratch / "all.0005.hair") + " --groom " + quoted(from_file) +
                                       " --frame 5 --roots " + quoted(scratch / "roots.txt"),
                                   scratch);
  CHECK(text.exit_code == 0);
  CHECK(text.out.find("requested roots without a strand: 1 of 1") != std::string::npos);
}

TEST_CASE("check --strict fails on transversal crossings, --strict-touching on touching ones too", "[cli]") {
  ScratchDir scratch("check_strict");
  const std::string mesh = " --mesh " + quoted(sintel_dir() + "/sintel.obj");
  // Above the head: strand 1 rises to the right, strand 2 runs 1e-4 beside it (touching at the
  // default tolerance, 1e-3 of the 0.25 segments), strand 3 crosses both at about 90 degrees.
  const auto write = [&](const std::string &name, bool with_crossing) {
    std::ofstream file(scratch / name);
    for (int i = 0; i <= 8; ++i) file << "v " << -1.0 + 0.25 * i * 0.8 << " " << 50.0 + 0.25 * i * 0.6 << " 0\n";
    for (int i = 0; i <= 8; ++i) file << "v " << -1.0 + 0.25 * i * 0.8 << " " << 50.0001 + 0.25 * i * 0.6 << " 0\n";
    if (with_crossing)
      for (int i = 0; i <= 8; ++i) file << "v " << 0.5 - 0.25 * i * 0.6 << " " << 50.2 + 0.25 * i * 0.8 << " 0\n";
    for (int s = 0; s < (with_crossing ? 3 : 2); ++s) {
      file << "l";
      for (int i = 1; i <= 9; ++i) file << " " << s * 9 + i;
      file << "\n";
    }
  };
  write("crossing.obj", true);
  write("touching.obj", false);
  const JsonCheck crossing = check_json(quoted(scratch / "crossing.obj") + mesh + " --strict", scratch);
  CHECK(crossing["crossings.transversal_pairs"] == 2);
  CHECK(crossing["crossings.touching_pairs"] == 1);
  CHECK(crossing["crossings.largest_angle_degrees"] == Approx(90.0).margin(0.1));
  CHECK(crossing.exit_code == 3);
  CHECK(crossing.text("violations.0") == "\"2 transversal crossing pairs\"");
  const RunResult touching = run_plume("check " + quoted(scratch / "touching.obj") + mesh + " --strict", scratch);
  INFO(touching.out);
  CHECK(touching.exit_code == 0);
  CHECK(touching.out.find("0 transversal (angle above 10 degrees), 1 touching (near-parallel)") != std::string::npos);
  CHECK(run_plume("check " + quoted(scratch / "touching.obj") + mesh + " --strict-touching", scratch).exit_code == 3);
  // Without --strict the verdict is printed, the exit code is 0.
  const RunResult loose = run_plume("check " + quoted(scratch / "crossing.obj") + mesh, scratch);
  CHECK(loose.exit_code == 0);
  CHECK(loose.out.find("VIOLATIONS (exit code 0 without --strict)") != std::string::npos);
  // A tolerance below the touching gap separates the touching pair.
  CHECK(check_json(quoted(scratch / "touching.obj") + mesh + " --tolerance 0.00005", scratch)["crossings.pairs"] == 0);
}

TEST_CASE("check --json prints every figure of the text report, and an independent parser reads it", "[cli]") {
  ScratchDir scratch("check_json");
  const std::string groom = write_sintel_groom(
      scratch, "g", "effects:\n  - {type: clump, seed: 1, radius: 3.0, amount: 1.0, ramp: [[0, 0], [1, 1]]}\n");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 3 --out " + quoted(scratch / "h.####.usda"), scratch)
              .exit_code == 0);
  const std::string args = quoted(scratch / "h.0003.usda") + " --groom " + quoted(groom) + " --frame 3 --roots " +
                           quoted(sintel_dir() + "/sintel_guides.hair");
  const JsonCheck json = check_json(args, scratch);
  const RunResult text = run_plume("check " + args, scratch);
  REQUIRE(text.exit_code == 0);
  INFO(text.out);
  for (const std::string key :
       {"strands", "skin", "frame", "groom_effects", "strands_off_groom_roots", "strand_count", "point_count",
        "median_segment_length", "root_tolerance", "inside_skin.margin", "inside_skin.points", "crossings_judged_on",
        "touching_is_violation", "crossings.tolerance", "crossings.transversal_degrees", "crossings.pairs",
        "crossings.transversal_pairs", "crossings.touching_pairs", "crossings.largest_angle_degrees",
        "crossings.segment_pairs_examined", "crossings.piece_pairs_binned", "crossings_after_effects.pairs",
        "crossings_after_effects.transversal_pairs", "crossings_after_effects.touching_pairs", "zones.checked",
        "zones.cross_zone_influences", "guides.checked", "guides.before_effects", "guides.strands_at_guide_roots",
        "guides.largest_deviation", "guides.largest_deviation_percent", "guides.limit_percent", "guides.over_limit",
        "guides.skin_band", "guides.near_skin", "guides.near_skin_largest_deviation_percent",
        "requested_roots.checked", "requested_roots.file", "requested_roots.requested", "requested_roots.missing",
        "clean", "strict", "exit_code"}) {
    INFO(key);
    CHECK(json.leaves.count(key) == 1);
  }
  CHECK(json["strand_count"] == 400);
  CHECK(json["point_count"] == 3200);
  CHECK(json["requested_roots.requested"] == 228);
  CHECK(json["guides.limit_percent"] == Approx(0.1));
  // The text report says the same numbers.
  const auto says = [&](const std::string &phrase) { return text.out.find(phrase) != std::string::npos; };
  CHECK(says("400 strands, 3200 points"));
  char line[200];
  std::snprintf(line, sizeof line, "points inside the skin (margin 0): %.0f", json["inside_skin.points"]);
  CHECK(says(line));
  std::snprintf(line, sizeof line, "after effects, a figure (tolerance %g): %.0f transversal", json["crossings.tolerance"],
                json["crossings_after_effects.transversal_pairs"]);
  CHECK(says(line));
  std::snprintf(line, sizeof line, "requested roots without a strand: %.0f of 228", json["requested_roots.missing"]);
  CHECK(says(line));
  // Examples are strand ids, as the text lists them.
  if (json["crossings_after_effects.transversal_pairs"] > 0) {
    const std::string first = json.text("crossings_after_effects.transversal_examples.0.0") + "/" +
                              json.text("crossings_after_effects.transversal_examples.0.1");
    CHECK(says("transversal: " + first));
  }
}

TEST_CASE("check refuses bad input with exit 2, naming the option or the file", "[cli]") {
  ScratchDir scratch("check_bad");
  const std::string strands = quoted(sintel_dir() + "/sintel_guides.hair");
  const std::string mesh = " --mesh " + quoted(sintel_dir() + "/sintel.obj");
  const std::string groom = " --groom " + quoted(write_sintel_groom(scratch, "g", ""));
  std::ofstream(scratch / "bad_roots.txt") << "0 45 0\n1 2 nan\n";
  std::ofstream(scratch / "flat.obj") << "v 0 50 0\nv 0 50 0\nl 1 2\n";
  const struct {
    std::string args, message;
  } cases[] = {
      {strands, "--mesh: expected the emitter mesh"},
      {strands + mesh + groom, "give --mesh or --groom, not both"},
      {strands + mesh + " --frame 3", "--frame: needs --groom"},
      {strands + mesh + " --guides-cache c.####.hair", "--guides-cache: needs --groom"},
      {strands + mesh + " --tolerance 0", "--tolerance"},
      {strands + mesh + " --tolerance -0.1", "--tolerance"},
      {strands + mesh + " --transversal-angle 95", "--transversal-angle"},
      {strands + mesh + " --guide-limit -1", "--guide-limit"},
      {strands + mesh + " --roots " + quoted(scratch / "missing.txt"), "missing.txt"},
      {strands + mesh + " --roots " + quoted(scratch / "bad_roots.txt"), "bad_roots.txt:2"},
      {quoted(scratch / "flat.obj") + mesh, "no segment of non-zero length"},
      {quoted(scratch / "missing.hair") + mesh, "missing.hair"},
      {strands + groom + " --frame 1000000000", "--frame"},
  };
  for (const auto &c : cases) {
    INFO(c.args);
    const RunResult run = run_plume_bounded("check " + c.args, scratch);
    INFO(run.out << run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find(c.message) != std::string::npos);
    CHECK(run.out.empty());
  }
}

TEST_CASE("every groom in grooms/ on the middle frame it renders: checked at its pose, nothing inside the skin", "[cli]") {
  // Each shipped groom at its full strand count, on the middle frame of the range it renders (the
  // head turned, the tail raised: the pose farthest from rest; the first frame too would double the
  // suite's longest test, the field growth taking about 20 CPU-s per Sintel frame): the checker
  // poses the emitter and simulates the guides itself, and with effects judges the crossings before
  // them. No point may be inside the skin; --strict fails exactly when a violation is listed, and
  // the figures are printed.
  ScratchDir info_scratch("shipped_info");
  for (const std::string &groom : shipped_grooms()) {
    const RunResult info = run_plume("info " + quoted(groom), info_scratch);
    REQUIRE(info.exit_code == 0);
    int first = 1, last = 1;
    const size_t at = info.out.find(", frames ");
    if (at != std::string::npos && std::sscanf(info.out.c_str() + at, ", frames %d-%d", &first, &last) < 2)
      last = first;
    {
      const int frame = (first + last) / 2;
      INFO(groom << " frame " << frame);
      ScratchDir scratch("shipped_check");
      const std::string out = scratch / "hair.####.usda";
      const RunResult run = run_plume("regrow " + quoted(groom) + " --frames " + std::to_string(frame) + " --out " +
                                          quoted(out),
                                      scratch);
      INFO(run.err);
      REQUIRE(run.exit_code == 0);
      char name[32];
      std::snprintf(name, sizeof name, "hair.%04d.usda", frame);
      const std::string args = quoted(scratch / name) + " --groom " + quoted(groom) + " --frame " + std::to_string(frame);
      // A groom of hair groups is checked group by group (--group), each against its description.
      const plume::GroomDesc desc = plume::io::read_groom_file(groom);
      std::vector<std::string> groups;
      for (const plume::GroomDesc &group : desc.groups) groups.push_back(" --group " + group.group_name);
      if (groups.empty()) groups.push_back("");
      for (const std::string &group : groups) {
        INFO(group);
        const JsonCheck json = check_json(args + group + " --strict", scratch);
        CHECK(json["inside_skin.points"] == 0);
        if (info.out.find("\nfeathers: ") != std::string::npos) {
          // A feather groom's curves: the skin is judged (feather against feather is another check).
          CHECK(json.exit_code == 0);
          continue;
        }
        CHECK(json["strands_off_groom_roots"] == 0);
        CHECK(json["zones.cross_zone_influences"] == 0);
        CHECK(json.exit_code == (json.text("clean") == "true" ? 0 : 3));
        // Every hair groom's strands pass --strict at its middle frame (the Sintel grooms and the
        // effects groom with their separation pass on): a change to growth or to the pass that makes
        // strands cross there fails here (the cat's frame 10 has a case of its own, below).
        CHECK(json["crossings.transversal_pairs"] == 0);
        CHECK(json.exit_code == 0);
        CHECK((json.leaves.count("violations.0") == 1) == (json.exit_code == 3));
        WARN(groom << " frame " << frame << ": " << json["crossings.transversal_pairs"] << " transversal and "
                   << json["crossings.touching_pairs"] << " touching crossing pairs "
                   << json.text("crossings_judged_on") << ", strands at guide roots over the limit "
                   << json["guides.over_limit"] << " of " << json["guides.strands_at_guide_roots"]);
      }
    }
  }
}

TEST_CASE("the cat's strands pass --strict on frame 10, where the tail rises", "[cli]") {
  // The frame where the field once gathered two strands 33 times closer than their roots, below their
  // 10-point polylines' sag, and crossed them (docs/controls.md): regrown alone (the dynamics
  // replayed from frame 1) and checked as a user would.
  ScratchDir scratch("cat_frame_10");
  const std::string groom = quoted(std::string(PLUME_SOURCE_DIR) + "/grooms/cat/cat.groom.yaml");
  REQUIRE(run_plume("regrow " + groom + " --frames 10 --no-preview --out " + quoted(scratch / "fur.####.usda"), scratch)
              .exit_code == 0);
  const JsonCheck json = check_json(quoted(scratch / "fur.0010.usda") + " --groom " + groom + " --frame 10 --strict", scratch);
  CHECK(json["inside_skin.points"] == 0);
  CHECK(json["crossings.transversal_pairs"] == 0);
  CHECK(json.exit_code == 0);
}

TEST_CASE("check --frames checks every frame of a range as --frame does, and fails on a missing frame", "[cli]") {
  ScratchDir scratch("check_frames");
  const std::string groom = write_sintel_groom(scratch, "rigid", "");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1-5 --out " + quoted(scratch / "h.####.hair"), scratch)
              .exit_code == 0);
  // Every other frame: each report is the one a check of that frame alone gives.
  const JsonCheck range = check_json(quoted(scratch / "h.####.hair") + " --groom " + quoted(groom) +
                                         " --frames 1-5:2 --strict", scratch);
  CHECK(range.exit_code == 0);
  CHECK(range["frames_checked"] == 3);
  CHECK(range.text("frames_failed") == "[]");
  for (const int i : {0, 1, 2}) {
    const int frame = 1 + 2 * i;
    INFO("frame " << frame);
    const JsonCheck alone = check_json(quoted(scratch / ("h.000" + std::to_string(frame) + ".hair")) + " --groom " +
                                           quoted(groom) + " --frame " + std::to_string(frame) + " --strict",
                                       scratch);
    const std::string prefix = "frames." + std::to_string(i) + ".";
    size_t compared = 0;
    for (const auto &[key, value] : alone.leaves) {
      if (key == "file") continue;  // the same file, named as given
      INFO(key);
      REQUIRE(range.leaves.count(prefix + key));
      CHECK(range.leaves.at(prefix + key) == value);
      ++compared;
    }
    CHECK(compared > 10);
    CHECK(range[prefix + "frame"] == frame);
  }
  // Frame 5 against the pose of frame 1 breaks the promise: a range whose file for one frame is
  // another frame's fails --strict there, and names it.
  fs::copy_file(scratch / "h.0005.hair", scratch / "w.0003.hair");
  fs::copy_file(scratch / "h.0001.hair", scratch / "w.0001.hair");
  fs::copy_file(scratch / "h.0002.hair", scratch / "w.0002.hair");
  const RunResult text = run_plume("check " + quoted(scratch / "w.####.hair") + " --groom " + quoted(groom) +
                                       " --frames 1-3 --strict", scratch);
  CHECK(text.exit_code == 3);
  CHECK(text.out.find("frames 1-3: 3 checked, broken promises at frames 3\n") != std::string::npos);

  // Bad uses exit 2 before any frame is checked.
  for (const auto &[args, message] : std::vector<std::pair<std::string, std::string>>{
           {quoted(scratch / "h.####.hair") + " --groom " + quoted(groom) + " --frames 1-6",
            "--frames: frame 6: " + (scratch / "h.0006.hair") + " does not exist"},
           {quoted(scratch / "h.0001.hair") + " --groom " + quoted(groom) + " --frames 1-2", "has no frame field"},
           {quoted(scratch / "h.####.hair") + " --mesh " + quoted(sintel_dir() + "/sintel.obj") + " --frames 1-2",
            "--frames: needs --groom"},
           {quoted(scratch / "h.####.hair") + " --groom " + quoted(groom) + " --frames 1-2 --frame 1",
            "give --frames or --frame, not both"},
           {quoted(scratch / "h.####.hair") + " --groom " + quoted(groom) + " --frames 3-1", "--frames"}}) {
    INFO(args);
    const RunResult bad = run_plume("check " + args, scratch);
    CHECK(bad.exit_code == 2);
    CHECK(bad.out.empty());
    CHECK(bad.err.find(message) != std::string::npos);
  }
}

TEST_CASE("interpolation.separate: the separation pass parts the written strands the checker finds crossing", "[cli]") {
  ScratchDir scratch("check_separate");
  // 4,000 strands of 8 points on Sintel: the field alone leaves transversal pairs there.
  const auto dense = [&](const std::string &name, const std::string &extra) {
    const std::string written = write_sintel_groom(scratch, name + "_400", extra);
    const std::string path = scratch / (name + ".groom.yaml");
    std::ifstream in(written);
    std::ofstream out(path);
    for (std::string line; std::getline(in, line);)
      out << (line.rfind("roots:", 0) == 0 ? "roots: {count: 4000, near_guides: 2.0, seed: 3}" : line) << "\n";
    return path;
  };
  const std::string plain = dense("plain", "interpolation: {separate: false}\n"), parted = dense("parted", "");
  REQUIRE(run_plume("regrow " + quoted(plain) + " --frames 1 --no-preview --out " + quoted(scratch / "p.####.hair"), scratch)
              .exit_code == 0);
  REQUIRE(run_plume("regrow " + quoted(parted) + " --frames 1 --no-preview --out " + quoted(scratch / "s.####.hair"), scratch)
              .exit_code == 0);
  const JsonCheck before = check_json(quoted(scratch / "p.0001.hair") + " --groom " + quoted(plain) + " --frame 1", scratch);
  const JsonCheck after = check_json(quoted(scratch / "s.0001.hair") + " --groom " + quoted(parted) + " --frame 1", scratch);
  INFO("transversal pairs: " << before["crossings.transversal_pairs"] << " without the pass, "
                             << after["crossings.transversal_pairs"] << " with it");
  REQUIRE(before["crossings.transversal_pairs"] > 0);
  CHECK(after["crossings.transversal_pairs"] * 4 < before["crossings.transversal_pairs"]);
  CHECK(after["inside_skin.points"] == 0);
  CHECK(after["guides.over_limit"] == 0);
  CHECK(after["strand_count"] == before["strand_count"]);
}

TEST_CASE("regrow warns when the separation pass leaves pairs it could not part, and names their count", "[cli]") {
  // The planar arch (tests/interp/hard_scenes.h; docs/interpolation.md, "What is guaranteed"): a
  // guide 1.5 long and one 3.6 long rising beside it, arching over its tip and curling back; strands
  // rooted between and beside them converge inside the arch until their curves coincide, where no
  // move parts them.
  ScratchDir scratch("separation_warning");
  const plume::test::Scene scene = plume::test::planar_arch(32, 40);
  std::ofstream obj(scratch / "strip.obj");
  for (const Eigen::Vector3f &p : scene.mesh.positions) obj << "v " << p.x() << " " << p.y() << " " << p.z() << "\n";
  for (const Eigen::Vector3i &t : scene.mesh.triangles) obj << "f " << t.x() + 1 << " " << t.y() + 1 << " " << t.z() + 1 << "\n";
  obj.close();
  plume::io::write_strands(scratch / "guides.hair", scene.guides.strands);
  std::ofstream roots(scratch / "roots.txt");
  for (const plume::SurfacePoint &root : scene.roots.points) {
    const Eigen::Vector3f p = plume::surface_position(scene.mesh, root);
    roots << p.x() << " " << p.y() << " " << p.z() << "\n";
  }
  roots.close();
  for (const bool separate : {true, false}) {
    const std::string groom = scratch / "arch.groom.yaml";
    std::ofstream(groom) << "plume: 1\nemitter: {mesh: strip.obj}\nguides: {file: guides.hair}\n"
                         << "roots: {file: roots.txt}\nstrands: {points: 24}\n"
                         << "interpolation: {separate: " << (separate ? "true" : "false") << "}\n";
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames 1 --no-preview --out " +
                                        quoted(scratch / "h.####.hair"),
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
    const std::string warning = "plume: warning: frame 1: the separation pass left ";
    const size_t at = run.err.find(warning);
    if (!separate) {
      CHECK(at == std::string::npos);
      continue;
    }
    REQUIRE(at != std::string::npos);
    const long long left = std::stoll(run.err.substr(at + warning.size()));
    CHECK(left > 0);
  }
}
