// The best rigid motion between two poses of the emitter and how far the skin departs from it:
// the bound that lets the collision pass skip exact closest-point queries of the emitter.
#pragma once

#include <Eigen/Core>
#include <span>

namespace plume::dynamics {

/// p -> rotation p + translation, plus `residual`: an upper bound of the distance between any
/// vertex of the target pose and where the motion carries it from the source pose.
///
/// Because every surface point is a barycentric combination of its triangle's vertices, each
/// point of the target surface lies within `residual` of the carried source surface and back, so
/// for any point p:  |dist_to(p) - dist_from(rotation^T (p - translation))| <= residual.
struct RigidMotion {
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double residual = 0.0;  // scene units, includes a slack for the float rounding of the vertices

  Eigen::Vector3d apply(const Eigen::Vector3d &p) const { return rotation * p + translation; }
};

/// Least-squares rigid fit of `from` -> `to` (same vertex count, at least one vertex): Kabsch,
/// centroids then the rotation from the SVD of the cross-covariance, reflection excluded.
RigidMotion fit_rigid_motion(std::span<const Eigen::Vector3f> from, std::span<const Eigen::Vector3f> to);

}  // namespace plume::dynamics
