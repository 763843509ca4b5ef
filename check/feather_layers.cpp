#include "check/feather_layers.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>
#include <omp.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iterator>

#include "groom/error.h"

namespace plume::check {

namespace {

using Kernel = CGAL::Simple_cartesian<double>;
using TriangleIterator = std::vector<Kernel::Triangle_3>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

Kernel::Point_3 to_cgal(const Eigen::Vector3d &p) { return {p.x(), p.y(), p.z()}; }

/// Where the segment origin + t * direction (t in [0, 1]) crosses triangle abc, or -1 (Moller and
/// Trumbore, in double; a segment in the triangle's plane does not cross it).
double crossing(const Eigen::Vector3d &origin, const Eigen::Vector3d &direction, const Eigen::Vector3d &a,
                const Eigen::Vector3d &b, const Eigen::Vector3d &c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, h = direction.cross(e2);
  const double det = e1.dot(h);
  if (!(std::abs(det) > 0.0)) return -1.0;
  const Eigen::Vector3d s = origin - a;
  const double u = s.dot(h) / det;
  if (u < 0.0 || u > 1.0) return -1.0;
  const Eigen::Vector3d q = s.cross(e1);
  const double v = direction.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return -1.0;
  const double t = e2.dot(q) / det;
  return t >= 0.0 && t <= 1.0 ? t : -1.0;
}

}  // namespace

VaneOverlaps vane_overlaps(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3i> triangles,
                           std::span<const uint64_t> triangle_feathers, const Mesh &skin, const MeshQuery &skin_query,
                           const OverlapOptions &options) {
  if (triangle_feathers.size() != triangles.size())
    throw InternalError("vane_overlaps: one feather id per triangle expected");
  VaneOverlaps result;
  const size_t n = triangles.size();
  if (n == 0) return result;
  for (const Eigen::Vector3i &t : triangles)
    for (int k = 0; k < 3; ++k)
      if (t[k] < 0 || size_t(t[k]) >= positions.size()) throw InternalError("vane_overlaps: a vertex index out of range");

  // Feathers: runs of consecutive triangles with one id, each with its base, extent and vertices.
  std::vector<int64_t> first_triangle;
  for (size_t t = 0; t < n; ++t)
    if (t == 0 || triangle_feathers[t] != triangle_feathers[t - 1]) first_triangle.push_back(int64_t(t));
  first_triangle.push_back(int64_t(n));
  const size_t feathers = first_triangle.size() - 1;
  std::vector<Eigen::Vector3d> bases(feathers);
  std::vector<double> extents(feathers, 0.0);
  std::vector<std::vector<int32_t>> vertices(feathers);
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t f = 0; f < int64_t(feathers); ++f) {
    std::vector<int32_t> &mine = vertices[size_t(f)];
    for (int64_t t = first_triangle[size_t(f)]; t < first_triangle[size_t(f) + 1]; ++t)
      for (int k = 0; k < 3; ++k) mine.push_back(triangles[size_t(t)][k]);
    std::sort(mine.begin(), mine.end());
    mine.erase(std::unique(mine.begin(), mine.end()), mine.end());
    bases[size_t(f)] = positions[size_t(triangles[size_t(first_triangle[size_t(f)])][0])].cast<double>();
    for (const int32_t v : mine)
      extents[size_t(f)] = std::max(extents[size_t(f)], (positions[size_t(v)].cast<double>() - bases[size_t(f)]).norm());
  }
  std::vector<double> sorted = extents;
  std::nth_element(sorted.begin(), sorted.begin() + long(sorted.size() / 2), sorted.end());
  result.median_extent = sorted[sorted.size() / 2];
  const double eps = options.thickness * result.median_extent;
  const double reach = *std::max_element(extents.begin(), extents.end());
  if (!(reach > 0.0)) return result;  // every vane collapsed onto its base
  const auto in_disc = [&](size_t f, const Eigen::Vector3d &p) {
    return (p - bases[f]).norm() <= options.root_disc * extents[f];
  };

  // One tree over the vane triangles outside their root discs, then the skin's triangles.
  std::vector<Kernel::Triangle_3> stored;
  std::vector<int64_t> stored_feather;  // per stored triangle: its feather, or -1 for the skin
  for (size_t f = 0; f < feathers; ++f)
    for (int64_t t = first_triangle[f]; t < first_triangle[f + 1]; ++t) {
      std::array<Eigen::Vector3d, 3> c;
      bool disc = true;
      for (int k = 0; k < 3; ++k) {
        c[size_t(k)] = positions[size_t(triangles[size_t(t)][k])].cast<double>();
        if (!c[size_t(k)].allFinite()) throw InputError("vane meshes: a vertex is not finite");
        disc = disc && in_disc(f, c[size_t(k)]);
      }
      if (disc || !((c[1] - c[0]).cross(c[2] - c[0]).squaredNorm() > 0.0)) continue;
      stored.emplace_back(to_cgal(c[0]), to_cgal(c[1]), to_cgal(c[2]));
      stored_feather.push_back(int64_t(f));
    }
  for (size_t f = 0; f < skin.triangle_count(); ++f) {
    if (!(skin.triangle_area(f) > 0.0)) continue;
    const Eigen::Vector3i &t = skin.triangles[f];
    stored.emplace_back(to_cgal(skin.positions[size_t(t[0])].cast<double>()),
                        to_cgal(skin.positions[size_t(t[1])].cast<double>()),
                        to_cgal(skin.positions[size_t(t[2])].cast<double>()));
    stored_feather.push_back(-1);
  }
  if (stored.empty()) return result;
  Tree tree(stored.cbegin(), stored.cend());
  tree.build();

  std::vector<std::vector<int64_t>> outer_of(feathers);  // per feather: the feathers outer to it
  int64_t samples = 0;
#pragma omp parallel for schedule(dynamic, 8) reduction(+ : samples)
  for (int64_t fi = 0; fi < int64_t(feathers); ++fi) {
    const size_t f = size_t(fi);
    std::vector<Primitive::Id> primitives;
    std::vector<std::pair<double, int64_t>> hits;  // (t, feather or -1 for the skin entered)
    std::vector<int64_t> &outer = outer_of[f];
    for (const int32_t v : vertices[f]) {
      const Eigen::Vector3d p = positions[size_t(v)].cast<double>();
      if (in_disc(f, p)) continue;
      const Eigen::Vector3d normal = surface_normal(skin, skin_query.closest(positions[size_t(v)])).cast<double>();
      const Eigen::Vector3d direction = reach * normal;
      ++samples;
      primitives.clear();
      tree.all_intersected_primitives(Kernel::Segment_3(to_cgal(p), to_cgal(p + direction)),
                                      std::back_inserter(primitives));
      hits.clear();
      for (const Primitive::Id &id : primitives) {
        const size_t k = size_t(std::distance(stored.cbegin(), id));
        const int64_t g = stored_feather[k];
        if (g == int64_t(f)) continue;
        const Kernel::Triangle_3 &tri = stored[k];
        const Eigen::Vector3d a(tri[0].x(), tri[0].y(), tri[0].z()), b(tri[1].x(), tri[1].y(), tri[1].z()),
            c(tri[2].x(), tri[2].y(), tri[2].z());
        const double t = crossing(p, direction, a, b, c);
        if (t < 0.0) continue;
        if (g < 0) {
          // The skin stops the way out where the segment enters it (against its outward normal).
          if ((b - a).cross(c - a).dot(direction) < 0.0) hits.emplace_back(t, -1);
          continue;
        }
        const double along = t * reach;
        if (along > eps && along <= extents[size_t(g)]) hits.emplace_back(t, g);
      }
      std::sort(hits.begin(), hits.end());
      for (const auto &[t, g] : hits) {
        if (g < 0) break;
        outer.push_back(g);
      }
    }
    std::sort(outer.begin(), outer.end());
    outer.erase(std::unique(outer.begin(), outer.end()), outer.end());
  }
  result.samples = samples;
  for (size_t f = 0; f < feathers; ++f)
    for (const int64_t g : outer_of[f])
      result.over.push_back({triangle_feathers[size_t(first_triangle[f])], triangle_feathers[size_t(first_triangle[size_t(g)])]});
  std::sort(result.over.begin(), result.over.end());
  result.over.erase(std::unique(result.over.begin(), result.over.end()), result.over.end());
  return result;
}

namespace {

/// Per unordered feather pair (a < b): whether a was seen over b, and b over a.
struct PairWays {
  uint64_t a = 0, b = 0;
  bool a_over = false, b_over = false;
};

std::vector<PairWays> pair_ways(const VaneOverlaps &overlaps) {
  std::vector<PairWays> ways;
  ways.reserve(overlaps.over.size());
  for (const Overlap &o : overlaps.over) {
    if (o.inner == o.outer) continue;
    const bool outer_first = o.outer < o.inner;
    ways.push_back({std::min(o.inner, o.outer), std::max(o.inner, o.outer), outer_first, !outer_first});
  }
  std::sort(ways.begin(), ways.end(), [](const PairWays &x, const PairWays &y) {
    return x.a < y.a || (x.a == y.a && x.b < y.b);
  });
  std::vector<PairWays> merged;
  for (const PairWays &w : ways) {
    if (!merged.empty() && merged.back().a == w.a && merged.back().b == w.b) {
      merged.back().a_over = merged.back().a_over || w.a_over;
      merged.back().b_over = merged.back().b_over || w.b_over;
    } else {
      merged.push_back(w);
    }
  }
  return merged;
}

}  // namespace

LayerOrderReport layer_order_violations(const VaneOverlaps &overlaps, const std::unordered_map<uint64_t, int64_t> &rank,
                                        size_t max_examples) {
  LayerOrderReport report;
  for (const PairWays &w : pair_ways(overlaps)) {
    ++report.overlapping_pairs;
    const auto ra = rank.find(w.a), rb = rank.find(w.b);
    if (ra == rank.end() || rb == rank.end()) {
      ++report.unranked_pairs;
      continue;
    }
    // The order puts `high` above `low`; the pair is wrong when low was seen over high.
    const bool a_high = ra->second > rb->second;
    const bool low_over = a_high ? w.b_over : w.a_over;
    if (!low_over) continue;
    ++report.violations;
    if (report.examples.size() < max_examples)
      report.examples.emplace_back(a_high ? w.b : w.a, a_high ? w.a : w.b);
  }
  return report;
}

OrderFlips order_flips(const VaneOverlaps &previous, const VaneOverlaps &current, size_t max_examples) {
  OrderFlips flips;
  const std::vector<PairWays> before = pair_ways(previous), now = pair_ways(current);
  size_t i = 0;
  for (const PairWays &w : now) {
    while (i < before.size() && (before[i].a < w.a || (before[i].a == w.a && before[i].b < w.b))) ++i;
    if (i == before.size() || before[i].a != w.a || before[i].b != w.b) continue;
    const PairWays &b = before[i];
    ++flips.pairs_in_both;
    if (b.a_over && !b.b_over && w.b_over) {
      ++flips.flips;
      if (flips.examples.size() < max_examples) flips.examples.emplace_back(w.a, w.b);
    } else if (b.b_over && !b.a_over && w.a_over) {
      ++flips.flips;
      if (flips.examples.size() < max_examples) flips.examples.emplace_back(w.b, w.a);
    }
  }
  return flips;
}

}  // namespace plume::check
