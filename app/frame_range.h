// Frame ranges ("1-48", "1-240:2", "7") and per-frame path patterns ("hair.####.usda",
// "hair.%04d.usda") for the `plume` command.
#pragma once

#include <string>
#include <vector>

namespace plume {

/// Frames first..last (inclusive) every `step`; first <= last, step >= 1.
struct FrameRange {
  int first = 1;
  int last = 1;
  int step = 1;

  /// The frames in order: first, first + step, ... up to last.
  std::vector<int> frames() const;
  int count() const { return (last - first) / step + 1; }
};

/// Parses "A", "A-B" or "A-B:S" (A, B may be negative: "-5-10"). Throws InputError naming `what`
/// (e.g. "--frames") for anything else, for B < A and for S < 1.
FrameRange parse_frame_range(const std::string &text, const std::string &what);

/// True when `pattern` holds a frame field: a run of '#' or a printf field %d / %0Nd.
bool has_frame_field(const std::string &pattern);

/// Replaces the frame field of `pattern` with `frame`, zero-padded to the number of '#' (or N of
/// %0Nd). A pattern without a field is returned as is. Throws InputError for two fields or a
/// malformed %-field.
std::string expand_frame_pattern(const std::string &pattern, int frame);

}  // namespace plume
