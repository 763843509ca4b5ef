// Scenes for the controls tests: an open, gently domed skin patch of any size, guides of varied
// shapes, lengths and point counts on it (some on its open edges), and a deformation of it.
#pragma once

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <vector>

#include "controls/control_rig.h"
#include "groom/control_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"

namespace plume::test {

constexpr float kPi = 3.14159265358979f;

/// An open grid patch over x, z in [-size, size], domed up to `dome` size at its centre, normals +y.
inline Mesh dome_patch(float size, int cells = 24, float dome = 0.25f) {
  Mesh mesh;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const float x = size * (2.0f * float(i) / float(cells) - 1.0f),
                  z = size * (2.0f * float(j) / float(cells) - 1.0f);
      const float r2 = (x * x + z * z) / (size * size);
      mesh.positions.emplace_back(x, dome * size * std::exp(-r2), z);
    }
  auto v = [&](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      // (x, z) counter-clockwise seen from +y: normals up.
      mesh.triangles.emplace_back(v(i, j), v(i, j + 1), v(i + 1, j + 1));
      mesh.triangles.emplace_back(v(i, j), v(i + 1, j + 1), v(i + 1, j));
    }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  for (size_t f = 0; f < mesh.triangles.size(); ++f)
    if (mesh.positions[size_t(mesh.triangles[f][0])].x() < 0.0f) mesh.triangle_groups[f] = 1;
  mesh.group_names = {"right", "left"};
  mesh.compute_normals();
  return mesh;
}

/// The patch bent and moved as a body would be at `frame`: each vertex turned about the z axis by
/// an angle growing with x (a bend), then about y, then shifted. Not rigid: skin frames turn
/// differently along the patch.
inline Mesh bent_patch(const Mesh &rest, float size, double frame) {
  Mesh posed = rest;
  const float phase = float(frame) * 0.13f;
  for (Eigen::Vector3f &p : posed.positions) {
    const float bend = 0.35f * std::sin(phase) * p.x() / size;
    p = Eigen::AngleAxisf(bend, Eigen::Vector3f::UnitZ()) * p;
    p = Eigen::AngleAxisf(0.4f * std::sin(0.7f * phase), Eigen::Vector3f::UnitY()) * p +
        size * Eigen::Vector3f(0.2f * std::cos(phase), 0.1f * std::sin(phase), 0.0f);
  }
  posed.compute_normals();
  return posed;
}

/// `count` guides on `mesh`, seeded: roots spread over the patch, one in eight on its open edge;
/// shapes combed (leaning at 5 to 60 degrees, curving down), straight up the normal, or arched;
/// lengths 0.1 to 0.4 `size`, 4 to 12 points each; ids 1000 + index.
inline Guides patch_guides(const Mesh &mesh, float size, int count, uint64_t seed) {
  const MeshQuery query(mesh);
  StrandSet strands;
  std::vector<Eigen::Vector3f> points;
  for (int g = 0; g < count; ++g) {
    auto unit = [&](int k) { return hash_to_unit(hash_combine(seed, uint64_t(g) * 16 + uint64_t(k))); };
    Eigen::Vector3f at(size * (1.8f * unit(0) - 0.9f), 0.0f, size * (1.8f * unit(1) - 0.9f));
    if (g % 8 == 3) at.x() = size;  // on the open edge
    at.y() = 0.25f * size * std::exp(-(at.x() * at.x() + at.z() * at.z()) / (size * size)) + 0.001f * size;
    const SurfacePoint root = query.closest(at);
    const SurfaceFrame frame = surface_frame(mesh, root);
    const int kind = g % 3;
    const int n = 4 + int(unit(2) * 9.0f);
    const float length = size * (0.1f + 0.3f * unit(3));
    const float azimuth = 2.0f * kPi * unit(4);
    const float lean = kind == 1 ? 0.5f * kPi : (5.0f + 55.0f * unit(5)) * kPi / 180.0f;
    points.assign(size_t(n), frame.origin);
    Eigen::Vector3f p = Eigen::Vector3f::Zero();
    for (int j = 1; j < n; ++j) {
      const float t = float(j - 1) / float(n - 1);
      float elevation = lean;
      if (kind == 0) elevation = lean * (1.0f - 0.8f * t);        // combed: flattens toward the tip
      if (kind == 2) elevation = lean + (kPi - 2.0f * lean) * t;  // arched over
      const Eigen::Vector3f d(std::cos(elevation) * std::cos(azimuth), std::cos(elevation) * std::sin(azimuth),
                              std::sin(elevation));
      p += (length / float(n - 1)) * d;
      points[size_t(j)] = frame.to_world(p);
    }
    strands.append(points, 1000 + uint64_t(g));
  }
  return bind_guides(query, std::move(strands), "test");
}

/// A control at `position` reaching `radius` (0: everything).
inline ControlDesc control_at(const Eigen::Vector3f &position, float radius,
                              ControlDesc::Falloff falloff = ControlDesc::Falloff::smooth) {
  ControlDesc c;
  c.name = std::string(1, 'c');
  c.position = position;
  c.radius = radius;
  c.falloff = falloff;
  return c;
}

/// Keys [frame, value] (linear).
inline Keyed<float> keys(std::initializer_list<std::pair<double, float>> list,
                         KeyInterpolation interpolation = KeyInterpolation::linear) {
  Keyed<float> k;
  k.interpolation = interpolation;
  for (const auto &[frame, value] : list) {
    k.frames.push_back(frame);
    k.values.push_back(value);
  }
  return k;
}

inline ControlSettings settings_of(std::vector<ControlDesc> controls,
                                   ControlSettings::Binding binding = ControlSettings::Binding::blend) {
  ControlSettings s;
  s.binding = binding;
  s.controls = std::move(controls);
  return s;
}

/// Whether two strand sets hold the same bits.
inline bool same_bits(const StrandSet &a, const StrandSet &b) {
  return a.offsets == b.offsets && a.positions.size() == b.positions.size() &&
         std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Eigen::Vector3f)) == 0;
}

/// Angle between two vectors, degrees.
inline double angle_degrees(const Eigen::Vector3f &a, const Eigen::Vector3f &b) {
  const Eigen::Vector3d u = a.cast<double>().normalized(), v = b.cast<double>().normalized();
  return std::atan2(u.cross(v).norm(), u.dot(v)) * 180.0 / 3.14159265358979;
}

/// The controls applied to the guides carried onto `posed`.
inline StrandSet controlled(const controls::ControlRig &rig, const Mesh &rest, const Mesh &posed, const Guides &guides,
                            double frame) {
  StrandSet out = carry_guides(rest, posed, guides);
  rig.apply(frame, posed, out);
  return out;
}

}  // namespace plume::test
