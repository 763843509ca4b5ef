// The feathers' state of one frame (the skin pass's and, with layers, the layering pass's), in a text
// file beside the guide cache: `plume simulate` writes it for every frame, `plume regrow
// --guides-cache` reads the frame before the one it grows (the passes' warm starts), so a frame
// regrown alone is the frame of a sequential run.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace plume::io {

/// Per feather, by its stable id: the turn about its root the skin pass gave it (radians, in
/// [0, pi]) and its size (in [0, 1]); with `layered`, also the layering pass's turn on top of it
/// (radians, in [0, pi]), its size (in [0, 1]), its yaw (radians, in [-pi, pi], 0 unless turned
/// aside; empty when read from a file of version 2, which does not hold it) and its bend (radians at
/// the tip, in [-pi, pi], 0 unless bent) with where the bend starts (a fraction of the shaft, in
/// [0, 1]; both empty when read from a file of version 3 or 2).
struct FeatherLifts {
  int frame = 0;
  std::vector<uint64_t> ids;
  std::vector<float> lifts;
  std::vector<float> scales;
  bool layered = false;
  std::vector<float> layer_turns;  // empty unless layered
  std::vector<float> layer_scales;
  std::vector<float> layer_yaws;
  std::vector<float> layer_bends;
  std::vector<float> layer_bend_starts;
};

/// The file pattern beside a guide cache pattern: its name without the extension, then `.lifts`
/// (cache/guides.####.hair -> cache/guides.####.lifts).
std::string feather_lifts_pattern(const std::string &guide_cache_pattern);

/// Writes `lifts` atomically (io/atomic_file.h), every float exactly (9 significant digits):
///   plume feather lifts 4
///   frame 12
///   feathers 4980
///   layers 1                 (0: the three first columns only)
///   <id> <lift> <scale> <layer turn> <layer scale> <layer yaw> <layer bend> <layer bend start>
///                                                                    (one line per feather)
/// Throws InputError naming the file when it cannot be written.
void write_feather_lifts(const std::string &path, const FeatherLifts &lifts);

/// Reads a file write_feather_lifts() wrote, one of version 3 (with `layers 1`, six columns, no bend:
/// `layer_bends` and `layer_bend_starts` empty), one of version 2 (with `layers 1`, five columns, no
/// yaw: `layer_yaws` empty too) or one of version 1 (no `layers` line, the three first columns: `layered`
/// false). Throws InputError with file:line and the field for a missing file, a bad
/// header, frame, count or layers line, a malformed, non-finite or out-of-range value, a repeated id,
/// or a count of lines other than the one announced.
FeatherLifts read_feather_lifts(const std::string &path);

}  // namespace plume::io
