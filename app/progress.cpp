#include "app/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace plume {

Progress::Progress(std::string label, int total)
    : label_(std::move(label)), total_(std::max(total, 1)), enabled_(isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() {
  if (enabled_ && done_ > 0) std::fputs("\n", stderr);
}

void Progress::frame_done(int frame) {
  ++done_;
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0.0 ? done_ / elapsed : 0.0;
  const double eta = rate > 0.0 ? (total_ - done_) / rate : 0.0;
  constexpr int width = 30;
  const int filled = done_ * width / total_;
  std::string bar(size_t(filled), '#');
  bar.resize(width, '.');
  std::fprintf(stderr, "\r%s [%s] %d/%d frames (frame %d)  %.2f frames/s  ETA %02d:%02d ", label_.c_str(),
               bar.c_str(), done_, total_, frame, rate, int(eta) / 60, int(eta) % 60);
  std::fflush(stderr);
}

}  // namespace plume
