// A progress line on stderr (frames done, frames per second, time left), shown only when stderr
// is a terminal so that logs and farm job output stay clean. The line fits the terminal, at most
// 79 columns (an 80-column terminal).
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
  /// Ends the line when it was shown, so that what follows starts on a line of its own.
  void finish();
  bool shown() const { return enabled_; }

 private:
  std::string label_;
  int total_;
  int done_ = 0;
  size_t width_ = 0;  // characters of the line last drawn
  bool enabled_;
  bool finished_ = false;
  std::chrono::steady_clock::time_point start_;
};

}  // namespace plume
