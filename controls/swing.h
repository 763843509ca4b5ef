// Turns of a guide about its root, in the root's skin frame (x tangent, y bitangent, z the skin
// normal), built so that they never flip. Every direction a behaviour aims at is reached by a swing
// from the normal: the shortest rotation from +z, continuous everywhere but at -z, straight into
// the skin, which no behaviour targets (targets are kept above the skin's tangent plane). A turn
// from one direction to another is the swing to the one after the inverse swing from the other, so
// it too is continuous in both, wherever they are above the skin, even 180 degrees apart.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

namespace plume::controls {

/// The shortest rotation taking +z to the unit vector `u`: q ~ (1 + u.z, z x u), so w >= 0.
/// Continuous in u except at u = -z, where it is a half turn about x.
inline Eigen::Quaternionf swing_from_normal(const Eigen::Vector3f &u) {
  const float w = 1.0f + u.z();
  if (!(w > 1e-7f)) return Eigen::Quaternionf(0.0f, 1.0f, 0.0f, 0.0f);
  Eigen::Quaternionf q(w, -u.y(), u.x(), 0.0f);
  q.normalize();
  return q;
}

/// The turn taking the unit vector `from` to the unit vector `to` through the normal:
/// swing(to) swing(from)^-1 (maps `from` onto `to` exactly, up to rounding).
inline Eigen::Quaternionf turn_between(const Eigen::Vector3f &from, const Eigen::Vector3f &to) {
  Eigen::Quaternionf q = swing_from_normal(to) * swing_from_normal(from).conjugate();
  q.normalize();
  return q;
}

/// `q` raised to the power t in [0, 1]: the same axis, t times the angle, taken the way q turns
/// (no sign flip to the shorter way, which would jump when q passes a half turn).
inline Eigen::Quaternionf partial_turn(const Eigen::Quaternionf &q, float t) {
  const Eigen::Vector3f v = q.vec();
  const float s = v.norm();
  if (!(s > 0.0f)) return Eigen::Quaternionf::Identity();
  const float half = std::atan2(s, q.w()) * t;
  const Eigen::Vector3f axis = v / s;
  return Eigen::Quaternionf(std::cos(half), std::sin(half) * axis.x(), std::sin(half) * axis.y(),
                            std::sin(half) * axis.z());
}

/// The unit vector `u` raised, about the normal's plane through it, to at least the elevation whose sine is
/// `min_sine` (in [-1, 1]); its azimuth is kept. A vector with no azimuth (u = -z) takes
/// `fallback_azimuth` (a unit vector in the tangent plane). Continuous in u.
inline Eigen::Vector3f at_least_elevation(const Eigen::Vector3f &u, float min_sine,
                                          const Eigen::Vector3f &fallback_azimuth) {
  if (u.z() >= min_sine) return u;
  Eigen::Vector3f across(u.x(), u.y(), 0.0f);
  const float len = across.norm();
  across = len > 1e-12f ? Eigen::Vector3f(across / len) : fallback_azimuth;
  const float sine = std::clamp(min_sine, -1.0f, 1.0f);
  return across * std::sqrt(std::max(0.0f, 1.0f - sine * sine)) + Eigen::Vector3f(0.0f, 0.0f, sine);
}

}  // namespace plume::controls
