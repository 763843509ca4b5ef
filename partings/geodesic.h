// Approximate geodesic distances on a triangle mesh, optionally cut open along mesh edges:
// Dijkstra over the mesh edges plus one unfolded link across every pair of adjacent triangles.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "groom/mesh.h"

namespace plume::partings {

/// Triangle adjacency of a mesh, with vertices welded by exact position (so a mesh split along
/// UV seams is still one surface). An edge shared by more than two triangles is a border.
struct MeshTopology {
  /// #V: welded vertex id of each mesh vertex (the lowest index with the same position).
  std::vector<int> welded;
  /// #F by 3: the triangle across edge (corner i, corner i+1), or -1 on a border.
  std::vector<Eigen::Vector3i> neighbours;
};

MeshTopology build_topology(const Mesh &mesh);

/// Key of the undirected edge between two welded vertices.
inline uint64_t edge_key(int a, int b) {
  const uint32_t lo = uint32_t(a < b ? a : b), hi = uint32_t(a < b ? b : a);
  return (uint64_t(lo) << 32) | hi;
}

/// #F by 3 flags: edge (corner i, corner i+1) of each triangle is cut. Both triangles of an edge
/// carry the same flag. Empty means "no cut".
using EdgeCut = std::vector<std::array<bool, 3>>;

/// Flags every triangle edge whose welded key is in `edge_keys` (sorted).
EdgeCut cut_from_edges(const Mesh &mesh, const MeshTopology &topology, std::span<const uint64_t> edge_keys);

/// The graph of a mesh cut open along `cut`: a vertex on the cut gets one node per side (one per
/// fan of triangles around it not separated by cut edges), so a path can go along the cut and
/// around its ends but never across it. Links are the mesh edges and, for every two triangles that
/// share an uncut edge and form a convex quad, the straight line between the opposite corners in
/// the unfolded quad: more directions than the edges alone, so less of the edge graph's
/// overestimate (metrication error), at the cost of one more link per edge.
class GeodesicGraph {
 public:
  GeodesicGraph(const Mesh &mesh, const MeshTopology &topology, const EdgeCut &cut = {});

  size_t node_count() const { return node_offsets_.size() - 1; }
  /// The node holding corner `corner` (0..2) of `triangle`, on that triangle's side of any cut.
  int node(int triangle, int corner) const { return corner_nodes_[size_t(triangle) * 3 + size_t(corner)]; }

  /// Reusable work arrays for distances_from (one per thread).
  struct Scratch {
    std::vector<std::pair<float, int>> heap;
  };
  /// Distances (scene units) from surface point `source` to every node; the source triangle's corners
  /// are seeded with their straight-line distance. r_distance is resized to node_count(); infinity
  /// marks nodes that cannot be reached.
  void distances_from(const Mesh &mesh, const SurfacePoint &source, std::vector<float> &r_distance,
                      Scratch &scratch) const;
  /// Distance at surface point `p`: barycentric blend of the distances at the nodes of p's triangle
  /// (continuous across uncut edges); the straight-line distance inside the source triangle itself.
  float evaluate(const Mesh &mesh, std::span<const float> distance, const SurfacePoint &p,
                 const SurfacePoint &source) const;

 private:
  std::vector<int> corner_nodes_;     // #F * 3
  std::vector<int64_t> node_offsets_;  // CSR over nodes
  std::vector<int> link_targets_;
  std::vector<float> link_lengths_;
};

/// The mesh edges that follow a polyline drawn on (or near) the surface: each point is snapped to
/// the nearest vertex of its closest triangle, and consecutive vertices are joined by the shortest
/// path along mesh edges that stays within a ball around the two points (falling back to the whole
/// mesh). Returns sorted, unique welded edge keys. `snapped` holds the closest surface point of
/// each polyline point (from MeshQuery). The cut's resolution is the mesh's edge length.
std::vector<uint64_t> polyline_edge_path(const Mesh &mesh, const MeshTopology &topology,
                                         std::span<const SurfacePoint> snapped, bool closed);

}  // namespace plume::partings
