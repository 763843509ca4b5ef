// Small meshes built in code for the groom/ tests.
#pragma once

#include <cmath>

#include "groom/mesh.h"

namespace plume::test {

/// A UV sphere of `radius` centred at the origin, outward-facing, with UVs.
inline Mesh make_sphere(float radius, int rings, int segments) {
  Mesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const float theta = float(M_PI) * float(r) / float(rings);
    // Exact poles, so the pole triangles are exactly degenerate rather than slivers.
    const float sin_theta = (r == 0 || r == rings) ? 0.0f : std::sin(theta);
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * float(M_PI) * float(s) / float(segments);
      mesh.positions.emplace_back(radius * sin_theta * std::cos(phi), radius * std::cos(theta),
                                  radius * sin_theta * std::sin(phi));
      mesh.uvs.emplace_back(float(s) / float(segments), 1.0f - float(r) / float(rings));
    }
  }
  auto index = [&](int r, int s) { return r * (segments + 1) + s; };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const Eigen::Vector3i t0(index(r, s), index(r, s + 1), index(r + 1, s));
      const Eigen::Vector3i t1(index(r, s + 1), index(r + 1, s + 1), index(r + 1, s));
      for (const Eigen::Vector3i &t : {t0, t1}) {
        mesh.triangles.push_back(t);
        mesh.triangle_uvs.push_back(t);
      }
    }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

}  // namespace plume::test
