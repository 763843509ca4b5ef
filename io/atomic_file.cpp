#include "io/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "groom/error.h"

namespace plume::io {

namespace fs = std::filesystem;

AtomicFile::AtomicFile(const std::string &path)
    : path_(path), temp_path_(path + ".tmp-" + std::to_string(long(::getpid()))) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code error;
    fs::create_directories(parent, error);
    if (error) throw InputError(FileLoc{path}, "cannot create directory " + parent.string() + ": " + error.message());
  }
  stream_.open(temp_path_, std::ios::binary | std::ios::trunc);
  if (!stream_) throw InputError(FileLoc{path}, std::string("cannot create file: ") + std::strerror(errno));
}

AtomicFile::~AtomicFile() {
  if (committed_) return;
  stream_.close();
  std::error_code ignored;
  fs::remove(temp_path_, ignored);
}

void AtomicFile::write(const void *data, size_t byte_count) {
  stream_.write(static_cast<const char *>(data), std::streamsize(byte_count));
}

void AtomicFile::commit() {
  stream_.flush();
  if (!stream_) throw InputError(FileLoc{path_}, "write failed (disk full or no permission?)");
  stream_.close();
  if (stream_.fail()) throw InputError(FileLoc{path_}, "closing the file failed");
  std::error_code error;
  fs::rename(temp_path_, path_, error);
  if (error) throw InputError(FileLoc{path_}, "cannot rename " + temp_path_ + " onto it: " + error.message());
  committed_ = true;
}

}  // namespace plume::io
