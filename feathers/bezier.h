// Bezier curves as feathers use them: evaluation, degree elevation and small fixed-capacity control
// polygons that live on the stack (no allocation per barb).
#pragma once

#include <Eigen/Core>
#include <array>
#include <span>

#include "groom/feather_desc.h"

namespace plume::feathers {

/// A control polygon of at most max_barb_control_points vertices: count - 1 is the curve's degree.
struct ControlPolygon {
  int count = 0;
  std::array<Eigen::Vector3f, max_barb_control_points> points;

  int degree() const { return count - 1; }
  std::span<const Eigen::Vector3f> view() const { return {points.data(), size_t(count)}; }
};

/// The point at parameter u in [0, 1] (de Casteljau: convex combinations only, so the curve stays in
/// the hull of its polygon and u = 0, 1 give the end vertices exactly). `points` holds 1 to
/// max_barb_control_points vertices.
Eigen::Vector3f bezier_point(std::span<const Eigen::Vector3f> points, float u);

/// The derivative d/du at u: n times the curve of the differences of consecutive vertices.
Eigen::Vector3f bezier_derivative(std::span<const Eigen::Vector3f> points, float u);

/// Degree elevation (Farin): the same curve with one more control vertex. For degree n with
/// vertices cv_0 .. cv_n, the new vertices are cv'_0 = cv_0, cv'_{n+1} = cv_n and
///   cv'_i = i / (n + 1) * cv_{i-1} + (1 - i / (n + 1)) * cv_i,   i = 1 .. n.
/// (Seed 001 sec. 4.2.1; it follows from (1 - u + u) B^n_i(u) = the two degree-(n+1) Bernstein terms
/// it feeds.) `polygon` must have fewer than max_barb_control_points vertices.
void elevate_degree(ControlPolygon &polygon);

/// Elevates `polygon` until it has `count` vertices (count >= polygon.count).
void elevate_to(ControlPolygon &polygon, int count);

/// Bernstein weights B^n_k(u) for k = 0 .. n, into r_weights[0 .. n]; n < max_barb_control_points.
void bernstein_weights(int degree, float u, float *r_weights);

}  // namespace plume::feathers
