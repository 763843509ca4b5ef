// `plume regrow` stopped by SIGTERM, SIGINT or SIGHUP while it writes an output leaves no partial
// file behind and still dies of the signal (docs/cli.md: a killed task leaves no partial file).
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <thread>

#include "cli/cli_fixtures.h"

using namespace plume::cli_test;

namespace {

using Clock = std::chrono::steady_clock;

/// Waits up to `limit` for `pid` to end; returns its wait status, or -1 if it is still running.
int wait_for_exit(pid_t pid, std::chrono::seconds limit) {
  const auto deadline = Clock::now() + limit;
  while (Clock::now() < deadline) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) return status;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return -1;
}

}  // namespace

TEST_CASE("regrow stopped by a signal while writing leaves no temporary file and dies of the signal", "[cli]") {
  const int signal_number = GENERATE(SIGTERM, SIGINT, SIGHUP);
  CAPTURE(signal_number);
  ScratchDir scratch("signal");
  // Several MB of .usda, far more than the pipe below holds.
  const std::string groom = write_big_sintel_groom(scratch);
  const std::string out_dir = scratch / "out";
  fs::create_directories(out_dir);
  const std::string out = out_dir + "/h.usda";

  // The temporary file is `<out>.tmp-<pid>`. The child makes it a FIFO before exec (same pid), so
  // plume opens it, writes until the pipe is full and then waits inside the write: the signal is
  // sure to arrive mid-output, with no race against the write finishing.
  const std::string binary = PLUME_BINARY;
  const std::string fifo_prefix = out + ".tmp-";
  const char *const argv[] = {binary.c_str(), "regrow",  groom.c_str(), "--frames", "1",
                              "--out",        out.c_str(), "--threads", "2",         nullptr};
  const pid_t pid = fork();
  REQUIRE(pid >= 0);
  if (pid == 0) {
    char fifo_path[4096];
    std::snprintf(fifo_path, sizeof(fifo_path), "%s%ld", fifo_prefix.c_str(), long(getpid()));
    if (mkfifo(fifo_path, 0600) != 0) _exit(120);
    const int null_fd = open("/dev/null", O_WRONLY);
    dup2(null_fd, STDOUT_FILENO);
    dup2(null_fd, STDERR_FILENO);
    // A test runner started in the background inherits SIGINT ignored; plume must see each signal.
    for (const int s : {SIGTERM, SIGINT, SIGHUP}) std::signal(s, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    sigprocmask(SIG_SETMASK, &none, nullptr);
    execv(argv[0], const_cast<char *const *>(argv));
    _exit(121);
  }
  const std::string fifo_path = fifo_prefix + std::to_string(long(pid));

  // Read the first bytes, proof that plume has the temporary file open and is writing the output.
  int fifo_fd = -1;
  bool writing = false;
  int early_status = -1;
  const auto deadline = Clock::now() + std::chrono::seconds(120);
  while (!writing && Clock::now() < deadline) {
    if (waitpid(pid, &early_status, WNOHANG) == pid) break;
    if (fifo_fd < 0) fifo_fd = open(fifo_path.c_str(), O_RDONLY | O_NONBLOCK);
    char byte = 0;
    if (fifo_fd >= 0 && read(fifo_fd, &byte, 1) == 1) {
      writing = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  if (!writing && early_status == -1) kill(pid, SIGKILL);
  INFO("plume ended before writing, wait status " << early_status);
  REQUIRE(writing);

  kill(pid, signal_number);
  int status = wait_for_exit(pid, std::chrono::seconds(30));
  if (status == -1) {
    kill(pid, SIGKILL);
    waitpid(pid, &status, 0);
    FAIL("plume did not end within 30 s of the signal");
  }
  close(fifo_fd);
  CHECK(WIFSIGNALED(status));
  CHECK((WIFSIGNALED(status) ? WTERMSIG(status) : 0) == signal_number);
  CHECK_FALSE(fs::exists(fifo_path));
  CHECK(fs::is_empty(out_dir));  // neither the FIFO nor any other temporary or final file
}
