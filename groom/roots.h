// Root placement: area-weighted scattering with stable ids, or roots snapped from a point list.
#pragma once

#include <cstdint>
#include <vector>

#include "groom/error.h"
#include "groom/mesh.h"

namespace plume {

struct Roots {
  std::vector<SurfacePoint> points;  // one per root
  std::vector<uint64_t> ids;         // stable ids, one per root
  /// Empty, or one per root: when the root arrives. A smaller set of the same roots (a proxy run,
  /// a lower count) holds exactly the roots that arrive first, so anything decided in arrival
  /// order, looking only at earlier roots, is the same in every such subset (effects/ chooses clump
  /// centres that way). scatter_roots gives the arrival time; roots from a file, their index in it.
  std::vector<double> arrival;
  size_t size() const { return points.size(); }
};

/// Scatters `count` roots over the triangles where `triangle_mask` is true (empty: all),
/// area-weighted. Stable: the same inputs give the same roots, and a larger count keeps every
/// root of a smaller one: root j of triangle f arrives at time (j + u) / area with u hashed
/// from (seed, f, j), and the `count` earliest arrivals are kept. Its position in the triangle
/// is hashed from the same numbers. Ids are (f << 24) | j. Roots are ordered by triangle; their
/// arrival times are in Roots::arrival.
/// Throws InputError at `where` (the groom's roots settings) when the selected triangles have no
/// area or an infinite one; it always returns (the search for the arrival time is bounded).
Roots scatter_roots(const Mesh &mesh, int64_t count, uint64_t seed, const std::vector<bool> &triangle_mask = {},
                    const FileLoc &where = {});

/// Triangles whose closest distance to any of `points` is at most `radius`.
std::vector<bool> triangles_near(const Mesh &mesh, const std::vector<Eigen::Vector3f> &points, double radius);

/// Area of the triangles selected by `triangle_mask` (empty: all).
double masked_area(const Mesh &mesh, const std::vector<bool> &triangle_mask);

/// 64-bit mixing hash (splitmix64 finaliser); the basis of every seeded random in Plume.
inline uint64_t hash64(uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}
inline uint64_t hash_combine(uint64_t a, uint64_t b) { return hash64(a ^ hash64(b)); }
/// Uniform float in [0, 1) from a hash.
inline float hash_to_unit(uint64_t h) { return float(h >> 40) * (1.0f / 16777216.0f); }

}  // namespace plume
