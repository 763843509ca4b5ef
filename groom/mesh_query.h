// Closest-point queries on an emitter mesh (a CGAL AABB tree, kept inside mesh_query.cpp).
#pragma once

#include <Eigen/Core>
#include <memory>

#include "groom/mesh.h"

namespace plume {

/// Built once for a mesh pose; query from any number of threads. The mesh must outlive it,
/// and its positions must not change while it is in use (build a new one per deformed pose).
class MeshQuery {
 public:
  /// How queries without a hint find their starting point.
  enum class Start {
    /// A kd-tree over the triangles, built with the tree: best for many unhinted queries.
    kd_tree,
    /// No extra structure (cheaper to build, e.g. every substep of a moving skin): callers pass
    /// a hint; unhinted queries start from the first triangle.
    hint_only,
  };
  explicit MeshQuery(const Mesh &mesh, Start start = Start::kd_tree);
  ~MeshQuery();
  MeshQuery(const MeshQuery &) = delete;
  MeshQuery &operator=(const MeshQuery &) = delete;

  /// The surface point closest to `point` (degenerate triangles are never returned).
  SurfacePoint closest(const Eigen::Vector3f &point) const;
  /// The same, searched from `hint`, any surface point of this mesh (the closer to the answer,
  /// the faster). The answer does not depend on the hint, up to ties between equidistant faces.
  SurfacePoint closest(const Eigen::Vector3d &point, const SurfacePoint &hint) const;
  /// Distance to the surface, negative inside: the sign is that of (point - closest) . normal,
  /// with the interpolated normal at the closest point (meaningful near a closed, outward-facing
  /// surface; on an open mesh "inside" means "behind the skin").
  float signed_distance(const Eigen::Vector3f &point, SurfacePoint *r_closest = nullptr) const;
  /// Double-precision signed distance searched from `hint` (see closest(point, hint)).
  double signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint, SurfacePoint &r_closest) const;
  const Mesh &mesh() const { return mesh_; }

 private:
  struct Tree;
  const Mesh &mesh_;
  std::unique_ptr<Tree> tree_;
};

}  // namespace plume
