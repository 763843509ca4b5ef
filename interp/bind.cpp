#include <nanoflann.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>

#include "groom/error.h"
#include "groom/guide_curve.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"

namespace plume::interp {

namespace {

/// nanoflann adaptor over the rest positions of a subset of guide roots (one hard zone).
struct GuideCloud {
  std::vector<Eigen::Vector3f> points;
  std::vector<int32_t> guides;  // guide index of each point

  size_t kdtree_get_point_count() const { return points.size(); }
  float kdtree_get_pt(size_t i, size_t dim) const { return points[i][int(dim)]; }
  template <class Box>
  bool kdtree_get_bbox(Box &) const {
    return false;
  }
};

using KdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, GuideCloud>, GuideCloud, 3>;

struct Zone {
  GuideCloud cloud;
  std::unique_ptr<KdTree> tree;
};

/// One guide considered for a root.
struct Candidate {
  int32_t guide;
  float distance;  // Euclidean, rest pose
  float factor;    // parting factor in (0, 1]
  float score;     // factor / distance^falloff; +inf for an exact hit
};

/// The largest turn (radians) a guide is carried by from its root's normal to a root's normal: 30 degrees.
constexpr float max_carry_turn = 0.5235988f;

float falloff_pow(float distance, float falloff) {
  return falloff == 2.0f ? distance * distance : std::pow(distance, falloff);
}

}  // namespace

Binding bind(const Mesh &rest_mesh, const Guides &guides, const Roots &roots, const InterpolationSettings &settings,
             const PartingField *partings) {
  const int k = settings.k;
  if (k < 1 || k > max_guides_per_root)
    throw InputError(settings.loc, "interpolation.k: expected an integer in [1, " + std::to_string(max_guides_per_root) +
                                       "], got " + std::to_string(k));
  if (!(settings.falloff > 0.0f) || !std::isfinite(settings.falloff))
    throw InputError(settings.loc, "interpolation.falloff: expected a positive number");
  if (!(settings.radius >= 0.0) || !std::isfinite(settings.radius))
    throw InputError(settings.loc, "interpolation.radius: expected a number >= 0");
  if (guides.size() == 0) throw InputError(settings.loc, "interpolation: there are no guides to interpolate");
  if (guides.strands.strand_count() != guides.size())
    throw InternalError("bind: guides have " + std::to_string(guides.strands.strand_count()) + " strands but " +
                        std::to_string(guides.size()) + " roots");

  const bool use_partings = partings != nullptr && !partings->empty();
  if (use_partings) partings->check_roots_have_guides(roots.points);

  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f &p : rest_mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // Streamline-ratio weighs guides by 1/d whatever the setting: the law that keeps the ratio of
  // distances (docs/interpolation.md); binding weights use the same law so growth starts from them.
  const float falloff = settings.method == InterpolationSettings::Method::streamline ? 1.0f : settings.falloff;

  const size_t guide_count = guides.size();
  std::vector<Eigen::Vector3f> guide_positions(guide_count);
  std::vector<Eigen::Matrix3f> guide_frames(guide_count);
  std::vector<float> guide_lengths(guide_count);
  for (size_t g = 0; g < guide_count; ++g) {
    const SurfaceFrame frame = surface_frame(rest_mesh, guides.roots[g]);
    guide_positions[g] = frame.origin;
    guide_frames[g] = frame.basis;
    guide_lengths[g] = float(guides.strands.length(g));
  }

  // One kd-tree per hard zone (a single one without zones): a root only ever sees its zone's guides.
  const int zone_count = use_partings ? partings->zone_count() : 1;
  std::vector<Zone> zones(size_t(std::max(zone_count, 1)));
  for (size_t g = 0; g < guide_count; ++g) {
    Zone &zone = zones[size_t(use_partings ? partings->guide_zone(g) : 0)];
    zone.cloud.points.push_back(guide_positions[g]);
    zone.cloud.guides.push_back(int32_t(g));
  }
  for (Zone &zone : zones)
    if (!zone.cloud.points.empty())
      zone.tree = std::make_unique<KdTree>(3, zone.cloud, nanoflann::KDTreeSingleIndexAdaptorParams(10));

  Binding binding;
  binding.k = k;
  binding.settings = settings;
  binding.guide_roots = guides.roots;
  binding.partings = use_partings ? partings : nullptr;
  binding.zone_count = zone_count;
  binding.guide_zones.assign(guide_count, 0);
  binding.root_zones.assign(roots.size(), 0);
  if (use_partings) {
    for (size_t g = 0; g < guide_count; ++g) binding.guide_zones[g] = int32_t(partings->guide_zone(g));
    for (size_t r = 0; r < roots.size(); ++r) binding.root_zones[r] = int32_t(partings->zone_of(roots.points[r]));
  }
  // The groom's length unit: the median rest guide segment (segments of no length left out), from
  // which every default length follows.
  std::vector<float> segment_lengths;
  for (size_t g = 0; g < guide_count; ++g) {
    const std::span<const Eigen::Vector3f> points = guides.strands.points(g);
    for (size_t j = 0; j + 1 < points.size(); ++j) {
      const float length = (points[j + 1] - points[j]).norm();
      if (length > 0.0f) segment_lengths.push_back(length);
    }
  }
  if (segment_lengths.empty()) {
    binding.length_unit = std::max(1e-3f * (hi - lo).norm(), 1e-12f);  // every guide of no length
  } else {
    std::nth_element(segment_lengths.begin(), segment_lengths.begin() + ptrdiff_t(segment_lengths.size() / 2),
                     segment_lengths.end());
    binding.length_unit = segment_lengths[segment_lengths.size() / 2];
  }
  // Distances below this count as a hit (the root sits on the guide root), never more than a
  // twentieth of the length unit (on an emitter far larger than its hair, the checker's tolerance
  // would otherwise make a clump of every guide).
  const float hit_distance =
      std::max(std::min(root_hit_of_diagonal * (hi - lo).norm(), root_hit_of_length_unit * binding.length_unit), 1e-12f);
  binding.skin_margin = settings.skin_margin >= 0.0f ? settings.skin_margin : default_margin_fraction * binding.length_unit;
  binding.step = step_fraction * binding.length_unit;
  binding.tolerance = tolerance_fraction * binding.length_unit;
  // Streamline strands follow the guides' curves (groom/guide_curve.h), a little longer than their
  // polylines where they bend: a strand at a guide's root is as long as its guide's curve, and ends
  // at the guide's tip.
  if (settings.method == InterpolationSettings::Method::streamline) {
    std::vector<CurvePiece> curve;
    for (size_t g = 0; g < guide_count; ++g) {
      guide_curve(guides.strands.points(g), 1e-6f * field_cell_fraction * binding.length_unit, curve);
      guide_lengths[g] = float(curve_length(curve));
    }
  }
  const size_t root_count = roots.size();
  binding.guide_ids.assign(root_count * size_t(k), -1);
  binding.weights.assign(root_count * size_t(k), 0.0f);
  binding.hits.assign(root_count, 0);
  binding.rest_rotations.assign(root_count * size_t(k), Eigen::Quaternionf::Identity());
  binding.lengths.assign(root_count, 0.0f);

  // With partial partings a near guide may be attenuated below a farther one: look at more
  // candidates than k and keep the k best scores. One more than needed gives the fade-out score.
  const bool has_partial = use_partings && partings->partial_line_count() > 0;
  const size_t wanted = size_t(has_partial ? 2 * k + 1 : k + 1);
  const float radius = float(settings.radius);
  const float radius_score = radius > 0.0f ? 1.0f / falloff_pow(radius, falloff) : 0.0f;

  std::vector<uint8_t> cut_off(root_count, 0);
#pragma omp parallel
  {
    std::vector<uint32_t> indices;
    std::vector<float> distances_sq;
    std::vector<Candidate> candidates;
#pragma omp for schedule(static)
    for (int64_t r = 0; r < int64_t(root_count); ++r) {
      const SurfacePoint &root = roots.points[size_t(r)];
      const SurfaceFrame root_frame = surface_frame(rest_mesh, root);
      const Zone &zone = zones[size_t(use_partings ? partings->zone_of(root) : 0)];
      const size_t zone_size = zone.cloud.points.size();

      // Gather candidates; if partings remove all of them, widen the search to the whole zone.
      for (size_t query_count = std::min(wanted, zone_size);; query_count = zone_size) {
        indices.resize(query_count);
        distances_sq.resize(query_count);
        const size_t found =
            zone.tree->knnSearch(root_frame.origin.data(), query_count, indices.data(), distances_sq.data());
        candidates.clear();
        for (size_t i = 0; i < found; ++i) {
          const int32_t g = zone.cloud.guides[indices[i]];
          const float factor = use_partings ? partings->weight_factor(root, size_t(g)) : 1.0f;
          if (!(factor > 0.0f)) continue;
          candidates.push_back({g, std::sqrt(distances_sq[i]), factor, 0.0f});
        }
        if (!candidates.empty() || query_count == zone_size) break;
      }
      if (candidates.empty()) {  // reported after the parallel loop (exceptions must not leave it)
        cut_off[size_t(r)] = 1;
        continue;
      }

      // Radius: keep the guides inside it; a root with none inside keeps its nearest guide alone.
      bool radius_cut = false;
      if (radius > 0.0f) {
        std::erase_if(candidates, [&](const Candidate &c) { return c.distance > radius; });
        radius_cut = true;
        if (candidates.empty()) {
          indices.resize(1);
          distances_sq.resize(1);
          zone.tree->knnSearch(root_frame.origin.data(), 1, indices.data(), distances_sq.data());
          const int32_t g = zone.cloud.guides[indices[0]];
          candidates.push_back({g, std::sqrt(distances_sq[0]), 1.0f, 1.0f});
          radius_cut = false;
        }
      }

      bool any_hit = false;
      for (Candidate &c : candidates) {
        const bool hit = c.distance <= hit_distance;
        any_hit |= hit;
        c.score = hit ? INFINITY : c.factor / falloff_pow(c.distance, falloff);
      }
      // Exact hit: the guides at distance ~0 share all the weight; everything else gets none.
      if (any_hit) std::erase_if(candidates, [](const Candidate &c) { return !std::isinf(c.score); });
      std::sort(candidates.begin(), candidates.end(), [](const Candidate &a, const Candidate &b) {
        return a.score != b.score ? a.score > b.score : a.guide < b.guide;
      });

      const size_t used = std::min(candidates.size(), size_t(k));
      const int64_t base = r * k;
      float total = 0.0f;
      if (any_hit) {
        binding.hits[size_t(r)] = 1;
        for (size_t s = 0; s < used; ++s) {
          binding.weights[size_t(base) + s] = candidates[s].factor;
          total += candidates[s].factor;
        }
      } else {
        // Fade each score by the first one left out (and by the radius) so that a guide's weight
        // reaches 0 exactly when it stops being among the k nearest: weights are continuous.
        float cutoff = candidates.size() > size_t(k) ? candidates[size_t(k)].score : 0.0f;
        if (radius_cut) cutoff = std::max(cutoff, radius_score);
        if (!(candidates[0].score - cutoff > 0.0f)) cutoff = 0.0f;  // all tied: plain falloff
        for (size_t s = 0; s < used; ++s) {
          const float raw = std::max(candidates[s].score - cutoff, 0.0f);
          binding.weights[size_t(base) + s] = raw;
          total += raw;
        }
      }
      float length = 0.0f;
      for (size_t s = 0; s < used; ++s) {
        const size_t slot = size_t(base) + s;
        const int32_t g = candidates[s].guide;
        binding.guide_ids[slot] = g;
        binding.weights[slot] /= total;
        length += binding.weights[slot] * guide_lengths[size_t(g)];
        // Minimal rotation from the guide root's normal to the root's normal, expressed between the
        // two rest frames so that per-frame carrying does not depend on their tangents. Its angle is
        // capped (continuously): where the skin turns sharply between a guide root and the root (an
        // ear below the scalp's guides), a guide turned whole would stick out of the head.
        Eigen::Quaternionf turn =
            Eigen::Quaternionf::FromTwoVectors(guide_frames[size_t(g)].col(2), root_frame.basis.col(2));
        const float angle = Eigen::AngleAxisf(turn).angle();
        if (angle > max_carry_turn) turn = Eigen::Quaternionf::Identity().slerp(max_carry_turn / angle, turn);
        const Eigen::Matrix3f local = root_frame.basis.transpose() * turn.toRotationMatrix() * guide_frames[size_t(g)];
        binding.rest_rotations[slot] = Eigen::Quaternionf(local).normalized();
      }
      binding.lengths[size_t(r)] = length;
    }
  }
  for (size_t r = 0; r < root_count; ++r)
    if (cut_off[r])
      throw InputError(settings.loc, "root " + std::to_string(roots.ids[r]) +
                                         ": every guide of its zone is cut off by a parting line");
  return binding;
}

}  // namespace plume::interp
