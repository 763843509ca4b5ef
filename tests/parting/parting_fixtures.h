// Small scenes for the parting and checker tests: a flat grid with two face groups, and guides
// standing on it.
#pragma once

#include <cmath>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/parting.h"

namespace plume::test {

/// A flat n x n quad grid over [-1, 1]^2 at z = 0, normals +z, two triangles per quad. Faces with
/// centre x < 0 are in group "left", the others in group "right".
inline Mesh make_grid(int n) {
  Mesh mesh;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.positions.emplace_back(-1.0f + 2.0f * float(i) / float(n), -1.0f + 2.0f * float(j) / float(n), 0.0f);
  const auto index = [&](int i, int j) { return j * (n + 1) + i; };
  mesh.group_names = {"left", "right"};
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int group = (2 * i + 1 < n) ? 0 : 1;
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
      mesh.triangle_groups.push_back(group);
      mesh.triangle_groups.push_back(group);
    }
  mesh.compute_normals();
  return mesh;
}

/// Straight vertical guides of `points` points and length `length` rooted at `roots` (on the grid).
inline Guides make_standing_guides(const MeshQuery &query, const std::vector<Eigen::Vector3f> &roots,
                                   float length = 0.5f, int points = 8) {
  StrandSet strands;
  std::vector<Eigen::Vector3f> strand(static_cast<size_t>(points));
  uint64_t id = 0;
  for (const Eigen::Vector3f &root : roots) {
    for (int p = 0; p < points; ++p) strand[size_t(p)] = root + Eigen::Vector3f(0, 0, length * float(p) / float(points - 1));
    strands.append(strand, id++);
  }
  return bind_guides(query, strands, "test guides");
}

/// A partial parting along y = 0 from x = x0 to x = x1.
inline PartingLine straight_line(float x0, float x1, float gamma, bool hard = false) {
  PartingLine line;
  line.name = hard ? "hard line" : "side parting";
  line.gamma = gamma;
  line.hard = hard;
  const int count = 9;
  for (int i = 0; i < count; ++i)
    line.points.emplace_back(x0 + (x1 - x0) * float(i) / float(count - 1), 0.0f, 0.0f);
  return line;
}

/// A closed UV sphere of `radius` at the origin with one vertex per pole (no degenerate triangle),
/// outward-facing.
inline Mesh make_closed_sphere(float radius, int rings, int segments) {
  Mesh mesh;
  mesh.positions.emplace_back(0.0f, radius, 0.0f);
  for (int r = 1; r < rings; ++r) {
    const float theta = float(M_PI) * float(r) / float(rings);
    for (int s = 0; s < segments; ++s) {
      const float phi = 2.0f * float(M_PI) * float(s) / float(segments);
      mesh.positions.emplace_back(radius * std::sin(theta) * std::cos(phi), radius * std::cos(theta),
                                  radius * std::sin(theta) * std::sin(phi));
    }
  }
  mesh.positions.emplace_back(0.0f, -radius, 0.0f);
  const int south = int(mesh.positions.size()) - 1;
  const auto index = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) {
    mesh.triangles.emplace_back(0, index(1, s + 1), index(1, s));
    mesh.triangles.emplace_back(south, index(rings - 1, s), index(rings - 1, s + 1));
    for (int r = 1; r + 1 < rings; ++r) {
      mesh.triangles.emplace_back(index(r, s), index(r, s + 1), index(r + 1, s));
      mesh.triangles.emplace_back(index(r, s + 1), index(r + 1, s + 1), index(r + 1, s));
    }
  }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

}  // namespace plume::test
