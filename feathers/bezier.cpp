#include "feathers/bezier.h"

#include <array>

#include "groom/error.h"

namespace plume::feathers {

namespace {

/// de Casteljau on N vertices, unrolled: the same operations in the same order as the loop below
/// (so the same bits), kept in registers. Through memory, each level's loads waited on the stores
/// of the level before.
template <size_t N>
Eigen::Vector3f de_casteljau(const Eigen::Vector3f *points, float u) {
  std::array<Eigen::Vector3f, N> work;
  for (size_t i = 0; i < N; ++i) work[i] = points[i];
  const float a = 1.0f - u;
  for (size_t level = N; level > 1; --level)
    for (size_t i = 0; i + 1 < level; ++i) work[i] = a * work[i] + u * work[i + 1];
  return work[0];
}

}  // namespace

Eigen::Vector3f bezier_point(std::span<const Eigen::Vector3f> points, float u) {
  // The cubics of barbs and rachises, and their derivatives' quadratics, in registers.
  if (points.size() == 4) return de_casteljau<4>(points.data(), u);
  if (points.size() == 3) return de_casteljau<3>(points.data(), u);
  std::array<Eigen::Vector3f, max_barb_control_points> work;
  const size_t n = points.size();
  for (size_t i = 0; i < n; ++i) work[i] = points[i];
  const float a = 1.0f - u;
  for (size_t level = n; level > 1; --level)
    for (size_t i = 0; i + 1 < level; ++i) work[i] = a * work[i] + u * work[i + 1];
  return work[0];
}

Eigen::Vector3f bezier_derivative(std::span<const Eigen::Vector3f> points, float u) {
  const size_t n = points.size();
  if (n < 2) return Eigen::Vector3f::Zero();
  std::array<Eigen::Vector3f, max_barb_control_points> differences;
  for (size_t i = 0; i + 1 < n; ++i) differences[i] = points[i + 1] - points[i];
  return float(n - 1) * bezier_point({differences.data(), n - 1}, u);
}

void elevate_degree(ControlPolygon &polygon) {
  if (polygon.count >= max_barb_control_points)
    throw InternalError("elevate_degree: a polygon already has the most vertices a barb may have");
  const int n = polygon.degree();
  // From the last vertex down, so each new vertex reads the old ones it needs before they change.
  polygon.points[size_t(n + 1)] = polygon.points[size_t(n)];
  for (int i = n; i >= 1; --i) {
    const float a = float(i) / float(n + 1);
    polygon.points[size_t(i)] = a * polygon.points[size_t(i - 1)] + (1.0f - a) * polygon.points[size_t(i)];
  }
  ++polygon.count;
}

void elevate_to(ControlPolygon &polygon, int count) {
  while (polygon.count < count) elevate_degree(polygon);
}

void bernstein_weights(int degree, float u, float *r_weights) {
  // The triangle of de Casteljau run on the unit vectors: each level splits every weight into its
  // (1 - u) and u parts, so the weights sum to 1 up to rounding.
  const float a = 1.0f - u;
  r_weights[0] = 1.0f;
  for (int level = 1; level <= degree; ++level) {
    r_weights[level] = u * r_weights[level - 1];
    for (int k = level - 1; k >= 1; --k) r_weights[k] = a * r_weights[k] + u * r_weights[k - 1];
    r_weights[0] *= a;
  }
}

}  // namespace plume::feathers
