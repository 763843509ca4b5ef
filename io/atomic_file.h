// Writes a file so that it appears whole or not at all: data goes to `<path>.tmp-<pid>` and is
// renamed onto `path` by commit(). A writer that throws before commit() leaves nothing behind, and
// remove_open_temp_files() lets a signal handler remove the temporary files of a stopped run. The
// temporary files a run killed by SIGKILL left are found and removed by remove_stale_temp_files().
#pragma once

#include <cstddef>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

namespace plume::io {

/// The most bytes the temporary suffix adds to a file's name: ".tmp-" and a process id, at most
/// 4,194,304 (2^22, Linux's largest pid_max): 7 digits. A name that fits the file system's limit
/// only without them cannot be written.
inline constexpr size_t kMaxTempSuffixBytes = 12;

class AtomicFile {
 public:
  /// Creates missing parent directories and the temporary file, which it holds locked (flock)
  /// until it is renamed or removed: the lock tells remove_stale_temp_files() on any machine that
  /// shares the folder that its writer is alive. Throws InputError naming `path` when the directory
  /// or the file cannot be created, after removing the directories it made.
  explicit AtomicFile(const std::string &path);
  /// Removes the temporary file unless commit() succeeded, and the directories the constructor
  /// made when they are left empty.
  ~AtomicFile();
  AtomicFile(const AtomicFile &) = delete;
  AtomicFile &operator=(const AtomicFile &) = delete;

  /// Appends raw bytes. A failure (a full disk) is remembered and reported by commit().
  void write(const void *data, size_t byte_count);
  void write(std::string_view text) { write(text.data(), text.size()); }

  /// Checks that every write succeeded, closes and renames the temporary file onto path().
  /// Throws InputError naming the file when any step fails (disk full, permissions).
  void commit();

  const std::string &path() const { return path_; }
  const std::string &temp_path() const { return temp_path_; }

 private:
  /// Removes the directories the constructor made, deepest first, as long as they are empty.
  void remove_made_directories() noexcept;

  std::string path_;
  std::string temp_path_;
  int fd_ = -1;
  int write_errno_ = 0;  // the first failed write's errno, 0 when none failed
  /// The directories the constructor created, outermost first.
  std::vector<std::string> made_directories_;
  /// Index of this file's entry in the registry that remove_open_temp_files() reads, or -1 when it
  /// has none (registry full or path too long).
  int registry_slot_ = -1;
  bool committed_ = false;
};

/// Unlinks the temporary file of every AtomicFile that is open and not yet committed, from any
/// thread. Async-signal-safe (atomics and unlink only): meant for a SIGTERM/SIGINT/SIGHUP handler,
/// after which the process must end, since the AtomicFiles it interrupted can no longer commit.
/// Covers up to 64 files open at once whose temporary path is shorter than PATH_MAX.
void remove_open_temp_files() noexcept;

/// Removes from `folder` the temporary files that writers killed by SIGKILL left: the regular files
/// named `<name>.tmp-<pid>` whose `<name>` satisfies `is_output_name`, whose process `<pid>` is not
/// running on this machine, and that no AtomicFile holds locked (a writer on another machine that
/// shares the folder keeps its file). Returns the paths removed. A missing or unreadable folder has
/// none; nothing else is touched.
std::vector<std::string> remove_stale_temp_files(const std::string &folder,
                                                 const std::function<bool(const std::string &name)> &is_output_name);

}  // namespace plume::io
