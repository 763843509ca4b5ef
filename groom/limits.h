// Bounds on the numbers of a scene that keep Plume's 32-bit float arithmetic finite. Readers
// reject input beyond them (InputError naming the file and the value), so the algorithms never
// meet an overflow they would turn into inf or NaN.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <string>

namespace plume {

/// Largest |coordinate| of any scene position (emitter vertices, guide and root points, parting
/// points, pivots, translations, collision shapes), and the largest length (radii, amplitudes,
/// margins, widths) a groom may give, in scene units. Two points within the bound are at most
/// 2 sqrt(3) 1e6 ~ 3.5e6 apart, so squared distances and edge cross products stay below ~1.2e13
/// and even their squares (~1.5e26) below the float maximum 3.4e38; noise lattice coordinates
/// (frequency <= max_frequency times a coordinate) stay below 2^31. 1e6 is 10 km in centimetres.
inline constexpr float max_coordinate = 1e6f;

/// True when every coordinate of `p` is finite and within max_coordinate.
inline bool within_scene_bounds(const Eigen::Vector3f &p) {
  return p.allFinite() && p.cwiseAbs().maxCoeff() <= max_coordinate;
}

/// "expected coordinates within [-1e+06, 1e+06], got (x, y, z)" for a point beyond the bound.
std::string out_of_bounds_message(const Eigen::Vector3f &p);

}  // namespace plume
