#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <span>
#include <string>

#include "groom/error.h"
#include "groom/guide_curve.h"
#include "interp/guide_field.h"
#include "interp/interpolate.h"
#include "interp/separate.h"
#include "partings/parting_field.h"
#include "skin/skin_grid.h"
#include "skin/skin_guard.h"

namespace plume::interp {

using namespace skin;

namespace {

/// The guides at one frame, prepared once per frame (never per strand).
struct FrameGuides {
  /// #guides surface frames at the guide roots on the posed mesh (columns tangent, bitangent, normal).
  std::vector<Eigen::Matrix3f> frames;
  /// #guides surface positions of the guide roots on the posed mesh.
  std::vector<Eigen::Vector3f> origins;
  /// Fur and linear: every guide resampled to N points by arc length (#guides * N points), with its
  /// #guides * (N - 1) unit segment directions and lengths.
  std::vector<Eigen::Vector3f> resampled;
  std::vector<Eigen::Vector3f> resampled_directions;
  std::vector<float> resampled_lengths;
  /// Streamline: one field per hard zone (null for a zone without guides).
  std::vector<std::unique_ptr<GuideField>> fields;
};

Eigen::Vector3f unit_or(const Eigen::Vector3f &v, const Eigen::Vector3f &fallback) {
  const float norm = v.norm();
  return norm > 1e-20f ? Eigen::Vector3f(v * (1.0f / norm)) : fallback;
}

/// Unit directions and lengths of the segments of a polyline; zero-length segments take the
/// direction of the previous valid one (the first valid one for leading ones, `fallback` if none).
void unit_segments(std::span<const Eigen::Vector3f> points, const Eigen::Vector3f &fallback,
                   Eigen::Vector3f *r_directions, float *r_lengths) {
  const size_t count = points.size() - 1;
  Eigen::Vector3f last = fallback;
  bool found = false;
  for (size_t j = 0; j < count; ++j) {
    const Eigen::Vector3f d = points[j + 1] - points[j];
    r_lengths[j] = d.norm();
    if (!found && r_lengths[j] > 1e-20f) {
      last = d / r_lengths[j];
      found = true;
    }
  }
  for (size_t j = 0; j < count; ++j) {
    if (r_lengths[j] > 1e-20f) last = (points[j + 1] - points[j]) / r_lengths[j];
    r_directions[j] = last;
  }
}

/// Walks `count` stations evenly spaced in arc length over the first `total` of a polyline's length
/// (at least two points): visit(i, segment, t) for station i, at t in [0, 1] along that segment.
template <typename Visit>
void arc_length_stations(std::span<const Eigen::Vector3f> points, int count, double total, Visit &&visit) {
  size_t segment = 0;
  double start = 0.0;
  double length = (points[1] - points[0]).norm();
  for (int i = 0; i < count; ++i) {
    const double target = total * double(i) / double(count - 1);
    while (segment + 2 < points.size() && start + length < target) {
      start += length;
      ++segment;
      length = (points[segment + 1] - points[segment]).norm();
    }
    visit(i, segment, length > 0.0 ? std::clamp((target - start) / length, 0.0, 1.0) : 0.0);
  }
}

/// `points` resampled to `count` points evenly spaced in arc length (a copy when counts match).
void resample(std::span<const Eigen::Vector3f> points, int count, Eigen::Vector3f *r_points) {
  if (points.size() == size_t(count)) {
    std::copy(points.begin(), points.end(), r_points);
    return;
  }
  double total = 0.0;
  for (size_t j = 0; j + 1 < points.size(); ++j) total += (points[j + 1] - points[j]).norm();
  arc_length_stations(points, count, total, [&](int i, size_t segment, double t) {
    r_points[i] = points[segment] + float(t) * (points[segment + 1] - points[segment]);
  });
  r_points[count - 1] = points.back();
}

/// The field's floor (FieldShape::floor) as a fraction of the length unit: one guide segment. Measured
/// on Sintel's frame 1 (docs/interpolation.md, "Bunching"): a floor of half a unit, 1 and 2 units left
/// 60%, 54% and 50% of the transversal crossing pairs, at 1.35, 1.7 and 2.6 times the CPU time.
constexpr float field_floor_fraction = 1.0f;

/// `points_per_strand` 0: the guide roots' frames alone (for the strands' first points).
FrameGuides prepare_guides(const Binding &binding, const Mesh &mesh, const StrandSet &guides, int points_per_strand) {
  const size_t guide_count = guides.strand_count();
  FrameGuides frame;
  frame.frames.resize(guide_count);
  frame.origins.resize(guide_count);
  for (size_t g = 0; g < guide_count; ++g) {
    const SurfaceFrame f = surface_frame(mesh, binding.guide_roots[g]);
    frame.frames[g] = f.basis;
    frame.origins[g] = f.origin;
  }
  if (points_per_strand == 0) return frame;
  if (binding.settings.method == InterpolationSettings::Method::streamline) {
    std::vector<std::vector<int32_t>> members(size_t(binding.zone_count));
    for (size_t g = 0; g < guide_count; ++g) members[size_t(binding.guide_zones[g])].push_back(int32_t(g));
    frame.fields.resize(members.size());
    FieldShape shape;
    shape.floor = field_floor_fraction * binding.length_unit;
    for (size_t z = 0; z < members.size(); ++z)
      if (!members[z].empty())
        frame.fields[z] = std::make_unique<GuideField>(guides, members[z], shape,
                                                     field_cell_fraction * binding.length_unit);
    return frame;
  }
  const size_t n = size_t(points_per_strand);
  frame.resampled.resize(guide_count * n);
  frame.resampled_directions.resize(guide_count * (n - 1));
  frame.resampled_lengths.resize(guide_count * (n - 1));
  for (size_t g = 0; g < guide_count; ++g) {
    Eigen::Vector3f *points = frame.resampled.data() + g * n;
    resample(guides.points(g), points_per_strand, points);
    unit_segments({points, n}, frame.frames[g].col(2), frame.resampled_directions.data() + g * (n - 1),
                  frame.resampled_lengths.data() + g * (n - 1));
  }
  return frame;
}

/// The skin band (docs/interpolation.md, "The skin"): within twice the margin m above the skin, a
/// direction's inward normal component is removed, fully at distance m and below, smoothly above;
/// below m the normal component is raised to at least lift * (1 - sd / m). So the surface at distance
/// m is never crossed inward, strands leave the skin from their roots, and hair lying along the skin
/// slides along it. The normal is the gradient of the signed distance to the faceted skin, (x - c) /
/// |x - c| with c the closest point (the side normal on the skin itself). One band per strand: it
/// remembers its last exact query, whose 1-Lipschitz bound spares queries where the band cannot
/// act; that never changes an answer.
class SkinBand {
 public:
  static constexpr float lift = 0.25f;

  SkinBand(const Mesh &mesh, const MeshQuery &query, const SkinGrid &grid, float margin, GrowStats &stats)
      : mesh_(mesh), query_(query), grid_(grid), margin_(margin), tiny_(1e-7f * mesh_scale(mesh)), stats_(stats) {}

  /// Starts a strand at p, whose signed distance is `distance` and closest triangle `triangle`.
  void start(const Eigen::Vector3f &p, float distance, int triangle) {
    known_point_ = p;
    known_distance_ = distance;
    hint_ = triangle;
  }
  /// A lower bound of the signed distance at x (minus infinity near an open edge of the mesh, where
  /// the side can change without crossing the skin).
  float lower_bound(const Eigen::Vector3f &x) const {
    if (grid_.near_open_edge(x)) return -INFINITY;
    return known_distance_ - (x - known_point_).norm();
  }
  /// The signed distance at x, queried.
  float exact(const Eigen::Vector3f &x) {
    SurfacePoint closest;
    return query_at(x, closest);
  }
  /// A lower bound of the signed distance at x of at least `needed` when one is cheap to prove;
  /// otherwise the queried signed distance (r_queried set, r_closest its closest point).
  float prove(const Eigen::Vector3f &x, float needed, bool &r_queried, SurfacePoint &r_closest) {
    r_queried = false;
    const float lower = lower_bound(x);
    if (lower >= needed) return lower;
    // The grid's bounds of the distance to every triangle (no search), then a search for any
    // triangle within `needed` that stops at the first: x is outside by that much when it cannot have
    // crossed the skin since the last known point (along the way the distance stays above (known +
    // bound - moved) / 2 > 0), as SkinGuard argues.
    if (!grid_.near_open_edge(x) && known_distance_ > 0.0f) {
      const float moved = (x - known_point_).norm();
      float bound = grid_.distance_lower_bound(x);
      if (bound < needed) bound = std::max(bound, grid_.block_lower_bound(x));
      if (bound >= needed && known_distance_ + bound > moved) return bound;
      if (known_distance_ + needed > moved && grid_.clear_within(x, needed)) {
        known_point_ = x;
        known_distance_ = needed;
        return needed;
      }
    }
    r_queried = true;
    return query_at(x, r_closest);
  }
  /// The closest point of the skin to x (queried from the last closest triangle). The band's known
  /// bound is left as it was, so asking for feet never changes a strand.
  SurfacePoint foot(const Eigen::Vector3f &x) {
    ++stats_.skin_queries;
    SurfacePoint closest;
    grid_.signed_distance(x, hint_, closest);
    return closest;
  }
  /// v bent by the band at x; r_lower gets a lower bound of the signed distance at x.
  Eigen::Vector3f bend(const Eigen::Vector3f &x, const Eigen::Vector3f &v, float &r_lower) {
    bool queried = false;
    SurfacePoint closest;
    const float band = skin_band_margins * margin_;
    const float distance = prove(x, band, queried, closest);
    r_lower = distance;
    if (distance >= band) return v;
    const Eigen::Vector3f offset = x - surface_position(mesh_, closest);
    const float length = offset.norm();
    const Eigen::Vector3f normal = length > tiny_ ? Eigen::Vector3f((distance >= 0.0f ? 1.0f : -1.0f) / length * offset)
                                                  : query_.side_normal(closest);
    const float keep = fade((distance - margin_) / (band - margin_));  // 1 at m and below, 0 at the band's top
    const float floor = lift * std::clamp(1.0f - distance / margin_, 0.0f, 1.0f);
    const float along = v.dot(normal);
    const float bent = std::max(along >= 0.0f ? along : (1.0f - keep) * along, floor);
    return v + (bent - along) * normal;
  }

 private:
  float query_at(const Eigen::Vector3f &x, SurfacePoint &r_closest) {
    ++stats_.skin_queries;
    const float distance = grid_.signed_distance(x, hint_, r_closest);
    hint_ = r_closest.triangle;
    known_point_ = x;
    known_distance_ = distance;
    return distance;
  }

  const Mesh &mesh_;
  const MeshQuery &query_;
  const SkinGrid &grid_;
  float margin_;
  float tiny_;
  GrowStats &stats_;
  Eigen::Vector3f known_point_ = Eigen::Vector3f::Zero();
  float known_distance_ = -INFINITY;
  int hint_ = -1;
};

/// A polyline grown finely, with a lower bound of each point's signed distance to the skin.
struct FinePolyline {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> lower;

  void clear() {
    points.clear();
    lower.clear();
  }
  void add(const Eigen::Vector3f &p, float bound) {
    points.push_back(p);
    lower.push_back(bound);
  }
  /// `count` points evenly spaced in arc length along the polyline's first `total` of length, and
  /// each one's lower bound of its signed distance (the better of its two fine neighbours' bounds
  /// less the way from them; r_lower may be null).
  void resample_to(int count, double total, Eigen::Vector3f *r_points, float *r_lower) const {
    if (points.size() < 2) {
      for (int i = 0; i < count; ++i) {
        r_points[i] = points[0];
        if (r_lower) r_lower[i] = lower[0];
      }
      return;
    }
    arc_length_stations(points, count, total, [&](int i, size_t segment, double t) {
      const Eigen::Vector3f &a = points[segment], &b = points[segment + 1];
      r_points[i] = a + float(t) * (b - a);
      if (r_lower)
        r_lower[i] = std::max(lower[segment] - (r_points[i] - a).norm(), lower[segment + 1] - (r_points[i] - b).norm());
    });
  }
};

/// Walks from `from` along unit direction `direction` for `length`, through the skin band: sub-steps
/// no longer than the room the bound leaves (at least half a margin), each along the bent direction,
/// one retried at half length when it would end inside the skin. Fur and linear grow this way.
Eigen::Vector3f walk(const Eigen::Vector3f &from, const Eigen::Vector3f &direction, float length, float margin,
                     SkinBand &band, GrowStats &stats, float &r_lower) {
  Eigen::Vector3f x = from;
  float remaining = length;
  r_lower = band.lower_bound(x);
  while (remaining > 0.0f) {
    const float bound = band.lower_bound(x);
    if (bound >= 2.0f * margin + remaining) {
      x += remaining * direction;
      r_lower = bound - remaining;
      ++stats.steps;
      return x;
    }
    float sub = std::min(remaining, std::max(0.5f * margin, bound - margin));
    float at_x = 0.0f;
    const Eigen::Vector3f bent = unit_or(band.bend(x, direction, at_x), direction);
    Eigen::Vector3f next = x + sub * bent;
    bool queried = false;
    SurfacePoint closest;
    float lower = band.prove(next, 0.5f * margin, queried, closest);
    for (int tries = 0; tries < 12 && lower < 0.0f; ++tries) {
      ++stats.halved_steps;
      sub *= 0.5f;
      next = x + sub * bent;
      lower = band.prove(next, 0.5f * margin, queried, closest);
    }
    if (lower < 0.0f) {  // no way forward outside the skin: stay
      r_lower = at_x;
      return x;
    }
    ++stats.steps;
    x = next;
    r_lower = lower;
    remaining -= sub;
  }
  return x;
}

/// Partial partings as the field sees them: at a point x, guide g counts with the factor a root at
/// x's closest point of the skin would give it, (D / D1)^gamma (partings/parting_field.h). A function
/// of x alone.
class PartingAttenuation : public GuideAttenuation {
 public:
  explicit PartingAttenuation(const PartingField &partings) : partings_(partings) {}
  SurfacePoint foot;
  float factor(int32_t guide) const override { return partings_.weight_factor(foot, size_t(guide)); }

 private:
  const PartingField &partings_;
};

/// One thread's state for streamline growth: the field's cache, the fine polyline.
struct StrandScratch {
  GuideField::Cache cache;
  FinePolyline fine;
  std::vector<CurvePiece> pieces;
};

/// Grows one streamline strand: steps of the Bogacki-Shampine 3(2) pair through the field bent by
/// the skin band, from `root` until the fine polyline is `length` long, then resampled.
/// The step adapts so that each step's error estimate (the distance between the third- and
/// second-order ends) stays below `tolerance`, or less near a guide (tolerance_per_distance); it is at
/// most `step`, and near the skin at most the room the distance bound leaves (at least four margins).
void grow_streamline(const GuideField &field, PartingAttenuation *partings, const Eigen::Vector3f &root,
                     const Eigen::Vector3f &root_normal, float length, float step, float tolerance, float margin,
                     SkinBand &band, StrandScratch &scratch, GrowStats &stats, int n, Eigen::Vector3f *r_points,
                     float *r_lower) {
  FinePolyline &fine = scratch.fine;
  fine.clear();
  fine.add(root, band.lower_bound(root));
  Eigen::Vector3f x = root, last = root_normal;
  float nearest = 0.0f;  // the nearest guide's distance at the last point evaluated
  // The least of (|V| - the length needed there) over the current step's evaluations: the strand
  // ends where it is negative (see min_field_length).
  float field_slack = INFINITY;
  auto velocity = [&](const Eigen::Vector3f &p) {
    ++stats.evaluations;
    if (partings) partings->foot = band.foot(p);
    const GuideField::Sample sample = field.evaluate(p, scratch.cache, partings);
    nearest = sample.nearest;
    float lower = 0.0f;
    const Eigen::Vector3f bent = band.bend(p, sample.direction, lower);
    // The length needed: min_field_length from twice the margin up, down to 0.4 of it on the skin,
    // where the band's lift alone gives 0.25 (a root never ends where it starts). A function of x:
    // below twice the margin `lower` is the exact signed distance.
    const float room = margin > 0.0f ? std::clamp(lower / (2.0f * margin), 0.0f, 1.0f) : 1.0f;
    field_slack = std::min(field_slack, bent.norm() - min_field_length * (0.4f + 0.6f * room));
    return unit_or(bent, last);
  };
  double arc = 0.0;
  // The curve is grown to the strand's length, then resampled: its output polyline is shorter by its
  // chords' shortfall, as the guide's own curve resampled to the same points would be.
  const float shortest = 1e-3f * step;
  const int64_t max_steps = int64_t(std::ceil(double(length) / double(std::min(step, 0.5f * margin)))) * 8 + 64;
  float h = std::min(step, 0.5f * margin);
  Eigen::Vector3f k1 = velocity(x);
  float nearest_at_x = nearest;
  if (field_slack < 0.0f) ++stats.ended_strands;
  for (int64_t s = 0; s < max_steps && arc < double(length) && field_slack >= 0.0f; ++s) {
    // The error allowed: `tolerance` far from the guides, shrinking in proportion to the nearest
    // guide's distance down to a hundredth of it, where the field turns fastest (its Lipschitz
    // constant grows as 1 / distance) and a strand near a guide must stay with it.
    const float allowed = std::clamp(nearest_at_x * tolerance_per_distance, 0.01f * tolerance, tolerance);
    const float bound = band.lower_bound(x);
    h = std::min({h, step, std::max(4.0f * margin, bound)});
    Eigen::Vector3f next, k4;
    float lower = 0.0f, error = 0.0f;
    for (;;) {
      field_slack = INFINITY;
      const Eigen::Vector3f k2 = velocity(x + 0.5f * h * k1);
      const Eigen::Vector3f k3 = velocity(x + 0.75f * h * k2);
      next = x + h * ((2.0f / 9.0f) * k1 + (1.0f / 3.0f) * k2 + (4.0f / 9.0f) * k3);
      k4 = velocity(next);
      const Eigen::Vector3f second = x + h * ((7.0f / 24.0f) * k1 + 0.25f * k2 + (1.0f / 3.0f) * k3 + 0.125f * k4);
      error = (next - second).norm();
      bool queried = false;
      SurfacePoint closest;
      lower = band.prove(next, 0.5f * margin, queried, closest);
      const bool inside = lower < 0.0f;
      if ((error <= allowed && !inside) || h <= shortest) break;
      ++(inside ? stats.halved_steps : stats.rejected_steps);
      h = inside ? 0.5f * h : std::max(0.25f * h, 0.9f * h * std::cbrt(allowed / error));
    }
    ++stats.steps;
    const float moved = (next - x).norm();
    if (lower < 0.0f || !(moved > 1e-3f * h)) break;
    if (field_slack < 0.0f) {  // the step passed where the field has no direction
      ++stats.ended_strands;
      break;
    }
    last = (next - x) / moved;
    fine.add(next, lower);
    arc += double(moved);
    x = next;
    k1 = k4;  // first same as last
    nearest_at_x = nearest;
    // The next step from this one's error (third order: the cube root), growing at most fourfold.
    h = std::min(step, error > 0.0f ? h * std::min(4.0f, 0.9f * std::cbrt(allowed / error)) : 4.0f * h);
  }
  if (arc < double(length)) ++stats.short_strands;
  // The cut: the curve is as long as the target (its guides' curve lengths, Binding::lengths),
  // whatever the point count written. Cutting where the n-point polyline had that length carried a
  // strand at a guide's root past the guide's tip by the chords' shortfall when the guide has more
  // points.
  const double cut = std::min(double(length), arc);
  fine.resample_to(n, cut, r_points, r_lower);
}

/// A strand rooted at a guide's root is that guide: the guide's curve (groom/guide_curve.h), which
/// is an integral curve of the field wherever the skin band leaves the field alone, resampled to
/// `n` points by arc length over its whole length. Integrating from the root would give the same
/// curve up to the integration's error, but that error is not small everywhere: where another guide
/// passes within a few hundredths of a segment, the field turns between the two within that gap and
/// multiplies a strand's distance from the guide many times over (by about the square of the ratio
/// of the way along the pass to the gap), and a guide that leaves the skin more flatly than the
/// band's lift is lifted off near its root and starts the pass already off it. A guide that runs
/// low (into the skin, or back into the band of skin_band_margins x `margin` once risen above it:
/// the checker's rule) is not followed here, since there the skin promise wins: returns false and
/// the strand is grown from the field.
bool follow_guide(std::span<const Eigen::Vector3f> guide, const MeshQuery &query, float tiny, float margin, int n,
                  std::vector<CurvePiece> &r_pieces, FinePolyline &r_fine, Eigen::Vector3f *r_points, float *r_lower) {
  guide_curve(guide, tiny, r_pieces);
  if (r_pieces.empty()) return false;
  const std::vector<Eigen::Vector3f> curve = sample_curve(r_pieces, guide_curve_samples_per_piece);
  std::vector<float> distances;
  if (guide_runs_low(curve, query, skin_band_margins * margin, &distances)) return false;
  r_fine.clear();
  double total = 0.0;
  for (size_t j = 0; j < curve.size(); ++j) {
    if (j > 0) total += double((curve[j] - curve[j - 1]).norm());
    r_fine.add(curve[j], std::max(distances[j], 0.0f));
  }
  r_fine.resample_to(n, total, r_points, r_lower);
  return true;
}

/// One of a root's guides at this frame: its weight, and the rotation carrying it from its root's
/// surface frame to the root's, Q_root(t) * rest rotation * Q_guide(t)^T (a rigid motion of the skin
/// gives back the rest rotation conjugated by that motion, so carried guides move rigidly).
struct Slot {
  int32_t guide;
  float weight;
  Eigen::Matrix3f rotation;
};

/// Root r's used slots at this frame, into r_slots (max_guides_per_root of them); returns their count.
int frame_slots(const Binding &binding, const FrameGuides &frame, size_t r, const SurfaceFrame &root_frame,
                Slot *r_slots) {
  const int k = binding.k;
  int used = 0;
  for (int s = 0; s < k; ++s) {
    const size_t slot = r * size_t(k) + size_t(s);
    const int32_t g = binding.guide_ids[slot];
    if (g < 0) break;
    r_slots[used++] = {g, binding.weights[slot],
                       root_frame.basis * binding.rest_rotations[slot].toRotationMatrix() *
                           frame.frames[size_t(g)].transpose()};
  }
  return used;
}

/// The guide a root is the root of (the binding found it at that guide's root alone: Binding::hits),
/// or -1: its strand is the guide itself, from the root's own
/// place (guide_start_offset), where the guide stays out of the skin.
int32_t guide_at_root(const Binding &binding, size_t r, const Slot *slots, int used) {
  if (used == 1 && r < binding.hits.size() && binding.hits[r]) return slots[0].guide;
  return -1;
}

/// How far a strand at guide root `g` starts from the guide's own first point: the root's offset
/// from the guide root on the skin at this frame, or none where the two coincide (within 1e-5 of
/// the length unit), so that a strand at the guide root itself is the guide to the bit.
Eigen::Vector3f guide_start_offset(const Binding &binding, const FrameGuides &frame, int32_t g,
                                   const SurfaceFrame &root_frame) {
  const Eigen::Vector3f offset = root_frame.origin - frame.origins[size_t(g)];
  return offset.norm() <= 1e-5f * binding.length_unit ? Eigen::Vector3f::Zero() : offset;
}

/// A strand's first point: the root on the skin, lifted along its normal by the height of the guides'
/// own first points above their surface points (carried), when that lifted point is outside the skin
/// (where the skin folds, as at a thin ear, the normal can lead behind another part of it). Only the
/// height: a sideways part would move the root off its place on the skin. `band` starts at the root.
Eigen::Vector3f lifted_root(const Binding &binding, const FrameGuides &frame, const StrandSet &guides,
                            const Slot *slots, int used, const SurfaceFrame &root_frame, int triangle,
                            SkinBand &band) {
  const Eigen::Vector3f normal = root_frame.normal();
  Eigen::Vector3f lift = Eigen::Vector3f::Zero();
  for (int s = 0; s < used; ++s) {
    const size_t g = size_t(slots[s].guide);
    lift += slots[s].weight * (slots[s].rotation * (guides.points(g)[0] - frame.origins[g]));
  }
  const float height = std::max(lift.dot(normal), 0.0f);
  if (height <= 1e-6f * binding.length_unit) return root_frame.origin;
  const float distance = band.exact(root_frame.origin + height * normal);
  if (distance >= 0.0f) return root_frame.origin + height * normal;
  band.start(root_frame.origin, 0.0f, triangle);
  return root_frame.origin;
}

/// Keeps a strand's fine polyline (its exact curve) and the length it was cut at.
void keep_curve(std::span<const Eigen::Vector3f> fine, float length, std::vector<Eigen::Vector3f> &r_curve,
                float &r_cut) {
  r_curve.assign(fine.begin(), fine.end());
  double arc = 0.0;
  for (size_t i = 1; i < fine.size(); ++i) arc += double((fine[i] - fine[i - 1]).norm());
  r_cut = float(std::min(double(length), arc));
}

/// Throws InputError when the roots or guides of a frame do not match the binding.
void check_frame_inputs(const Binding &binding, const Roots &roots, const StrandSet &guides) {
  if (roots.size() != binding.root_count())
    throw InputError("grow: " + std::to_string(roots.size()) + " roots, but the binding has " +
                     std::to_string(binding.root_count()));
  if (guides.strand_count() != binding.guide_roots.size())
    throw InputError("grow: " + std::to_string(guides.strand_count()) + " guides, but the binding has " +
                     std::to_string(binding.guide_roots.size()));
  for (size_t g = 0; g < guides.strand_count(); ++g)
    if (guides.points_in(g) < 2)
      throw InputError("guide " + std::to_string(g) + ": expected at least 2 points, got " +
                       std::to_string(guides.points_in(g)));
  for (const Eigen::Vector3f &p : guides.positions)
    if (!p.allFinite()) throw InputError("grow: a guide point is not finite");
}

}  // namespace

GrowStats &GrowStats::operator+=(const GrowStats &other) {
  steps += other.steps;
  evaluations += other.evaluations;
  skin_queries += other.skin_queries;
  halved_steps += other.halved_steps;
  rejected_steps += other.rejected_steps;
  short_strands += other.short_strands;
  ended_strands += other.ended_strands;
  return *this;
}

std::string GrowStats::summary() const {
  const double per_step = steps > 0 ? 1.0 / double(steps) : 0.0;
  char text[256];
  std::snprintf(text, sizeof text,
                "%.2f field evaluations per step, %.3f skin queries per step; %lld steps rejected, %lld halved, %lld "
                "strands short, %lld ended where the field had no direction",
                double(evaluations) * per_step, double(skin_queries) * per_step, static_cast<long long>(rejected_steps),
                static_cast<long long>(halved_steps), static_cast<long long>(short_strands), static_cast<long long>(ended_strands));
  return text;
}

void grow(const Binding &binding, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
          const StrandSet &guides, const GrowOptions &options, StrandSet &r_strands,
          std::vector<float> *r_clearance, const SkinGrid *shared_skin_grid) {
  const int n = options.points_per_strand;
  if (n < 2) throw InputError("points_per_strand: expected at least 2, got " + std::to_string(n));
  check_frame_inputs(binding, roots, guides);

  const FrameGuides frame = prepare_guides(binding, mesh, guides, n);
  const InterpolationSettings &settings = binding.settings;
  const float margin = binding.skin_margin;
  const float scale = mesh_scale(mesh);
  std::unique_ptr<SkinGrid> own_skin_grid;
  if (!shared_skin_grid) own_skin_grid = std::make_unique<SkinGrid>(mesh, query);
  const SkinGrid &skin_grid = shared_skin_grid ? *shared_skin_grid : *own_skin_grid;

  r_strands.resize_uniform(roots.size(), n, options.with_widths, StrandSet::Fill::unset);  // all written below
  r_strands.ids = roots.ids;
  std::vector<float> own_clearance;
  std::vector<float> &clearance = r_clearance ? *r_clearance : own_clearance;
  clearance.resize(r_strands.positions.size());
  const int64_t root_count = int64_t(roots.size());
  GrowStats stats;
  bool finite = true;
  // Streamline: each strand's exact curve (its fine polyline and cut), for the separation pass.
  const bool streamline = settings.method == InterpolationSettings::Method::streamline;
  std::vector<std::vector<Eigen::Vector3f>> fine_curves(streamline && options.separate ? roots.size() : 0);
  std::vector<float> cuts(fine_curves.size(), 0.0f);
  std::vector<uint8_t> at_guide_root(fine_curves.size(), 0);
#pragma omp parallel reduction(&& : finite)
  {
    GrowStats counts;  // this thread's
    StrandScratch scratch;
    std::unique_ptr<PartingAttenuation> attenuation;
    if (binding.partings && binding.partings->partial_line_count() > 0)
      attenuation = std::make_unique<PartingAttenuation>(*binding.partings);
#pragma omp for schedule(dynamic, 16)
    for (int64_t r = 0; r < root_count; ++r) {
      const SurfaceFrame root_frame = surface_frame(mesh, roots.points[size_t(r)]);
      const Eigen::Vector3f normal = root_frame.normal();
      Eigen::Vector3f *points = r_strands.positions.data() + r * n;
      float *lower = clearance.data() + r * n;
      SkinBand band(mesh, query, skin_grid, margin, counts);
      band.start(root_frame.origin, 0.0f, roots.points[size_t(r)].triangle);

      Slot slots[max_guides_per_root];
      const int used = frame_slots(binding, frame, size_t(r), root_frame, slots);
      const Eigen::Vector3f root = lifted_root(binding, frame, guides, slots, used, root_frame,
                                               roots.points[size_t(r)].triangle, band);

      const int32_t on_guide = guide_at_root(binding, size_t(r), slots, used);

      if (on_guide >= 0 && !at_guide_root.empty()) at_guide_root[size_t(r)] = 1;
      if (settings.method == InterpolationSettings::Method::streamline) {
        const GuideField *field = frame.fields[size_t(binding.root_zones[size_t(r)])].get();
        if (field && !field->empty() && on_guide >= 0 &&
            follow_guide(guides.points(size_t(on_guide)), query, curve_merge_fraction * binding.length_unit, margin, n,
                         scratch.pieces, scratch.fine, points, lower)) {
          // the guide's own curve, which is also its exact curve for the separation pass; a root
          // beside the guide root (a hit, Binding::hits) starts as far beside the guide's start
          const Eigen::Vector3f beside = guide_start_offset(binding, frame, on_guide, root_frame);
          points[0] += beside;
          lower[0] = std::max(lower[0] - beside.norm(), 0.0f);
          if (!fine_curves.empty())
            keep_curve(scratch.fine.points, std::numeric_limits<float>::max(), fine_curves[size_t(r)], cuts[size_t(r)]);
        } else if (field && !field->empty()) {
          grow_streamline(*field, attenuation.get(), root, normal, binding.lengths[size_t(r)], binding.step,
                          binding.tolerance, margin, band, scratch, counts, n, points, lower);
          if (!fine_curves.empty())
            keep_curve(scratch.fine.points, binding.lengths[size_t(r)], fine_curves[size_t(r)], cuts[size_t(r)]);
        } else {
          // A zone whose guides have no length: the strand rises along the normal.
          points[0] = root;
          lower[0] = band.lower_bound(root);
          for (int i = 1; i < n; ++i)
            points[i] = walk(points[i - 1], normal, binding.lengths[size_t(r)] / float(n - 1), margin, band, counts, lower[i]);
          if (!fine_curves.empty())
            keep_curve(std::span<const Eigen::Vector3f>(points, size_t(n)), INFINITY, fine_curves[size_t(r)], cuts[size_t(r)]);
        }
      } else if (settings.method == InterpolationSettings::Method::fur) {
        // Segment j: weighted length and weighted direction of the carried guides' segments j; a
        // point that falls inside the skin (or within the margin) is moved out to the margin, and the
        // strand goes on from there. Points outside the margin are the blend's own.
        points[0] = root;
        lower[0] = band.lower_bound(root);
        SkinGuard guard(query, margin, scale, &skin_grid);
        guard.start(root, roots.points[size_t(r)].triangle);  // on the skin or lifted above it
        Eigen::Vector3f direction = normal;
        for (int i = 0; i + 1 < n; ++i) {
          Eigen::Vector3f blend = Eigen::Vector3f::Zero();
          float length = 0.0f;
          for (int s = 0; s < used; ++s) {
            const size_t at = size_t(slots[s].guide) * size_t(n - 1) + size_t(i);
            blend += slots[s].weight * (slots[s].rotation * frame.resampled_directions[at]);
            length += slots[s].weight * frame.resampled_lengths[at];
          }
          direction = unit_or(blend, direction);
          points[i + 1] = points[i] + length * direction;
          guard.keep_out(points[i + 1]);
          lower[i + 1] = guard.lower_bound(points[i + 1]);
        }
      } else {
        // Linear: root-relative offsets of the resampled guides blended as they are (no rotation),
        // after the root point the other methods start from; a point that falls inside the skin (or
        // within the margin) is moved out to the margin.
        points[0] = root;
        lower[0] = band.lower_bound(root);
        SkinGuard guard(query, margin, scale, &skin_grid);
        guard.start(root, roots.points[size_t(r)].triangle);  // on the skin or lifted above it
        for (int i = 1; i < n; ++i) {
          Eigen::Vector3f p = root_frame.origin;
          for (int s = 0; s < used; ++s) {
            const size_t g = size_t(slots[s].guide);
            p += slots[s].weight * (frame.resampled[g * size_t(n) + size_t(i)] - frame.origins[g]);
          }
          guard.keep_out(p);
          points[i] = p;
          lower[i] = guard.lower_bound(p);
        }
      }
      for (int i = 0; i < n; ++i) finite = points[i].allFinite() && finite;
      if (options.with_widths)
        for (int i = 0; i < n; ++i)
          r_strands.widths[size_t(r * n + i)] =
              options.width_root + (options.width_tip - options.width_root) * float(i) / float(n - 1);
    }
#pragma omp critical(plume_grow_stats)
    stats += counts;
  }

  if (!finite) throw InternalError("grow: a strand point is not finite");

  // The separation pass: the exact curves never meet, the written polylines may where the field
  // brings neighbours closer than the chords' sag; their points are moved apart, each to its curve's
  // side (interp/separate.h).
  if (streamline && options.separate && root_count > 1) {
    ExactCurves curves;
    curves.offsets.reserve(fine_curves.size() + 1);
    curves.offsets.push_back(0);
    for (const std::vector<Eigen::Vector3f> &curve : fine_curves) {
      curves.points.insert(curves.points.end(), curve.begin(), curve.end());
      curves.offsets.push_back(curves.points.size());
    }
    fine_curves = {};
    curves.cuts = std::move(cuts);
    // The checker's default crossing tolerance on these strands (check/check.h): a thousandth of
    // their median segment.
    const float tolerance = 1e-3f * float(median_segment_length(r_strands));
    const SeparationStats separation =
        separate_strands(r_strands.positions, n, curves, tolerance, margin, mesh, skin_grid, clearance, at_guide_root);
    stats.separated_pairs = separation.pairs_found;
    stats.unseparated_pairs = separation.pairs_left;
    stats.separation_points_moved = separation.points_moved;
    stats.separation_sweeps = separation.sweeps;
    stats.separation_largest_move = separation.largest_move;
    for (const Eigen::Vector3f &p : r_strands.positions)
      if (!p.allFinite()) throw InternalError("grow: a separated strand point is not finite");
  }
  if (options.r_stats) *options.r_stats = stats;
}

std::vector<Eigen::Vector3f> strand_starts(const Binding &binding, const Mesh &mesh, const MeshQuery &query,
                                           const Roots &roots, const StrandSet &guides,
                                           const SkinGrid *shared_skin_grid) {
  check_frame_inputs(binding, roots, guides);
  const FrameGuides frame = prepare_guides(binding, mesh, guides, 0);
  std::unique_ptr<SkinGrid> own_skin_grid;
  if (!shared_skin_grid) own_skin_grid = std::make_unique<SkinGrid>(mesh, query);
  const SkinGrid &skin_grid = shared_skin_grid ? *shared_skin_grid : *own_skin_grid;
  std::vector<Eigen::Vector3f> starts(roots.size());
  const int64_t root_count = int64_t(roots.size());
  const bool streamline = binding.settings.method == InterpolationSettings::Method::streamline;
#pragma omp parallel
  {
    GrowStats counts;
    std::vector<CurvePiece> pieces;
    FinePolyline fine;
#pragma omp for schedule(dynamic, 64)
    for (int64_t r = 0; r < root_count; ++r) {
      const SurfaceFrame root_frame = surface_frame(mesh, roots.points[size_t(r)]);
      SkinBand band(mesh, query, skin_grid, binding.skin_margin, counts);
      band.start(root_frame.origin, 0.0f, roots.points[size_t(r)].triangle);
      Slot slots[max_guides_per_root];
      const int used = frame_slots(binding, frame, size_t(r), root_frame, slots);
      starts[size_t(r)] = lifted_root(binding, frame, guides, slots, used, root_frame,
                                      roots.points[size_t(r)].triangle, band);
      // A streamline strand at a guide root is the guide's own curve where grow() follows it.
      const int32_t on_guide = guide_at_root(binding, size_t(r), slots, used);
      if (streamline && on_guide >= 0) {
        Eigen::Vector3f ends[2];
        float lower[2];
        if (follow_guide(guides.points(size_t(on_guide)), query, curve_merge_fraction * binding.length_unit,
                         binding.skin_margin, 2, pieces, fine, ends, lower))
          starts[size_t(r)] = ends[0] + guide_start_offset(binding, frame, on_guide, root_frame);
      }
    }
  }
  return starts;
}

}  // namespace plume::interp
