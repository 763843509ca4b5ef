// A progress line on stderr (frames done, frames per second, time left), shown only when stderr
// is a terminal so that logs and farm job output stay clean.
#pragma once

#include <chrono>
#include <string>

namespace plume {

class Progress {
 public:
  /// `label` prefixes the line ("regrow", "simulate"); `total` is the number of frames.
  Progress(std::string label, int total);
  /// Clears the line when it was shown.
  ~Progress();
  Progress(const Progress &) = delete;
  Progress &operator=(const Progress &) = delete;

  /// Marks one more frame done and redraws.
  void frame_done(int frame);
  bool shown() const { return enabled_; }

 private:
  std::string label_;
  int total_;
  int done_ = 0;
  bool enabled_;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace plume
