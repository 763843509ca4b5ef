// A uniform grid of the emitter's triangles for exact closest-point queries near a known triangle.
// Strands walk along the skin in small steps, so the previous closest triangle bounds the search to
// a few cells, far cheaper than a query of the whole tree. Built once per posed frame: growth and
// the effects stack can share one (grow(), EffectStack::apply()).
#pragma once

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "skin/lanes.h"

namespace plume::skin {

class SkinGrid {
 public:
  /// Built per pose; `query` (on the same mesh) answers what the grid cannot answer cheaply.
  SkinGrid(const Mesh &mesh, const MeshQuery &query);

  /// Signed distance to the surface as MeshQuery::signed_distance defines it (sign of
  /// (p - closest) . MeshQuery::side_normal(closest)). `hint` is a triangle near p (or -1): the true closest
  /// triangle is within |p - closest point of hint|, so only the cells of that ball are searched;
  /// when they are too many, the whole-mesh query is used.
  float signed_distance(const Eigen::Vector3f &p, int hint, SurfacePoint &r_closest) const;
  /// The same, searching only the cells of that ball that lie within one cell of p's cell (cells
  /// farther than the best distance found are skipped). Returns true with the signed distance in
  /// r_distance when the answer is exact; otherwise false, with r_distance a lower bound of the
  /// unsigned distance (the distance from p to the searched block's cut faces, at least p's
  /// distance to its own cell's faces) and no sign. Never queries the whole mesh.
  bool local_signed_distance(const Eigen::Vector3f &p, int hint, float &r_distance, SurfacePoint &r_closest) const;
  /// True when no triangle is closer than `radius` to p: a search of the cells the ball touches,
  /// stopping at the first triangle inside it (false, too, when the ball spans more than 27 cells).
  /// Far cheaper than a distance query when only "at least this far" is needed.
  bool clear_within(const Eigen::Vector3f &p, float radius) const;
  /// A lower bound of the (unsigned) distance from p to the surface, from the chessboard distance
  /// of p's cell to the nearest cell holding a triangle: (k - 1) * cell size; outside the box of the
  /// triangles (where the cells, clamped to the grid, bound little) the distance to that box when
  /// larger. No search.
  float distance_lower_bound(const Eigen::Vector3f &p) const;
  /// A tighter lower bound near the skin: the distance from p to the nearest box of a cell holding a
  /// triangle among the 27 cells around p's cell, or to the faces of that block (at least one cell
  /// size) when none is nearer. No triangle is looked at.
  float block_lower_bound(const Eigen::Vector3f &p) const;
  /// True when p lies within one cell of a cell that an open edge of the mesh (an edge of one
  /// triangle only) passes through. Past an open edge the signed distance changes sign without
  /// crossing the skin, so there no bound or "nothing crossed" argument decides the side: callers
  /// query. Points farther from every open edge than a cell are assumed to keep their side.
  bool near_open_edge(const Eigen::Vector3f &p) const {
    if (near_open_edge_.empty()) return false;
    const Eigen::Vector3i c = cell_of(p);
    return near_open_edge_[cell_index(c.x(), c.y(), c.z())] != 0;
  }
  /// Whether the mesh has an open edge at all (else near_open_edge is false everywhere).
  bool has_open_edges() const { return !near_open_edge_.empty(); }

 private:
  /// The cell holding p, clamped to the grid (a point outside it gets the nearest cell).
  Eigen::Vector3i cell_of(const Eigen::Vector3f &p) const {
    Eigen::Vector3i c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / cell_size_)), 0, dims_[a] - 1);
    return c;
  }
  /// Index of cell (x, y, z) in the flat per-cell arrays.
  size_t cell_index(int x, int y, int z) const {
    return (size_t(z) * size_t(dims_.y()) + size_t(y)) * size_t(dims_.x()) + size_t(x);
  }
  /// Squared distance from p to the box of cell (x, y, z); 0 inside it.
  float cell_box_distance_sq(const Eigen::Vector3f &p, int x, int y, int z) const {
    const Eigen::Vector3f box_lo = origin_ + cell_size_ * Eigen::Vector3f(float(x), float(y), float(z));
    return (box_lo - p).cwiseMax(p - box_lo - Eigen::Vector3f::Constant(cell_size_)).cwiseMax(0.0f).squaredNorm();
  }
  /// Corner i of triangle f.
  const Eigen::Vector3f &vertex(int f, int i) const { return mesh_.positions[size_t(mesh_.triangles[size_t(f)][i])]; }
  /// The nearest triangle a search has found, and the nearest other one (its runner-up).
  struct Nearest {
    float best_sq = INFINITY;
    int best = -1;
    Eigen::Vector3f best_bary = Eigen::Vector3f::Zero();
    float second_sq = INFINITY;
    int second = -1;
    Eigen::Vector3f second_bary = Eigen::Vector3f::Zero();
  };
  /// The signed distance of p from a finished search (r_closest set from it). The tree's answer,
  /// MeshQuery::signed_distance, replaces it where the side is ill-conditioned: the side normal
  /// nearly perpendicular to the offset, or a runner-up at a near tie on the other side (p
  /// between two parts of the skin that overlap), so that every part of Plume agrees on the side.
  float signed_at(const Eigen::Vector3f &p, const Nearest &nearest, SurfacePoint &r_closest) const;
  /// Closest point of triangle `hint` to p and its squared distance; false when there is no hint, or
  /// the hint is degenerate (then the caller queries the whole mesh).
  bool hint_distance(const Eigen::Vector3f &p, int hint, Eigen::Vector3f &r_bary, float &r_distance_sq) const;
  /// Tests the triangles of cell `c` against p, keeping the closest (ties: lowest triangle index)
  /// and the runner-up when it is within a near tie of the closest.
  void scan_cell(const Eigen::Vector3f &p, size_t c, Nearest &r_nearest) const;

  const Mesh &mesh_;
  const MeshQuery &query_;
  Eigen::Vector3f origin_;       // the low corner of the grid and of the box of its triangles
  Eigen::Vector3f box_high_ = Eigen::Vector3f::Zero();  // the high corner of that box
  float cell_size_ = 1.0f;
  Eigen::Vector3i dims_;
  /// Four triangles as a cell lists them (SIMD lanes), each with a bounding disc in its plane, so
  /// that most triangles of a scanned cell are rejected four at a time without the closest-point
  /// computation (see may_be_within). A cell's last block is padded with lanes of triangle -1.
  struct CellBlock {
    Float4 centre[3];  // centroid
    Float4 radius;     // largest distance from the centroid to a corner
    Float4 normal[3];  // unit normal of the triangle's plane (0 for a triangle too thin for one)
    Int4 triangle;
  };
  /// Closest points of the block's four triangles to p (barycentric weights and squared distances,
  /// lanes as the block's; the corners gathered from the mesh), each the same to the bit as
  /// closest_on_triangle for that triangle alone. A padding lane gets triangle 0's.
  void closest_in_block(const CellBlock &block, Float4 px, Float4 py, Float4 pz, Float4 r_bary[3],
                        Float4 &r_distance_sq) const;
  /// Bit l set unless the triangle of lane l is certainly farther than `reach` from p (px, py, pz in
  /// every lane): p is too far from its bounding sphere, or from the disc of that radius in the
  /// triangle's plane (the distance to the plane and the gap beside the disc, with slack for
  /// rounding). Above a smooth skin the sphere test lets through every triangle near the foot of p;
  /// the disc test keeps only those under it.
  static int may_be_within(const CellBlock &block, Float4 px, Float4 py, Float4 pz, float reach);
  /// For each triangle of cell c that may lie within `reach` of p (may_be_within; `reach` is read
  /// again before each block, so a caller may shrink it), calls visit(triangle, bary, lane,
  /// distance_sq) with its closest point (barycentric weights in lane `lane` of `bary`); stops,
  /// returning false, as soon as visit returns false.
  template <class Visit>
  bool visit_near(size_t c, Float4 px, Float4 py, Float4 pz, const float &reach, Visit &&visit) const;
  /// CSR: the blocks of cell c are cell_blocks_[cell_offsets_[c] .. cell_offsets_[c + 1]).
  std::vector<int32_t> cell_offsets_;
  std::vector<CellBlock> cell_blocks_;
  /// Per cell: chessboard distance (in cells, capped at 255) to the nearest cell holding a triangle.
  std::vector<uint8_t> cell_distance_;
  /// Per cell: 1 within one cell of an open edge (see near_open_edge); empty for a closed mesh.
  std::vector<uint8_t> near_open_edge_;
};

}  // namespace plume::skin
