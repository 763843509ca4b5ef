// Keeps the points of one strand out of the skin, point after point, with few closest-point queries.
// Internal to interp/: used by streamline growth and push_out_of_skin().
#pragma once

#include <Eigen/Core>
#include <algorithm>

#include "groom/mesh_query.h"

namespace plume::interp {

/// The signed distance to a closed surface is 1-Lipschitz: sd(p) >= sd(q) - |p - q|. Knowing it at
/// the last queried point q, a point p with sd(q) - |p - q| >= margin is certainly outside by the
/// margin and needs no query. A strand rising from the skin is queried about log2(#points) times.
class SkinGuard {
 public:
  /// `scale`: a length of the scene (the mesh's size) for the absolute push tolerance.
  SkinGuard(const MeshQuery &query, float margin, float scale)
      : query_(query), margin_(margin), overshoot_(1e-6f * scale + 1e-4f * std::max(margin, 0.0f)) {}

  /// Starts a strand at a point known to be on (or above) the skin.
  void start(const Eigen::Vector3f &on_skin) {
    known_point_ = on_skin;
    known_distance_ = 0.0f;
  }
  /// Starts a strand at any point (one query), without moving it.
  void start_anywhere(const Eigen::Vector3f &p) {
    known_point_ = p;
    known_distance_ = query_.signed_distance(p);
  }

  /// Moves `p` out along the surface normal if its signed distance is below the margin (a few
  /// iterations for concave places, where one move along the normal falls short).
  void keep_out(Eigen::Vector3f &p) {
    if (known_distance_ - (p - known_point_).norm() >= margin_) return;
    SurfacePoint closest;
    float distance = query_.signed_distance(p, &closest);
    for (int iteration = 0; iteration < 4 && distance < margin_; ++iteration) {
      p += (margin_ - distance + overshoot_) * surface_normal(query_.mesh(), closest);
      distance = query_.signed_distance(p, &closest);
    }
    known_point_ = p;
    known_distance_ = distance;
  }

 private:
  const MeshQuery &query_;
  float margin_;
  float overshoot_;
  Eigen::Vector3f known_point_ = Eigen::Vector3f::Zero();
  float known_distance_ = 0.0f;
};

/// Diagonal of the bounding box of a mesh's vertices.
inline float mesh_scale(const Mesh &mesh) {
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e30f), hi = -lo;
  for (const Eigen::Vector3f &p : mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  return mesh.positions.empty() ? 0.0f : (hi - lo).norm();
}

}  // namespace plume::interp
