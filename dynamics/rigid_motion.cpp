#include "dynamics/rigid_motion.h"

#include <Eigen/LU>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>

#include "groom/error.h"

namespace plume::dynamics {

using Eigen::Matrix3d;
using Eigen::Vector3d;

RigidMotion fit_rigid_motion(std::span<const Eigen::Vector3f> from, std::span<const Eigen::Vector3f> to) {
  if (from.size() != to.size() || from.empty()) throw InternalError("fit_rigid_motion: mismatched or empty poses");
  const size_t count = from.size();
  Vector3d c0 = Vector3d::Zero(), c1 = Vector3d::Zero();
  for (size_t p = 0; p < count; ++p) {
    c0 += from[p].cast<double>();
    c1 += to[p].cast<double>();
  }
  c0 /= double(count);
  c1 /= double(count);
  Matrix3d covariance = Matrix3d::Zero();
  for (size_t p = 0; p < count; ++p) covariance += (from[p].cast<double>() - c0) * (to[p].cast<double>() - c1).transpose();
  const Eigen::JacobiSVD<Matrix3d> svd(covariance, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Matrix3d flip = Matrix3d::Identity();
  flip(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  RigidMotion motion;
  motion.rotation = svd.matrixV() * flip * svd.matrixU().transpose();
  motion.translation = c1 - motion.rotation * c0;
  double residual2 = 0.0;
  double extent2 = 0.0;
  for (size_t p = 0; p < count; ++p) {
    const Vector3d target = to[p].cast<double>();
    residual2 = std::max(residual2, (target - motion.apply(from[p].cast<double>())).squaredNorm());
    extent2 = std::max(extent2, target.squaredNorm());
  }
  // Float positions: a slack of a few of their rounding units (relative 6e-8) at the largest
  // coordinate in play.
  motion.residual = std::sqrt(residual2) + 1e-5 * (1.0 + std::sqrt(extent2));
  return motion;
}

}  // namespace plume::dynamics
