// Emitters, roots, guides and strands built in code for the effects tests.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/strand_set.h"
#include "groom/test_fixtures.h"

namespace plume::test {

/// A square in the xz plane (y = 0, normal +y) of side `size` centred at the origin, `cells` x `cells`
/// quads, with UVs; faces with x < 0 are in group "left", the others in group "right".
inline Mesh make_plane(float size, int cells) {
  Mesh mesh;
  for (int r = 0; r <= cells; ++r)
    for (int c = 0; c <= cells; ++c) {
      const float u = float(c) / float(cells), v = float(r) / float(cells);
      mesh.positions.emplace_back((u - 0.5f) * size, 0.0f, (0.5f - v) * size);
      mesh.uvs.emplace_back(u, v);
    }
  mesh.group_names = {"left", "right"};
  auto index = [&](int r, int c) { return r * (cells + 1) + c; };
  for (int r = 0; r < cells; ++r)
    for (int c = 0; c < cells; ++c) {
      const Eigen::Vector3i t0(index(r, c), index(r, c + 1), index(r + 1, c));
      const Eigen::Vector3i t1(index(r, c + 1), index(r + 1, c + 1), index(r + 1, c));
      for (const Eigen::Vector3i &t : {t0, t1}) {
        mesh.triangles.push_back(t);
        mesh.triangle_uvs.push_back(t);
        mesh.triangle_groups.push_back(2 * c < cells ? 0 : 1);
      }
    }
  mesh.compute_normals();
  return mesh;
}

/// One strand per root: from the root along the surface normal, `length` long, `points` points,
/// bent toward the root frame's tangent by `bend` * length * t^2 (t in [0, 1]).
inline StrandSet grow_straight(const Mesh &mesh, const Roots &roots, float length, int points, float bend = 0.0f) {
  StrandSet strands;
  std::vector<Eigen::Vector3f> pts(points);
  for (size_t i = 0; i < roots.size(); ++i) {
    const SurfaceFrame f = surface_frame(mesh, roots.points[i]);
    for (int j = 0; j < points; ++j) {
      const float t = float(j) / float(points - 1);
      pts[j] = f.origin + f.normal() * (length * t) + f.basis.col(0) * (bend * length * t * t);
    }
    strands.append(pts, roots.ids[i]);
  }
  return strands;
}

/// Guides: straight strands at `count` scattered roots (seed 99), bound to the mesh.
inline Guides make_guides(const Mesh &mesh, const MeshQuery &query, int count, float length, float bend) {
  const Roots guide_roots = scatter_roots(mesh, count, 99);
  return bind_guides(query, grow_straight(mesh, guide_roots, length, 9, bend), "guides");
}

/// Index of the guide whose rest root is nearest each root (brute force).
inline std::vector<int32_t> nearest_guides(const Mesh &mesh, const Roots &roots, const Guides &guides) {
  std::vector<int32_t> nearest(roots.size(), -1);
  for (size_t i = 0; i < roots.size(); ++i) {
    const Eigen::Vector3f p = surface_position(mesh, roots.points[i]);
    float best = INFINITY;
    for (size_t g = 0; g < guides.size(); ++g) {
      const float d = (surface_position(mesh, guides.roots[g]) - p).squaredNorm();
      if (d < best) {
        best = d;
        nearest[i] = int32_t(g);
      }
    }
  }
  return nearest;
}

/// The mesh moved by x -> rotation * x + translation (normals recomputed).
inline Mesh moved(const Mesh &mesh, const Eigen::Matrix3f &rotation, const Eigen::Vector3f &translation) {
  Mesh out = mesh;
  for (Eigen::Vector3f &p : out.positions) p = rotation * p + translation;
  out.compute_normals();
  return out;
}

inline StrandSet moved(const StrandSet &strands, const Eigen::Matrix3f &rotation, const Eigen::Vector3f &translation) {
  StrandSet out = strands;
  for (Eigen::Vector3f &p : out.positions) p = rotation * p + translation;
  return out;
}

}  // namespace plume::test
