#include "effects/noise.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "groom/roots.h"
#include "skin/lanes.h"

namespace plume::effects {

using namespace skin;

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
  for (int channel = 0; channel < 3; ++channel)
    for (int hash = 0; hash < 256; ++hash)
      gradient_of_[size_t(channel)][size_t(hash)] = uint8_t((channel == 0 ? hash : perm_[size_t(hash + 85 * channel)]) % 12);
  for (size_t k = 0; k < 512; ++k) {
    const size_t hash = perm_[k];
    corner_codes_[k] = int32_t(gradient_of_[0][hash]) | int32_t(gradient_of_[1][hash]) << 8 |
                       int32_t(gradient_of_[2][hash]) << 16;
  }
}

namespace {

// The lattice corners around a point, its offsets from them and their kernels, shared by every channel.
struct Simplex {
  float dx[4], dy[4], dz[4];  // offsets from the four corners
  float kernel[4];            // (0.5 - r^2)^4, 0 beyond the radius
  int hashes[4];              // 0..255, one per corner
};

inline void locate(const std::array<uint8_t, 512> &perm, const Eigen::Vector3f &pos, Simplex &r_simplex) {
  // Cell of the skewed lattice that holds the point, and the point's offset from its first corner.
  const float s = (pos.x() + pos.y() + pos.z()) * kSkew;
  const int i = floor_to_int(pos.x() + s);
  const int j = floor_to_int(pos.y() + s);
  const int k = floor_to_int(pos.z() + s);
  const float t = float(i + j + k) * kUnskew;
  const float x0 = pos.x() - (float(i) - t);
  const float y0 = pos.y() - (float(j) - t);
  const float z0 = pos.z() - (float(k) - t);

  // Which of the six tetrahedra of the cube, from the order of the offsets (without branches): the
  // second corner steps along the largest offset, the third along all but the smallest.
  const bool x_ge_y = x0 >= y0, y_ge_z = y0 >= z0, x_ge_z = x0 >= z0;
  const int i1 = x_ge_y & x_ge_z, j1 = !x_ge_y & y_ge_z, k1 = !(i1 | j1);
  const bool z_least = y_ge_z & x_ge_z, y_least = x_ge_y & !y_ge_z, x_least = !(z_least | y_least);
  const int i2 = !x_least, j2 = !y_least, k2 = !z_least;
  const int corner[4][3] = {{0, 0, 0}, {i1, j1, k1}, {i2, j2, k2}, {1, 1, 1}};
  const int ii = i & 255, jj = j & 255, kk = k & 255;
  for (int c = 0; c < 4; ++c) {
    const float dx = x0 - float(corner[c][0]) + float(c) * kUnskew;
    const float dy = y0 - float(corner[c][1]) + float(c) * kUnskew;
    const float dz = z0 - float(corner[c][2]) + float(c) * kUnskew;
    r_simplex.dx[c] = dx;
    r_simplex.dy[c] = dy;
    r_simplex.dz[c] = dz;
    const float falloff = std::max(0.5f - dx * dx - dy * dy - dz * dz, 0.0f);
    const float f2 = falloff * falloff;
    r_simplex.kernel[c] = f2 * f2;
    r_simplex.hashes[c] = perm[ii + corner[c][0] + perm[jj + corner[c][1] + perm[kk + corner[c][2]]]];
  }
}

// One channel: the sum over the corners of the kernel times the corner's linear ramp g . d, with the
// corner gradients picked by `gradient_of` from the corner hashes.
inline float channel_sum(const Simplex &simplex, const std::array<uint8_t, 256> &gradient_of) {
  float sum = 0.0f;
  for (int c = 0; c < 4; ++c) {
    const float *g = kGradients[gradient_of[size_t(simplex.hashes[c])]];
    sum += simplex.kernel[c] * (g[0] * simplex.dx[c] + g[1] * simplex.dy[c] + g[2] * simplex.dz[c]);
  }
  return kScale * sum;
}

}  // namespace

float SimplexNoise3::at(const Eigen::Vector3f &p) const {
  Simplex simplex;
  locate(perm_, p, simplex);
  return channel_sum(simplex, gradient_of_[0]);
}

Eigen::Vector3f SimplexNoise3::vector_at(const Eigen::Vector3f &p) const {
  // One lattice walk, three gradient sets (gradient_of_): the channels are independent fields at about
  // 40% of the cost of three.
  Simplex simplex;
  locate(perm_, p, simplex);
  return {channel_sum(simplex, gradient_of_[0]), channel_sum(simplex, gradient_of_[1]),
          channel_sum(simplex, gradient_of_[2])};
}

void SimplexNoise3::vector_at4(const Float4 p[3], Float4 r_channels[3]) const {
  // locate() and channel_sum() above, lane by lane: every float operation is the scalar one, in the
  // same order, so each lane gives vector_at's bits. Only the table lookups are done lane by lane.
  const Float4 px = p[0], py = p[1], pz = p[2];
  const Float4 s = (px + py + pz) * kSkew;
  // floor_to_int: truncate, then one less where that rounded up (a true comparison is -1).
  auto floor4 = [](Float4 v) {
    const Int4 truncated = __builtin_convertvector(v, Int4);
    return truncated + (v < __builtin_convertvector(truncated, Float4));
  };
  const Int4 i = floor4(px + s), j = floor4(py + s), k = floor4(pz + s);
  const Float4 t = __builtin_convertvector(i + j + k, Float4) * kUnskew;
  const Float4 x0 = px - (__builtin_convertvector(i, Float4) - t);
  const Float4 y0 = py - (__builtin_convertvector(j, Float4) - t);
  const Float4 z0 = pz - (__builtin_convertvector(k, Float4) - t);

  // Comparisons give -1 (true) or 0; & 1 makes the 0/1 corner steps.
  const Int4 x_ge_y = x0 >= y0, y_ge_z = y0 >= z0, x_ge_z = x0 >= z0;
  const Int4 i1 = x_ge_y & x_ge_z, j1 = ~x_ge_y & y_ge_z, k1 = ~(i1 | j1);
  const Int4 z_least = y_ge_z & x_ge_z, y_least = x_ge_y & ~y_ge_z, x_least = ~(z_least | y_least);
  const Int4 corner_x[4] = {Int4{}, i1 & 1, ~x_least & 1, Int4{} + 1};
  const Int4 corner_y[4] = {Int4{}, j1 & 1, ~y_least & 1, Int4{} + 1};
  const Int4 corner_z[4] = {Int4{}, k1 & 1, ~z_least & 1, Int4{} + 1};
  const Int4 ii = i & 255, jj = j & 255, kk = k & 255;

  // The corner hashes perm[ii + cx + perm[jj + cy + perm[kk + cz]]], with the last lookup folded
  // into corner_codes_. The corners step by 0 or 1 along z, so the first lookup takes two values
  // per lane, picked per corner; the lattice indices go through memory once, so the lookups read
  // plain ints instead of lanes one by one.
  alignas(16) int32_t z_index[4], below[4], above[4];
  std::memcpy(z_index, &kk, sizeof z_index);
  for (int l = 0; l < 4; ++l) {
    below[l] = perm_[size_t(z_index[l])];
    above[l] = perm_[size_t(z_index[l] + 1)];
  }
  Int4 z_below, z_above;
  std::memcpy(&z_below, below, sizeof z_below);
  std::memcpy(&z_above, above, sizeof z_above);
  Int4 codes[4];
  for (int c = 0; c < 4; ++c) {
    const Int4 y_index = jj + corner_y[c] + (corner_z[c] != 0 ? z_above : z_below);
    const Int4 x_index = ii + corner_x[c];
    alignas(16) int32_t ys[4], xs[4], code[4];
    std::memcpy(ys, &y_index, sizeof ys);
    std::memcpy(xs, &x_index, sizeof xs);
    for (int l = 0; l < 4; ++l) code[l] = corner_codes_[size_t(xs[l] + perm_[size_t(ys[l])])];
    std::memcpy(&codes[c], code, sizeof code);
  }

  Float4 sum[3] = {Float4{}, Float4{}, Float4{}};
  for (int c = 0; c < 4; ++c) {
    const Float4 dx = x0 - __builtin_convertvector(corner_x[c], Float4) + float(c) * kUnskew;
    const Float4 dy = y0 - __builtin_convertvector(corner_y[c], Float4) + float(c) * kUnskew;
    const Float4 dz = z0 - __builtin_convertvector(corner_z[c], Float4) + float(c) * kUnskew;
    const Float4 reach = 0.5f - dx * dx - dy * dy - dz * dz;
    const Float4 falloff = reach < 0.0f ? Float4{} : reach;
    const Float4 f2 = falloff * falloff;
    const Float4 kernel = f2 * f2;
    for (int channel = 0; channel < 3; ++channel) {
      // g . d for the twelve gradients (kGradients): index h < 4 is (+-1, +-1, 0), h < 8 is
      // (+-1, 0, +-1), else (0, +-1, +-1); bit 0 of h negates the first non-zero component, bit 1
      // the second. The same value as the dot product, without reading the gradient.
      const Int4 h = (codes[c] >> (8 * channel)) & 255;
      const Float4 first_term = h < 8 ? dx : dy, second_term = h < 4 ? dy : dz;
      const Float4 signed_first = (Float4)((Int4)first_term ^ ((h & 1) << 31));
      const Float4 signed_second = (Float4)((Int4)second_term ^ ((h & 2) << 30));
      sum[channel] += kernel * (signed_first + signed_second);
    }
  }
  for (int channel = 0; channel < 3; ++channel) r_channels[channel] = kScale * sum[channel];
}

}  // namespace plume::effects
