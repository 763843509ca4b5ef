// libFuzzer target: a feather lifts file (`.lifts`, io/feather_lifts.h), read by io::read_feather_lifts().
// What it returns must be what the layering and skin passes may start from: one lift and scale per
// feather, ids unique, every value finite and within its range, the layering columns exactly when
// the file is layered (the yaw from version 3 on, the bend and where it starts in version 4).
#include <cmath>
#include <unordered_set>

#include "fuzz_common.h"
#include "io/feather_lifts.h"

namespace {

void check_lifts(const plume::io::FeatherLifts &lifts) {
  const float pi = 3.14159265f + 1e-5f;
  const size_t n = lifts.ids.size();
  bool valid = lifts.lifts.size() == n && lifts.scales.size() == n;
  if (lifts.layered)
    valid = valid && lifts.layer_turns.size() == n && lifts.layer_scales.size() == n &&
            (lifts.layer_yaws.empty() || lifts.layer_yaws.size() == n) &&
            lifts.layer_bends.size() == lifts.layer_bend_starts.size() &&
            (lifts.layer_bends.empty() || (lifts.layer_bends.size() == n && lifts.layer_yaws.size() == n));
  else
    valid = valid && lifts.layer_turns.empty() && lifts.layer_scales.empty() && lifts.layer_yaws.empty() &&
            lifts.layer_bends.empty() && lifts.layer_bend_starts.empty();
  std::unordered_set<uint64_t> ids(lifts.ids.begin(), lifts.ids.end());
  valid = valid && ids.size() == n;
  for (size_t i = 0; valid && i < n; ++i) {
    valid = lifts.lifts[i] >= 0.0f && lifts.lifts[i] <= pi && lifts.scales[i] >= 0.0f && lifts.scales[i] <= 1.0f;
    if (valid && lifts.layered)
      valid = lifts.layer_turns[i] >= 0.0f && lifts.layer_turns[i] <= pi && lifts.layer_scales[i] >= 0.0f &&
              lifts.layer_scales[i] <= 1.0f && (lifts.layer_yaws.empty() || std::abs(lifts.layer_yaws[i]) <= pi) &&
              (lifts.layer_bends.empty() || (std::abs(lifts.layer_bends[i]) <= pi && lifts.layer_bend_starts[i] >= 0.0f &&
                                             lifts.layer_bend_starts[i] <= 1.0f));
  }
  if (!valid) plume::fuzz::finding("read_feather_lifts returned lifts out of their invariants");
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  const std::string path = plume::fuzz::write_input(data, size, "input.lifts");
  plume::fuzz::only_input_errors([&] { check_lifts(plume::io::read_feather_lifts(path)); });
  return 0;
}
