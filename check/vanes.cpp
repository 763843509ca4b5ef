#include "check/vanes.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <Eigen/Geometry>
#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <tuple>

#include "groom/error.h"

namespace plume::check {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

Kernel::Triangle_3 to_cgal(const std::array<Eigen::Vector3d, 3> &t) {
  return {Kernel::Point_3(t[0].x(), t[0].y(), t[0].z()), Kernel::Point_3(t[1].x(), t[1].y(), t[1].z()),
          Kernel::Point_3(t[2].x(), t[2].y(), t[2].z())};
}

bool degenerate(const std::array<Eigen::Vector3d, 3> &t) {
  return (t[1] - t[0]).cross(t[2] - t[0]).squaredNorm() == 0.0;
}

/// A cell of the broad phase's grid, packed into 63 bits (21 per axis; coordinates are offsets from
/// the grid's corner, clamped).
uint64_t cell_key(int64_t x, int64_t y, int64_t z) {
  constexpr int64_t kMax = (int64_t(1) << 21) - 1;
  return (uint64_t(std::clamp<int64_t>(x, 0, kMax)) << 42) | (uint64_t(std::clamp<int64_t>(y, 0, kMax)) << 21) |
         uint64_t(std::clamp<int64_t>(z, 0, kMax));
}

}  // namespace

VaneCheckReport check_vanes(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3i> triangles,
                            std::span<const uint64_t> triangle_feathers, const VaneCheckOptions &options) {
  if (triangle_feathers.size() != triangles.size())
    throw InternalError("check_vanes: one feather id per triangle expected");
  VaneCheckReport report;
  const size_t n = triangles.size();
  report.triangles = n;
  if (n == 0) return report;
  for (const Eigen::Vector3i &t : triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || size_t(t[k]) >= positions.size()) throw InternalError("check_vanes: a vertex index out of range");

  // Feathers: runs of consecutive triangles with one id; each run's base and extent.
  std::vector<int64_t> feather_of(n);
  std::vector<Eigen::Vector3d> bases;
  std::vector<double> extents;
  for (size_t t = 0; t < n; ++t) {
    if (t == 0 || triangle_feathers[t] != triangle_feathers[t - 1]) {
      bases.push_back(positions[size_t(triangles[t][0])].cast<double>());
      extents.push_back(0.0);
    }
    feather_of[t] = int64_t(bases.size()) - 1;
    for (int k = 0; k < 3; ++k)
      extents.back() = std::max(extents.back(), (positions[size_t(triangles[t][k])].cast<double>() - bases.back()).norm());
  }
  report.feathers = bases.size();
  std::vector<double> sorted = extents;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  report.median_extent = sorted[sorted.size() / 2];
  const double eps = options.thickness * report.median_extent;
  report.thickness = eps;

  // Triangles in double, their boxes grown by the thickness, and whether each is in its root disc.
  std::vector<std::array<Eigen::Vector3d, 3>> corners(n);
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  std::vector<char> in_disc(n);
  Eigen::Vector3d all_lo = Eigen::Vector3d::Constant(INFINITY), all_hi = -all_lo;
  double size_sum = 0.0;
  for (size_t t = 0; t < n; ++t) {
    const int64_t f = feather_of[t];
    bool disc = true;
    for (int k = 0; k < 3; ++k) {
      corners[t][size_t(k)] = positions[size_t(triangles[t][k])].cast<double>();
      if (!corners[t][size_t(k)].allFinite()) throw InputError("vane meshes: a vertex is not finite");
      disc = disc && (corners[t][size_t(k)] - bases[size_t(f)]).norm() <= options.root_disc * extents[size_t(f)];
    }
    in_disc[t] = disc;
    lo[t] = corners[t][0].cwiseMin(corners[t][1]).cwiseMin(corners[t][2]).array() - 0.5 * eps;
    hi[t] = corners[t][0].cwiseMax(corners[t][1]).cwiseMax(corners[t][2]).array() + 0.5 * eps;
    all_lo = all_lo.cwiseMin(lo[t]);
    all_hi = all_hi.cwiseMax(hi[t]);
    size_sum += (hi[t] - lo[t]).maxCoeff();
  }
  // Each triangle's plane (unit normal and offset; none for a triangle too flat to have one) and a
  // bound of the rounding of a point's distance to it: a triangle whose three corners all lie farther
  // than the thickness plus that bound on one side of the other's plane can neither meet nor touch
  // it (it lies in the convex hull of its corners), so the exact tests are spared for it: the
  // answers are the same.
  std::vector<Eigen::Vector3d> plane_normals(n, Eigen::Vector3d::Zero());
  std::vector<double> plane_offsets(n, 0.0);
  for (size_t t = 0; t < n; ++t) {
    const Eigen::Vector3d e1 = corners[t][1] - corners[t][0], e2 = corners[t][2] - corners[t][0];
    const Eigen::Vector3d normal = e1.cross(e2);
    const double length = normal.norm();
    // A sliver's normal is ill-conditioned (its direction's rounding grows as 1 / sin of its angle):
    // only triangles whose sides meet at more than a micro-radian get a plane.
    if (!(length > 1e-6 * e1.norm() * e2.norm())) continue;
    plane_normals[t] = normal / length;
    plane_offsets[t] = -plane_normals[t].dot(corners[t][0]);
  }
  const double rounding = 1e-9 * std::max({all_lo.cwiseAbs().maxCoeff(), all_hi.cwiseAbs().maxCoeff(), eps});
  const auto apart = [&](size_t from, size_t other) {
    const Eigen::Vector3d &normal = plane_normals[from];
    if (normal.isZero()) return false;
    const double gap = eps + rounding;
    int above = 0, below = 0;
    for (int k = 0; k < 3; ++k) {
      const double d = normal.dot(corners[other][size_t(k)]) + plane_offsets[from];
      above += d > gap ? 1 : 0;
      below += d < -gap ? 1 : 0;
    }
    return above == 3 || below == 3;
  };
  // Cells about twice the mean triangle's size: a triangle touches a few cells.
  double cell = std::max(2.0 * size_sum / double(n), 1e-300);
  cell = std::max(cell, (all_hi - all_lo).maxCoeff() / double((1 << 21) - 2));
  std::vector<std::pair<uint64_t, int64_t>> entries;
  for (size_t t = 0; t < n; ++t) {
    const Eigen::Array3d a = ((lo[t] - all_lo) / cell).array().floor(), b = ((hi[t] - all_lo) / cell).array().floor();
    for (int64_t x = int64_t(a.x()); x <= int64_t(b.x()); ++x)
      for (int64_t y = int64_t(a.y()); y <= int64_t(b.y()); ++y)
        for (int64_t z = int64_t(a.z()); z <= int64_t(b.z()); ++z) entries.emplace_back(cell_key(x, y, z), int64_t(t));
  }
  std::sort(entries.begin(), entries.end());
  std::vector<size_t> cell_starts;
  for (size_t e = 0; e < entries.size(); ++e)
    if (e == 0 || entries[e].first != entries[e - 1].first) cell_starts.push_back(e);
  cell_starts.push_back(entries.size());

  struct Hit {
    int64_t fa, fb, ta, tb;
    bool intersects;
  };
  const int threads = omp_get_max_threads();
  std::vector<std::vector<Hit>> hits(size_t(std::max(threads, 1)));
  int64_t tested = 0;
#pragma omp parallel for schedule(dynamic, 64) reduction(+ : tested)
  for (int64_t c = 0; c < int64_t(cell_starts.size()) - 1; ++c) {
    std::vector<Hit> &mine = hits[size_t(omp_get_thread_num())];
    const size_t begin = cell_starts[size_t(c)], end = cell_starts[size_t(c) + 1];
    const uint64_t key = entries[begin].first;
    for (size_t i = begin; i < end; ++i)
      for (size_t j = i + 1; j < end; ++j) {
        int64_t ta = entries[i].second, tb = entries[j].second;
        if (feather_of[size_t(ta)] == feather_of[size_t(tb)]) continue;
        if (in_disc[size_t(ta)] || in_disc[size_t(tb)]) continue;
        const Eigen::Vector3d box_lo = lo[size_t(ta)].cwiseMax(lo[size_t(tb)]);
        const Eigen::Vector3d box_hi = hi[size_t(ta)].cwiseMin(hi[size_t(tb)]);
        if ((box_lo.array() > box_hi.array()).any()) continue;
        // The pair is judged in one cell only: the one holding its boxes' overlap's lower corner.
        const Eigen::Array3d corner = ((box_lo - all_lo) / cell).array().floor();
        if (cell_key(int64_t(corner.x()), int64_t(corner.y()), int64_t(corner.z())) != key) continue;
        ++tested;
        if (apart(size_t(ta), size_t(tb)) || apart(size_t(tb), size_t(ta))) continue;
        bool intersects = false, touches = false;
        const bool flat_a = degenerate(corners[size_t(ta)]), flat_b = degenerate(corners[size_t(tb)]);
        const Kernel::Triangle_3 a = to_cgal(corners[size_t(ta)]), b = to_cgal(corners[size_t(tb)]);
        if (!flat_a && !flat_b) intersects = CGAL::do_intersect(a, b);
        if (!intersects) {
          if (flat_a || flat_b) {
            // A triangle collapsed to a segment or a point: its vertices against the other
            // triangle (or its edges when that one is flat too), and the edges against each other.
            const auto &p = corners[size_t(flat_a ? ta : tb)], &q = corners[size_t(flat_a ? tb : ta)];
            const Kernel::Triangle_3 cp = to_cgal(p), cq = to_cgal(q);
            const bool both_flat = flat_a && flat_b;
            double d2 = INFINITY;
            for (int k = 0; k < 3; ++k) {
              if (!both_flat) d2 = std::min(d2, CGAL::to_double(CGAL::squared_distance(cp[k], cq)));
              const Kernel::Segment_3 s(cp[k], cp[(k + 1) % 3]);
              for (int m = 0; m < 3; ++m)
                d2 = std::min(d2, CGAL::to_double(CGAL::squared_distance(s, Kernel::Segment_3(cq[m], cq[(m + 1) % 3]))));
            }
            touches = d2 <= eps * eps;
          } else {
            touches = CGAL::to_double(CGAL::squared_distance(a, b)) <= eps * eps;
          }
        }
        if (!intersects && !touches) continue;
        int64_t fa = feather_of[size_t(ta)], fb = feather_of[size_t(tb)];
        if (triangle_feathers[size_t(ta)] > triangle_feathers[size_t(tb)]) {
          std::swap(fa, fb);
          std::swap(ta, tb);
        }
        mine.push_back({fa, fb, ta, tb, intersects});
      }
  }
  report.triangle_pairs_tested = tested;
  std::vector<Hit> all;
  for (const std::vector<Hit> &h : hits) all.insert(all.end(), h.begin(), h.end());
  std::sort(all.begin(), all.end(), [](const Hit &x, const Hit &y) {
    return std::tie(x.fa, x.fb, x.ta, x.tb) < std::tie(y.fa, y.fb, y.ta, y.tb);
  });
  for (size_t h = 0; h < all.size(); ++h) {
    (all[h].intersects ? report.intersecting_triangle_pairs : report.touching_triangle_pairs) += 1;
    if (h > 0 && all[h].fa == all[h - 1].fa && all[h].fb == all[h - 1].fb) continue;
    ++report.feather_pairs;
    if (report.examples.size() < options.max_examples)
      report.examples.push_back({triangle_feathers[size_t(all[h].ta)], triangle_feathers[size_t(all[h].tb)], all[h].ta,
                                 all[h].tb});
  }
  return report;
}

}  // namespace plume::check
