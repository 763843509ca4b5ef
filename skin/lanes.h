// Four-lane float and int vectors (GCC vector extensions: SSE2 on x86-64, the target's own SIMD
// elsewhere), eight-lane ones where the build targets AVX (one register), and the few lane-wise
// functions the stages need (growth, effects, skin queries). Code written once for W lanes reads Lanes<W>.
#pragma once

#include <cmath>
#include <cstdint>
#ifdef __SSE2__
#include <emmintrin.h>
#endif
#ifdef __AVX__
#include <immintrin.h>
#endif

namespace plume::skin {

typedef float Float4 __attribute__((vector_size(16)));
typedef int32_t Int4 __attribute__((vector_size(16)));

/// The float and int vectors of W lanes.
template <int W>
struct Lanes;
template <>
struct Lanes<4> {
  using Float = Float4;
  using Int = Int4;
};

/// Lanes 4q .. 4q + 3 (here all four).
inline Float4 lane_quad(Float4 v, int) { return v; }
inline Int4 lane_quad(Int4 v, int) { return v; }
/// Four lanes repeated to fill W.
template <int W>
typename Lanes<W>::Float repeat_lanes(Float4 v);
template <int W>
typename Lanes<W>::Int repeat_lanes(Int4 v);
template <>
inline Float4 repeat_lanes<4>(Float4 v) {
  return v;
}
template <>
inline Int4 repeat_lanes<4>(Int4 v) {
  return v;
}

/// Square root of each lane (correctly rounded, as std::sqrt).
inline Float4 lane_sqrt(Float4 v) {
#ifdef __SSE2__
  return _mm_sqrt_ps(v);
#else
  for (int l = 0; l < 4; ++l) v[l] = std::sqrt(v[l]);
  return v;
#endif
}

/// The lanes of a comparison (-1 true, 0 false) as bits: bit l set when lane l is true.
inline int lane_bits(Int4 mask) {
#ifdef __SSE2__
  return _mm_movemask_ps(_mm_castsi128_ps(__m128i(mask)));
#else
  return (mask[0] & 1) | (mask[1] & 2) | (mask[2] & 4) | (mask[3] & 8);
#endif
}

/// Whether any lane of a comparison is true.
inline bool any(Int4 mask) { return lane_bits(mask) != 0; }

#ifdef __AVX__
// Eight lanes: only where they are one register. Without AVX, GCC splits them through memory,
// slower than four lanes.
typedef float Float8 __attribute__((vector_size(32)));
typedef int32_t Int8 __attribute__((vector_size(32)));
template <>
struct Lanes<8> {
  using Float = Float8;
  using Int = Int8;
};
inline Float4 lane_quad(Float8 v, int q) {
  return q == 0 ? __builtin_shufflevector(v, v, 0, 1, 2, 3) : __builtin_shufflevector(v, v, 4, 5, 6, 7);
}
inline Int4 lane_quad(Int8 v, int q) {
  return q == 0 ? __builtin_shufflevector(v, v, 0, 1, 2, 3) : __builtin_shufflevector(v, v, 4, 5, 6, 7);
}
/// The eight lanes of two four-lane vectors.
inline Float8 join(Float4 low, Float4 high) { return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7); }
inline Int8 join(Int4 low, Int4 high) { return __builtin_shufflevector(low, high, 0, 1, 2, 3, 4, 5, 6, 7); }
template <>
inline Float8 repeat_lanes<8>(Float4 v) {
  return join(v, v);
}
template <>
inline Int8 repeat_lanes<8>(Int4 v) {
  return join(v, v);
}
inline Float8 lane_sqrt(Float8 v) { return _mm256_sqrt_ps(v); }
inline int lane_bits(Int8 mask) { return _mm256_movemask_ps(_mm256_castsi256_ps(__m256i(mask))); }
inline bool any(Int8 mask) { return lane_bits(mask) != 0; }
#endif

/// Lane-wise dot product of two 3-vectors given by components (u[c] holds component c of every
/// lane), added x + (y + z) as Eigen's dot products and norms are, so that a lane gives Eigen's bits.
template <class Float>
inline Float dot_lanes(const Float u[3], const Float v[3]) {
  return u[0] * v[0] + (u[1] * v[1] + u[2] * v[2]);
}

/// Lane-wise unit vector of a 3-vector given by components: r = v / |v| (|v| as dot_lanes, one
/// division, then products: the bits of unit_or in interp/grow.cpp), or `fallback` where |v| is
/// 1e-20 or less. r may be v.
template <class Float>
inline void unit_lanes(const Float v[3], const Float fallback[3], Float r[3]) {
  const Float norm = lane_sqrt(dot_lanes(v, v));
  const Float inverse_norm = 1.0f / norm;
  for (int c = 0; c < 3; ++c) r[c] = norm > 1e-20f ? v[c] * inverse_norm : fallback[c];
}

/// The vector of W lanes whose lane l is value(l).
template <int W, class Value>
[[gnu::always_inline]] inline typename Lanes<W>::Float lanes_of(Value &&value) {
  if constexpr (W == 4)
    return typename Lanes<W>::Float{value(0), value(1), value(2), value(3)};
  else
    return typename Lanes<W>::Float{value(0), value(1), value(2), value(3), value(4), value(5), value(6), value(7)};
}

/// The 4 x 4 transpose: r[c][l] = rows[l][c] (four records of four floats turned into lanes).
inline void transpose4(const Float4 rows[4], Float4 r[4]) {
  const Float4 low01 = __builtin_shufflevector(rows[0], rows[1], 0, 4, 1, 5);
  const Float4 low23 = __builtin_shufflevector(rows[2], rows[3], 0, 4, 1, 5);
  const Float4 high01 = __builtin_shufflevector(rows[0], rows[1], 2, 6, 3, 7);
  const Float4 high23 = __builtin_shufflevector(rows[2], rows[3], 2, 6, 3, 7);
  r[0] = __builtin_shufflevector(low01, low23, 0, 1, 4, 5);
  r[1] = __builtin_shufflevector(low01, low23, 2, 3, 6, 7);
  r[2] = __builtin_shufflevector(high01, high23, 0, 1, 4, 5);
  r[3] = __builtin_shufflevector(high01, high23, 2, 3, 6, 7);
}

/// Sine and cosine of four angles (radians) with only adds, multiplies and one conversion: the same
/// bits on every machine, unlike the C library's, whose code differs with the processor. The angle
/// is reduced by the nearest multiple of pi/2 (pi/2 split in three parts, exact products for
/// |x| < 2^15), then minimax polynomials on [-pi/4, pi/4] (Cephes sinf/cosf) give an absolute
/// error below 2e-7 for |x| < 1e4 (tested).
inline void sin_cos4(Float4 x, Float4 &r_sin, Float4 &r_cos) {
  constexpr float kTwoOverPi = 0.636619772367581343f;
  constexpr float kHalfPi1 = 1.5703125f, kHalfPi2 = 4.837512969970703125e-4f, kHalfPi3 = 7.54978995489188216e-8f;
  // Nearest integer by adding and subtracting a half toward the sign, then truncating.
  const Float4 scaled = x * kTwoOverPi;
  const Int4 quadrant = __builtin_convertvector(scaled + (scaled < 0.0f ? Float4{} - 0.5f : Float4{} + 0.5f), Int4);
  const Float4 q = __builtin_convertvector(quadrant, Float4);
  const Float4 r = ((x - q * kHalfPi1) - q * kHalfPi2) - q * kHalfPi3;
  const Float4 z = r * r;
  const Float4 sin_r = ((-1.9515295891e-4f * z + 8.3321608736e-3f) * z - 1.6666654611e-1f) * z * r + r;
  const Float4 cos_r = ((2.443315711809948e-5f * z - 1.388731625493765e-3f) * z + 4.166664568298827e-2f) * z * z -
                       0.5f * z + 1.0f;
  // Quadrant k: sin x = (sin r, cos r, -sin r, -cos r)[k], cos x = (cos r, -sin r, -cos r, sin r)[k].
  const Int4 k = quadrant & 3;
  const Int4 swap = (k & 1) != 0;
  const Float4 s = swap ? cos_r : sin_r, c = swap ? sin_r : cos_r;
  r_sin = k >= 2 ? -s : s;
  r_cos = (k == 1) | (k == 2) ? -c : c;
}

/// Natural logarithm of four positive, finite, normal numbers with only exact bit operations,
/// adds and multiplies (the same bits on every machine): x = m 2^e with m in [sqrt(1/2), sqrt(2)),
/// then Cephes' logf polynomial in m - 1. Relative error below 1e-7 (tested).
inline Float4 log4(Float4 x) {
  const Int4 bits = (Int4)x;
  // Exponent and mantissa in [1, 2); a mantissa above sqrt(2) is halved (and the exponent raised).
  Int4 exponent = ((bits >> 23) & 255) - 127;
  Float4 m = (Float4)((bits & 0x007fffff) | 0x3f800000);
  const Int4 high = m > 1.41421356f;
  m = high ? m * 0.5f : m;
  exponent -= high;  // a true comparison is -1
  const Float4 e = __builtin_convertvector(exponent, Float4);
  const Float4 f = m - 1.0f;
  const Float4 z = f * f;
  Float4 y = 7.0376836292e-2f * f - 1.1514610310e-1f;
  y = y * f + 1.1676998740e-1f;
  y = y * f - 1.2420140846e-1f;
  y = y * f + 1.4249322787e-1f;
  y = y * f - 1.6668057665e-1f;
  y = y * f + 2.0000714765e-1f;
  y = y * f - 2.4999993993e-1f;
  y = y * f + 3.3333331174e-1f;
  y = y * f * z;
  y += e * -2.12194440e-4f;
  y += -0.5f * z;
  return f + y + e * 0.693359375f;
}

}  // namespace plume::skin
