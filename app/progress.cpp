#include "app/progress.h"

#include <sys/ioctl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>

namespace plume {

namespace {

/// The columns the line may take: one less than the terminal's width (a character in the last
/// column makes some terminals wrap), at most 79, so that it fits an 80-column terminal.
int line_columns() {
  struct winsize size = {};
  const int width = ioctl(STDERR_FILENO, TIOCGWINSZ, &size) == 0 && size.ws_col > 0 ? int(size.ws_col) : 80;
  return std::clamp(width, 20, 80) - 1;
}

/// "1:02:03" or "02:03".
std::string duration_text(double seconds) {
  const long total = long(std::max(seconds, 0.0) + 0.5);
  char text[32];
  if (total >= 3600)
    std::snprintf(text, sizeof text, "%ld:%02ld:%02ld", total / 3600, total / 60 % 60, total % 60);
  else
    std::snprintf(text, sizeof text, "%02ld:%02ld", total / 60, total % 60);
  return text;
}

}  // namespace

Progress::Progress(std::string label, int total)
    : label_(std::move(label)), total_(std::max(total, 1)), enabled_(isatty(STDERR_FILENO) == 1),
      start_(std::chrono::steady_clock::now()) {}

Progress::~Progress() { finish(); }

void Progress::finish() {
  if (enabled_ && done_ > 0 && !finished_) std::fputs("\n", stderr);
  finished_ = true;
}

void Progress::frame_done(int frame) {
  ++done_;
  if (!enabled_) return;
  const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  const double rate = elapsed > 0.0 ? done_ / elapsed : 0.0;
  const double eta = rate > 0.0 ? (total_ - done_) / rate : 0.0;
  // "regrow [#####.....] 12/48 frames (frame 12) 2.41 frames/s ETA 00:15": the bar takes what the
  // figures leave (none below 5 columns); a narrow terminal loses the frame number, then words.
  const int columns = line_columns();
  const std::string time_left = duration_text(eta);
  // snprintf rather than string sums, which g++ 12 warns about (a false -Wrestrict) at -O3.
  char forms[3][160];
  std::snprintf(forms[0], sizeof forms[0], " %d/%d frames (frame %d) %.3g frames/s ETA %s", done_, total_, frame, rate,
                time_left.c_str());
  std::snprintf(forms[1], sizeof forms[1], " %d/%d frames %.3g frames/s ETA %s", done_, total_, rate, time_left.c_str());
  std::snprintf(forms[2], sizeof forms[2], " %d/%d %.3g/s ETA %s", done_, total_, rate, time_left.c_str());
  std::string line;
  for (const char *figures : forms) {
    line = label_ + figures;
    if (int(line.size()) <= columns) break;
  }
  const int bar_width = std::min(30, columns - int(line.size()) - 3);
  if (bar_width >= 5) {
    std::string bar(size_t(done_) * size_t(bar_width) / size_t(total_), '#');
    bar.resize(size_t(bar_width), '.');
    std::string with_bar = label_;
    with_bar += " [";
    with_bar += bar;
    with_bar += "]";
    with_bar += line.substr(label_.size());
    line = std::move(with_bar);
  }
  line.resize(std::min(line.size(), size_t(columns)));
  // Blanks over what a longer previous line left.
  const size_t shown = line.size();
  if (shown < width_) line.append(width_ - shown, ' ');
  width_ = shown;
  std::fprintf(stderr, "\r%s", line.c_str());
  std::fflush(stderr);
}

}  // namespace plume
