// The conventions of the `plume` command that pipelines rely on: frame ranges (every malformed one
// refused, naming the accepted forms; Nuke's and Deadline's 1-240x2), frame fields (####, %04d,
// Houdini's $F4), `plume help`, `plume version`, the exit codes in --help, parse errors prefixed like
// every other error, a progress line that fits 80 columns, and `info --json`.
#include <catch2/catch.hpp>

#include <regex>
#include <sstream>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

/// Output of a shell command (stdout), trailing newline removed; empty when it fails.
std::string shell_output(const std::string &command) {
  std::string text;
  if (FILE *pipe = popen(command.c_str(), "r")) {
    char buffer[256];
    while (fgets(buffer, sizeof buffer, pipe)) text += buffer;
    if (pclose(pipe) != 0) return {};
  }
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r')) text.pop_back();
  return text;
}

/// The pieces of terminal output between carriage returns and newlines.
std::vector<std::string> terminal_lines(const std::string &text) {
  std::vector<std::string> lines(1);
  for (const char c : text) {
    if (c == '\r' || c == '\n')
      lines.emplace_back();
    else
      lines.back() += c;
  }
  return lines;
}

}  // namespace

TEST_CASE("every malformed frame range is refused with exit 2, naming the accepted forms, before any output",
          "[cli]") {
  ScratchDir scratch("malformed_ranges");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string out = scratch / "out";
  for (const std::string range : {"1:240", "1:4", "5:2", "1x2", "48-1", "1-", "-", "1-4:", "1-4x", "1-4:0", "1-4x0",
                                  "1-4:-2", "1..4", "1-4:2:3", "1-4x2x3", "1 - 4", "one", "1-4:2x", "+1-4", "1-4 ", ""}) {
    INFO("--frames '" << range << "'");
    const RunResult run = run_plume("regrow " + quoted(groom) + " --frames " + quoted(range) + " --out " +
                                        quoted(out + "/h.####.hair"),
                                    scratch);
    CHECK(run.exit_code == 2);
    INFO(run.err);
    CHECK(run.err.rfind("plume: error: --frames", 0) == 0);
    CHECK(run.err.find("1-240x2") != std::string::npos);
    CHECK(files_in(out).empty());
  }
  // The same in a groom file's output.frames, and for simulate and view.
  const std::string in_groom = write_sintel_groom(scratch, "in_groom", "output: {frames: \"1:240\"}\n");
  const RunResult groom_run = run_plume("regrow " + quoted(in_groom) + " --out " + quoted(out + "/h.####.hair"), scratch);
  CHECK(groom_run.exit_code == 2);
  CHECK(groom_run.err.find("output.frames") != std::string::npos);
  const std::string dynamic = write_sintel_groom(scratch, "dynamic", "dynamics: {enabled: true}\n");
  for (const std::string &args : {"simulate " + quoted(dynamic) + " --cache " + quoted(out + "/g.####.hair"),
                                 "view " + quoted(groom) + " --out " + quoted(out + "/x.html")}) {
    INFO(args);
    const RunResult run = run_plume(args + " --frames 1:4", scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find("1-240x2") != std::string::npos);
  }
  CHECK(files_in(out).empty());
}

TEST_CASE("1-9x2 picks the frames 1-9:2 picks, in a run and in a groom file", "[cli]") {
  ScratchDir scratch("step_x");
  const std::string groom = write_sintel_groom(scratch, "g", "output: {frames: 2-8x3}\n");
  RunResult run = run_plume("regrow " + quoted(groom) + " --strands 40 --frames 1-9x2 --out " +
                                quoted(scratch / "x/h.####.hair"),
                            scratch);
  REQUIRE(run.exit_code == 0);
  run = run_plume("regrow " + quoted(groom) + " --strands 40 --frames 1-9:2 --out " + quoted(scratch / "colon/h.####.hair"),
                  scratch);
  REQUIRE(run.exit_code == 0);
  const std::vector<std::string> expected = {"h.0001.hair", "h.0003.hair", "h.0005.hair", "h.0007.hair", "h.0009.hair"};
  for (const std::string folder : {"x", "colon"}) {
    std::vector<std::string> names;
    for (const std::string &file : files_in(scratch.path / folder)) names.push_back(fs::path(file).filename().string());
    CHECK(names == expected);
  }
  for (const std::string &name : expected) CHECK(read_text(scratch / ("x/" + name)) == read_text(scratch / ("colon/" + name)));
  // The groom's own 2-8x3: frames 2, 5 and 8.
  run = run_plume("regrow " + quoted(groom) + " --strands 40 --out " + quoted(scratch / "groom/h.####.hair"), scratch);
  REQUIRE(run.exit_code == 0);
  std::vector<std::string> names;
  for (const std::string &file : files_in(scratch.path / "groom")) names.push_back(fs::path(file).filename().string());
  CHECK(names == std::vector<std::string>{"h.0002.hair", "h.0005.hair", "h.0008.hair"});
}

TEST_CASE("$F4 and $F name frames as Houdini does, beside #### and %04d", "[cli]") {
  ScratchDir scratch("dollar_f");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  for (const std::string pattern : {"a/h.$F4.hair", "b/h.$F.hair", "c/h.####.hair", "d/h.%04d.hair"}) {
    INFO(pattern);
    const RunResult run = run_plume("regrow " + quoted(groom) + " --strands 40 --frames 9-11 --out " +
                                        quoted(scratch / pattern) + " --preview " +
                                        quoted(scratch / (pattern.substr(0, 2) + "p.$F3.png")) + " --preview-size 32",
                                    scratch);
    INFO(run.err);
    REQUIRE(run.exit_code == 0);
  }
  CHECK(fs::exists(scratch / "a/h.0009.hair"));
  CHECK(fs::exists(scratch / "a/h.0011.hair"));
  CHECK(fs::exists(scratch / "b/h.9.hair"));
  CHECK(fs::exists(scratch / "b/h.11.hair"));
  CHECK(fs::exists(scratch / "a/p.009.png"));
  CHECK_FALSE(fs::exists(scratch / "a/p.010.png"));  // one preview, the first frame (preview_every 0)
  for (const std::string frame : {"0009", "0010", "0011"}) {
    CHECK(read_text(scratch / ("a/h." + frame + ".hair")) == read_text(scratch / ("c/h." + frame + ".hair")));
    CHECK(read_text(scratch / ("a/h." + frame + ".hair")) == read_text(scratch / ("d/h." + frame + ".hair")));
  }
  // $FF and $Foo are other Houdini variables, not frame fields: a range needs a field.
  const RunResult other = run_plume("regrow " + quoted(groom) + " --strands 40 --frames 1-2 --out " +
                                        quoted(scratch / "e/h.$FF.hair"),
                                    scratch);
  CHECK(other.exit_code == 2);
  CHECK(other.err.find("$F4") != std::string::npos);
  const RunResult two = run_plume("regrow " + quoted(groom) + " --frames 1-2 --out " + quoted(scratch / "e/h.$F2.##.hair"),
                                  scratch);
  CHECK(two.exit_code == 2);
  CHECK(two.err.find("got two") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch / "e"));
  // In a groom file: output.path and dynamics.cache.
  const std::string in_groom = write_sintel_groom(scratch, "in_groom", "output: {path: out/h.$F4.hair, frames: 3-4}\n");
  const RunResult groom_run = run_plume("regrow " + quoted(in_groom), scratch);
  INFO(groom_run.err);
  REQUIRE(groom_run.exit_code == 0);
  CHECK(fs::exists(scratch / "out/h.0003.hair"));
  CHECK(fs::exists(scratch / "out/h.0004.hair"));
}

TEST_CASE("plume help and plume version; every --help lists the exit codes", "[cli]") {
  ScratchDir scratch("help_version");
  const RunResult help = run_plume("help", scratch);
  CHECK(help.exit_code == 0);
  for (const std::string command : {"regrow", "simulate", "preview", "view", "info", "check", "help", "version"})
    CHECK(help.out.find(command) != std::string::npos);
  for (const std::string command : {"", "regrow ", "simulate ", "preview ", "view ", "info ", "check "}) {
    INFO(command);
    const RunResult run = run_plume(command + "--help", scratch);
    CHECK(run.exit_code == 0);
    CHECK(run.out.find("Exit codes:") != std::string::npos);
    CHECK(run.out.find("  2  bad input") != std::string::npos);
    CHECK(run.out.find("  3  plume check --strict") != std::string::npos);
  }
  const RunResult regrow_help = run_plume("help regrow", scratch);
  CHECK(regrow_help.exit_code == 0);
  CHECK(regrow_help.out == run_plume("regrow --help", scratch).out);
  CHECK(regrow_help.out.find("--skip-existing") != std::string::npos);
  CHECK(regrow_help.out.find("--no-preview") != std::string::npos);
  const RunResult unknown = run_plume("help regrw", scratch);
  CHECK(unknown.exit_code == 2);
  CHECK(unknown.err.rfind("plume: error: help: no command \"regrw\"", 0) == 0);

  const RunResult version = run_plume("version", scratch);
  CHECK(version.exit_code == 0);
  CHECK(version.out == run_plume("--version", scratch).out);
  INFO(version.out);
  const std::regex form(R"(plume \d+\.\d+\.\d+ \(commit ([0-9a-f]{12}(-dirty)?|unknown), (\w+ build|no build type), .+\)\n)");
  CHECK(std::regex_match(version.out, form));
  // From a git checkout, the commit is HEAD's (as built: the build writes it every time).
  const std::string head = shell_output("git -C " + quoted(PLUME_SOURCE_DIR) + " rev-parse --short=12 HEAD 2>/dev/null");
  if (!head.empty()) CHECK(version.out.find("(commit " + head) != std::string::npos);
  // An OMP_NUM_THREADS that would fail a run does not stop help or version.
  CHECK(run_plume_command("OMP_NUM_THREADS=zero " + quoted(PLUME_BINARY) + " version", scratch).exit_code == 0);
}

TEST_CASE("command-line errors are prefixed like every other error and exit with 2", "[cli]") {
  ScratchDir scratch("parse_errors");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  for (const std::string &args : {std::string(""), std::string("regrw"), std::string("regrow"),
                                 "regrow " + quoted(groom) + " --no-such-option",
                                 "regrow " + quoted(groom) + " --threads 0",
                                 "regrow " + quoted(groom) + " --strands many",
                                 "regrow " + quoted(groom) + " --no-preview --preview " + quoted(scratch / "p.png"),
                                 std::string("check"), std::string("info")}) {
    INFO("plume " << args);
    const RunResult run = run_plume(args, scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.rfind("plume: error: ", 0) == 0);
    CHECK(run.err.find("plume help") != std::string::npos);
  }
  // Within a command, the pointer names its help.
  CHECK(run_plume("regrow " + quoted(groom) + " --bogus", scratch).err.find("plume help regrow") != std::string::npos);
}

TEST_CASE("the progress line fits an 80-column terminal, and a narrower one, whatever the figures", "[cli]") {
  ScratchDir scratch("progress_width");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  // Nine-digit frames and a range of hundreds: wide figures.
  for (const std::string columns : {"80", "200", "44"}) {
    INFO("terminal of " << columns << " columns");
    const std::string inner = "stty cols " + columns + "; " + quoted(PLUME_BINARY) + " regrow " + quoted(groom) +
                              " --frames 999999970-999999999 --strands 10 --no-preview --out " +
                              quoted(scratch / "h/h.#########.hair");
    const std::string command = "script -qec \"" + inner + "\" /dev/null >" + quoted(scratch / "tty.txt") + " 2>&1";
    std::system(command.c_str());
    const std::string shown = read_text(scratch / "tty.txt");
    const size_t limit = std::min<size_t>(std::stoul(columns), 80) - 1;
    size_t progress_lines = 0;
    for (const std::string &line : terminal_lines(shown)) {
      if (line.find("ETA") == std::string::npos) continue;
      ++progress_lines;
      INFO(line);
      CHECK(line.size() <= limit);
    }
    CHECK(progress_lines > 0);
  }
}

TEST_CASE("info --json describes strands, a mesh and a groom as one JSON object each", "[cli]") {
  ScratchDir scratch("info_json");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  REQUIRE(run_plume("regrow " + quoted(groom) + " --frames 1 --strands 25 --out " + quoted(scratch / "h.####.usda"), scratch)
              .exit_code == 0);
  // Node's JSON parser reads each (an independent parser), and the figures match the text form.
  const auto json_field = [&](const std::string &file, const std::string &expression) {
    const RunResult run = run_plume("info --json " + quoted(file), scratch);
    REQUIRE(run.exit_code == 0);
    std::ofstream(scratch / "info.json") << run.out;
    return shell_output("node -e 'const j = JSON.parse(require(\"fs\").readFileSync(process.argv[1], \"utf8\")); "
                        "console.log(String(" +
                        expression + "))' " + quoted(scratch / "info.json"));
  };
  CHECK(json_field(scratch / "h.0001.usda", "j.kind") == "strands");
  CHECK(json_field(scratch / "h.0001.usda", "j.strands") == "25");
  CHECK(json_field(scratch / "h.0001.usda", "j.points") == "200");
  CHECK(json_field(scratch / "h.0001.usda", "j.points_per_strand.min + \",\" + j.points_per_strand.max") == "8,8");
  CHECK(json_field(scratch / "h.0001.usda", "j.bounds.min.length + j.bounds.max.length") == "6");
  CHECK(json_field(scratch / "h.0001.usda", "j.widths.max > 0") == "true");
  CHECK(json_field(sintel_dir() + "/sintel.obj", "j.kind + \",\" + j.vertices + \",\" + j.uvs") == "mesh,3046,false");
  CHECK(json_field(groom, "j.kind + \",\" + j.name + \",\" + j.dynamics") == "groom,g,false");
  CHECK(json_field(groom, "j.description.length > 3") == "true");
  // A broken file is an error as without --json, and prints no JSON.
  const RunResult bad = run_plume("info --json " + quoted(PLUME_TEST_DATA "/bad/hair_truncated.hair"), scratch);
  CHECK(bad.exit_code == 2);
  CHECK(bad.out.empty());
}
