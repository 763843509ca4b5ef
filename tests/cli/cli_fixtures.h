// Helpers for the `plume` command tests: run the binary, read files, make scratch folders.
#pragma once

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace plume::cli_test {

namespace fs = std::filesystem;

/// A fresh, empty folder under the temp dir, removed when the object goes away.
struct ScratchDir {
  fs::path path;
  explicit ScratchDir(const std::string &name) {
    path = fs::temp_directory_path() / ("plume_cli_" + name + "_" + std::to_string(getpid()));
    fs::remove_all(path);
    fs::create_directories(path);
  }
  ~ScratchDir() { fs::remove_all(path); }
  std::string operator/(const std::string &name) const { return (path / name).string(); }
};

struct RunResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

inline std::string read_text(const std::string &path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

inline std::string quoted(const std::string &s) { return "'" + s + "'"; }

/// Runs a shell command with stdout and stderr captured in files of `scratch` (not a terminal, so
/// no progress line).
inline RunResult run_plume_command(const std::string &shell_command, const ScratchDir &scratch) {
  const std::string out_path = scratch.path.string() + "/.stdout";
  const std::string err_path = scratch.path.string() + "/.stderr";
  const std::string command = "(" + shell_command + ") >" + quoted(out_path) + " 2>" + quoted(err_path);
  const int status = std::system(command.c_str());
  RunResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  result.out = read_text(out_path);
  result.err = read_text(err_path);
  fs::remove(out_path);
  fs::remove(err_path);
  return result;
}

/// Runs `plume ARGS` (arguments already quoted as needed), as run_plume_command().
inline RunResult run_plume(const std::string &args, const ScratchDir &scratch) {
  return run_plume_command(quoted(PLUME_BINARY) + " " + args, scratch);
}

/// run_plume() under an address-space limit (KiB, default 2 GB) and a 60 s timeout, for inputs that
/// once made plume allocate without bound or loop: a regression then fails (exit 1 or 124) instead
/// of taking the machine. Two OpenMP threads (OMP_NUM_THREADS = `omp_threads`, as the shell reads
/// it) and two malloc arenas, so that the address space a run reserves (a stack per thread, up to
/// 64 MB per arena) does not grow with the machine's cores.
///
/// In a sanitizer build (tests/sanitize.sh) AddressSanitizer, which reserves terabytes of address
/// space for its shadow memory, cannot start under `ulimit -v`: memory is bounded by AddressSanitizer
/// itself instead. An allocation larger than the limit, or a resident size (shadow and quarantine of
/// freed blocks included) above twice the limit, ends the run with a report and exit 1. The timeout
/// is 300 s there: sanitized code runs several times slower.
inline RunResult run_plume_bounded(const std::string &args, const ScratchDir &scratch,
                                   long long address_space_kib = 2000000, const std::string &omp_threads = "2") {
#if defined(__SANITIZE_ADDRESS__)
  const long long limit_mb = address_space_kib / 1024;
  const std::string bound = "export ASAN_OPTIONS=\"${ASAN_OPTIONS:+$ASAN_OPTIONS:}max_allocation_size_mb=" +
                            std::to_string(limit_mb) + ":hard_rss_limit_mb=" + std::to_string(2 * limit_mb) + "\"; ";
  const std::string timeout = "300";
#else
  const std::string bound = "ulimit -v " + std::to_string(address_space_kib) + "; ";
  const std::string timeout = "60";
#endif
  return run_plume_command(bound + "OMP_NUM_THREADS=" + omp_threads + " MALLOC_ARENA_MAX=2 exec timeout " + timeout + " " +
                               quoted(PLUME_BINARY) + " " + args,
                           scratch);
}

/// Every regular file below `dir` (recursively), sorted.
inline std::vector<std::string> files_in(const fs::path &dir) {
  std::vector<std::string> files;
  if (!fs::exists(dir)) return files;
  for (const auto &entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file()) files.push_back(entry.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

/// The groom files shipped in grooms/ (every *.groom.yaml, recursively), sorted.
inline std::vector<std::string> shipped_grooms() {
  std::vector<std::string> grooms;
  for (const auto &entry : fs::recursive_directory_iterator(fs::path(PLUME_SOURCE_DIR) / "grooms")) {
    const std::string name = entry.path().filename().string();
    if (entry.is_regular_file() && name.size() > 11 && name.substr(name.size() - 11) == ".groom.yaml")
      grooms.push_back(entry.path().string());
  }
  std::sort(grooms.begin(), grooms.end());
  return grooms;
}

inline std::string sintel_dir() {
  // Appended to a named string: GCC 12 warns (-Warray-bounds, falsely) on the temporary's concatenation.
  std::string dir = PLUME_SOURCE_DIR;
  dir += "/grooms/sintel";
  return dir;
}

/// A small groom on the Sintel head (absolute paths), with `extra` YAML appended at the top level.
inline std::string write_sintel_groom(const ScratchDir &scratch, const std::string &name, const std::string &extra,
                                      const std::string &guides = sintel_dir() + "/sintel_guides.hair") {
  const std::string path = scratch / (name + ".groom.yaml");
  std::ofstream out(path);
  out << "plume: 1\n"
      << "emitter:\n"
      << "  mesh: " << sintel_dir() << "/sintel.obj\n"
      << "  animation:\n"
      << "    pivot: [0, 24, -2]\n"
      << "    keys:\n"
      << "      - {frame: 1, rotate: [0, 0, 0]}\n"
      << "      - {frame: 5, rotate: [0, 30, 0], translate: [1, 0, 0]}\n"
      << "guides: {file: " << guides << "}\n"
      << "roots: {count: 400, near_guides: 2.0, seed: 3}\n"
      << "strands: {points: 8}\n"
      << extra;
  return path;
}

/// A rest-pose groom on the Sintel head whose one frame takes a while to write (4,000 strands x 64
/// points, about 250k points: a .usda of several MB), for tests that stop or kill a run mid-write.
inline std::string write_big_sintel_groom(const ScratchDir &scratch) {
  const std::string path = scratch / "big.groom.yaml";
  std::ofstream(path) << "plume: 1\n"
                      << "emitter: {mesh: " << sintel_dir() << "/sintel.obj}\n"
                      << "guides: {file: " << sintel_dir() << "/sintel_guides.hair}\n"
                      << "roots: {count: 4000, near_guides: 2.0, seed: 3}\n"
                      << "strands: {points: 64}\n";
  return path;
}

}  // namespace plume::cli_test
