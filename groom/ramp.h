// A root-to-tip curve: a few (t, value) points, t in [0, 1] along the strand, linear between them.
#pragma once

#include <vector>

namespace plume {

struct Ramp {
  /// (t, value) pairs sorted by t; empty means a constant 1.
  std::vector<float> t;
  std::vector<float> value;

  /// Value at parameter u in [0, 1]; clamps outside the given points.
  float at(float u) const {
    if (t.empty()) return 1.0f;
    if (u <= t.front()) return value.front();
    if (u >= t.back()) return value.back();
    size_t i = 1;
    while (t[i] < u) ++i;
    const float span = t[i] - t[i - 1];
    const float a = span > 0.0f ? (u - t[i - 1]) / span : 1.0f;
    return value[i - 1] + a * (value[i] - value[i - 1]);
  }
  static Ramp linear(float root_value, float tip_value) { return Ramp{{0.0f, 1.0f}, {root_value, tip_value}}; }
};

}  // namespace plume
