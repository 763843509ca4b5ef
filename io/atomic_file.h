// Writes a file so that it appears whole or not at all: data goes to `<path>.tmp-<pid>` and is
// renamed onto `path` by commit(). A writer that throws before commit() leaves nothing behind.
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
  bool committed_ = false;
};

}  // namespace plume::io
