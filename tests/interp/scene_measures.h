// Growth on a hard scene, and every promise measured on it: crossings (the checker's count, and the
// exact 2-D test on planar scenes), points inside the skin, guides reproduced at their roots, NaN,
// the closest approach of neighbouring strands against their roots' spacing.
#pragma once

#include <omp.h>

#include <algorithm>
#include <cstdio>
#include <cstring>
#include <string>

#include "check/check.h"
#include "groom/guide_curve.h"
#include "interp/hard_scenes.h"
#include "interp/interpolate.h"

namespace plume::test {

/// The deviation of `strand` from guide g's curve (groom/guide_curve.h, 8 samples per piece), as
/// the checker measures it (check::guide_deviation), as a fraction of the curve's length; the
/// curve's length in r_length.
inline double curve_deviation(const Guides &guides, size_t g, std::span<const Eigen::Vector3f> strand,
                              double *r_length = nullptr) {
  std::vector<CurvePiece> pieces;
  plume::guide_curve(guides.strands.points(g), 1e-7f * float(guides.strands.length(g)), pieces);
  const std::vector<Eigen::Vector3f> curve = plume::sample_curve(pieces, 8);
  double length = 0.0;
  const double deviation = check::guide_deviation(strand, strand.front(), curve, length);
  if (r_length) *r_length = length;
  return length > 0.0 ? deviation / length : 0.0;
}

inline InterpolationSettings settings_of(InterpolationSettings::Method method, int k = 4) {
  InterpolationSettings settings;
  settings.method = method;
  settings.k = k;
  return settings;
}

inline StrandSet grow_scene(const Scene &scene, const Roots &roots, const InterpolationSettings &settings, int points,
                            interp::GrowStats *r_stats = nullptr, const partings::PartingField *partings = nullptr) {
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, roots, settings, partings);
  interp::GrowOptions options;
  options.points_per_strand = points;
  options.r_stats = r_stats;
  StrandSet strands;
  interp::grow(binding, scene.mesh, *scene.query, roots, scene.guides.strands, options, strands);
  return strands;
}

/// The median segment length of a set of strands.
inline float median_segment(const StrandSet &strands) {
  std::vector<float> lengths;
  for (size_t s = 0; s < strands.strand_count(); ++s)
    for (size_t j = 0; j + 1 < size_t(strands.points_in(s)); ++j)
      lengths.push_back((strands.points(s)[j + 1] - strands.points(s)[j]).norm());
  std::nth_element(lengths.begin(), lengths.begin() + ptrdiff_t(lengths.size() / 2), lengths.end());
  return lengths[lengths.size() / 2];
}

/// Largest distance from strand points to the guide's points at the same arc length, over its length.
inline float guide_deviation(std::span<const Eigen::Vector3f> strand, std::span<const Eigen::Vector3f> guide) {
  auto at_arc = [](std::span<const Eigen::Vector3f> points, float s) {
    for (size_t j = 0; j + 1 < points.size(); ++j) {
      const float length = (points[j + 1] - points[j]).norm();
      if (s <= length) return Eigen::Vector3f(points[j] + (length > 0.0f ? s / length : 0.0f) * (points[j + 1] - points[j]));
      s -= length;
    }
    return points.back();
  };
  float worst = 0.0f, s = 0.0f, total = 0.0f;
  for (size_t j = 0; j + 1 < guide.size(); ++j) total += (guide[j + 1] - guide[j]).norm();
  for (size_t i = 0; i < strand.size(); ++i) {
    if (i > 0) s += (strand[i] - strand[i - 1]).norm();
    worst = std::max(worst, (strand[i] - at_arc(guide, s)).norm());
  }
  return worst / total;
}

struct Measures {
  size_t crossings = 0;        // the checker's pairs at 1e-3 of the median segment
  size_t planar = 0;           // exact 2-D intersections (planar scenes)
  size_t inside = 0;           // points inside the skin (the checker's count)
  float guide_deviation = 0;   // largest, strands at guide roots, share of the guide's length
  bool finite = true;
  float approach = INFINITY;   // closest approach / root spacing, neighbours
  interp::GrowStats stats;
  double seconds = 0.0;

  std::string text() const {
    char line[300];
    std::snprintf(line, sizeof line,
                  "crossings %zu, planar %zu, inside %zu, guide deviation %.4f%%, finite %d, approach %.3f, %.2f s; %s",
                  crossings, planar, inside, 100.0 * guide_deviation, int(finite), approach, seconds,
                  stats.summary().c_str());
    return line;
  }
};

/// Grows the scene's roots and its guides' roots; measures them. `near`: roots closer than this are
/// neighbours for the closest approach (0: skip it).
inline Measures measure(const Scene &scene, const InterpolationSettings &settings, int points, float near,
                        const partings::PartingField *partings = nullptr) {
  Measures m;
  const double start = omp_get_wtime();
  const StrandSet strands = grow_scene(scene, scene.roots, settings, points, &m.stats, partings);
  m.seconds = omp_get_wtime() - start;
  m.finite = all_finite(strands);
  m.crossings = check::count_crossings(strands, 1e-3f * median_segment(strands), 0).pairs;
  if (scene.planar) m.planar = planar_intersections(strands);
  std::vector<uint64_t> examples;
  m.inside = check::count_points_inside(strands, *scene.query, 0.0f, 0, examples);
  const Roots at_guides = roots_of(scene.guides);
  const StrandSet reproduced = grow_scene(scene, at_guides, settings, points, nullptr, partings);
  for (size_t g = 0; g < scene.guides.size(); ++g)
    m.guide_deviation =
        std::max(m.guide_deviation, guide_deviation(reproduced.points(g), scene.guides.strands.points(g)));
  m.finite = m.finite && all_finite(reproduced);
  m.inside += check::count_points_inside(reproduced, *scene.query, 0.0f, 0, examples);
  if (near > 0.0f) m.approach = closest_approach_ratio(strands, near);
  return m;
}

}  // namespace plume::test
