// Frame ranges ("1-48", "1-240:2", "1-240x2", "7") and per-frame path patterns ("hair.####.usda",
// "hair.%04d.usda", "hair.$F4.usda") for the `plume` command.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace plume {

/// The largest frame number, and step, a range may hold: nine digits, as a groom file's
/// output.frames allows. Frames lie in [-kMaxFrame, kMaxFrame], so first + step never overflows an int.
inline constexpr int kMaxFrame = 999999999;

/// The most frames one run writes, and the most it simulates beyond a groom's largest
/// dynamics.preroll (100,000): over an hour at 24 fps. Every frame's output location is checked
/// before the first is written, so a billion-frame range would spend hours in checks alone; longer
/// shots are run in chunks (--frames), each a farm task.
inline constexpr int64_t kMaxFramesPerRun = 100000;

/// Frames first..last (inclusive) every `step`; first <= last, step >= 1, all within +-kMaxFrame.
/// A range may hold up to 2e9 frames: walk it by index (at()) rather than listing it.
struct FrameRange {
  int first = 1;
  int last = 1;
  int step = 1;

  /// How many frames: first, first + step, ... up to last.
  int64_t count() const { return (int64_t(last) - first) / step + 1; }
  /// The i-th frame, i in [0, count()).
  int at(int64_t i) const { return int(first + i * step); }
};

/// Parses "A", "A-B", "A-B:S" or "A-BxS" (A, B may be negative: "-5-10"; the x form is Nuke's and
/// Deadline's). Throws InputError naming `what` (e.g. "--frames") and the accepted forms for
/// anything else ("1:240", whose meaning differs between tools, included), for B < A, for S < 1
/// and for a number beyond kMaxFrame.
FrameRange parse_frame_range(const std::string &text, const std::string &what);

/// Throws InputError naming `what` when `range` holds more than kMaxFramesPerRun frames.
void check_frames_per_run(const FrameRange &range, const std::string &what);

/// The widest frame field: a run of 255 '#' or %0255d, the longest file name Linux file systems
/// allow. A wider field could name no file.
inline constexpr int kMaxFramePadding = 255;

/// True when `pattern` holds a frame field: a run of '#', a printf field %d / %0Nd, or Houdini's
/// $F / $FN (not followed by a letter or '_': $FF and $Foo are other variables, kept as text).
bool has_frame_field(const std::string &pattern);

/// Replaces the frame field of `pattern` with `frame`, zero-padded to the number of '#' (or N of
/// %0Nd or $FN), whatever the width (the sign counts in it, as in printf). A pattern without a field is
/// returned as is. Throws InputError for two fields, a malformed %-field or one wider than
/// kMaxFramePadding.
std::string expand_frame_pattern(const std::string &pattern, int frame);

/// The frame whose expansion of `pattern` has the file name of `path` (folders are not compared),
/// or none: a file name that does not fit the pattern, or a pattern whose frame field is in a
/// folder name. The caller compares the expanded path with `path` itself (a number with other
/// padding fits the name but not the expansion).
std::optional<int> frame_in_file_name(const std::string &pattern, const std::string &path);

/// Throws InputError naming `what` (the option or groom key) when a frame field of `pattern` is
/// malformed (%x, %ld, two fields).
void check_frame_syntax(const std::string &pattern, const std::string &what);

/// Throws InputError naming `what` (the option or groom key) unless `pattern` can name every frame
/// of `range`: no NUL character (a file name would end there), a frame field when there is more
/// than one frame, no malformed field.
void check_frame_pattern(const std::string &pattern, const FrameRange &range, const std::string &what);

/// Removes the temporary files that runs killed by SIGKILL left for `pattern`'s files, of any frame,
/// in the folders the frames of `range` go to (io::remove_stale_temp_files(): only names
/// `<a file of the pattern>.tmp-<pid>`, only when process `<pid>` is gone and no writer holds the
/// file). An empty pattern has none. Returns the paths removed.
std::vector<std::string> remove_stale_temp_files(const std::string &pattern, const FrameRange &range);

}  // namespace plume
