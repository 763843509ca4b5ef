// The feathers' skin pass state of one frame, in a text file beside the guide cache: `plume
// simulate` writes it for every frame, `plume regrow --guides-cache` reads the frame before the one
// it grows (the skin pass's warm start), so a frame regrown alone is the frame of a sequential run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plume::io {

/// Per feather, by its stable id: the turn about its root the skin pass gave it (radians, in
/// [0, pi]) and its size (in [0, 1]).
struct FeatherLifts {
  int frame = 0;
  std::vector<uint64_t> ids;
  std::vector<float> lifts;
  std::vector<float> scales;
};

/// The file pattern beside a guide cache pattern: its name without the extension, then `.lifts`
/// (cache/guides.####.hair -> cache/guides.####.lifts).
std::string feather_lifts_pattern(const std::string &guide_cache_pattern);

/// Writes `lifts` atomically (io/atomic_file.h), every float exactly (9 significant digits):
///   plume feather lifts 1
///   frame 12
///   feathers 4980
///   <id> <lift> <scale>      (one line per feather)
/// Throws InputError naming the file when it cannot be written.
void write_feather_lifts(const std::string &path, const FeatherLifts &lifts);

/// Reads a file write_feather_lifts() wrote. Throws InputError with file:line and the field for a
/// missing file, a bad header, frame or count, a malformed, non-finite or out-of-range value, a
/// repeated id, or a count of lines other than the one announced.
FeatherLifts read_feather_lifts(const std::string &path);

}  // namespace plume::io
