// `plume regrow --skip-existing` after a task killed with SIGKILL mid-batch (an out-of-memory
// killer, a preempted farm task): the rerun regrows only the frames whose files are missing, leaves
// the complete ones alone, and ends with the same bytes as a run that was never stopped.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <map>
#include <thread>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

using Clock = std::chrono::steady_clock;

/// Inode and modification time of a file: a file renamed into place anew has another inode.
std::pair<ino_t, int64_t> identity(const std::string &path) {
  struct stat status = {};
  REQUIRE(::stat(path.c_str(), &status) == 0);
  return {status.st_ino, int64_t(status.st_mtim.tv_sec) * 1000000000 + status.st_mtim.tv_nsec};
}

}  // namespace

TEST_CASE("--skip-existing after kill -9 mid-batch regrows only the missing frames, to the same bytes", "[cli]") {
  ScratchDir scratch("skip_existing");
  // With dynamics: frames after a skipped one are still simulated through it.
  const std::string groom =
      write_sintel_groom(scratch, "g", "dynamics: {enabled: true}\noutput: {preview_size: 32, preview_every: 2}\n");
  const std::string common = " --frames 1-6 --strands 300 --threads 2";
  const std::string ref = scratch / "ref";
  RunResult run = run_plume("regrow " + quoted(groom) + common + " --out " + quoted(ref + "/h.####.usda") + " --preview " +
                                quoted(ref + "/p.####.png"),
                            scratch);
  REQUIRE(run.exit_code == 0);
  REQUIRE(files_in(ref).size() == 11);  // 6 frames, 3 previews, the USD stage and its manifest

  // The run to kill: the temporary file of frame 3 is a FIFO made before exec (same pid), so the
  // run blocks while writing frame 3, after frames 1 and 2 are complete.
  const std::string out = scratch / "out";
  fs::create_directories(out);
  const std::string out_pattern = out + "/h.####.usda", preview_pattern = out + "/p.####.png";
  const std::string binary = PLUME_BINARY;
  const std::string args = "regrow " + quoted(groom) + common + " --out " + quoted(out_pattern) + " --preview " +
                           quoted(preview_pattern);
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    char fifo[4096];
    std::snprintf(fifo, sizeof fifo, "%s/h.0003.usda.tmp-%ld", out.c_str(), long(getpid()));
    if (mkfifo(fifo, 0600) != 0) _exit(120);
    const int null_fd = open("/dev/null", O_WRONLY);
    dup2(null_fd, STDOUT_FILENO);
    dup2(null_fd, STDERR_FILENO);
    execl("/bin/sh", "sh", "-c", ("exec " + quoted(binary) + " " + args).c_str(), static_cast<char *>(nullptr));
    _exit(121);
  }
  const std::string fifo = out + "/h.0003.usda.tmp-" + std::to_string(long(pid));
  std::string partial;
  int fifo_fd = -1, early_status = -1;
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (partial.empty() && Clock::now() < deadline) {
    if (waitpid(pid, &early_status, WNOHANG) == pid) break;
    if (fifo_fd < 0) fifo_fd = open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    char bytes[512];
    const ssize_t got = fifo_fd >= 0 ? read(fifo_fd, bytes, sizeof bytes) : 0;
    if (got > 0) partial.assign(bytes, size_t(got));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  kill(pid, SIGKILL);
  int status = 0;
  waitpid(pid, &status, 0);
  if (fifo_fd >= 0) close(fifo_fd);
  INFO("plume ended before writing frame 3, wait status " << early_status);
  REQUIRE(!partial.empty());
  REQUIRE(WIFSIGNALED(status));
  // What SIGKILL leaves: frames 1 and 2 whole, frame 3 as a partial temporary file.
  fs::remove(fifo);
  std::ofstream(fifo, std::ios::binary) << partial;
  CHECK(fs::exists(out + "/h.0001.usda"));
  CHECK(fs::exists(out + "/h.0002.usda"));
  CHECK(fs::exists(out + "/p.0001.png"));
  CHECK_FALSE(fs::exists(out + "/h.0003.usda"));
  const auto first = identity(out + "/h.0001.usda"), second = identity(out + "/h.0002.usda");

  run = run_plume(args + " --skip-existing", scratch);
  INFO(run.err);
  REQUIRE(run.exit_code == 0);
  INFO(run.out);
  CHECK(identity(out + "/h.0001.usda") == first);  // left alone
  CHECK(identity(out + "/h.0002.usda") == second);
  CHECK(run.out.find(out_pattern + ": 4 files, ") != std::string::npos);
  CHECK(run.out.find("2 complete already, kept (--skip-existing)") != std::string::npos);
  std::vector<std::string> names;
  for (const std::string &file : files_in(out)) names.push_back(fs::path(file).filename().string());
  CHECK(names == std::vector<std::string>{"h.0001.usda", "h.0002.usda", "h.0003.usda", "h.0004.usda", "h.0005.usda",
                                          "h.0006.usda", "h.manifest.usda", "h.usda", "p.0001.png", "p.0003.png",
                                          "p.0005.png"});
  for (const std::string &name : names) {
    INFO(name);
    CHECK(read_text(out + "/" + name) == read_text(ref + "/" + name));
  }

  // A frame is complete when all its files are: frame 5 without its preview is regrown (same bytes).
  fs::remove(out + "/p.0005.png");
  const auto fourth = identity(out + "/h.0004.usda"), fifth = identity(out + "/h.0005.usda");
  run = run_plume(args + " --skip-existing", scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(identity(out + "/h.0004.usda") == fourth);
  CHECK(identity(out + "/h.0005.usda") != fifth);
  CHECK(read_text(out + "/h.0005.usda") == read_text(ref + "/h.0005.usda"));
  CHECK(read_text(out + "/p.0005.png") == read_text(ref + "/p.0005.png"));
  CHECK(run.out.find(out_pattern + ": 1 file, ") != std::string::npos);

  // Nothing missing: nothing regrown, and without --skip-existing everything is.
  run = run_plume(args + " --skip-existing", scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(run.out.find(out_pattern + ": 0 files, 0 bytes; 6 complete already") != std::string::npos);
  CHECK(identity(out + "/h.0004.usda") == fourth);
  run = run_plume(args, scratch);
  REQUIRE(run.exit_code == 0);
  CHECK(identity(out + "/h.0004.usda") != fourth);
  CHECK(run.out.find(out_pattern + ": 6 files, ") != std::string::npos);
}

TEST_CASE("--skip-existing on a feather groom: a frame is complete when its curves and its vanes are", "[cli]") {
  ScratchDir scratch("skip_existing_feathers");
  const std::string bird = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/bird.groom.yaml";
  const std::string args = "regrow " + quoted(bird) + " --frames 1-3 --strands 20 --no-preview --out " +
                           quoted(scratch / "f.####.usda") + " --vanes " + quoted(scratch / "v.####.obj");
  RunResult run = run_plume(args, scratch);
  REQUIRE(run.exit_code == 0);
  const std::string vanes_2 = read_text(scratch / "v.0002.obj");
  fs::remove(scratch / "v.0002.obj");
  const auto curves_1 = identity(scratch / "f.0001.usda"), curves_2 = identity(scratch / "f.0002.usda");
  const auto curves_3 = identity(scratch / "f.0003.usda"), vanes_3 = identity(scratch / "v.0003.obj");
  run = run_plume(args + " --skip-existing", scratch);
  INFO(run.err << run.out);
  REQUIRE(run.exit_code == 0);
  CHECK(identity(scratch / "f.0001.usda") == curves_1);
  CHECK(identity(scratch / "f.0003.usda") == curves_3);
  CHECK(identity(scratch / "v.0003.obj") == vanes_3);
  CHECK(identity(scratch / "f.0002.usda") != curves_2);  // frame 2 regrown whole, to the same bytes
  CHECK(read_text(scratch / "v.0002.obj") == vanes_2);
  CHECK(run.out.find("vanes     " + scratch / "v.####.obj" + ": 1 file, ") != std::string::npos);
  CHECK(run.out.find("curves    " + scratch / "f.####.usda" + ": 1 file, ") != std::string::npos);
  CHECK(run.out.find("2 complete already") != std::string::npos);
}
