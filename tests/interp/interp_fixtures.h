// Meshes, guides and measures built in code for the interpolation tests.
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/segment_distance.h"
#include "groom/strand_set.h"
#include "groom/test_fixtures.h"
#include "interp/interpolate.h"

namespace plume::test {

/// A square grid in the XY plane, z = 0, normal +z, side `size` centred at the origin.
inline Mesh make_plane(float size, int cells) {
  Mesh mesh;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      mesh.positions.emplace_back(size * (float(i) / float(cells) - 0.5f), size * (float(j) / float(cells) - 0.5f),
                                  0.0f);
  auto index = [&](int i, int j) { return j * (cells + 1) + i; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j), index(i + 1, j + 1));
      mesh.triangles.emplace_back(index(i, j), index(i + 1, j + 1), index(i, j + 1));
    }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

/// Roots snapped from points, ids 0..n-1.
inline Roots roots_at(const MeshQuery &query, const std::vector<Eigen::Vector3f> &points) {
  Roots roots;
  for (size_t i = 0; i < points.size(); ++i) {
    roots.points.push_back(query.closest(points[i]));
    roots.ids.push_back(i);
  }
  return roots;
}

/// The roots of the guides themselves (same surface points).
inline Roots roots_of(const Guides &guides) {
  Roots roots;
  roots.points = guides.roots;
  for (size_t i = 0; i < guides.size(); ++i) roots.ids.push_back(i);
  return roots;
}

/// A guide that starts on the surface at the closest point to `near` and follows `shape(s)`, a
/// function of arc length s in [0, length] giving the offset in the root's (tangent, bitangent,
/// normal) frame; `points` samples evenly spaced in s.
inline std::vector<Eigen::Vector3f> guide_curve(const Mesh &mesh, const MeshQuery &query, const Eigen::Vector3f &near,
                                                float length, int points,
                                                const std::function<Eigen::Vector3f(float)> &shape) {
  const SurfaceFrame frame = surface_frame(mesh, query.closest(near));
  std::vector<Eigen::Vector3f> curve;
  for (int i = 0; i < points; ++i) curve.push_back(frame.to_world(shape(length * float(i) / float(points - 1))));
  return curve;
}

/// A planar arc of curvature `kappa`, leaving along the normal and bending towards the tangent.
inline std::function<Eigen::Vector3f(float)> arc_shape(float kappa) {
  return [kappa](float s) {
    return Eigen::Vector3f((1.0f - std::cos(kappa * s)) / kappa, 0.0f, std::sin(kappa * s) / kappa);
  };
}

/// Largest distance between strand i and strand j of two sets, points paired by index.
inline float max_point_distance(const StrandSet &a, size_t i, const StrandSet &b, size_t j) {
  float worst = 0.0f;
  for (int64_t p = 0; p < a.points_in(i); ++p) worst = std::max(worst, (a.points(i)[p] - b.points(j)[p]).norm());
  return worst;
}

inline float segment_distance(const Eigen::Vector3f &p0, const Eigen::Vector3f &p1, const Eigen::Vector3f &q0,
                              const Eigen::Vector3f &q1) {
  return float(std::sqrt(segment_distance_squared(p0, p1, q0, q1)));
}

/// Non-root points with a negative signed distance to the skin.
inline size_t count_inside(const MeshQuery &query, const StrandSet &strands, float tolerance = 0.0f) {
  size_t inside = 0;
  for (size_t s = 0; s < strands.strand_count(); ++s)
    for (size_t p = 1; p < size_t(strands.points_in(s)); ++p)
      inside += query.signed_distance(strands.points(s)[p]) < -tolerance;
  return inside;
}

inline bool all_finite(const StrandSet &strands) {
  return std::all_of(strands.positions.begin(), strands.positions.end(),
                     [](const Eigen::Vector3f &p) { return p.allFinite(); });
}

}  // namespace plume::test
