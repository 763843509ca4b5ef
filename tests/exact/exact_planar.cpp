#include "exact/exact_planar.h"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/squared_distance_2.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace plume::test {

namespace {

/// Exact predicates: enough to decide whether two segments share a point.
using Predicates = CGAL::Exact_predicates_inexact_constructions_kernel;
/// Exact constructions: squared distances and dot products as exact numbers.
using Exact = CGAL::Exact_predicates_exact_constructions_kernel;

/// One segment's end points (float coordinates are exact in double) and its box.
struct Segment {
  std::array<double, 2> a, b;
  double low[2], high[2];
};

std::vector<std::vector<Segment>> segments_of(const StrandSet &strands) {
  std::vector<std::vector<Segment>> result(strands.strand_count());
  for (size_t s = 0; s < strands.strand_count(); ++s) {
    const auto points = strands.points(s);
    for (size_t j = 1; j < points.size(); ++j) {
      Segment segment;
      segment.a = {double(points[j - 1].x()), double(points[j - 1].y())};
      segment.b = {double(points[j].x()), double(points[j].y())};
      for (int k = 0; k < 2; ++k) {
        segment.low[k] = std::min(segment.a[size_t(k)], segment.b[size_t(k)]);
        segment.high[k] = std::max(segment.a[size_t(k)], segment.b[size_t(k)]);
      }
      result[s].push_back(segment);
    }
  }
  return result;
}

/// Whether the boxes of two segments are within `reach` of each other on both axes (a necessary
/// condition for the segments to be within `reach`; computed in double, so `reach` carries a slack).
bool boxes_near(const Segment &p, const Segment &q, double reach) {
  for (int k = 0; k < 2; ++k)
    if (p.low[k] > q.high[k] + reach || q.low[k] > p.high[k] + reach) return false;
  return true;
}

bool share_a_point(const Segment &p, const Segment &q) {
  const Predicates::Point_2 pa(p.a[0], p.a[1]), pb(p.b[0], p.b[1]), qa(q.a[0], q.a[1]), qb(q.b[0], q.b[1]);
  if (pa == pb && qa == qb) return pa == qa;
  if (pa == pb) return Predicates::Segment_2(qa, qb).has_on(pa);
  if (qa == qb) return Predicates::Segment_2(pa, pb).has_on(qa);
  return CGAL::do_intersect(Predicates::Segment_2(pa, pb), Predicates::Segment_2(qa, qb));
}

Exact::FT squared_distance(const Segment &p, const Segment &q) {
  const Exact::Point_2 pa(p.a[0], p.a[1]), pb(p.b[0], p.b[1]), qa(q.a[0], q.a[1]), qb(q.b[0], q.b[1]);
  if (pa == pb && qa == qb) return CGAL::squared_distance(pa, qa);
  if (pa == pb) return CGAL::squared_distance(pa, Exact::Segment_2(qa, qb));
  if (qa == qb) return CGAL::squared_distance(qa, Exact::Segment_2(pa, pb));
  return CGAL::squared_distance(Exact::Segment_2(pa, pb), Exact::Segment_2(qa, qb));
}

/// Whether the angle between the segments' lines has a cosine below `cos` in magnitude, decided
/// exactly against cos^2 x (its band factor): |d1 . d2|^2 < factor cos^2 |d1|^2 |d2|^2. A segment
/// without a length has no direction and is never transversal (as the checker rules).
bool angle_above(const Segment &p, const Segment &q, double cos, double factor) {
  const Exact::Vector_2 e1 = Exact::Point_2(p.b[0], p.b[1]) - Exact::Point_2(p.a[0], p.a[1]);
  const Exact::Vector_2 e2 = Exact::Point_2(q.b[0], q.b[1]) - Exact::Point_2(q.a[0], q.a[1]);
  const Exact::FT n1 = e1.squared_length(), n2 = e2.squared_length();
  if (n1 == 0 || n2 == 0) return false;
  const Exact::FT dot = e1 * e2;
  return dot * dot < Exact::FT(factor) * Exact::FT(cos) * Exact::FT(cos) * n1 * n2;
}

}  // namespace

std::vector<std::pair<uint32_t, uint32_t>> exact_intersecting_pairs(const StrandSet &strands) {
  const std::vector<std::vector<Segment>> segments = segments_of(strands);
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (size_t a = 0; a < segments.size(); ++a)
    for (size_t b = a + 1; b < segments.size(); ++b) {
      bool meet = false;
      for (size_t i = 0; i < segments[a].size() && !meet; ++i)
        for (size_t j = 0; j < segments[b].size() && !meet; ++j)
          meet = boxes_near(segments[a][i], segments[b][j], 0.0) && share_a_point(segments[a][i], segments[b][j]);
      if (meet) pairs.emplace_back(uint32_t(a), uint32_t(b));
    }
  return pairs;
}

ExactCrossings exact_crossings(const StrandSet &strands, double tolerance, double transversal_degrees, double band) {
  ExactCrossings result;
  result.intersecting_pairs = exact_intersecting_pairs(strands).size();
  const std::vector<std::vector<Segment>> segments = segments_of(strands);
  const Exact::FT tolerance_squared = Exact::FT(tolerance) * Exact::FT(tolerance);
  const Exact::FT sure_within = tolerance_squared * Exact::FT(1.0 - band);
  const Exact::FT maybe_within = tolerance_squared * Exact::FT(1.0 + band);
  const double cos = std::cos(transversal_degrees * 3.14159265358979323846 / 180.0);
  double scale = 0.0;
  for (const Eigen::Vector3f &p : strands.positions) scale = std::max(scale, double(p.cwiseAbs().maxCoeff()));
  const double reach = tolerance * (1.0 + band) + 1e-12 * scale;
  for (size_t a = 0; a < segments.size(); ++a)
    for (size_t b = a + 1; b < segments.size(); ++b) {
      if (segments[a].empty() || segments[b].empty()) continue;
      // The root rule: first segments are ignored when the roots are closer than the tolerance.
      const Exact::FT root_distance =
          CGAL::squared_distance(Exact::Point_2(segments[a][0].a[0], segments[a][0].a[1]),
                                 Exact::Point_2(segments[b][0].a[0], segments[b][0].a[1]));
      const bool roots_sure_close = root_distance < sure_within, roots_maybe_close = root_distance < maybe_within;
      bool within_sure = false, within_maybe = false, transversal_sure = false, transversal_maybe = false;
      for (size_t i = 0; i < segments[a].size(); ++i)
        for (size_t j = 0; j < segments[b].size(); ++j) {
          if (!boxes_near(segments[a][i], segments[b][j], reach)) continue;
          const bool at_root = i == 0 || j == 0;
          if (at_root && roots_sure_close) continue;
          const Exact::FT d = squared_distance(segments[a][i], segments[b][j]);
          if (!(d <= maybe_within)) continue;
          // A pair exempt or not depending on rounding of the roots' distance is uncertain.
          const bool sure = d <= sure_within && !(at_root && roots_maybe_close);
          within_maybe = true;
          const bool above_maybe = angle_above(segments[a][i], segments[b][j], cos, 1.0 + band);
          transversal_maybe = transversal_maybe || above_maybe;
          if (sure) {
            within_sure = true;
            transversal_sure = transversal_sure || angle_above(segments[a][i], segments[b][j], cos, 1.0 - band);
          }
        }
      if (!within_maybe) continue;
      if (!within_sure || transversal_sure != transversal_maybe) {
        ++result.uncertain_pairs;
        continue;
      }
      ++result.pairs;
      ++(transversal_sure ? result.transversal_pairs : result.touching_pairs);
    }
  return result;
}

}  // namespace plume::test
