// Small synthetic scenes for the dynamics tests: a sphere "head", guides on it, head motions.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <span>
#include <vector>

#include "groom/dynamics_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"

namespace plume::test {

/// A closed UV sphere (rings x segments quads split in two, poles fanned), outward normals.
inline Mesh sphere_mesh(float radius, const Eigen::Vector3f &centre = Eigen::Vector3f::Zero(), int rings = 16,
                        int segments = 24) {
  Mesh mesh;
  const float pi = 3.14159265358979f;
  mesh.positions.push_back(centre + Eigen::Vector3f(0.0f, radius, 0.0f));
  for (int r = 1; r < rings; ++r) {
    const float theta = pi * float(r) / float(rings);
    for (int s = 0; s < segments; ++s) {
      const float phi = 2.0f * pi * float(s) / float(segments);
      mesh.positions.push_back(centre + radius * Eigen::Vector3f(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                                 -std::sin(theta) * std::sin(phi)));
    }
  }
  mesh.positions.push_back(centre + Eigen::Vector3f(0.0f, -radius, 0.0f));
  const int bottom = int(mesh.positions.size()) - 1;
  auto ring_vertex = [&](int r, int s) { return 1 + (r - 1) * segments + (s % segments); };
  for (int s = 0; s < segments; ++s) mesh.triangles.emplace_back(0, ring_vertex(1, s), ring_vertex(1, s + 1));
  for (int r = 1; r < rings - 1; ++r)
    for (int s = 0; s < segments; ++s) {
      mesh.triangles.emplace_back(ring_vertex(r, s), ring_vertex(r + 1, s), ring_vertex(r + 1, s + 1));
      mesh.triangles.emplace_back(ring_vertex(r, s), ring_vertex(r + 1, s + 1), ring_vertex(r, s + 1));
    }
  for (int s = 0; s < segments; ++s)
    mesh.triangles.emplace_back(bottom, ring_vertex(rings - 1, s + 1), ring_vertex(rings - 1, s));
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

/// The mesh turned by `angle` radians about the y axis through `pivot`, then moved by `shift`.
inline Mesh moved_mesh(const Mesh &rest, float angle, const Eigen::Vector3f &shift = Eigen::Vector3f::Zero(),
                       const Eigen::Vector3f &pivot = Eigen::Vector3f::Zero()) {
  Mesh posed = rest;
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(angle, Eigen::Vector3f::UnitY()).toRotationMatrix();
  for (Eigen::Vector3f &p : posed.positions) p = pivot + turn * (p - pivot) + shift;
  posed.compute_normals();
  return posed;
}

/// One guide per direction: rooted on the sphere surface along `direction`, growing `joints`
/// points. `bend` (radians over the guide) turns it from the outward normal toward -y (a groomed
/// hair that falls), `length` is its total length.
inline Guides sphere_guides(const Mesh &mesh, float radius, const std::vector<Eigen::Vector3f> &directions, int joints,
                            float length, float bend) {
  StrandSet strands;
  for (size_t g = 0; g < directions.size(); ++g) {
    const Eigen::Vector3f normal = directions[g].normalized();
    Eigen::Vector3f side = normal.cross(Eigen::Vector3f::UnitY());
    if (side.squaredNorm() < 1e-6f) side = Eigen::Vector3f::UnitX();
    side.normalize();
    std::vector<Eigen::Vector3f> points;
    Eigen::Vector3f p = radius * normal;
    points.push_back(p);
    const float segment = length / float(joints - 1);
    for (int j = 1; j < joints; ++j) {
      const float angle = bend * float(j - 1) / float(std::max(1, joints - 2));
      // Rotate the normal about `side` toward -y by `angle`.
      const Eigen::Vector3f d = Eigen::AngleAxisf(-angle, side) * normal;
      p += segment * d;
      points.push_back(p);
    }
    strands.append(points, g);
  }
  const MeshQuery query(mesh);
  return bind_guides(query, std::move(strands), "test");
}

/// Settings with no collisions and no wind, the given substeps.
inline DynamicsSettings quiet_settings(int substeps = 1) {
  DynamicsSettings settings;
  settings.enabled = true;
  settings.substeps = substeps;
  settings.collide_with_emitter = false;
  return settings;
}

/// Largest relative segment length error of the joint positions `x` (laid out like `rest`)
/// against the rest guides.
inline double max_length_error(std::span<const Eigen::Vector3d> x, const StrandSet &rest) {
  double worst = 0.0;
  for (size_t g = 0; g < rest.strand_count(); ++g) {
    const auto b = rest.points(g);
    const Eigen::Vector3d *a = x.data() + rest.offsets[g];
    for (size_t i = 1; i < b.size(); ++i) {
      const double l0 = (b[i] - b[i - 1]).cast<double>().norm();
      const double l = (a[i] - a[i - 1]).norm();
      worst = std::max(worst, std::abs(l - l0) / l0);
    }
  }
  return worst;
}

/// Largest distance between corresponding points, over all guides, divided by the guide's length.
inline double max_relative_offset(const StrandSet &a, const StrandSet &b) {
  double worst = 0.0;
  for (size_t g = 0; g < a.strand_count(); ++g) {
    const double length = b.length(g);
    const auto pa = a.points(g), pb = b.points(g);
    for (size_t i = 0; i < pa.size(); ++i) worst = std::max(worst, double((pa[i] - pb[i]).norm()) / length);
  }
  return worst;
}

}  // namespace plume::test
