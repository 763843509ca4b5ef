#include "interp/noise.h"

#include <cmath>

#include "groom/roots.h"

namespace plume::interp {

namespace {

// The 12 edge midpoints of the cube: gradient directions with no axis bias (Perlin 2002).
constexpr float kGradients[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                     {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};

// Skewing to the simplex lattice and back, for n = 3: F = (sqrt(n+1)-1)/n, G = (1-1/sqrt(n+1))/n.
constexpr float kSkew = 1.0f / 3.0f;
constexpr float kUnskew = 1.0f / 6.0f;

// With a kernel (0.5 - r^2)^4, a single corner peaks at 0.5^4 * |g.d| with |d|^2 <= 0.5 and |g| = sqrt 2;
// this factor brings the sum of the four corners to [-1, 1] (measured maximum 0.975 over 10^7 random samples, RMS 0.38).
constexpr float kScale = 75.0f;

inline int floor_to_int(float x) {
  const int i = int(x);
  return x < float(i) ? i - 1 : i;
}

}  // namespace

SimplexNoise3::SimplexNoise3(uint64_t seed) {
  std::array<uint8_t, 256> p;
  for (int i = 0; i < 256; ++i) p[i] = uint8_t(i);
  // Fisher-Yates shuffle driven by the shared hash, so the table depends on the seed alone.
  for (int i = 255; i > 0; --i) {
    const int j = int(hash_combine(seed, uint64_t(i)) % uint64_t(i + 1));
    std::swap(p[i], p[j]);
  }
  for (int i = 0; i < 512; ++i) perm_[i] = p[i & 255];
}

float SimplexNoise3::at(const Eigen::Vector3f &pos) const {
  // Cell of the skewed lattice that holds the point, and the point's offset from its first corner.
  const float s = (pos.x() + pos.y() + pos.z()) * kSkew;
  const int i = floor_to_int(pos.x() + s);
  const int j = floor_to_int(pos.y() + s);
  const int k = floor_to_int(pos.z() + s);
  const float t = float(i + j + k) * kUnskew;
  const float x0 = pos.x() - (float(i) - t);
  const float y0 = pos.y() - (float(j) - t);
  const float z0 = pos.z() - (float(k) - t);

  // Which of the six tetrahedra of the cube: order the offsets.
  int i1, j1, k1, i2, j2, k2;
  if (x0 >= y0) {
    if (y0 >= z0) { i1 = 1; j1 = 0; k1 = 0; i2 = 1; j2 = 1; k2 = 0; }
    else if (x0 >= z0) { i1 = 1; j1 = 0; k1 = 0; i2 = 1; j2 = 0; k2 = 1; }
    else { i1 = 0; j1 = 0; k1 = 1; i2 = 1; j2 = 0; k2 = 1; }
  } else {
    if (y0 < z0) { i1 = 0; j1 = 0; k1 = 1; i2 = 0; j2 = 1; k2 = 1; }
    else if (x0 < z0) { i1 = 0; j1 = 1; k1 = 0; i2 = 0; j2 = 1; k2 = 1; }
    else { i1 = 0; j1 = 1; k1 = 0; i2 = 1; j2 = 1; k2 = 0; }
  }
  const float offsets[4][3] = {{x0, y0, z0},
                               {x0 - float(i1) + kUnskew, y0 - float(j1) + kUnskew, z0 - float(k1) + kUnskew},
                               {x0 - float(i2) + 2 * kUnskew, y0 - float(j2) + 2 * kUnskew, z0 - float(k2) + 2 * kUnskew},
                               {x0 - 1 + 3 * kUnskew, y0 - 1 + 3 * kUnskew, z0 - 1 + 3 * kUnskew}};
  const int ii = i & 255, jj = j & 255, kk = k & 255;
  const int corner_gradient[4] = {
      perm_[ii + perm_[jj + perm_[kk]]] % 12,
      perm_[ii + i1 + perm_[jj + j1 + perm_[kk + k1]]] % 12,
      perm_[ii + i2 + perm_[jj + j2 + perm_[kk + k2]]] % 12,
      perm_[ii + 1 + perm_[jj + 1 + perm_[kk + 1]]] % 12,
  };

  // Sum of radial kernels (0.5 - r^2)^4 times the corner's linear ramp g . d.
  float sum = 0.0f;
  for (int c = 0; c < 4; ++c) {
    const float *d = offsets[c];
    const float falloff = 0.5f - d[0] * d[0] - d[1] * d[1] - d[2] * d[2];
    if (falloff <= 0.0f) continue;
    const float *g = kGradients[corner_gradient[c]];
    const float f2 = falloff * falloff;
    sum += f2 * f2 * (g[0] * d[0] + g[1] * d[1] + g[2] * d[2]);
  }
  return kScale * sum;
}

Eigen::Vector3f SimplexNoise3::vector_at(const Eigen::Vector3f &p) const {
  // Offsets a third of the period apart along a diagonal: far enough that the channels are unrelated.
  return {at(p), at(p + Eigen::Vector3f(85.3f, 17.9f, 41.1f)), at(p + Eigen::Vector3f(170.7f, 128.3f, 213.9f))};
}

}  // namespace plume::interp
