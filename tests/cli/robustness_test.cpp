// The `plume` command on hostile input: absurd numbers, bad output locations and broken per-frame
// inputs give exit 2 with a message naming the option or file, never a crash, a hang or a memory
// blow-up, and exit 2 leaves no output behind.
#include <catch2/catch.hpp>

#include <fstream>
#include <functional>

#include <sys/stat.h>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

/// Runs `args` (bounded) and checks exit 2, `message` on stderr and no file under `out`.
void require_rejected(const std::string &args, const std::string &message, const ScratchDir &scratch,
                      const fs::path &out) {
  INFO("plume " << args);
  const RunResult run = run_plume_bounded(args, scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find(message) != std::string::npos);
  CHECK(files_in(out).empty());
}

/// Runs `args` (bounded) and checks exit 0 and that it wrote `written`.
void require_written(const std::string &args, const fs::path &written, const ScratchDir &scratch) {
  INFO("plume " << args);
  const RunResult run = run_plume_bounded(args, scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(fs::exists(written));
}

}  // namespace

TEST_CASE("frame numbers beyond nine digits are rejected, as in a groom's output.frames", "[cli]") {
  ScratchDir scratch("frame_bounds");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string dyn = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n");
  const fs::path out = scratch.path / "out";
  const std::string dest = " --out " + quoted(out.string() + "/h.#.usda");
  for (const std::string frames : {"2147483647", "2147483640-2147483647:5", "1000000000", "1-1000000000",
                                   "-1000000000", "1-3:1000000000"}) {
    require_rejected("regrow " + quoted(groom) + " --frames " + frames + dest, "9 digits", scratch, out);
    require_rejected("simulate " + quoted(dyn) + " --frames " + frames + " --cache " + quoted(out.string() + "/c.#.hair"),
                     "9 digits", scratch, out);
  }
  require_rejected("preview " + quoted(groom) + " --frame 1000000000 --out " + quoted(out.string() + "/p.png"),
                   "--frame", scratch, out);
  // The largest frame is a frame like any other.
  require_written("regrow " + quoted(groom) + " --frames 999999999 --strands 20 --out " + quoted(scratch / "h.#.hair"),
                  scratch.path / "h.999999999.hair", scratch);
}

TEST_CASE("a run that writes or simulates more than 100000 frames is rejected before any check or work",
          "[cli]") {
  ScratchDir scratch("frames_per_run");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string far = write_sintel_groom(scratch, "far", "output: {frames: \"-999999999-1\"}\n");
  const std::string dyn = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1, preroll: 5}\n");
  const fs::path out = scratch.path / "out";
  const std::string dest = " --out " + quoted(out.string() + "/h.#.usda");
  // Every frame's output location is checked before the first is written: a billion frames would
  // take hours there, without a word.
  for (const std::string frames : {"1-999999999", "-999999999-999999999", "1-100001", "0-200000:2"}) {
    require_rejected("regrow " + quoted(groom) + " --frames " + frames + dest, "--frames: frames", scratch, out);
    require_rejected("simulate " + quoted(dyn) + " --frames " + frames + " --cache " + quoted(out.string() + "/c.#.hair"),
                     "expected at most 100000 in one run", scratch, out);
  }
  require_rejected("regrow " + quoted(far) + dest, "far.groom.yaml: output.frames: frames -999999999 to 1 are 1000000001",
                   scratch, out);
  // A step keeps the count down: 9 frames spread over a billion are 9 frames.
  require_written("regrow " + quoted(groom) + " --frames 1-999999999:111111111 --strands 20 --out " +
                      quoted(scratch / "s.#.hair"),
                  scratch.path / "s.888888889.hair", scratch);
  // Dynamics simulate from the groom's first frame (1) to the last frame asked for: one frame far
  // away is 100,001 frames of simulation (its preroll aside).
  for (const std::string &command :
       {"regrow " + quoted(dyn) + " --frames 100001" + dest,
        "regrow " + quoted(dyn) + " --frames 99999-100001" + dest,
        "simulate " + quoted(dyn) + " --frames 100001 --cache " + quoted(out.string() + "/c.#.hair"),
        "preview " + quoted(dyn) + " --frame 100001 --out " + quoted(out.string() + "/p.png")})
    require_rejected(command, "dyn.groom.yaml:12:11: dynamics: frame 100001 is simulated from rest at frame 1", scratch,
                     out);
}

TEST_CASE("a malformed frame field names the option or the groom key it came from", "[cli]") {
  ScratchDir scratch("pattern_fields");
  const fs::path out = scratch.path / "out";
  const std::string o = out.string();
  const std::string path = write_sintel_groom(scratch, "path", "output: {path: " + o + "/h.%ld.usda}\n");
  const std::string preview = write_sintel_groom(scratch, "preview", "output: {preview: " + o + "/p.%5$d.png}\n");
  const std::string cache = write_sintel_groom(scratch, "cache", "dynamics: {cache: " + o + "/g.####.%04d.hair}\n");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string one = " --frames 1-2";
  require_rejected("regrow " + quoted(path) + one, "path.groom.yaml: output.path: path pattern", scratch, out);
  require_rejected("regrow " + quoted(preview) + one + " --out " + quoted(o + "/h.#.usda"),
                   "preview.groom.yaml: output.preview: path pattern", scratch, out);
  require_rejected("simulate " + quoted(cache) + one, "cache.groom.yaml: dynamics.cache: path pattern", scratch, out);
  require_rejected("regrow " + quoted(groom) + one + " --out " + quoted(o + "/h.%s.usda"),
                   "--out: path pattern \"" + o + "/h.%s.usda\": expected a frame field like %04d after '%'", scratch, out);
  require_rejected("regrow " + quoted(groom) + one + " --out " + quoted(o + "/h.#.usda") + " --preview " +
                       quoted(o + "/p.%x.png"),
                   "--preview: path pattern", scratch, out);
  require_rejected("simulate " + quoted(cache) + one + " --cache " + quoted(o + "/c.#.%d.hair"),
                   "--cache: path pattern \"" + o + "/c.#.%d.hair\": expected one frame field (####, %04d or $F4), got two",
                   scratch, out);
}

TEST_CASE("--threads or OMP_NUM_THREADS beyond 1024 is rejected before any thread is started", "[cli]") {
  ScratchDir scratch("threads_bound");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  const std::string regrow = "regrow " + quoted(groom) + " --frames 1 --out " + quoted(out.string() + "/h.usda");
  const std::string preview = "preview " + quoted(groom) + " --size 64 --out " + quoted(out.string() + "/p.png");
  const std::string check = "check " + quoted(sintel_dir() + "/sintel_guides.hair") + " --mesh " +
                            quoted(sintel_dir() + "/sintel.obj") + " --tolerance 0.01";
  for (const std::string threads : {"1025", "32768", "100000"})
    for (const std::string &command : {regrow, preview, check})
      require_rejected(command + " --threads " + threads, "--threads", scratch, out);
  require_rejected("simulate " + quoted(write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n")) +
                       " --frames 1 --cache " + quoted(out.string() + "/c.#.hair") + " --threads 100000",
                   "--threads", scratch, out);
  // The same bound on OMP_NUM_THREADS, which sets the count when --threads is not given (this
  // crashed libgomp); --threads still overrides it.
  for (const std::string &command : {check, regrow}) {
    INFO(command);
    const RunResult run = run_plume_bounded(command, scratch, 2000000, "100000");
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find("OMP_NUM_THREADS: expected at most 1024 threads (as --threads), got 100000") != std::string::npos);
    CHECK(files_in(out).empty());
  }
  const RunResult overridden = run_plume_bounded(check + " --threads 2", scratch, 2000000, "100000");
  INFO(overridden.err);
  CHECK(overridden.exit_code == 0);
}

TEST_CASE("--strands beyond 100,000,000 roots is rejected, as a groom's roots.count", "[cli]") {
  ScratchDir scratch("strands_bound");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  for (const std::string strands : {"100000001", "2147483648", "999999999999"}) {
    require_rejected("regrow " + quoted(groom) + " --frames 1 --out " + quoted(out.string() + "/h.usda") +
                         " --strands " + strands,
                     "--strands", scratch, out);
    require_rejected("preview " + quoted(groom) + " --size 64 --out " + quoted(out.string() + "/p.png") +
                         " --strands " + strands,
                     "--strands", scratch, out);
  }
  // The groom `name`, the one above with each (from, to) replaced.
  auto variant = [&](const std::string &name, const std::vector<std::pair<std::string, std::string>> &edits) {
    std::string text = read_text(groom);
    for (const auto &[from, to] : edits) text.replace(text.find(from), from.size(), to);
    const std::string path = scratch / (name + ".groom.yaml");
    std::ofstream(path) << text;
    return path;
  };
  // The same bound on the count a groom's roots.density gives over the emitter's area.
  const std::string dense = variant("dense", {{"count: 400", "density: 100000000"}});
  require_rejected("regrow " + quoted(dense) + " --frames 1 --out " + quoted(out.string() + "/h.usda"), "roots.density",
                   scratch, out);
  // Counts within the bound that no machine's memory holds (1e8 strands of 4,096 points: over 10 TB)
  // are refused before roots are scattered, naming the count's source, instead of an allocation
  // failure or swapping after minutes of work.
  const std::string huge = variant("huge", {{"points: 8", "points: 4096"}, {"count: 400", "count: 100000000"}});
  const std::string huge_out = " --frames 1 --out " + quoted(out.string() + "/h.usda");
  require_rejected("regrow " + quoted(huge) + huge_out, "huge.groom.yaml:10:8: roots.count: 100000000 strands of 4096 points need about",
                   scratch, out);
  require_rejected("regrow " + quoted(huge) + huge_out + " --strands 100000000",
                   "--strands: 100000000 strands of 4096 points need about", scratch, out);
  require_rejected("preview " + quoted(huge) + " --size 64 --out " + quoted(out.string() + "/p.png"),
                   "GB of memory this run may use", scratch, out);
  // And a density too small to give a single root over that area.
  const std::string sparse = variant("sparse", {{"count: 400", "density: 1e-9"}});
  require_rejected("regrow " + quoted(sparse) + " --frames 1 --out " + quoted(out.string() + "/h.usda"),
                   "roots.density: density x area gives no root", scratch, out);
}

TEST_CASE("check rejects a NaN tolerance or margin, as it rejects inf and negatives", "[cli]") {
  ScratchDir scratch("check_nan");
  const std::string strands = quoted(sintel_dir() + "/sintel_guides.hair");
  const std::string mesh = " --mesh " + quoted(sintel_dir() + "/sintel.obj");
  for (const std::string option : {"--tolerance", "--margin"}) {
    for (const std::string value : {"nan", "NaN", "-nan", "inf", "-1", "1e39"}) {
      INFO(option << " " << value);
      const RunResult run = run_plume_bounded("check " + strands + mesh + " " + option + " " + value, scratch);
      INFO(run.out << run.err);
      CHECK(run.exit_code == 2);
      CHECK(run.err.find(option) != std::string::npos);
    }
  }
  const RunResult run = run_plume_bounded("check " + strands + mesh + " --tolerance 0.01 --margin 0", scratch);
  CHECK(run.exit_code == 0);
}

TEST_CASE("check refuses a guide file without strands instead of skipping the deviation", "[cli]") {
  ScratchDir scratch("check_no_guides");
  const std::string strands = quoted(sintel_dir() + "/sintel_guides.hair");
  const std::string mesh = " --mesh " + quoted(sintel_dir() + "/sintel.obj");
  const std::string empty = scratch / "empty.obj";
  std::ofstream(empty) << "v 0 0 0\n";
  const RunResult run = run_plume_bounded("check " + strands + mesh + " --guides " + quoted(empty), scratch);
  INFO(run.out << run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("--guides: " + empty + " holds no strands") != std::string::npos);
}

TEST_CASE("check refuses a mesh that is not an OBJ instead of reading it as one", "[cli]") {
  ScratchDir scratch("check_mesh_kind");
  const std::string guides = quoted(sintel_dir() + "/sintel_guides.hair");
  const RunResult run = run_plume_bounded("check " + guides + " --mesh " + guides, scratch);
  INFO(run.out << run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("--mesh: expected an .obj mesh, got \"" + sintel_dir() + "/sintel_guides.hair\"") !=
        std::string::npos);
}

TEST_CASE("input files that are devices or pipes are refused instead of read without end", "[cli]") {
  ScratchDir scratch("device_inputs");
  const std::string guides = quoted(sintel_dir() + "/sintel_guides.hair");
  const std::string mesh = quoted(sintel_dir() + "/sintel.obj");
  // /dev/zero behind names a reader takes by extension, and a pipe nobody writes to.
  const std::string zero_obj = scratch / "zero.obj", zero_hair = scratch / "zero.hair", pipe = scratch / "pipe.obj";
  fs::create_symlink("/dev/zero", zero_obj);
  fs::create_symlink("/dev/zero", zero_hair);
  REQUIRE(mkfifo(pipe.c_str(), 0600) == 0);
  for (const std::string &args :
       {"info " + quoted(zero_obj), "info " + quoted(zero_hair), "info " + quoted(pipe),
        "check " + quoted(zero_hair) + " --mesh " + mesh, "check " + guides + " --mesh " + quoted(zero_obj),
        "check " + guides + " --mesh " + quoted(pipe), "check " + guides + " --mesh " + mesh + " --guides " + quoted(zero_hair)})
    require_rejected(args, "not a regular file", scratch, scratch.path / "out");
}

TEST_CASE("simulate names the groom file when the groom has no dynamics", "[cli]") {
  ScratchDir scratch("simulate_no_dynamics");
  const std::string groom = write_sintel_groom(scratch, "still", "");
  const RunResult run = run_plume_bounded(
      "simulate " + quoted(groom) + " --frames 1 --cache " + quoted(scratch / "out/c.#.hair"), scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("still.groom.yaml: dynamics.enabled") != std::string::npos);
  CHECK(run.err.find("<input>") == std::string::npos);
}

TEST_CASE("a guide cache without a frame field cannot serve a range of frames", "[cli]") {
  ScratchDir scratch("cache_field");
  const std::string groom = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n");
  const fs::path out = scratch.path / "out";
  REQUIRE(run_plume_bounded("simulate " + quoted(groom) + " --frames 1-3 --cache " + quoted(scratch / "c.####.hair"),
                            scratch)
              .exit_code == 0);
  const std::string one = " --guides-cache " + quoted(scratch / "c.0001.hair");
  require_rejected("regrow " + quoted(groom) + " --frames 1-3 --strands 20" + one + " --out " +
                       quoted(out.string() + "/h.####.usda"),
                   "--guides-cache: 3 frames need a frame field", scratch, out);
  // One frame may name its cache file directly.
  const RunResult run = run_plume_bounded(
      "regrow " + quoted(groom) + " --frames 1 --strands 20" + one + " --out " + quoted(scratch / "h.usda"), scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
}

TEST_CASE("an output path holding a NUL character is rejected", "[cli]") {
  ScratchDir scratch("nul_path");
  // YAML's "\0" escape puts a NUL into the string: the system would cut the name there.
  const std::string groom = write_sintel_groom(scratch, "nul", "output: {path: \"out/ha\\0ir.####.usda\"}\n");
  const RunResult run = run_plume_bounded("regrow " + quoted(groom) + " --frames 1-2 --strands 20", scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("nul.groom.yaml:12:16: output.path: expected a path without a NUL character") != std::string::npos);
  CHECK(files_in(scratch.path / "out").empty());
}

TEST_CASE("every output location of a run is checked before the first file is written", "[cli]") {
  ScratchDir scratch("output_locations");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  std::ofstream(scratch / "notadir") << "a file, not a folder\n";
  // A preview under a regular file: the strands would have been written first.
  require_rejected("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(out.string() + "/A/h.usda") +
                       " --preview " + quoted(scratch / "notadir/p.png"),
                   "notadir is not a directory", scratch, out);
  // The strands under a regular file, two levels down.
  require_rejected("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " +
                       quoted(scratch / "notadir/deeper/h.usda") + " --preview " + quoted(out.string() + "/p.png"),
                   "notadir is not a directory", scratch, out);
  // Frame 3's strand file is an existing directory: frames 1 and 2 would have been written.
  fs::create_directories(out / "B/h.0003.usda");
  require_rejected("regrow " + quoted(groom) + " --frames 1-4 --strands 20 --out " +
                       quoted(out.string() + "/B/h.####.usda"),
                   "h.0003.usda is an existing directory", scratch, out);
  // Frame 3's preview (every second frame of 1-4: frames 1 and 3) is an existing directory.
  fs::create_directories(out / "P/p.0003.png");
  require_rejected("regrow " + quoted(groom) + " --frames 1-4 --strands 20 --out " +
                       quoted(out.string() + "/P/h.####.hair") + " --preview " + quoted(out.string() + "/P/p.####.png") +
                       " --preview-every 2",
                   "p.0003.png is an existing directory", scratch, out);
  // A cache frame of simulate that is a directory.
  const std::string dyn = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n");
  fs::create_directories(out / "C/c.0002.hair");
  require_rejected("simulate " + quoted(dyn) + " --frames 1-3 --cache " + quoted(out.string() + "/C/c.####.hair"),
                   "c.0002.hair is an existing directory", scratch, out);
  // The one picture of plume preview.
  require_rejected("preview " + quoted(groom) + " --size 64 --out " + quoted(scratch / "notadir/p.png"),
                   "notadir is not a directory", scratch, out);
  // A file or folder name longer than the file system allows (255 bytes): the first write would fail.
  const std::string long_name(300, 'n');
  require_rejected("regrow " + quoted(groom) + " --frames 1-2 --strands 20 --out " +
                       quoted(out.string() + "/" + long_name + ".####.usda"),
                   "has 310 bytes, more than the", scratch, out);
  // The message shows the start of a long name cut before a whole UTF-8 character (a two-byte one
  // would straddle byte 40 here), not in the middle of one.
  std::string accented_name = "n";
  for (int i = 0; i < 150; ++i) accented_name += "\xc3\xa9";
  std::string shown = "the name \"n";
  for (int i = 0; i < 19; ++i) shown += "\xc3\xa9";
  require_rejected("regrow " + quoted(groom) + " --frames 1-2 --strands 20 --out " +
                       quoted(out.string() + "/" + accented_name + ".####.usda"),
                   shown + "...\" has 311 bytes", scratch, out);
  require_rejected("simulate " + quoted(dyn) + " --frames 1-2 --cache " + quoted(out.string() + "/" + long_name + "/c.#.hair"),
                   "--cache: cannot write", scratch, out);
  // Folders that do not exist yet are made.
  require_written("regrow " + quoted(groom) + " --frames 1-2 --strands 20 --out " + quoted(scratch / "new/deep/h.####.hair"),
                  scratch.path / "new/deep/h.0002.hair", scratch);
}

TEST_CASE("every needed guide-cache frame is read and checked before the first file is written", "[cli]") {
  ScratchDir scratch("cache_frames");
  const std::string groom = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n");
  const fs::path out = scratch.path / "out";
  const std::string cache = scratch / "cache/c.####.hair";
  RunResult run = run_plume_bounded("simulate " + quoted(groom) + " --frames 1-3 --cache " + quoted(cache), scratch);
  REQUIRE(run.exit_code == 0);
  const std::string frame2 = scratch / "cache/c.0002.hair";
  const std::string good = read_text(frame2);
  REQUIRE(good.size() > 1000);
  const std::string regrow = "regrow " + quoted(groom) + " --frames 1-3 --strands 20 --guides-cache " + quoted(cache) +
                             " --out " + quoted(out.string() + "/h.####.usda");
  auto damage = [&](const std::string &what, const std::function<void()> &make, const std::string &message) {
    INFO(what);
    fs::remove_all(frame2);
    make();
    require_rejected(regrow, message, scratch, out);
  };
  damage("truncated", [&] { std::ofstream(frame2, std::ios::binary) << good.substr(0, good.size() / 2); }, "c.0002.hair");
  damage("empty", [&] { std::ofstream(frame2, std::ios::binary); }, "c.0002.hair");
  damage("other strands", [&] {
    run_plume_bounded("regrow " + quoted(groom) + " --frames 2 --strands 5 --out " + quoted(frame2), scratch);
  }, "c.0002.hair: guide cache: expected 228 guides");
  damage("a NaN", [&] { fs::copy_file(PLUME_TEST_DATA "/bad/hair_nan.hair", frame2); }, "c.0002.hair");
  damage("a directory", [&] { fs::create_directories(frame2); }, "c.0002.hair");
  fs::remove_all(frame2);
  std::ofstream(frame2, std::ios::binary) << good;
  run = run_plume_bounded(regrow, scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(files_in(out).size() == 5);  // the 3 frames, the USD stage and its manifest
}

TEST_CASE("every needed frame of an emitter sequence is checked before the first file is written", "[cli]") {
  ScratchDir scratch("sequence_frames");
  // A unit square (two triangles) with two upright guides; the sequence lifts it frame by frame.
  auto square = [](float y, const std::string &extra = "") {
    const std::string h = std::to_string(y);
    return "v 0 " + h + " 0\nv 1 " + h + " 0\nv 1 " + h + " 1\nv 0 " + h + " 1\n" + extra + "f 1 2 3\nf 1 3 4\n";
  };
  std::ofstream(scratch / "plane.obj") << square(0.0f);
  std::ofstream(scratch / "guides.obj") << "v 0.2 0 0.2\nv 0.2 0.5 0.2\nv 0.2 1 0.2\nl 1 2\nl 2 3\n"
                                           "v 0.8 0 0.8\nv 0.8 0.5 0.8\nv 0.8 1 0.8\nl 4 5\nl 5 6\n";
  const std::string head = "plume: 1\nemitter: {mesh: plane.obj, animation: {sequence: anim/a.####.obj}}\n"
                           "guides: {file: guides.obj}\nroots: {count: 20}\nstrands: {points: 4}\n";
  std::ofstream(scratch / "seq.groom.yaml") << head;
  std::ofstream(scratch / "dyn.groom.yaml") << head << "dynamics: {substeps: 1}\noutput: {frames: 1-3}\n";
  fs::create_directories(scratch / "anim");
  auto write_frames = [&] {
    for (int f = 1; f <= 3; ++f) std::ofstream(scratch / ("anim/a.000" + std::to_string(f) + ".obj")) << square(0.1f * f);
  };
  const fs::path out = scratch.path / "out";
  const std::string regrow = "regrow " + quoted(scratch / "seq.groom.yaml") + " --frames 1-3 --out " +
                             quoted(out.string() + "/h.####.hair");
  struct Case {
    std::string what, frame2, message;
  };
  const std::vector<Case> cases = {
      {"a NaN vertex", "v nan 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 3\nf 1 3 4\n", "a.0002.obj"},
      {"other triangles", "v 0 0 0\nv 1 0 0\nv 1 0 1\nv 0 0 1\nf 1 2 4\nf 2 3 4\n", "a.0002.obj"},
      {"a vertex fewer", "v 0 0 0\nv 1 0 0\nv 1 0 1\nf 1 2 3\n", "a.0002.obj"},
      {"collapsed to a point", "v 0 0 0\nv 0 0 0\nv 0 0 0\nv 0 0 0\nf 1 2 3\nf 1 3 4\n", "a.0002.obj"},
  };
  for (const Case &c : cases) {
    INFO(c.what);
    write_frames();
    std::ofstream(scratch / "anim/a.0002.obj") << c.frame2;
    require_rejected(regrow, c.message, scratch, out);
  }
  write_frames();
  fs::remove(scratch / "anim/a.0003.obj");
  require_rejected(regrow, "a.0003.obj does not exist", scratch, out);
  // With dynamics the simulation poses the emitter from the groom's first frame: regrowing frames
  // 2-3 needs frame 1 too.
  write_frames();
  fs::remove(scratch / "anim/a.0001.obj");
  require_rejected("regrow " + quoted(scratch / "dyn.groom.yaml") + " --frames 2-3 --out " +
                       quoted(out.string() + "/d.####.hair"),
                   "a.0001.obj does not exist", scratch, out);
  write_frames();
  const RunResult run = run_plume_bounded(regrow, scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(files_in(out).size() == 3);
}

TEST_CASE("a preview is drawn in bands: a 2048-pixel picture fits in 400 MB of address space", "[cli]") {
  // At 3x supersampling the whole raster of a 2048-pixel picture would take 600 MB.
  ScratchDir scratch("preview_memory");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const RunResult run = run_plume_bounded("preview " + quoted(groom) + " --strands 300 --guides --size 2048 --out " +
                                              quoted(scratch / "p.png"),
                                          scratch, 400000);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(read_text(scratch / "p.png").find("PNG") == 1);
}

TEST_CASE("preview sizes are bounded alike on the command line and in the groom file", "[cli]") {
  ScratchDir scratch("preview_size");
  const fs::path out = scratch.path / "out";
  const std::string groom = write_sintel_groom(scratch, "g", "");
  require_rejected("preview " + quoted(groom) + " --size 8193 --out " + quoted(out.string() + "/p.png"), "--size",
                   scratch, out);
  require_rejected("regrow " + quoted(groom) + " --frames 1 --out " + quoted(out.string() + "/h.usda") + " --preview " +
                       quoted(out.string() + "/p.png") + " --preview-size 8193",
                   "--preview-size", scratch, out);
  const std::string big = write_sintel_groom(
      scratch, "big", "output: {path: " + out.string() + "/h.####.usda, preview: " + out.string() +
                          "/p.####.png, preview_size: 16384}\n");
  require_rejected("regrow " + quoted(big) + " --frames 1-2 --strands 20", "output.preview_size", scratch, out);
  const std::string dyn = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\noutput: {preview_size: 16384}\n");
  require_rejected("simulate " + quoted(dyn) + " --frames 1 --cache " + quoted(out.string() + "/c.#.hair") +
                       " --preview " + quoted(out.string() + "/g.png"),
                   "output.preview_size", scratch, out);
}

TEST_CASE("an output that is one of the run's own inputs is refused, and the input is left as it was", "[cli]") {
  ScratchDir scratch("inputs_kept");
  const std::string guides = scratch / "guides.hair";
  fs::copy_file(sintel_dir() + "/sintel_guides.hair", guides);
  const std::string original = read_text(guides);
  const std::string groom = write_sintel_groom(scratch, "g", "", guides);
  const fs::path out = scratch.path / "out";
  // A typo in --out must not overwrite the groom's guides.
  RunResult run = run_plume_bounded("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(guides), scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("the groom's guides.file") != std::string::npos);
  CHECK(read_text(guides) == original);
  // Nor the guide cache that a regrow reads, frame for frame.
  const std::string dyn = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n", guides);
  const std::string cache = scratch / "cache/c.####.hair";
  run = run_plume_bounded("simulate " + quoted(dyn) + " --frames 1-2 --cache " + quoted(cache), scratch);
  REQUIRE(run.exit_code == 0);
  const std::string frame2 = read_text(scratch / "cache/c.0002.hair");
  run = run_plume_bounded("regrow " + quoted(dyn) + " --frames 1-2 --strands 20 --guides-cache " + quoted(cache) +
                              " --out " + quoted(cache),
                          scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("the --guides-cache file of frame 1") != std::string::npos);
  CHECK(read_text(scratch / "cache/c.0002.hair") == frame2);
  // Nor another frame's: frame 1 written over frame 2's cache file.
  run = run_plume_bounded("regrow " + quoted(dyn) + " --frames 1 --strands 20 --guides-cache " + quoted(cache) +
                              " --out " + quoted(scratch / "cache/c.0002.hair"),
                          scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("the --guides-cache file of frame 2") != std::string::npos);
  CHECK(read_text(scratch / "cache/c.0002.hair") == frame2);
  // Nor the emitter mesh (a simulation cache may be written as .obj).
  const std::string mesh = scratch / "head.obj";
  fs::copy_file(sintel_dir() + "/sintel.obj", mesh);
  const std::string on_copy = scratch / "on_copy.groom.yaml";
  {
    std::string text = read_text(dyn);
    text.replace(text.find(sintel_dir() + "/sintel.obj"), (sintel_dir() + "/sintel.obj").size(), mesh);
    std::ofstream(on_copy) << text;
  }
  const std::string mesh_text = read_text(mesh);
  run = run_plume_bounded("simulate " + quoted(on_copy) + " --frames 1 --cache " + quoted(mesh), scratch);
  INFO(run.err);
  CHECK(run.exit_code == 2);
  CHECK(run.err.find("the groom's emitter.mesh") != std::string::npos);
  CHECK(read_text(mesh) == mesh_text);
}

TEST_CASE("a guide cache with a point beyond the scene bound is refused before anything is written", "[cli]") {
  ScratchDir scratch("cache_bound");
  const std::string groom = write_sintel_groom(scratch, "dyn", "dynamics: {substeps: 1}\n");
  const fs::path out = scratch.path / "out";
  const std::string cache = scratch / "cache/c.####.usda";
  RunResult run = run_plume_bounded("simulate " + quoted(groom) + " --frames 1-2 --cache " + quoted(cache), scratch);
  REQUIRE(run.exit_code == 0);
  const std::string frame2 = scratch / "cache/c.0002.usda";
  std::string text = read_text(frame2);
  const std::string points_key = "2: [(";  // points.timeSamples at frame 2
  const size_t points = text.find(points_key);
  REQUIRE(points != std::string::npos);
  const size_t x = points + points_key.size();
  text.replace(x, text.find(',', x) - x, "2e7");  // the first point's x
  std::ofstream(frame2) << text;
  require_rejected("regrow " + quoted(groom) + " --frames 1-2 --strands 20 --guides-cache " + quoted(cache) +
                       " --out " + quoted(out.string() + "/h.####.usda"),
                   "c.0002.usda: guide 0, point 0: expected coordinates within", scratch, out);
}

TEST_CASE("a groom file's input paths holding a NUL character are rejected", "[cli]") {
  ScratchDir scratch("nul_input");
  const fs::path out = scratch.path / "out";
  const std::string groom = write_sintel_groom(scratch, "g", "", sintel_dir() + "/sintel_guides\\0.hair");
  {
    // YAML's "\0" escape inside a double-quoted scalar.
    std::string text = read_text(groom);
    const std::string written = sintel_dir() + "/sintel_guides\\0.hair";
    text.replace(text.find(written), written.size(), "\"" + written + "\"");
    std::ofstream(groom) << text;
  }
  require_rejected("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(out.string() + "/h.usda"),
                   "guides.file: expected a path without a NUL character", scratch, out);
}

TEST_CASE("roots with no area to scatter on are named by the groom file and keys", "[cli]") {
  ScratchDir scratch("roots_no_area");
  const fs::path out = scratch.path / "out";
  // Face group "scalp" holds only a degenerate triangle (three points on a line).
  std::ofstream(scratch / "m.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 0 0\nv 3 0 0\n"
                                      "g skin\nf 1 2 3\ng scalp\nf 2 4 5\n";
  std::ofstream(scratch / "guides.obj") << "v 0.2 0.2 0\nv 0.2 0.2 0.5\nv 0.2 0.2 1\nl 1 2 3\n";
  const std::string groom = scratch / "g.groom.yaml";
  std::ofstream(groom) << "plume: 1\nemitter: {mesh: m.obj}\nguides: {file: guides.obj}\n"
                          "roots: {count: 10, groups: [scalp]}\nstrands: {points: 4}\n";
  require_rejected("regrow " + quoted(groom) + " --frames 1 --out " + quoted(out.string() + "/h.usda"),
                   "g.groom.yaml:4", scratch, out);
}

TEST_CASE("check refuses a crossing tolerance that would compare nearly every pair of segments", "[cli]") {
  ScratchDir scratch("check_tolerance");
  const std::string args = "check " + quoted(sintel_dir() + "/sintel_guides.hair") + " --mesh " +
                           quoted(sintel_dir() + "/sintel.obj") + " --tolerance ";
  const RunResult refused = run_plume_bounded(args + "1e6", scratch);
  INFO(refused.err);
  CHECK(refused.exit_code == 2);
  CHECK(refused.err.find("--tolerance 1e+06") != std::string::npos);
  const RunResult counted = run_plume_bounded(args + "0.01", scratch);
  INFO(counted.err);
  CHECK(counted.exit_code == 0);
  CHECK(counted.out.find("crossing strand pairs") != std::string::npos);
}

TEST_CASE("check counts long strands running side by side once each, without a search per segment pair", "[cli]") {
  // Two strands of 65,536 points, 1 apart along the first half of their length and 0.0005 apart
  // along the second: at tolerance 0.001 every segment of one's second half crosses its neighbours
  // on the other. Each crossing segment pair used to search all the earlier segment pairs of the
  // two strands for the strand pair's witness (the first half of one against all of the other, for
  // each of some 200,000 crossing pairs: days); the first crossing is now searched once per strand
  // pair.
  ScratchDir scratch("check_long_strands");
  const std::string path = scratch / "long.obj";
  {
    std::ofstream file(path);
    constexpr int kPoints = 65536;
    for (int s = 0; s < 2; ++s)
      for (int i = 0; i < kPoints; ++i)
        file << "v " << 10.0 * i / (kPoints - 1) << " " << 100.0 + (i < kPoints / 2 ? 1.0 : 0.0005) * s << " 0\n";
    for (int s = 0; s < 2; ++s) {
      file << "l";
      for (int i = 1; i <= kPoints; ++i) file << " " << s * kPoints + i;
      file << "\n";
    }
  }
  const RunResult run = run_plume_bounded(
      "check " + quoted(path) + " --mesh " + quoted(sintel_dir() + "/sintel.obj") + " --tolerance 0.001", scratch);
  INFO(run.out << run.err);
  CHECK(run.exit_code == 0);
  // One pair, counted once: transversal where the second strand drops across to its neighbour.
  CHECK(run.out.find("crossing strand pairs (tolerance 0.001): 1 transversal") != std::string::npos);
  CHECK(run.out.find("transversal: 0/1\n") != std::string::npos);
}
