// Seeded 3D simplex noise for waviness and frizz: smooth, cheap (4 corners per sample), and the same
// bits on every machine (only float add/multiply and floor; no transcendental functions).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>

#include "skin/lanes.h"

namespace plume::effects {

using skin::Float4;

/// Simplex noise in 3D (Perlin 2001, in Gustavson's formulation) over a lattice of unit spacing,
/// with a permutation shuffled from `seed` (so two seeds give unrelated fields). Periodic with
/// period 256 along each axis. Values lie in [-1, 1]; the field is C1 (kernel radius^2 = 0.5, so
/// each corner's contribution and its gradient vanish before the next simplex).
class SimplexNoise3 {
 public:
  explicit SimplexNoise3(uint64_t seed);

  /// One channel at `p` (lattice units: about one bump per unit).
  float at(const Eigen::Vector3f &p) const;
  /// Three independent channels (same lattice, unrelated gradients), each in [-1, 1].
  Eigen::Vector3f vector_at(const Eigen::Vector3f &p) const;
  /// vector_at at four points at once, in SIMD lanes: point l is (p[0][l], p[1][l], p[2][l]) and its
  /// channel c goes to r_channels[c][l]. The same operations in the same order, so the same bits as
  /// vector_at.
  void vector_at4(const Float4 p[3], Float4 r_channels[3]) const;

 private:
  std::array<uint8_t, 512> perm_;  // a shuffle of 0..255, stored twice to skip a wrap
  /// Per channel, the gradient index (0..11) of a corner hash: channel 0 reads hash % 12, channel c
  /// reads perm[hash + 85 c] % 12 (unrelated gradients from the same lattice walk).
  std::array<std::array<uint8_t, 256>, 3> gradient_of_;
  /// Per index k < 512 of the last lattice lookup (k = i + perm[...]), the three channels' gradient
  /// indices of the corner hash perm[k] in one word (byte c for channel c): what vector_at4 gathers.
  std::array<int32_t, 512> corner_codes_;
};

}  // namespace plume::effects
