#include "check/feather_motion.h"

#include <Eigen/SVD>

#include <algorithm>
#include <cmath>
#include <vector>

#include "groom/error.h"

namespace plume::check {

namespace {

void check_layout(size_t a, size_t b, std::span<const int64_t> first_vertex, size_t per_feather_a, size_t per_feather_b,
                  const char *what) {
  if (first_vertex.empty() || per_feather_a != first_vertex.size() - 1 || per_feather_b != first_vertex.size() - 1 ||
      first_vertex.front() < 0 || size_t(first_vertex.back()) > std::min(a, b))
    throw InternalError(std::string(what) + ": the feathers' layouts do not match");
}

}  // namespace

Popping popping(std::span<const Eigen::Vector3f> previous, std::span<const Eigen::Vector3f> current,
                std::span<const int64_t> first_vertex, std::span<const SurfaceFrame> previous_frames,
                std::span<const SurfaceFrame> current_frames, std::span<const float> rachis_widths,
                std::span<const uint64_t> ids) {
  check_layout(previous.size(), current.size(), first_vertex, previous_frames.size(), current_frames.size(), "popping");
  check_layout(previous.size(), current.size(), first_vertex, rachis_widths.size(), ids.size(), "popping");
  const size_t n = first_vertex.size() - 1;
  std::vector<double> jumps(n, 0.0);
#pragma omp parallel for schedule(static)
  for (int64_t f = 0; f < int64_t(n); ++f) {
    const SurfaceFrame &a = previous_frames[size_t(f)], &b = current_frames[size_t(f)];
    double jump = 0.0;
    for (int64_t v = first_vertex[size_t(f)]; v < first_vertex[size_t(f) + 1]; ++v) {
      const Eigen::Vector3d before = (a.basis.cast<double>().transpose() * (previous[size_t(v)] - a.origin).cast<double>());
      const Eigen::Vector3d now = (b.basis.cast<double>().transpose() * (current[size_t(v)] - b.origin).cast<double>());
      jump = std::max(jump, (now - before).norm());
    }
    jumps[size_t(f)] = jump;
  }
  Popping result;
  result.feathers = int64_t(n);
  double sum = 0.0;
  for (size_t f = 0; f < n; ++f) {
    const double widths = jumps[f] / double(rachis_widths[f]);
    sum += widths;
    if (widths > result.largest) {
      result.largest = widths;
      result.largest_distance = jumps[f];
      result.worst_feather = ids[f];
    }
  }
  result.mean = n ? sum / double(n) : 0.0;
  return result;
}

ShapeDrift shape_drift(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3f> template_positions,
                       std::span<const int64_t> first_vertex, std::span<const float> lengths,
                       std::span<const uint64_t> ids) {
  check_layout(positions.size(), template_positions.size(), first_vertex, lengths.size(), ids.size(), "shape_drift");
  const size_t n = first_vertex.size() - 1;
  std::vector<double> drift(n, 0.0);
#pragma omp parallel for schedule(static)
  for (int64_t f = 0; f < int64_t(n); ++f) {
    const int64_t v0 = first_vertex[size_t(f)], v1 = first_vertex[size_t(f) + 1];
    if (v1 - v0 < 1) continue;
    // Kabsch: the rotation R and translation minimising sum |R (t - ct) + cp - p|^2, from the SVD of
    // the covariance H = sum (t - ct)(p - cp)^T = U S V^T: R = V diag(1, 1, det(V U^T)) U^T.
    Eigen::Vector3d cp = Eigen::Vector3d::Zero(), ct = Eigen::Vector3d::Zero();
    for (int64_t v = v0; v < v1; ++v) {
      cp += positions[size_t(v)].cast<double>();
      ct += template_positions[size_t(v)].cast<double>();
    }
    cp /= double(v1 - v0);
    ct /= double(v1 - v0);
    Eigen::Matrix3d h = Eigen::Matrix3d::Zero();
    for (int64_t v = v0; v < v1; ++v)
      h += (template_positions[size_t(v)].cast<double>() - ct) * (positions[size_t(v)].cast<double>() - cp).transpose();
    const Eigen::JacobiSVD<Eigen::Matrix3d> svd(h, Eigen::ComputeFullU | Eigen::ComputeFullV);
    Eigen::Matrix3d d = Eigen::Matrix3d::Identity();
    d(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
    const Eigen::Matrix3d r = svd.matrixV() * d * svd.matrixU().transpose();
    double largest = 0.0;
    for (int64_t v = v0; v < v1; ++v)
      largest = std::max(largest, (r * (template_positions[size_t(v)].cast<double>() - ct) + cp -
                                   positions[size_t(v)].cast<double>()).norm());
    drift[size_t(f)] = largest / double(lengths[size_t(f)]);
  }
  ShapeDrift result;
  result.feathers = int64_t(n);
  double sum = 0.0;
  for (size_t f = 0; f < n; ++f) {
    sum += drift[f];
    if (drift[f] > result.largest) {
      result.largest = drift[f];
      result.worst_feather = ids[f];
    }
  }
  result.mean = n ? sum / double(n) : 0.0;
  return result;
}

}  // namespace plume::check
