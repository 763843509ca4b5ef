// Closest points on the moving emitter for the collision pass: an AABB tree per pose, searched
// from a hint (a surface point near the answer, such as the joint's previous closest point).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "groom/mesh.h"

namespace plume::dynamics {

/// Built for one pose of the emitter; query from any number of threads. The mesh must outlive
/// it and keep its positions while it is in use. Unlike MeshQuery it builds no extra search
/// structure for a starting point (built every substep while the skin moves, that would cost
/// more than it saves): the caller passes one.
class EmitterQuery {
 public:
  explicit EmitterQuery(const Mesh &mesh);
  ~EmitterQuery();
  EmitterQuery(const EmitterQuery &) = delete;
  EmitterQuery &operator=(const EmitterQuery &) = delete;

  /// Signed distance from `point` to the surface (negative behind the skin, the sign of
  /// (point - closest) . interpolated normal), the closest surface point in r_closest.
  /// `hint` is any surface point of this mesh; the closer to the answer, the faster the search.
  /// The answer does not depend on the hint (up to ties between equidistant triangles).
  double signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint, SurfacePoint &r_closest) const;

 private:
  struct Tree;
  const Mesh &mesh_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace plume::dynamics
