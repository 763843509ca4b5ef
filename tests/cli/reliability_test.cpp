// The `plume` command as a broken pipeline would run it: frame fields wider than any frame number,
// output names that fit only without the temporary suffix, a malformed OMP_NUM_THREADS, a run
// killed by SIGKILL and run again, values beyond float range in the files it reads.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <fstream>
#include <thread>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

/// A process id that names no process: a child that has exited and been reaped.
pid_t dead_pid() {
  const pid_t pid = fork();
  if (pid == 0) _exit(0);
  int status = 0;
  waitpid(pid, &status, 0);
  return pid;
}

}  // namespace

TEST_CASE("a frame field of 32 or more '#' pads every frame to its width: no two frames share a file", "[cli]") {
  ScratchDir scratch("wide_field");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const std::string hashes(40, '#');
  const RunResult run = run_plume_bounded("regrow " + quoted(groom) + " --frames 1-3 --strands 20 --out " +
                                              quoted(scratch / ("out/h." + hashes + ".hair")) + " --preview " +
                                              quoted(scratch / ("out/p." + std::string(32, '#') + ".png")) +
                                              " --preview-every 1 --preview-size 16",
                                          scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  const std::vector<std::string> files = files_in(scratch.path / "out");
  CHECK(files.size() == 6);
  for (int frame = 1; frame <= 3; ++frame) {
    const std::string digits = std::to_string(frame);
    CHECK(fs::exists(scratch.path / "out" / ("h." + std::string(39, '0') + digits + ".hair")));
    CHECK(fs::exists(scratch.path / "out" / ("p." + std::string(31, '0') + digits + ".png")));
  }
  // A printf field of the same width names the same files; wider than a file name, it is refused.
  const RunResult printf_field =
      run_plume_bounded("regrow " + quoted(groom) + " --frames=-2 --strands 20 --out " + quoted(scratch / "n/h.%040d.hair"),
                        scratch);
  INFO(printf_field.err);
  CHECK(printf_field.exit_code == 0);
  CHECK(fs::exists(scratch.path / "n" / ("h.-" + std::string(38, '0') + "2.hair")));
  const RunResult too_wide = run_plume_bounded(
      "regrow " + quoted(groom) + " --frames 1-2 --strands 20 --out " + quoted(scratch / ("w/h." + std::string(256, '#') + ".hair")),
      scratch);
  CHECK(too_wide.exit_code == 2);
  CHECK(too_wide.err.find("--out: path pattern") != std::string::npos);
  CHECK(too_wide.err.find("expected a frame field of at most 255 digits") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch.path / "w"));
}

TEST_CASE("an output name that fits only without the temporary suffix is refused before any work", "[cli]") {
  ScratchDir scratch("name_with_suffix");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  // 246 to 255 bytes fit the file system's 255, but "<name>.tmp-<pid>" does not.
  for (const size_t bytes : {size_t(244), size_t(246), size_t(250), size_t(255)}) {
    INFO(bytes << " bytes");
    const std::string name = std::string(bytes - 5, 'n') + ".hair";
    const RunResult run = run_plume_bounded(
        "regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(scratch / ("new/" + name)), scratch);
    INFO(run.err);
    CHECK(run.exit_code == 2);
    CHECK(run.err.find("has " + std::to_string(bytes) + " bytes; a file is written under its name plus up to 12 bytes") !=
          std::string::npos);
    CHECK(run.err.find("so at most 243 bytes fit the 255") != std::string::npos);
    CHECK_FALSE(fs::exists(scratch.path / "new"));  // no empty folder left behind
  }
  // The whole path, with the suffix, within the system's 4,095 bytes (folders of 200 bytes each).
  std::string deep = "new";
  while (deep.size() < 4100) deep += "/" + std::string(200, 'd');
  const RunResult too_deep =
      run_plume_bounded("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(scratch / (deep + "/h.hair")), scratch);
  CHECK(too_deep.exit_code == 2);
  CHECK(too_deep.err.find("bytes, with its temporary suffix more than the 4095 the system allows") != std::string::npos);
  CHECK_FALSE(fs::exists(scratch.path / "new"));
  const std::string longest = std::string(238, 'n') + ".hair";
  const RunResult run = run_plume_bounded(
      "regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(scratch / ("new/" + longest)), scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(fs::exists(scratch.path / "new" / longest));
}

TEST_CASE("an OMP_NUM_THREADS that is not a thread count is refused, naming the variable", "[cli]") {
  ScratchDir scratch("omp_env");
  const std::string groom = write_sintel_groom(scratch, "g", "");
  const fs::path out = scratch.path / "out";
  const std::string regrow = "regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(out.string() + "/h.hair");
  const std::string check = "check " + quoted(sintel_dir() + "/sintel_guides.hair") + " --mesh " +
                            quoted(sintel_dir() + "/sintel.obj");
  for (const std::string value : {"abc", "", "0", "-1", "2,abc", "4 4", "1.5", "99999999999999999999999"}) {
    for (const std::string &command : {regrow, check, regrow + " --threads 2", "info " + quoted(groom)}) {
      INFO("OMP_NUM_THREADS='" << value << "' plume " << command);
      const RunResult run = run_plume_bounded(command, scratch, 2000000, quoted(value));
      INFO(run.err);
      CHECK(run.exit_code == 2);
      CHECK(run.err.find("plume: error: OMP_NUM_THREADS: expected a whole number of threads >= 1") != std::string::npos);
      CHECK(files_in(out).empty());
    }
  }
  // What OpenMP reads as a count: a number, blanks around it, a list of one per nesting level.
  for (const std::string value : {"1", " 2 ", "2,1", "3, 2"}) {
    INFO("OMP_NUM_THREADS='" << value << "'");
    const RunResult run = run_plume_bounded(regrow, scratch, 2000000, quoted(value));
    INFO(run.err);
    CHECK(run.exit_code == 0);
  }
}

TEST_CASE("the temporary file a run killed by SIGKILL left is removed by the next run of the same outputs", "[cli]") {
  ScratchDir scratch("kill9");
  const std::string groom = write_big_sintel_groom(scratch);
  const fs::path out = scratch.path / "out";
  const std::string pattern = (out / "h.####.usda").string();
  const std::string frame1 = (out / "h.0001.usda").string();

  // Kill plume while it writes frame 1: wait for its temporary file to have bytes, then SIGKILL.
  std::string left;
  for (int attempt = 0; attempt < 5 && left.empty(); ++attempt) {
    fs::remove_all(out);
    const std::string binary = PLUME_BINARY;
    const pid_t pid = fork();
    REQUIRE(pid >= 0);
    if (pid == 0) {
      const char *const argv[] = {binary.c_str(), "regrow", groom.c_str(), "--frames", "1", "--out", pattern.c_str(),
                                  "--threads", "2", nullptr};
      execv(argv[0], const_cast<char *const *>(argv));
      _exit(121);
    }
    const std::string temp = frame1 + ".tmp-" + std::to_string(long(pid));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    int status = 0;
    while (std::chrono::steady_clock::now() < deadline) {
      std::error_code error;
      if (fs::file_size(temp, error) > 0 && !error) {
        kill(pid, SIGKILL);
        break;
      }
      if (waitpid(pid, &status, WNOHANG) == pid) break;  // finished before it was seen writing: again
      std::this_thread::sleep_for(std::chrono::microseconds(200));
    }
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    if (WIFSIGNALED(status) && fs::exists(temp)) left = temp;
  }
  INFO("plume was never caught writing its frame");
  REQUIRE_FALSE(left.empty());
  CHECK_FALSE(fs::exists(frame1));

  // Other files beside it: another frame's leftover from a dead run (removed too), and what is not
  // Plume's to remove: another pattern's, a live process's, a name that only looks alike.
  const std::string dead = std::to_string(long(dead_pid()));
  const std::string other_frame = (out / ("h.0007.usda.tmp-" + dead)).string();
  const std::string other_pattern = (out / ("g.0001.usda.tmp-" + dead)).string();
  const std::string live = (out / ("h.0002.usda.tmp-" + std::to_string(long(getpid())))).string();
  const std::string padded = (out / ("h.02.usda.tmp-" + dead)).string();
  for (const std::string &path : {other_frame, other_pattern, live, padded}) std::ofstream(path) << "partial";
  const RunResult run = run_plume_bounded("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(pattern),
                                          scratch);
  INFO(run.err);
  CHECK(run.exit_code == 0);
  CHECK(fs::exists(frame1));
  CHECK_FALSE(fs::exists(left));
  CHECK_FALSE(fs::exists(other_frame));
  CHECK(fs::exists(other_pattern));
  CHECK(fs::exists(live));
  CHECK(fs::exists(padded));

  // A leftover that a writer on another machine holds locked (its process id means nothing here).
  const std::string locked = (out / ("h.0003.usda.tmp-" + dead)).string();
  std::ofstream(locked) << "partial";
  const int fd = open(locked.c_str(), O_RDWR);
  REQUIRE(fd >= 0);
  REQUIRE(flock(fd, LOCK_EX) == 0);
  const RunResult again = run_plume_bounded("regrow " + quoted(groom) + " --frames 1 --strands 20 --out " + quoted(pattern),
                                            scratch);
  CHECK(again.exit_code == 0);
  CHECK(fs::exists(locked));
  close(fd);
}

TEST_CASE("info and check refuse a strand file with a value beyond float range instead of an infinite point", "[cli]") {
  ScratchDir scratch("float_range");
  const std::string mesh = quoted(sintel_dir() + "/sintel.obj");
  for (const std::string name : {"usda_point_1e300.usda", "ply_binary_double_1e300.ply", "usda_counts_1e30.usda",
                                 "ply_strand_id_7e31.ply"}) {
    const std::string file = quoted(std::string(PLUME_TEST_DATA) + "/bad/" + name);
    for (const std::string &command : {"info " + file, "check " + file + " --mesh " + mesh}) {
      INFO("plume " << command);
      const RunResult run = run_plume_bounded(command, scratch);
      INFO(run.out << run.err);
      CHECK(run.exit_code == 2);
      CHECK(run.err.find(name) != std::string::npos);
      CHECK(run.out.find("inf") == std::string::npos);
    }
  }
}
