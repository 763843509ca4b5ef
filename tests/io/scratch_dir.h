// A fresh temporary directory per test, removed when the test ends.
#pragma once

#include <unistd.h>

#include <filesystem>
#include <string>

namespace plume::test {

class ScratchDir {
 public:
  explicit ScratchDir(const std::string &name)
      : path_(std::filesystem::temp_directory_path() / ("plume_" + name + "_" + std::to_string(long(::getpid())))) {
    std::filesystem::remove_all(path_);
    std::filesystem::create_directories(path_);
  }
  ~ScratchDir() {
    std::error_code ignored;
    std::filesystem::remove_all(path_, ignored);
  }
  std::string file(const std::string &name) const { return (path_ / name).string(); }
  const std::filesystem::path &path() const { return path_; }

 private:
  std::filesystem::path path_;
};

}  // namespace plume::test
