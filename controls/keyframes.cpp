#include "controls/keyframes.h"

#include <algorithm>
#include <cmath>

#include "groom/error.h"

namespace plume::controls {

namespace {

// Fritsch and Butland (1984), as in PCHIP: with h the key spacings and s the secant slopes around
// key k,  m_k = 3 (h0 + h1) / ((2 h1 + h0) / s0 + (h1 + 2 h0) / s1)  when s0 s1 > 0, else 0. A
// weighted harmonic mean of the secants: |m_k| <= 3 min(|s0|, |s1|), which keeps each cubic
// segment monotone (Fritsch and Carlson's condition).
double tangent(double h0, double s0, double h1, double s1) {
  if (!(s0 * s1 > 0.0)) return 0.0;
  return 3.0 * (h0 + h1) / ((2.0 * h1 + h0) / s0 + (h1 + 2.0 * h0) / s1);
}

// Evaluates component `c` of the keys (get(k) gives key k's value) at `frame`.
template <class Get>
double evaluate(const std::vector<double> &frames, KeyInterpolation interpolation, Get get, double frame) {
  const size_t n = frames.size();
  if (n == 0) throw InternalError("controls: a keyed value without keys");
  if (!(frame > frames.front())) return get(0);
  if (!(frame < frames.back())) return get(n - 1);
  // The segment [k, k + 1] holding the frame.
  const size_t k = size_t(std::upper_bound(frames.begin(), frames.end(), frame) - frames.begin()) - 1;
  const double h = frames[k + 1] - frames[k];
  const double t = (frame - frames[k]) / h;
  const double y0 = get(k), y1 = get(k + 1);
  if (interpolation == KeyInterpolation::linear) return y0 + t * (y1 - y0);
  const double s = (y1 - y0) / h;
  const double m0 =
      k == 0 ? 0.0 : tangent(frames[k] - frames[k - 1], (y0 - get(k - 1)) / (frames[k] - frames[k - 1]), h, s);
  const double m1 =
      k + 2 == n ? 0.0
                 : tangent(h, s, frames[k + 2] - frames[k + 1], (get(k + 2) - y1) / (frames[k + 2] - frames[k + 1]));
  // Cubic Hermite basis.
  const double t2 = t * t, t3 = t2 * t;
  const double h00 = 2.0 * t3 - 3.0 * t2 + 1.0, h10 = t3 - 2.0 * t2 + t, h01 = -2.0 * t3 + 3.0 * t2, h11 = t3 - t2;
  const double y = h00 * y0 + h10 * h * m0 + h01 * y1 + h11 * h * m1;
  // Rounding only: the segment lies between its end values.
  return std::clamp(y, std::min(y0, y1), std::max(y0, y1));
}

}  // namespace

float value_at(const Keyed<float> &keyed, double frame) {
  return float(evaluate(
      keyed.frames, keyed.interpolation, [&](size_t k) { return double(keyed.values[k]); }, frame));
}

Eigen::Vector3f value_at(const Keyed<Eigen::Vector3f> &keyed, double frame) {
  Eigen::Vector3f v;
  for (int c = 0; c < 3; ++c)
    v[c] = float(evaluate(
        keyed.frames, keyed.interpolation, [&](size_t k) { return double(keyed.values[k][c]); }, frame));
  return v;
}

}  // namespace plume::controls
