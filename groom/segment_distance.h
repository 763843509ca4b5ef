// The distance between two line segments, shared by the strand checker's crossings and the feather
// layering's gap tests. Eigen only, header-only.
#pragma once

#include <Eigen/Core>
#include <algorithm>

namespace plume {

/// The closest points of segments p0-p1 and q0-q1, as parameters r_s and r_t in [0, 1] along each
/// (clamped to both segments; Ericson, Real-Time Collision Detection, 5.1.9), in double precision.
/// Segments whose directions' cross product is below 1e-14 of their lengths' product are taken as
/// parallel (s = 0, then t clamped and s recomputed from it, which still gives a closest pair). A
/// segment of no length is its point.
inline void closest_segment_parameters(const Eigen::Vector3d &p0, const Eigen::Vector3d &p1, const Eigen::Vector3d &q0,
                                       const Eigen::Vector3d &q1, double &r_s, double &r_t) {
  const Eigen::Vector3d d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  double s = 0.0, t = 0.0;
  if (a <= 0.0 && e <= 0.0) {
    r_s = r_t = 0.0;
    return;
  }
  if (a <= 0.0) {
    t = std::clamp(f / e, 0.0, 1.0);
  } else {
    const double c = d1.dot(r);
    if (e <= 0.0) {
      s = std::clamp(-c / a, 0.0, 1.0);
    } else {
      const double b = d1.dot(d2), denom = a * e - b * b;
      s = denom > 1e-14 * a * e ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
      t = (b * s + f) / e;
      if (t < 0.0) {
        t = 0.0;
        s = std::clamp(-c / a, 0.0, 1.0);
      } else if (t > 1.0) {
        t = 1.0;
        s = std::clamp((b - c) / a, 0.0, 1.0);
      }
    }
  }
  r_s = s;
  r_t = t;
}

/// Squared distance between segments p0-p1 and q0-q1, at their closest points
/// (closest_segment_parameters()), in double precision.
inline double segment_distance_squared(const Eigen::Vector3d &p0, const Eigen::Vector3d &p1, const Eigen::Vector3d &q0,
                                       const Eigen::Vector3d &q1) {
  double s = 0.0, t = 0.0;
  closest_segment_parameters(p0, p1, q0, q1, s, t);
  return ((p0 + (p1 - p0) * s) - (q0 + (q1 - q0) * t)).squaredNorm();
}

/// The same for float coordinates, computed in double: float coordinates are exact in double, so the
/// rounding stays far below any tolerance at any scale.
inline double segment_distance_squared(const Eigen::Vector3f &p0, const Eigen::Vector3f &p1, const Eigen::Vector3f &q0,
                                       const Eigen::Vector3f &q1) {
  return segment_distance_squared(Eigen::Vector3d(p0.cast<double>()), Eigen::Vector3d(p1.cast<double>()),
                                  Eigen::Vector3d(q0.cast<double>()), Eigen::Vector3d(q1.cast<double>()));
}

}  // namespace plume
