// The closed UV sphere the guide benchmarks grow on: one vertex at each pole (no degenerate
// triangles), `rings` bands of `segments` quads between them, outward-facing.
#pragma once

#include <Eigen/Core>
#include <cmath>

#include "groom/mesh.h"

namespace plume::bench {

inline Mesh closed_sphere(float radius, int rings, int segments) {
  constexpr double pi = 3.14159265358979;
  Mesh mesh;
  mesh.positions.push_back(Eigen::Vector3f(0.0f, radius, 0.0f));
  for (int r = 1; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const float theta = float(pi) * r / rings, phi = 2.0f * float(pi) * s / segments;
      mesh.positions.push_back(radius * Eigen::Vector3f(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                        -std::sin(theta) * std::sin(phi)));
    }
  mesh.positions.push_back(Eigen::Vector3f(0.0f, -radius, 0.0f));
  const int bottom = int(mesh.positions.size()) - 1;
  auto ring = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) mesh.triangles.emplace_back(0, ring(1, s), ring(1, s + 1));
  for (int r = 1; r < rings - 1; ++r)
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.emplace_back(ring(r, s), ring(r + 1, s), ring(r + 1, s + 1));
      mesh.triangles.emplace_back(ring(r, s), ring(r + 1, s + 1), ring(r, s + 1));
    }
  for (int s = 0; s < segments; ++s) mesh.triangles.emplace_back(bottom, ring(rings - 1, s + 1), ring(rings - 1, s));
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

}  // namespace plume::bench
