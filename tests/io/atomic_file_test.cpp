// AtomicFile: a file appears whole on commit, and nothing is left when the writer throws; the
// temporary files of writers killed by SIGKILL are found and removed, and only those.
#include <catch2/catch.hpp>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "groom/error.h"
#include "io/atomic_file.h"
#include "io/strand_file.h"
#include "scratch_dir.h"

TEST_CASE("AtomicFile creates missing directories and renames onto the path only on commit", "[io]") {
  plume::test::ScratchDir dir("atomic");
  const std::string path = dir.file("a/b/out.txt");
  {
    plume::io::AtomicFile file(path);
    file.write("hello");
    CHECK(std::filesystem::exists(file.temp_path()));
    CHECK_FALSE(std::filesystem::exists(path));
    file.commit();
    CHECK_FALSE(std::filesystem::exists(file.temp_path()));
  }
  std::ifstream in(path);
  std::string text;
  in >> text;
  CHECK(text == "hello");
}

TEST_CASE("AtomicFile leaves no file, temporary or final, when the writer throws", "[io]") {
  plume::test::ScratchDir dir("atomic_throw");
  const std::string path = dir.file("out.usda");
  std::ofstream(path) << "previous";
  try {
    plume::io::AtomicFile file(path);
    file.write("half of a fi");
    throw std::runtime_error("writer failed");
  } catch (const std::runtime_error &) {
  }
  std::size_t entries = 0;
  for ([[maybe_unused]] const auto &entry : std::filesystem::directory_iterator(dir.path())) ++entries;
  CHECK(entries == 1);  // only the previous, untouched file
  std::ifstream in(path);
  std::string text;
  in >> text;
  CHECK(text == "previous");
}

TEST_CASE("a strand writer that fails midway leaves no output file", "[io]") {
  plume::test::ScratchDir dir("atomic_writer");
  plume::StrandSet strands;
  strands.append(std::vector<Eigen::Vector3f>{{0, 0, 0}, {0, 1, 0}}, std::numeric_limits<uint64_t>::max());
  CHECK_THROWS_AS(plume::io::write_strands(dir.file("ids.usda"), strands, {}), plume::InputError);
  CHECK(std::filesystem::is_empty(dir.path()));
}

TEST_CASE("AtomicFile names the file when it cannot be created", "[io]") {
  plume::test::ScratchDir dir("atomic_fail");
  std::ofstream(dir.file("plain")) << "x";
  CHECK_THROWS_WITH(plume::io::AtomicFile(dir.file("plain/sub/out.hair")),
                    Catch::Contains("plain/sub/out.hair") && Catch::Contains("cannot create"));
}

TEST_CASE("AtomicFile removes the folders it made when its file cannot be created", "[io]") {
  plume::test::ScratchDir dir("atomic_folders");
  const std::string too_long(300, 'n');
  CHECK_THROWS_WITH(plume::io::AtomicFile(dir.file("new/deeper/" + too_long)), Catch::Contains("cannot create file"));
  CHECK(std::filesystem::is_empty(dir.path()));
  // A folder that was there stays, and so do the folders holding a file written before.
  std::filesystem::create_directories(dir.file("kept"));
  {
    plume::io::AtomicFile file(dir.file("made/first.txt"));
    file.write("x");
    file.commit();
  }
  CHECK_THROWS(plume::io::AtomicFile(dir.file("kept/sub/" + too_long)));
  CHECK_THROWS(plume::io::AtomicFile(dir.file("made/" + too_long)));
  CHECK(std::filesystem::is_directory(dir.file("kept")));
  CHECK_FALSE(std::filesystem::exists(dir.file("kept/sub")));
  CHECK(std::filesystem::exists(dir.file("made/first.txt")));
}

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

TEST_CASE("stale temporary files are removed only when they are the outputs', their writer is gone and unlocked",
          "[io]") {
  plume::test::ScratchDir dir("stale_temps");
  const std::string dead = std::to_string(long(dead_pid()));
  const std::string alive = std::to_string(long(getppid()));  // the test runner's parent: running
  auto make = [&](const std::string &name) {
    std::ofstream(dir.file(name)) << "partial";
    return dir.file(name);
  };
  const std::string stale = make("out.usda.tmp-" + dead);
  const std::string running = make("out.usda.tmp-" + alive);
  const std::string other_output = make("other.usda.tmp-" + dead);
  const std::string not_a_pid = make("out.usda.tmp-x" + dead);
  const std::string zero_padded = make("out.usda.tmp-0" + dead);
  const std::string not_temp = make("out.usda");
  std::filesystem::create_directories(dir.file("out.usda.tmp-" + dead + "0"));  // a folder, not a file
  // A file that a writer elsewhere holds locked: its process id means nothing on this machine.
  const std::string locked = make("locked.usda.tmp-" + dead);
  const int fd = ::open(locked.c_str(), O_RDWR);
  REQUIRE(fd >= 0);
  REQUIRE(::flock(fd, LOCK_EX) == 0);
  // An open AtomicFile holds its own temporary file locked too.
  plume::io::AtomicFile open_file(dir.file("open.usda"));
  const int probe = ::open(open_file.temp_path().c_str(), O_RDWR);
  REQUIRE(probe >= 0);
  CHECK(::flock(probe, LOCK_EX | LOCK_NB) != 0);
  ::close(probe);

  const auto outputs = [](const std::string &name) { return name == "out.usda" || name == "locked.usda"; };
  const std::vector<std::string> removed = plume::io::remove_stale_temp_files(dir.path().string(), outputs);
  CHECK(removed == std::vector<std::string>{stale});
  CHECK_FALSE(std::filesystem::exists(stale));
  for (const std::string &kept : {running, other_output, not_a_pid, zero_padded, not_temp, locked})
    CHECK(std::filesystem::exists(kept));
  CHECK(std::filesystem::is_directory(dir.file("out.usda.tmp-" + dead + "0")));
  ::close(fd);
  // Unlocked now: stale.
  CHECK(plume::io::remove_stale_temp_files(dir.path().string(), outputs) == std::vector<std::string>{locked});
  CHECK(plume::io::remove_stale_temp_files(dir.file("no_such_folder"), outputs).empty());
}
