// Small meshes built in code for the groom/ tests.
#pragma once

#include <cmath>

#include "groom/mesh.h"

namespace plume::test {

/// Which axis a UV sphere's poles lie on.
enum class PoleAxis { y, z };

/// A UV sphere of `radius` centred at the origin, outward-facing, poles on `poles` (exactly
/// degenerate pole triangles, no slivers), with UVs unless `with_uvs` is false.
inline Mesh make_sphere(float radius, int rings, int segments, PoleAxis poles = PoleAxis::y, bool with_uvs = true) {
  Mesh mesh;
  for (int r = 0; r <= rings; ++r) {
    const float theta = float(M_PI) * float(r) / float(rings);
    const float sin_theta = (r == 0 || r == rings) ? 0.0f : std::sin(theta);
    for (int s = 0; s <= segments; ++s) {
      const float phi = 2.0f * float(M_PI) * float(s) / float(segments);
      const float x = radius * sin_theta * std::cos(phi), h = radius * std::cos(theta),
                  w = radius * sin_theta * std::sin(phi);
      mesh.positions.push_back(poles == PoleAxis::y ? Eigen::Vector3f(x, h, w) : Eigen::Vector3f(x, w, h));
      if (with_uvs) mesh.uvs.emplace_back(float(s) / float(segments), 1.0f - float(r) / float(rings));
    }
  }
  auto index = [&](int r, int s) { return r * (segments + 1) + s; };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      const int a = index(r, s), b = index(r, s + 1), c = index(r + 1, s), d = index(r + 1, s + 1);
      // Swapping y and z mirrors the sphere, so the z-pole winding is reversed to face outward.
      const Eigen::Vector3i t0 = poles == PoleAxis::y ? Eigen::Vector3i(a, b, c) : Eigen::Vector3i(a, c, b);
      const Eigen::Vector3i t1 = poles == PoleAxis::y ? Eigen::Vector3i(b, d, c) : Eigen::Vector3i(b, c, d);
      for (const Eigen::Vector3i &t : {t0, t1}) {
        mesh.triangles.push_back(t);
        if (with_uvs) mesh.triangle_uvs.push_back(t);
      }
    }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

}  // namespace plume::test
