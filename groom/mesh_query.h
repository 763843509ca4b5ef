// Closest-point queries on an emitter mesh (a CGAL AABB tree, kept inside mesh_query.cpp).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

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

  /// The surface point closest to `point` (degenerate triangles are never returned). Its weights
  /// are closest_on_triangle's: they name the feature (face, edge or corner) that holds it.
  SurfacePoint closest(const Eigen::Vector3f &point) const;
  /// The same, searched from `hint`, any surface point of this mesh (the closer to the answer,
  /// the faster). The answer does not depend on the hint, up to ties between equidistant faces.
  SurfacePoint closest(const Eigen::Vector3d &point, const SurfacePoint &hint) const;
  /// Distance to the surface, negative inside: the sign is that of (point - closest) . side_normal
  /// (closest). On a closed, consistently oriented surface this is the true signed distance: it
  /// changes sign only across the skin, so it is 1-Lipschitz (every bound Plume takes from an
  /// earlier distance relies on that). Near an open edge "inside" means "behind the skin".
  float signed_distance(const Eigen::Vector3f &point, SurfacePoint *r_closest = nullptr) const;
  /// Double-precision signed distance searched from `hint` (see closest(point, hint)).
  double signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint, SurfacePoint &r_closest) const;
  /// The unit normal that decides the side of a point whose closest surface point is `closest`
  /// (weights as closest_on_triangle gives them, naming the feature): the angle-weighted
  /// pseudo-normal of that feature (Baerentzen and Aanaes 2005). Inside a face it is the face's
  /// normal; on an edge, the mean of its two faces' normals; at a corner, the faces' normals weighted
  /// by their angles there. Vertices are welded first (welded_vertices), so a seam is no edge.
  /// Unlike the interpolated normal, it never calls a point inside the skin that no part of the
  /// skin separates from the outside: where vertex normals average the two sides of a thin ear,
  /// that one did.
  const Eigen::Vector3f &side_normal(const SurfacePoint &closest) const;
  /// The open edges: edges of exactly one triangle, over welded vertices (a mesh split along its UV
  /// seams is not open there), as (lower, higher) welded vertex indices. Past an open edge the signed
  /// distance changes sign without crossing the skin.
  const std::vector<std::pair<uint32_t, uint32_t>> &open_edges() const { return open_edges_; }
  const Mesh &mesh() const { return mesh_; }

 private:
  struct Tree;
  /// Fills the pseudo-normals of side_normal() and the open edges.
  void compute_side_normals();
  const Mesh &mesh_;
  std::unique_ptr<Tree> tree_;
  std::vector<Eigen::Vector3f> face_normals_;    // per triangle (zero when degenerate)
  std::vector<Eigen::Vector3f> edge_normals_;    // 3 per triangle: edge k is the one opposite corner k
  std::vector<Eigen::Vector3f> corner_normals_;  // per vertex
  std::vector<std::pair<uint32_t, uint32_t>> open_edges_;
};

/// The surface point whose normal line (surface_normal(), along which Plume lifts a strand's root)
/// passes through `point`, for a point above the skin: the closest point, then moved along the skin
/// by the part of `point - position` across its normal (or a half, a quarter... of it) while that
/// part shrinks. The closest point's own line misses `point` wherever the interpolated normal leans
/// from the face's. The answer stays within 4 times the closest point's miss of it, so it never
/// moves to another part of the skin; for a point on or below the skin it is the closest point. Guide roots,
/// roots read from a file and the roots of strands read back are all found this way, so a strand
/// lifted from a root along its normal finds that root again.
SurfacePoint surface_point_below(const MeshQuery &query, const Eigen::Vector3f &point);

}  // namespace plume
