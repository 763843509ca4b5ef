// Writes a file so that it appears whole or not at all: data goes to `<path>.tmp-<pid>` and is
// renamed onto `path` by commit(). A writer that throws before commit() leaves nothing behind, and
// remove_open_temp_files() lets a signal handler remove the temporary files of a stopped run.
#pragma once

#include <fstream>
#include <string>
#include <string_view>

namespace plume::io {

class AtomicFile {
 public:
  /// Creates missing parent directories and opens the temporary file for binary writing.
  /// Throws InputError naming `path` when the directory or the file cannot be created.
  explicit AtomicFile(const std::string &path);
  /// Removes the temporary file unless commit() succeeded.
  ~AtomicFile();
  AtomicFile(const AtomicFile &) = delete;
  AtomicFile &operator=(const AtomicFile &) = delete;

  /// The stream to write to (binary mode).
  std::ofstream &stream() { return stream_; }
  /// Appends raw bytes.
  void write(const void *data, size_t byte_count);
  void write(std::string_view text) { write(text.data(), text.size()); }

  /// Flushes, checks the stream, closes and renames the temporary file onto path().
  /// Throws InputError naming the file when any step fails (disk full, permissions).
  void commit();

  const std::string &path() const { return path_; }
  const std::string &temp_path() const { return temp_path_; }

 private:
  std::string path_;
  std::string temp_path_;
  std::ofstream stream_;
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

}  // namespace plume::io
