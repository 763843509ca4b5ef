#include "check/check.h"

#include <nanoflann.hpp>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <utility>

#include "groom/error.h"
#include "groom/guide_curve.h"

namespace plume::check {

namespace {

using Eigen::Vector3f;

float mesh_diagonal(const Mesh &mesh) {
  if (mesh.positions.empty()) return 0.0f;
  Eigen::AlignedBox3f box;
  for (const Vector3f &p : mesh.positions) box.extend(p);
  return box.diagonal().norm();
}

uint64_t id_of(const StrandSet &strands, size_t s) { return strands.ids.size() == strands.strand_count() ? strands.ids[s] : s; }

/// Cumulative arc lengths of a polyline (first entry 0).
std::vector<double> arc_lengths(std::span<const Vector3f> points) {
  std::vector<double> arc(points.size(), 0.0);
  for (size_t i = 1; i < points.size(); ++i) arc[i] = arc[i - 1] + double((points[i] - points[i - 1]).norm());
  return arc;
}

/// Distance from `p` to the stretch of the polyline `points` (cumulative arcs `arc`) between arc
/// lengths `from` and `to` (clamped to the polyline).
double distance_to_stretch(const Vector3f &p, std::span<const Vector3f> points, const std::vector<double> &arc,
                           double from, double to) {
  from = std::clamp(from, 0.0, arc.back());
  to = std::clamp(to, from, arc.back());
  double best = std::numeric_limits<double>::infinity();
  const Eigen::Vector3d q = p.cast<double>();
  for (size_t k = 0; k + 1 < points.size(); ++k) {
    if (arc[k + 1] < from || arc[k] > to) continue;
    const double length = arc[k + 1] - arc[k];
    const Eigen::Vector3d a = points[k].cast<double>(), d = (points[k + 1] - points[k]).cast<double>();
    const double t0 = length > 0.0 ? std::max(0.0, (from - arc[k]) / length) : 0.0;
    const double t1 = length > 0.0 ? std::min(1.0, (to - arc[k]) / length) : 0.0;
    const double dd = d.squaredNorm();
    const double t = dd > 0.0 ? std::clamp((q - a).dot(d) / dd, t0, t1) : t0;
    best = std::min(best, (a + t * d - q).norm());
  }
  if (!std::isfinite(best)) best = (points.back().cast<double>() - q).norm();
  return best;
}

/// nanoflann adaptor over the strands' first points.
struct RootCloud {
  std::vector<Vector3f> points;
  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return points[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box &) const {
    return false;
  }
};
using RootTree =
    nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, RootCloud>, RootCloud, 3, uint32_t>;

std::string count_text(size_t count, const char *one, const char *many) {
  return std::to_string(count) + " " + (count == 1 ? one : many);
}

}  // namespace

float crossing_tolerance_for(const StrandSet &strands, const CheckOptions &options) {
  if (options.crossing_tolerance > 0.0f) return options.crossing_tolerance;
  const float tolerance = float(kToleranceOfMedianSegment * median_segment_length(strands));
  if (!(tolerance > 0.0f))
    throw InputError("the strands have no segment of non-zero length: no crossing tolerance can be derived from them "
                     "(give one)");
  return tolerance;
}

float root_tolerance_for(const Mesh &mesh, const CheckOptions &options) {
  return options.root_tolerance > 0.0f ? options.root_tolerance : float(kRootToleranceOfDiagonal) * mesh_diagonal(mesh);
}

size_t count_points_inside(const StrandSet &strands, const MeshQuery &query, float skin_margin, size_t max_examples,
                           std::vector<uint64_t> &r_examples) {
  const float eps = 1e-5f * mesh_diagonal(query.mesh());
  const int64_t strand_count = int64_t(strands.strand_count());
  std::vector<uint32_t> inside_per_strand(size_t(strand_count), 0);
  // The unsigned distance to the skin is 1-Lipschitz and a strand can only get inside by passing
  // through the skin, so after a point at distance d outside, the following points within
  // d - margin of travel along the strand are outside and need no query. (On an open mesh this
  // defines "inside" as "reached through the skin": a point far behind an open border that the
  // strand reached without touching the skin is outside.)
#pragma omp parallel for schedule(dynamic, 256)
  for (int64_t s = 0; s < strand_count; ++s) {
    const auto points = strands.points(size_t(s));
    uint32_t inside = 0;
    float free_travel = 0.0f;  // distance the next points may move and stay surely outside
    for (size_t j = 0; j < points.size(); ++j) {
      const float threshold = (j == 0 ? 0.0f : skin_margin) - eps;
      if (j > 0) {
        free_travel -= (points[j] - points[j - 1]).norm();
        if (free_travel > 0.0f) continue;
      }
      const float d = query.signed_distance(points[j]);
      if (d < threshold) ++inside;
      free_travel = d - std::max(skin_margin, 0.0f) - eps;
    }
    inside_per_strand[size_t(s)] = inside;
  }
  size_t total = 0;
  r_examples.clear();
  for (size_t s = 0; s < size_t(strand_count); ++s) {
    total += inside_per_strand[s];
    if (inside_per_strand[s] && r_examples.size() < max_examples) r_examples.push_back(id_of(strands, s));
  }
  std::sort(r_examples.begin(), r_examples.end());
  return total;
}

size_t count_cross_zone_influences(const PartingField &partings, const Roots &roots, const Binding &binding,
                                   size_t max_examples, std::vector<uint64_t> &r_examples) {
  if (binding.root_count() != roots.size())
    throw InternalError("count_cross_zone_influences: the binding has " + std::to_string(binding.root_count()) +
                        " roots, given " + std::to_string(roots.size()));
  size_t count = 0;
  r_examples.clear();
  for (size_t r = 0; r < roots.size(); ++r) {
    const int zone = partings.zone_of(roots.points[r]);
    bool counted = false;
    for (int s = 0; s < binding.k; ++s) {
      const size_t slot = r * size_t(binding.k) + size_t(s);
      const int32_t guide = binding.guide_ids[slot];
      if (guide < 0 || binding.weights[slot] <= 0.0f || partings.guide_zone(size_t(guide)) == zone) continue;
      ++count;
      if (!counted && r_examples.size() < max_examples) r_examples.push_back(roots.ids[r]);
      counted = true;
    }
  }
  return count;
}

double guide_deviation(std::span<const Vector3f> strand, const Vector3f &guide_start, std::span<const Vector3f> guide,
                       double &r_guide_length) {
  // The guide joined to the strand's root.
  std::vector<Vector3f> joined;
  joined.reserve(guide.size() + 1);
  if (guide.empty() || guide.front() != guide_start) joined.push_back(guide_start);
  joined.insert(joined.end(), guide.begin(), guide.end());
  const std::vector<double> guide_arc = arc_lengths(joined), strand_arc = arc_lengths(strand);
  r_guide_length = guide_arc.back();
  if (strand.empty()) return 0.0;
  const double strand_length = strand_arc.back();
  const double stretch = strand_length > 0.0 ? r_guide_length / strand_length : 0.0;
  double worst = std::max((strand.front() - joined.front()).cast<double>().norm(),
                          (strand.back() - joined.back()).cast<double>().norm());
  for (size_t j = 1; j + 1 < strand.size(); ++j) {
    const double at = strand_arc[j] * stretch;
    const double reach = std::max(strand_arc[j] - strand_arc[j - 1], strand_arc[j + 1] - strand_arc[j]) * stretch;
    worst = std::max(worst, distance_to_stretch(strand[j], joined, guide_arc, at - reach, at + reach));
  }
  return worst;
}

GuideDeviation measure_guide_deviation(const StrandSet &strands, const Roots *strand_roots, const MeshQuery &query,
                                       const Guides &guides, float root_tolerance, double limit, float skin_band,
                                       size_t max_examples) {
  const Mesh &mesh = query.mesh();
  GuideDeviation result;
  result.skin_band = skin_band;
  const size_t guide_count = guides.strands.strand_count();
  if (guides.roots.size() != guide_count)
    throw InternalError("measure_guide_deviation: " + std::to_string(guides.roots.size()) + " guide roots for " +
                        std::to_string(guide_count) + " guides");
  // The guide of each strand rooted at a guide root (strands_at_roots()), or at a guide's first point.
  std::vector<int64_t> guide_of(strands.strand_count(), -1);
  const std::vector<int64_t> on_line = strands_at_roots(strands, strand_roots, mesh, guides.roots, root_tolerance);
  for (size_t g = 0; g < guide_count; ++g)
    if (on_line[g] >= 0 && guide_of[size_t(on_line[g])] < 0) guide_of[size_t(on_line[g])] = int64_t(g);
  const int64_t strand_count = int64_t(strands.strand_count());
#pragma omp parallel for schedule(dynamic, 256)
  for (int64_t s = 0; s < strand_count; ++s) {
    if (guide_of[size_t(s)] >= 0 || strands.points_in(size_t(s)) == 0) continue;
    const Vector3f &root = strands.points(size_t(s)).front();
    for (size_t g = 0; g < guide_count && guide_of[size_t(s)] < 0; ++g)
      if (guides.strands.points_in(g) > 0 && (guides.strands.points(g).front() - root).norm() <= root_tolerance)
        guide_of[size_t(s)] = int64_t(g);
  }
  // Each guide as the curve through its points that Plume's growth follows (groom/guide_curve.h),
  // sampled as growth samples it: a strand whose points lie on that curve deviates by nothing, where
  // it leaves the guide's chords by their sag. A guide that runs low (guide_runs_low) is counted apart.
  std::vector<std::vector<Vector3f>> curves(guide_count);
  std::vector<uint8_t> used(guide_count, 0), low(guide_count, 0);
  for (const int64_t g : guide_of)
    if (g >= 0) used[size_t(g)] = 1;
  const float tiny = curve_merge_fraction * float(median_segment_length(guides.strands));
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t g = 0; g < int64_t(guide_count); ++g) {
    if (!used[size_t(g)]) continue;
    const auto points = guides.strands.points(size_t(g));
    std::vector<CurvePiece> pieces;
    guide_curve(points, tiny, pieces);
    curves[size_t(g)] = pieces.empty() ? std::vector<Vector3f>(points.begin(), points.end())
                                       : sample_curve(pieces, guide_curve_samples_per_piece);
    low[size_t(g)] = guide_runs_low(curves[size_t(g)], query, skin_band);
  }
  std::vector<double> deviation(size_t(strand_count), -1.0), relative(size_t(strand_count), 0.0);
#pragma omp parallel for schedule(dynamic, 64)
  for (int64_t s = 0; s < strand_count; ++s) {
    if (guide_of[size_t(s)] < 0) continue;
    const auto points = strands.points(size_t(s));
    double length = 0.0;
    deviation[size_t(s)] = guide_deviation(points, points.front(), curves[size_t(guide_of[size_t(s)])], length);
    relative[size_t(s)] = length > 0.0 ? deviation[size_t(s)] / length : 0.0;
  }
  size_t held = 0;
  for (size_t s = 0; s < size_t(strand_count); ++s) {
    if (deviation[s] < 0.0) continue;
    ++result.strands_at_guide_roots;
    if (low[size_t(guide_of[s])]) {
      if (relative[s] > result.near_skin_largest_relative || result.near_skin == 0) {
        result.near_skin_largest_relative = relative[s];
        result.near_skin_worst_strand = id_of(strands, s);
      }
      ++result.near_skin;
      continue;
    }
    ++held;
    if (relative[s] > limit) {
      ++result.over_limit;
      if (result.over_limit_examples.size() < max_examples) result.over_limit_examples.push_back(id_of(strands, s));
    }
    if (relative[s] > result.largest_relative || held == 1) {
      result.largest = deviation[s];
      result.largest_relative = relative[s];
      result.worst_strand = id_of(strands, s);
    }
  }
  std::sort(result.over_limit_examples.begin(), result.over_limit_examples.end());
  return result;
}

std::vector<int64_t> strands_at_roots(const StrandSet &strands, const Roots *strand_roots, const Mesh &mesh,
                                      const std::vector<SurfacePoint> &roots, float root_tolerance) {
  if (strand_roots && strand_roots->size() != strands.strand_count())
    throw InternalError("strands_at_roots: " + std::to_string(strand_roots->size()) + " roots for " +
                        std::to_string(strands.strand_count()) + " strands");
  std::vector<int64_t> found(roots.size(), -1);
  // The points searched: the strands' roots when known, else their first points.
  RootCloud cloud;
  std::vector<uint32_t> strand_of_point;
  for (size_t s = 0; s < strands.strand_count(); ++s) {
    if (strand_roots) {
      cloud.points.push_back(surface_position(mesh, strand_roots->points[s]));
    } else if (strands.points_in(s) > 0) {
      cloud.points.push_back(strands.points(s).front());
    } else {
      continue;
    }
    strand_of_point.push_back(uint32_t(s));
  }
  if (cloud.points.empty() || roots.empty()) return found;
  RootTree tree(3, cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  tree.buildIndex();
  if (strand_roots) {
    const float limit = root_tolerance * root_tolerance;
#pragma omp parallel for schedule(static)
    for (int64_t r = 0; r < int64_t(roots.size()); ++r) {
      const Vector3f c = surface_position(mesh, roots[size_t(r)]);
      uint32_t index = 0;
      float distance_squared = std::numeric_limits<float>::infinity();
      tree.knnSearch(c.data(), 1, &index, &distance_squared);
      if (distance_squared <= limit) found[size_t(r)] = int64_t(strand_of_point[index]);
    }
    return found;
  }
  // A strand lies near its root, lifted by its guides' height. The search starts at 4 tolerances
  // and widens 4x at a time up to twice the largest distance of a first point from the skin (a
  // lift along the normal is that distance, unless the skin curves more tightly than the lift),
  // so that a root without a strand costs a bounded search.
  std::vector<float> heights(cloud.points.size());
  const MeshQuery query(mesh);
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < int64_t(cloud.points.size()); ++s)
    heights[size_t(s)] = std::abs(query.signed_distance(cloud.points[size_t(s)]));
  const float widest = 2.0f * *std::max_element(heights.begin(), heights.end()) + 4.0f * root_tolerance;
#pragma omp parallel for schedule(dynamic, 64)
  for (int64_t r = 0; r < int64_t(roots.size()); ++r) {
    const Vector3f c = surface_position(mesh, roots[size_t(r)]);
    const Vector3f n = surface_normal(mesh, roots[size_t(r)]);
    std::vector<std::pair<uint32_t, float>> near;
    for (float radius = 4.0f * root_tolerance;; radius = std::min(4.0f * radius, widest)) {
      near.clear();
      tree.radiusSearch(c.data(), radius * radius, near, nanoflann::SearchParams(32, 0.0f, false));
      float best = std::numeric_limits<float>::infinity();
      for (const auto &[index, distance_squared] : near) {
        const Vector3f d = cloud.points[index] - c;
        const float h = d.dot(n), off = (d - h * n).norm();
        if (h >= -root_tolerance && off <= root_tolerance && off < best) {
          best = off;
          found[size_t(r)] = int64_t(strand_of_point[index]);
        }
      }
      if (found[size_t(r)] >= 0 || radius >= widest) break;
    }
  }
  return found;
}

RootCoverage check_requested_roots(const StrandSet &strands, const Roots *strand_roots, const Mesh &mesh,
                                   const std::vector<SurfacePoint> &requested, float root_tolerance,
                                   size_t max_examples) {
  RootCoverage result;
  result.requested = requested.size();
  const std::vector<int64_t> found = strands_at_roots(strands, strand_roots, mesh, requested, root_tolerance);
  for (size_t r = 0; r < requested.size(); ++r) {
    if (found[r] >= 0) continue;
    ++result.missing;
    if (result.missing_examples.size() < max_examples) result.missing_examples.push_back(r);
  }
  return result;
}

Roots roots_of(const StrandSet &strands, const MeshQuery &query) {
  Roots roots;
  roots.points.resize(strands.strand_count());
  roots.ids.resize(strands.strand_count());
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < int64_t(strands.strand_count()); ++s) {
    roots.points[size_t(s)] = surface_point_below(query, strands.positions[size_t(strands.offsets[size_t(s)])]);
    roots.ids[size_t(s)] = id_of(strands, size_t(s));
  }
  return roots;
}

std::vector<std::string> CheckReport::violations() const {
  std::vector<std::string> found;
  if (points_inside_skin > 0) found.push_back(count_text(points_inside_skin, "point", "points") + " inside the skin");
  const char *which = crossings_before_effects ? " (before effects)" : "";
  if (crossings.transversal_pairs > 0)
    found.push_back(count_text(crossings.transversal_pairs, "transversal crossing pair", "transversal crossing pairs") +
                    which);
  if (touching_is_violation && crossings.touching_pairs > 0)
    found.push_back(count_text(crossings.touching_pairs, "touching pair", "touching pairs") + which);
  if (zones_checked && cross_zone_influences > 0)
    found.push_back(count_text(cross_zone_influences, "influence", "influences") + " across hard partings");
  if (guides_checked && guide_deviation.over_limit > 0) {
    char limit[32];
    std::snprintf(limit, sizeof limit, "%g%%", 100.0 * guide_deviation_limit);
    found.push_back(count_text(guide_deviation.over_limit, "strand", "strands") +
                    " at guide roots deviating from their guide by more than " + limit + " of its length");
  }
  if (roots_checked && requested_roots.missing > 0)
    found.push_back(count_text(requested_roots.missing, "requested root", "requested roots") + " without a strand");
  return found;
}

CheckReport check_strands(const StrandSet &strands, const MeshQuery &query, const CheckOptions &options,
                          const CheckInputs &inputs) {
  CheckReport report;
  report.strand_count = strands.strand_count();
  report.point_count = strands.point_count();
  report.median_segment_length = median_segment_length(strands);
  report.root_tolerance = root_tolerance_for(query.mesh(), options);
  report.skin_margin = options.skin_margin;
  report.transversal_degrees = options.transversal_degrees;
  report.touching_is_violation = options.touching_is_violation;
  report.guide_deviation_limit = options.guide_deviation_limit;

  const StrandSet *judged = &strands;
  if (inputs.interpolated) {
    const StrandSet &before = *inputs.interpolated;
    bool same_roots = before.strand_count() == strands.strand_count();
    for (size_t s = 0; same_roots && s < strands.strand_count(); ++s)
      same_roots = before.points_in(s) > 0 && strands.points_in(s) > 0 &&
                   (before.points(s).front() - strands.points(s).front()).norm() <= report.root_tolerance;
    if (!same_roots)
      throw InputError("the strands grown without effects do not start at the strands' roots (" +
                       std::to_string(before.strand_count()) + " strands for " +
                       std::to_string(strands.strand_count()) + ")");
    judged = inputs.interpolated;
    report.crossings_before_effects = true;
    report.guides_before_effects = true;
  }

  report.points_inside_skin =
      count_points_inside(strands, query, options.skin_margin, options.max_examples, report.inside_examples);

  const float tolerance = crossing_tolerance_for(strands, options);
  report.crossings = count_crossings(*judged, tolerance, options.max_examples, options.transversal_degrees);
  if (inputs.interpolated)
    report.crossings_after_effects =
        count_crossings(strands, tolerance, options.max_examples, options.transversal_degrees, inputs.interpolated);

  const Roots *grown_roots = inputs.roots && inputs.roots_grown ? inputs.roots : nullptr;
  if (inputs.partings && inputs.roots && inputs.binding) {
    report.zones_checked = true;
    report.cross_zone_influences = count_cross_zone_influences(*inputs.partings, *inputs.roots, *inputs.binding,
                                                               options.max_examples, report.cross_zone_examples);
  }

  if (inputs.guides && inputs.guides->size() > 0) {
    report.guides_checked = true;
    // The skin band of the growth (docs/interpolation.md, "The skin"), from the groom's margin when
    // the groom is known, else from --margin.
    const float band =
        interp::skin_band_margins * (inputs.binding ? inputs.binding->skin_margin : options.skin_margin);
    report.guide_deviation = measure_guide_deviation(*judged, grown_roots, query, *inputs.guides, report.root_tolerance,
                                                     options.guide_deviation_limit, band, options.max_examples);
  }

  if (inputs.requested_roots) {
    report.roots_checked = true;
    report.requested_roots = check_requested_roots(strands, grown_roots, query.mesh(), *inputs.requested_roots,
                                                   report.root_tolerance, options.max_examples);
  }
  return report;
}

}  // namespace plume::check
