#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <span>
#include <string>

#include "groom/error.h"
#include "interp/interpolate.h"
#include "skin/lanes.h"
#include "skin/skin_guard.h"

namespace plume::interp {

using namespace skin;

namespace {

/// One guide segment as streamline growth reads it: one cache line of four quads of four floats,
/// (start, arc), (direction, length), (tangent_start, inverse_length), (tangent_end, curvature), so
/// that the field loads a quad of four guides' segments at once and transposes it into lanes
/// (load_quad).
struct alignas(64) GuideSegment {
  Eigen::Vector3f start;  // first point
  float arc;              // arc length from the guide's first point to `start`
  Eigen::Vector3f direction;  // unit
  float length;
  Eigen::Vector3f tangent_start;  // continuous tangents at its two points
  float inverse_length;           // 1 / length, 0 for a zero-length segment
  Eigen::Vector3f tangent_end;
  float curvature;  // sustained curvature (see prepare_guides)
};
static_assert(sizeof(GuideSegment) == 16 * sizeof(float) && sizeof(Eigen::Vector3f) == 3 * sizeof(float),
              "GuideSegment must be four packed quads of floats");

/// The guides at one frame, prepared once per frame (never per strand).
struct FrameGuides {
  /// #guides surface frames at the guide roots on the posed mesh (columns tangent, bitangent, normal).
  std::vector<Eigen::Matrix3f> frames;
  /// #guides surface positions of the guide roots on the posed mesh.
  std::vector<Eigen::Vector3f> origins;
  /// Streamline: segment j of guide g is at index segment_offsets[g] + j (#guides + 1 offsets).
  std::vector<int64_t> segment_offsets;
  /// Streamline: every guide segment, packed (see GuideSegment).
  std::vector<GuideSegment> segments;
  /// Fur and linear: every guide resampled to N points by arc length (#guides * N points), with its
  /// #guides * (N - 1) unit segment directions and lengths.
  std::vector<Eigen::Vector3f> resampled;
  std::vector<Eigen::Vector3f> resampled_directions;
  std::vector<float> resampled_lengths;
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

/// `points` resampled to `count` points evenly spaced in arc length (a copy when counts match).
void resample(std::span<const Eigen::Vector3f> points, int count, Eigen::Vector3f *r_points) {
  if (points.size() == size_t(count)) {
    std::copy(points.begin(), points.end(), r_points);
    return;
  }
  double total = 0.0;
  for (size_t j = 0; j + 1 < points.size(); ++j) total += (points[j + 1] - points[j]).norm();
  size_t segment = 0;
  double segment_start = 0.0;
  double segment_length = (points[1] - points[0]).norm();
  for (int i = 0; i < count; ++i) {
    const double target = total * double(i) / double(count - 1);
    while (segment + 2 < points.size() && segment_start + segment_length < target) {
      segment_start += segment_length;
      ++segment;
      segment_length = (points[segment + 1] - points[segment]).norm();
    }
    const double t = segment_length > 0.0 ? std::clamp((target - segment_start) / segment_length, 0.0, 1.0) : 0.0;
    r_points[i] = points[segment] + float(t) * (points[segment + 1] - points[segment]);
  }
  r_points[count - 1] = points.back();
}

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
  if (binding.settings.method == InterpolationSettings::Method::streamline) {
    frame.segment_offsets.resize(guide_count + 1, 0);
    for (size_t g = 0; g < guide_count; ++g)
      frame.segment_offsets[g + 1] = frame.segment_offsets[g] + guides.points_in(g) - 1;
    const size_t segment_count = size_t(frame.segment_offsets.back());
    // Per segment: unit direction (a zero-length segment takes a neighbour's), length, and arc length
    // from the guide's first point to its start.
    std::vector<Eigen::Vector3f> segment_directions(segment_count);
    std::vector<float> segment_lengths(segment_count), segment_arcs(segment_count);
    for (size_t g = 0; g < guide_count; ++g) {
      const int64_t first = frame.segment_offsets[g];
      unit_segments(guides.points(g), frame.frames[g].col(2), segment_directions.data() + first,
                    segment_lengths.data() + first);
      float arc = 0.0f;
      for (int64_t j = first; j < frame.segment_offsets[g + 1]; ++j) {
        segment_arcs[size_t(j)] = arc;
        arc += segment_lengths[size_t(j)];
      }
    }
    // Unit tangent at each guide point (indexed like the guides' positions): the bisector of the two
    // segments meeting there. Along a segment the field's direction goes linearly from one end's
    // tangent to the other's, so it is continuous at vertices.
    std::vector<Eigen::Vector3f> point_tangents(guides.point_count());
    for (size_t g = 0; g < guide_count; ++g) {
      const int64_t first = frame.segment_offsets[g];
      const int64_t segments = frame.segment_offsets[g + 1] - first;
      Eigen::Vector3f *tangents = point_tangents.data() + guides.offsets[g];
      const Eigen::Vector3f *directions = segment_directions.data() + first;
      for (int64_t j = 1; j < segments; ++j) tangents[j] = unit_or(directions[j - 1] + directions[j], directions[j]);
      // End tangents: the inner tangent mirrored about the end segment, exact on a circular arc.
      auto mirror = [](const Eigen::Vector3f &inner, const Eigen::Vector3f &segment) {
        return unit_or(2.0f * segment.dot(inner) * segment - inner, segment);
      };
      tangents[0] = segments > 1 ? mirror(tangents[1], directions[0]) : directions[0];
      tangents[segments] = segments > 1 ? mirror(tangents[segments - 1], directions[segments - 1]) : directions[0];
    }
    // Per segment, the guide's sustained curvature there: the smallest turning rate
    // |t_end - t_start| / length over the segment and the two on each side. A curl keeps it high
    // along its coils; a single sharp bend (one vertex) does not count.
    std::vector<float> segment_curvatures(segment_count);
    std::vector<float> turning;
    for (size_t g = 0; g < guide_count; ++g) {
      const int64_t first = frame.segment_offsets[g];
      const int64_t segments = frame.segment_offsets[g + 1] - first;
      const Eigen::Vector3f *tangents = point_tangents.data() + guides.offsets[g];
      turning.resize(size_t(segments));
      for (int64_t j = 0; j < segments; ++j) {
        const float length = segment_lengths[size_t(first + j)];
        turning[size_t(j)] = length > 0.0f ? (tangents[j + 1] - tangents[j]).norm() / length : 0.0f;
      }
      constexpr int64_t spread = 2;
      for (int64_t j = 0; j < segments; ++j) {
        float sustained = turning[size_t(j)];
        for (int64_t i = std::max<int64_t>(j - spread, 0); i <= std::min(j + spread, segments - 1); ++i)
          sustained = std::min(sustained, turning[size_t(i)]);
        segment_curvatures[size_t(first + j)] = sustained;
      }
    }
    frame.segments.resize(segment_count);
    for (size_t g = 0; g < guide_count; ++g) {
      const int64_t first = frame.segment_offsets[g];
      const std::span<const Eigen::Vector3f> points = guides.points(g);
      const Eigen::Vector3f *tangents = point_tangents.data() + guides.offsets[g];
      for (int64_t j = 0; j < frame.segment_offsets[g + 1] - first; ++j) {
        const size_t at = size_t(first + j);
        const float length = segment_lengths[at];
        GuideSegment &segment = frame.segments[at];
        segment.start = points[size_t(j)];
        segment.arc = segment_arcs[at];
        segment.direction = segment_directions[at];
        segment.length = length;
        segment.tangent_start = tangents[j];
        segment.inverse_length = length > 0.0f ? 1.0f / length : 0.0f;
        segment.tangent_end = tangents[j + 1];
        segment.curvature = segment_curvatures[at];
      }
    }
  } else {
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
  }
  return frame;
}

/// Per guide point (indexed like the guides' positions), a lower bound of its signed distance to
/// the skin, within a factor of two of it. Each guide is walked from its root; a point takes the
/// better of the 1-Lipschitz bound from the last queried point and the grid's bound on its distance
/// to every triangle (SkinGrid::distance_lower_bound; the point cannot have crossed the skin since
/// the previous one, as SkinGuard::keep_out argues), and is queried only where that falls below half
/// of the last queried distance: a few queries per guide.
/// -infinity (no bound) next to an open edge of the mesh, where the side of a point is not kept by
/// moving without crossing the skin (SkinGrid::near_open_edge).
std::vector<float> guide_clearances(const StrandSet &guides, const std::vector<SurfacePoint> &guide_roots,
                                    const MeshQuery &query, const SkinGrid &skin_grid) {
  std::vector<float> clearances(guides.point_count());
  const int64_t guide_count = int64_t(guides.strand_count());
#pragma omp parallel for schedule(dynamic, 16)
  for (int64_t g = 0; g < guide_count; ++g) {
    SurfacePoint hint = guide_roots[size_t(g)];
    Eigen::Vector3f queried_point = Eigen::Vector3f::Zero(), previous_point = queried_point;
    float queried = -INFINITY, previous = -INFINITY;
    for (int64_t j = guides.offsets[size_t(g)]; j < guides.offsets[size_t(g) + 1]; ++j) {
      const Eigen::Vector3f &p = guides.positions[size_t(j)];
      float &clearance = clearances[size_t(j)];
      if (skin_grid.near_open_edge(p)) {
        clearance = queried = previous = -INFINITY;
        continue;
      }
      clearance = queried - (p - queried_point).norm();
      if (!(clearance >= 0.5f * queried)) {
        const float lower = skin_grid.distance_lower_bound(p);
        if (previous > 0.0f && lower > 0.0f && previous + lower > (p - previous_point).norm())
          clearance = std::max(clearance, lower);
      }
      if (!(queried > 0.0f && clearance >= 0.5f * queried)) {
        SurfacePoint closest;
        clearance = float(query.signed_distance(p.cast<double>(), hint, closest));
        hint = closest;
        queried_point = p;
        queried = clearance;
      }
      previous_point = p;
      previous = clearance;
    }
  }
  return clearances;
}

/// One influencing guide of the strand being grown, as the binding gives it.
struct Slot {
  int32_t guide;
  float weight;     // binding weight
  float influence;  // scale of the 1/d law (streamline)
  Eigen::Matrix3f rotation;  // carries the guide at this frame to the root's frame
};

/// Points of earlier strands (of one thread) known to be outside the skin, with their signed
/// distances or lower bounds of them: the last few strands' first points. No skin lies within that
/// distance of such a point, so a point inside that ball by the margin is on its side, outside by the
/// margin (1-Lipschitz, as SkinGuard argues within a strand). Roots come in the order of their
/// triangles, so a strand's first point usually lies near an earlier one: its proof needs no search.
class RecentOutside {
 public:
  /// A point outside the skin, and its signed distance or a lower bound of it: no skin lies closer.
  struct Ball {
    Eigen::Vector3f centre = Eigen::Vector3f::Zero();
    float radius = -INFINITY;  // an unused entry proves nothing
  };
  /// The ball that proves p outside by the most, at least `margin`; null when none does.
  const Ball *proving(const Eigen::Vector3f &p, float margin) const {
    const Ball *best = nullptr;
    float best_bound = margin;
    for (const Ball &ball : balls_) {
      const float bound = ball.radius - (p - ball.centre).norm();
      if (bound >= best_bound) {
        best_bound = bound;
        best = &ball;
      }
    }
    return best;
  }
  /// Keeps the ball in place of the oldest one.
  void add(const Eigen::Vector3f &centre, float radius) {
    balls_[next_] = {centre, radius};
    next_ = (next_ + 1) % size;
  }

 private:
  static constexpr int size = 4;  // as many as the roots of a triangle or two: more found little more
  Ball balls_[size];
  int next_ = 0;
};

/// Quad `quad` (0..3, see GuideSegment) of segment index[l] of segments[l] in each lane l, transposed:
/// r[c] holds component c of the four lanes.
void load_quad(const GuideSegment *const segments[4], Int4 index, int quad, Float4 r[4]) {
  Float4 rows[4];
  for (int l = 0; l < 4; ++l)
    std::memcpy(&rows[l], reinterpret_cast<const float *>(segments[l] + index[l]) + 4 * quad, sizeof(Float4));
  transpose4(rows, r);
}
#ifdef __AVX__
/// The same for eight lanes: lanes 0-3, then 4-7.
void load_quad(const GuideSegment *const segments[8], Int8 index, int quad, Float8 r[4]) {
  Float4 low[4], high[4];
  load_quad(segments, lane_quad(index, 0), quad, low);
  load_quad(segments + 4, lane_quad(index, 1), quad, high);
  for (int c = 0; c < 4; ++c) r[c] = join(low[c], high[c]);
}
#endif

/// Guides as the streamline field walks them, W at a time, one per SIMD lane: either four
/// influencing guides of one strand (StreamlineField) or guide slots s and s + 1 of four strands
/// (QuadField, W = 8).
template <int W>
struct GuideLanes {
  using Float = typename Lanes<W>::Float;
  using Int = typename Lanes<W>::Int;
  const GuideSegment *segments[W];  // the guide's first segment
  const float *clearances[W];       // the guide's first point's clearance (guide_clearances)
  Int segment_count;  // segment indices along one guide fit 32 bits (the guide's points would not fit memory)
  Float influence;    // scale of the 1/d law
  Float arc_scale;    // guide length / strand length
};
/// What the field keeps of one evaluation for the next, per lane of a GuideLanes.
template <int W>
struct GuideProgress {
  typename Lanes<W>::Int segment;  // segment of the guide holding the last closest point
  typename Lanes<W>::Float pace;   // the pace term's lambda for the next evaluation (see match_guides)
};

/// The influencing guides of one strand, four to a group (one guide per lane). Lanes past the last
/// guide repeat the group's first lane and are left out of the blend.
struct StreamlineSlots {
  static constexpr int max_groups = (max_guides_per_root + 3) / 4;
  int used = 0;  // guides
  int group_count = 0;
  GuideLanes<4> groups[max_groups];
  GuideProgress<4> progress[max_groups];
};

/// How far a strand's guide search looks, per lane; it scales with the strand's step.
template <int W>
struct SearchWindow {
  typename Lanes<W>::Float half_arc;  // half width of the window in guide arc length (lookahead * step / 2)
  typename Lanes<W>::Int lookahead;   // and at least this many segments
  typename Lanes<W>::Float tie_sq;    // a later segment within this of the best wins (vertex ties go forward)
};

/// The point match_guides chose on each lane's guide.
template <int W>
struct GuideMatch {
  using Float = typename Lanes<W>::Float;
  Float distance_sq;
  Float tangent[3];  // the guide's unit tangent there
  Float clearance;   // lower bound of the probe's signed distance to the skin (see match_guides)
  Float weight;      // influence / distance
};

/// On each lane's guide, the closest point to the lane's probe (px, py, pz), at the strand's arc
/// length `arc`, within a window moving forward from the lane's last segment (`progress`, updated);
/// the guide's tangent there and the weight influence / d of the streamline field.
///
/// The lanes walk their guides in step, a lane that has stopped masked out of the rest, so each picks
/// the segment a search of its guide alone would: the same window start, pace term, ties and window
/// end. Every lane does that search's float operations in the same order (Eigen's dot products and
/// norms add x + (y + z); no fused multiply-add), so a lane's result does not depend on the others.
///
/// `clearance`: a lower bound of the probe's signed distance to the skin from the guides' own. The
/// signed distance is 1-Lipschitz, so at the chosen point q, t along a segment of length L whose
/// ends are c0 and c1 from the skin, sd(q) >= max(c0 - t, c1 - (L - t)), and sd(p) >= sd(q) - |p - q|
/// (the ball of that radius round q holds no skin, so p is on q's side). Free, as the search has
/// found q: growth's skin guard then needs no query for most points away from the root.
template <int W>
[[gnu::always_inline]] inline GuideMatch<W> match_guides(typename Lanes<W>::Float px, typename Lanes<W>::Float py,
                                                         typename Lanes<W>::Float pz, typename Lanes<W>::Float arc,
                                                         const SearchWindow<W> &window, const GuideLanes<W> &guides,
                                                         GuideProgress<W> &progress) {
  using Float = typename Lanes<W>::Float;
  using Int = typename Lanes<W>::Int;
  // The window: from the last closest point (never backwards), over the guide arc around where a
  // strand keeping pace with the guide would be (arc * guide length / strand length).
  const Float expected = arc * guides.arc_scale;
  const Float window_low = expected - window.half_arc, window_high = expected + window.half_arc;
  // Farther from a curl than about its radius (1 / curvature), the squared distance along the
  // guide is no longer convex (its second derivative is 2 (1 - kappa (p - q).N), N the principal
  // normal): the closest point jumps round the coil, or sticks on the far side of it, as p moves,
  // and the blended direction wanders between coils. The pace term lambda (s - expected)^2, with
  // lambda = max(0, 2 kappa |p - q| - 1/2) and kappa the sustained curvature, keeps the cost
  // convex there, so the chosen point moves smoothly and keeps pace with the strand. Near the
  // guide and along gentle or single sharp bends lambda is 0: plain closest points, as the ratio
  // of distances needs. |p - q| is the previous evaluation's, half a step behind.
  const Float lambda = progress.pace;
  const Float inverse_one_plus_lambda = lambda > 0.0f ? 1.0f / (1.0f + lambda) : Float{} + 1.0f;
  // Segment j's cost in each lane: its point of least cost (at r_t along it), the squared
  // distance there, the segment's arc, and whether that point lies before the segment's end.
  auto segment_cost = [&](const Float (&start_arc)[4], const Float (&direction_length)[4], Float &r_t,
                          Float &r_distance_sq, Float &r_arc, Int &r_inner) {
    const Float &segment_arc = start_arc[3], &length = direction_length[3];
    r_arc = segment_arc;
    const Float ox = px - start_arc[0], oy = py - start_arc[1], oz = pz - start_arc[2];
    const Float dx = direction_length[0], dy = direction_length[1], dz = direction_length[2];
    const Float t = (ox * dx + (oy * dy + oz * dz) + lambda * (expected - segment_arc)) * inverse_one_plus_lambda;
    r_t = t < 0.0f ? Float{} : (length < t ? length : t);  // std::clamp(t, 0, length)
    r_inner = t < length;
    const Float ex = ox - r_t * dx, ey = oy - r_t * dy, ez = oz - r_t * dz;
    r_distance_sq = ex * ex + (ey * ey + ez * ez);
    const Float lag = segment_arc + r_t - expected;
    return r_distance_sq + lambda * lag * lag;
  };
  // The cost is convex along the guide (the pace term above), so its minimum over each segment
  // falls then rises along the window: walk forward from the window's first segment while the
  // next segment is no worse (ties go forward: a vertex belongs to its outgoing segment), or
  // until the window ends (past both `lookahead` segments and the window's arc). A segment whose
  // least cost lies before its end holds the minimum (the cost rises past it): the walk stops
  // there without looking at the next. Usually one segment is looked at instead of the whole
  // window.
  // One loop finds the window's first segment and then walks: a lane first moves forward from its
  // last segment while the next one starts at or before the window's low end (its start is this
  // one's arc plus length, the same float sum prepare_guides made), takes the first that does not
  // (whatever its cost), then walks. The lanes look at the segment after the last in every pass,
  // whatever they decided, so that the next loads need not wait for the costs; they go round
  // together while any of them still moves on.
  const Int last = guides.segment_count - 1;
  Int segment = progress.segment;  // looked at in this pass
  Int finding = segment == segment, walking = Int{};  // lanes still looking for the window's start, walking
  Int start = segment, best = segment;
  Float best_cost = Float{}, best_t = Float{}, best_sq = Float{};
  Float direction_length[4] = {};  // quad 1 of the best segment
  do {
    Float quads[2][4];
    load_quad(guides.segments, segment, 0, quads[0]);
    load_quad(guides.segments, segment, 1, quads[1]);
    Float t, distance_sq, segment_arc;
    Int inner;
    const Float cost = segment_cost(quads[0], quads[1], t, distance_sq, segment_arc, inner);
    const Int advance = finding & (segment < last) & (quads[0][3] + quads[1][3] <= window_low);
    const Int first = finding & ~advance;
    const Int in_window = (segment - start < window.lookahead) | ~(segment_arc > window_high);
    const Int take = first | (walking & in_window & ~(cost > best_cost + window.tie_sq));
    start = first ? segment : start;
    best = take ? segment : best;
    best_cost = take ? cost : best_cost;
    best_sq = take ? distance_sq : best_sq;
    best_t = take ? t : best_t;
    for (int c = 0; c < 4; ++c) direction_length[c] = take ? quads[1][c] : direction_length[c];
    walking = take & (segment < last) & ~inner;
    finding = advance;
    segment = segment < last ? segment + 1 : segment;
  } while (any(finding | walking));
  progress.segment = best;
  const Float best_distance = lane_sqrt(best_sq);
  GuideMatch<W> match;
  match.distance_sq = best_sq;
  // The guides' tangents at the chosen points: linear along the segment between its two ends'.
  Float start_tangent[4], end_tangent[4];
  load_quad(guides.segments, best, 2, start_tangent);
  load_quad(guides.segments, best, 3, end_tangent);
  const Float u = best_t * start_tangent[3];
  Float tangent[3];
  for (int c = 0; c < 3; ++c) tangent[c] = (1.0f - u) * start_tangent[c] + u * end_tangent[c];
  unit_lanes(tangent, direction_length, match.tangent);  // unit_or(tangent, segment direction)
  const Float start_clearance = lanes_of<W>([&](int l) { return guides.clearances[l][best[l]]; });
  const Float end_clearance = lanes_of<W>([&](int l) { return guides.clearances[l][best[l] + 1]; });
  const Float from_start = start_clearance - best_t, from_end = end_clearance - (direction_length[3] - best_t);
  match.clearance = (from_start < from_end ? from_end : from_start) - best_distance;
  match.weight = guides.influence / best_distance;
  const Float pace = 2.0f * end_tangent[3] * best_distance - 0.5f;
  progress.pace = 0.0f < pace ? pace : Float{};  // std::max(0, pace)
  return match;
}

/// Streamline direction field at `p`: on each guide, the closest point within a window moving
/// forward from the slot's last segment (match_guides); the guides' tangents there are blended with
/// weights influence_i / d_i (a guide at distance ~0 takes all the weight). 1/d keeps the ratio of
/// distances: between two straight guides meeting at an angle, sin(a - phi) e_0 + sin(phi) e_a is
/// parallel to e_phi (sine rule), so the blended direction points along the ray of constant ratio.
/// Returns the unit direction, or `fallback` where the blend vanishes (guides pointing opposite ways).
///
/// The strand's guides are searched four at once, one per SIMD lane, and the blend adds them up one
/// by one in slot order, so the result is the same to the bit as a guide-by-guide search.
struct StreamlineField {
  SearchWindow<4> window;
  float hit_distance_sq;

  /// `r_nearest`: the distance to the nearest influencing guide (0 on one); `r_nearest_tangent`: that
  /// guide's tangent at its chosen point. `r_clearance`: a lower bound of p's signed distance to the
  /// skin from the guides' own (match_guides).
  Eigen::Vector3f operator()(const Eigen::Vector3f &p, float arc, StreamlineSlots &slots,
                             const Eigen::Vector3f &fallback, float *r_nearest = nullptr,
                             float *r_clearance = nullptr, Eigen::Vector3f *r_nearest_tangent = nullptr) const {
    Eigen::Vector3f blend = Eigen::Vector3f::Zero(), hit_blend = Eigen::Vector3f::Zero();
    float weight_sum = 0.0f, hit_sum = 0.0f, nearest_sq = INFINITY;
    Float4 clearance = Float4{} - INFINITY;
    const Float4 px = Float4{} + p.x(), py = Float4{} + p.y(), pz = Float4{} + p.z(), arcs = Float4{} + arc;
    for (int group_index = 0; group_index < slots.group_count; ++group_index) {
      const GuideLanes<4> &group = slots.groups[group_index];
      const GuideMatch<4> match = match_guides(px, py, pz, arcs, window, group, slots.progress[group_index]);
      const Float4 &best_sq = match.distance_sq, &weight = match.weight;
      const Float4(&tangent)[3] = match.tangent;
      clearance = clearance < match.clearance ? match.clearance : clearance;
      // The blend, guide by guide in slot order. The usual case, four guides of which none is hit
      // and none before them was, takes the products lane-wise and only the sums one by one (the
      // same operations, so the same bits).
      if (4 * group_index + 3 < slots.used && hit_sum == 0.0f && !any(best_sq <= hit_distance_sq)) {
        const Float4 x = weight * tangent[0], y = weight * tangent[1], z = weight * tangent[2];
        const Float4 counted = group.influence > 0.0f ? best_sq : Float4{} + INFINITY;
        if (r_nearest_tangent) {
          for (int l = 0; l < 4; ++l)
            if (counted[l] < nearest_sq) {
              nearest_sq = counted[l];
              *r_nearest_tangent = Eigen::Vector3f(tangent[0][l], tangent[1][l], tangent[2][l]);
            }
        } else {
          nearest_sq = std::min(nearest_sq, std::min(std::min(counted[0], counted[1]), std::min(counted[2], counted[3])));
        }
        for (int l = 0; l < 4; ++l) {
          blend.x() += x[l];
          blend.y() += y[l];
          blend.z() += z[l];
          weight_sum += weight[l];
        }
        continue;
      }
      for (int l = 0; l < 4 && 4 * group_index + l < slots.used; ++l) {
        const float influence = group.influence[l];
        const Eigen::Vector3f direction(tangent[0][l], tangent[1][l], tangent[2][l]);
        if (influence > 0.0f && best_sq[l] < nearest_sq) {
          nearest_sq = best_sq[l];
          if (r_nearest_tangent) *r_nearest_tangent = direction;
        }
        if (best_sq[l] <= hit_distance_sq) {
          hit_blend += influence * direction;
          hit_sum += influence;
        } else if (hit_sum == 0.0f) {
          blend += weight[l] * direction;
          weight_sum += weight[l];
        }
      }
    }
    if (hit_sum > 0.0f) {
      blend = hit_blend;
      weight_sum = hit_sum;
      nearest_sq = 0.0f;
    }
    if (r_nearest) *r_nearest = std::sqrt(nearest_sq);
    if (r_clearance) *r_clearance = std::max(std::max(clearance[0], clearance[1]), std::max(clearance[2], clearance[3]));
    const float norm = blend.norm();
    return norm > 1e-6f * weight_sum && norm > 0.0f ? Eigen::Vector3f(blend * (1.0f / norm)) : fallback;
  }
};

/// Guide slots searched side by side in one QuadField group: two where eight-lane vectors are one
/// register (AVX), so that two slots' chains of loads and compares overlap; one elsewhere (SSE2
/// would split eight lanes into two registers through memory).
#ifdef __AVX__
constexpr int kSlotsPerGroup = 2;
#else
constexpr int kSlotsPerGroup = 1;
#endif

/// The streamline fields of four strands with the same number of guides, one strand per SIMD lane:
/// guide slot s of the four strands sits in lanes 4 (s % S) .. 4 (s % S) + 3 of group s / S
/// (S = kSlotsPerGroup). A lane does the strand's own field's float operations in the same order
/// (StreamlineField adds its guides up in slot order, as the groups' quarters are added here), so it
/// gives that field to the bit, except in a lane where a guide is hit (d ~ 0): that lane is flagged
/// for the strand's own field, which blends the hit guides alone. Past the last guide, a group's
/// quarters repeat the strands' last guide and are left out.
struct QuadField {
  static constexpr int W = 4 * kSlotsPerGroup;
  using Float = Lanes<W>::Float;
  using Int = Lanes<W>::Int;
  static constexpr int max_groups = (max_guides_per_root + kSlotsPerGroup - 1) / kSlotsPerGroup;
  SearchWindow<W> window;  // the four strands' windows, repeated
  Float4 hit_distance_sq;
  int used = 0;
  int group_count = 0;
  GuideLanes<W> groups[max_groups];
  GuideProgress<W> progress[max_groups];

  /// Guide slot s of strand l: its group and its lane there.
  static int group_of(int s) { return s / kSlotsPerGroup; }
  static int lane_of(int s, int l) { return 4 * (s % kSlotsPerGroup) + l; }

  /// At p[c][l] (component c of lane l's point), at the lanes' arc lengths `arc`: the unit directions
  /// (`fallback` where the blend vanishes), the distances to the nearest influencing guides, the
  /// guides' lower bounds of the points' signed distances to the skin, the lanes with a hit guide and,
  /// if asked, the nearest guides' tangents at their chosen points.
  void operator()(const Float4 p[3], Float4 arc, const Float4 fallback[3], Float4 r_direction[3], Float4 &r_nearest,
                  Float4 &r_clearance, Int4 &r_hit, Float4 *r_nearest_tangent = nullptr) {
    Float4 blend[3] = {Float4{}, Float4{}, Float4{}}, weight_sum = Float4{};
    if (r_nearest_tangent)
      for (int c = 0; c < 3; ++c) r_nearest_tangent[c] = Float4{};
    Float4 nearest_sq = Float4{} + INFINITY, clearance = Float4{} - INFINITY;
    Int4 hit = Int4{};
    const Float px = repeat_lanes<W>(p[0]), py = repeat_lanes<W>(p[1]), pz = repeat_lanes<W>(p[2]);
    const Float arcs = repeat_lanes<W>(arc);
    for (int group = 0; group < group_count; ++group) {
      const GuideMatch<W> match = match_guides(px, py, pz, arcs, window, groups[group], progress[group]);
      for (int q = 0; q < kSlotsPerGroup && kSlotsPerGroup * group + q < used; ++q) {
        const Float4 distance_sq = lane_quad(match.distance_sq, q), weight = lane_quad(match.weight, q);
        const Float4 slot_clearance = lane_quad(match.clearance, q);
        clearance = clearance < slot_clearance ? slot_clearance : clearance;
        hit |= distance_sq <= hit_distance_sq;
        const Float4 counted = lane_quad(groups[group].influence, q) > 0.0f ? distance_sq : Float4{} + INFINITY;
        const Int4 nearer = counted < nearest_sq;
        nearest_sq = nearer ? counted : nearest_sq;
        if (r_nearest_tangent)
          for (int c = 0; c < 3; ++c)
            r_nearest_tangent[c] = nearer ? lane_quad(match.tangent[c], q) : r_nearest_tangent[c];
        for (int c = 0; c < 3; ++c) blend[c] += weight * lane_quad(match.tangent[c], q);
        weight_sum += weight;
      }
    }
    r_nearest = lane_sqrt(nearest_sq);
    r_clearance = clearance;
    r_hit = hit;
    const Float4 norm = lane_sqrt(dot_lanes(blend, blend));
    const Float4 inverse_norm = 1.0f / norm;
    const Int4 defined = (norm > 1e-6f * weight_sum) & (norm > 0.0f);
    for (int c = 0; c < 3; ++c) r_direction[c] = defined ? blend[c] * inverse_norm : fallback[c];
  }
};

/// What every streamline strand of one grow() call reads.
struct GrowScene {
  const Binding &binding;
  const MeshQuery &query;
  const Roots &roots;
  const StrandSet &guides;
  const FrameGuides &frame;
  const std::vector<float> &clearances;  // guide_clearances, streamline only
  const SkinGrid *skin_grid;             // streamline only
  float scale;                           // mesh_scale
  int n;                                 // points per strand
  float *clearance;                      // r_clearance's data, or null
};

// Midpoint steps (StreamlineStrand::step_from): the smoothness tests of a predicted step, far from and
// within half a step of a guide, and the turning of the field near a guide above which a full step
// is split into substeps (at most max_substeps).
constexpr float kSmoothTurning = 0.01f, kNearSmoothTurning = 0.003f, kConeTurning = 0.02f;
constexpr int max_substeps = 8;

/// One strand's streamline-ratio growth: its guides' field, its skin guard and what its steps
/// remember. begin() places the first point after the root, step_from(i) the point i + 1. StrandQuad runs
/// four of them side by side and hands the steps it does not take in lanes back to them.
struct StreamlineStrand {
  const GrowScene &scene;
  GrowStats &counts;
  int64_t root = 0;
  Eigen::Vector3f *points = nullptr;
  float step = 0.0f;  // segment length
  StreamlineField field{};
  StreamlineSlots slots;
  SkinGuard guard;
  // The last point where the field was evaluated, and the lower bound of its signed distance to the
  // skin that the guides give (match_guides).
  Eigen::Vector3f evaluated_at = Eigen::Vector3f::Zero();
  float evaluated_clearance = -INFINITY;
  // The field at the last two midpoints (when `history`), and the distance to the nearest guide
  // there. last_middle is also the direction the last step aimed along.
  Eigen::Vector3f last_middle = Eigen::Vector3f::Zero(), previous_middle = Eigen::Vector3f::Zero();
  float nearest = 0.0f;
  bool history = false;

  StreamlineStrand(const GrowScene &scene, GrowStats &counts)
      : scene(scene), counts(counts),
        guard(scene.query, scene.binding.skin_margin, scene.scale, scene.skin_grid) {}

  float skin_margin() const { return scene.binding.skin_margin; }
  bool near_a_guide(float distance) const { return distance > 0.0f && distance < 0.5f * step; }

  Eigen::Vector3f evaluate(const Eigen::Vector3f &p, float arc, const Eigen::Vector3f &fallback, float *r_nearest,
                           Eigen::Vector3f *r_nearest_tangent = nullptr) {
    ++counts.evaluations;
    evaluated_at = p;
    return field(p, arc, slots, fallback, r_nearest, &evaluated_clearance, r_nearest_tangent);
  }

  /// Step along `direction` by one segment, out of the skin; if pushed, re-aim so the segment keeps
  /// its length, and check again with a query (see SkinGuard::keep_out). A point that the guides'
  /// clearance puts outside by the margin is not looked at.
  Eigen::Vector3f advance(const Eigen::Vector3f &from, const Eigen::Vector3f &direction) {
    const Eigen::Vector3f to = from + step * direction;
    const float guided = evaluated_clearance - (to - evaluated_at).norm();
    if (guided >= skin_margin() && guided > guard.lower_bound(to) && guard.know_outside(to, guided)) return to;
    return keep_out(from, direction, to);
  }
  /// The rest of advance() for `to` = from + step * direction, when the guides do not prove it outside.
  Eigen::Vector3f keep_out(const Eigen::Vector3f &from, const Eigen::Vector3f &direction, Eigen::Vector3f to) {
    const Eigen::Vector3f aimed = to;
    guard.keep_out(to);
    if (to != aimed) {
      to = from + step * unit_or(to - from, direction);
      guard.keep_out(to, true);
    }
    return to;
  }

  /// Writes r_clearance for point i: what the guard proved there, or the grid's cell bound (a lookup)
  /// when that is larger.
  void record_clearance(int i) {
    if (!scene.clearance) return;
    const Eigen::Vector3f &p = points[i];
    scene.clearance[root * scene.n + i] = std::max(guard.lower_bound(p), scene.skin_grid->distance_lower_bound(p));
  }

  /// Sets the strand up on root r, whose first point (on or above the skin) is in strand_points[0],
  /// and takes its first step: along the guides' first directions carried to this root's frame, so
  /// the strand leaves the skin the way its guides do.
  void begin(int64_t r, Eigen::Vector3f *strand_points, const Slot *root_slots, int used,
             const SurfaceFrame &root_frame, RecentOutside &recent_outside) {
    const Binding &binding = scene.binding;
    const FrameGuides &frame = scene.frame;
    const InterpolationSettings &settings = binding.settings;
    root = r;
    points = strand_points;
    step = binding.lengths[size_t(r)] / float(scene.n - 1);
    const int lookahead = std::max(settings.lookahead_segments, 1);
    const float hit_distance = std::max(1e-6f * step, 1e-12f), tie = 1e-5f * step;
    field.window = {Float4{} + 0.5f * float(lookahead) * step, Int4{} + lookahead, Float4{} + tie * tie};
    field.hit_distance_sq = hit_distance * hit_distance;
    // The field's slots: lanes past the last guide repeat their group's first lane.
    slots.used = used;
    slots.group_count = (used + 3) / 4;
    for (int lane = 0; lane < 4 * slots.group_count; ++lane) {
      const int s = lane < used ? lane : lane & ~3;
      const size_t g = size_t(root_slots[s].guide);
      const int64_t first = frame.segment_offsets[g], last = frame.segment_offsets[g + 1] - 1;
      const float guide_length = frame.segments[size_t(last)].arc + frame.segments[size_t(last)].length;
      GuideLanes<4> &group = slots.groups[lane / 4];
      GuideProgress<4> &progress = slots.progress[lane / 4];
      const int l = lane % 4;
      group.segments[l] = frame.segments.data() + first;
      group.clearances[l] = scene.clearances.data() + scene.guides.offsets[g];
      group.segment_count[l] = int32_t(last + 1 - first);
      group.influence[l] = root_slots[s].influence;
      group.arc_scale[l] = binding.lengths[size_t(r)] > 0.0f ? guide_length / binding.lengths[size_t(r)] : 1.0f;
      progress.segment[l] = 0;
      progress.pace[l] = 0.0f;  // no distance known yet
    }
    guard.start(root_frame.origin, scene.roots.points[size_t(r)].triangle);
    evaluated_at = root_frame.origin;
    evaluated_clearance = -INFINITY;

    Eigen::Vector3f seed = Eigen::Vector3f::Zero();
    for (int s = 0; s < used; ++s) {
      const size_t g = size_t(root_slots[s].guide);
      seed += root_slots[s].weight * (root_slots[s].rotation * frame.segments[size_t(frame.segment_offsets[g])].direction);
    }
    const Eigen::Vector3f first_direction = unit_or(seed, root_frame.normal());
    // The guard knows only the root, on the skin, from which no bound follows: an earlier strand's
    // first point may prove this one outside (RecentOutside), else the guard searches. What the guard
    // then knows is kept for the next strands.
    ++counts.first_points;
    const RecentOutside::Ball *proof = recent_outside.proving(points[0] + step * first_direction, skin_margin());
    if (proof) guard.know(proof->centre, proof->radius);
    points[1] = advance(points[0], first_direction);
    if (proof && guard.known_point() == proof->centre)
      ++counts.first_points_proven;
    else
      recent_outside.add(guard.known_point(), guard.known_distance());
    record_clearance(0);
    record_clearance(1);
    nearest = 0.0f;
    history = false;
    last_middle = previous_middle = first_direction;
  }

  /// Places point i + 1 (i >= 1) by a midpoint step through the guides' direction field: exact on a
  /// guide traced from its root. Where the field is smooth along the strand, the midpoint is placed
  /// with the field's direction at the step's start predicted from the directions found at the last
  /// two midpoints (linear extrapolation, F(p_i) ~ 1.5 F(m_i-1/2) - 0.5 F(m_i-3/2)): the midpoint is
  /// then off by O(h^3) and the step keeps the midpoint rule's order with one field evaluation instead
  /// of two. Smooth means that the second difference of those directions, with the new one, stays
  /// below kSmoothTurning (kNearSmoothTurning within half a step of a guide); otherwise (a sharp bend
  /// of a guide, a tight curl, the strand pushed off by the skin) the step is redone in full from the
  /// field at its start (full_step_from). The first step after begin() is a full step too.
  void step_from(int i) {
    ++counts.steps;
    if (history) {
      const float smooth = near_a_guide(nearest) ? kNearSmoothTurning : kSmoothTurning;
      const Eigen::Vector3f start_direction = unit_or(1.5f * last_middle - 0.5f * previous_middle, last_middle);
      const Eigen::Vector3f middle = points[i] + (0.5f * step) * start_direction;
      float middle_nearest = 0.0f;
      GuideProgress<4> saved[StreamlineSlots::max_groups];
      std::copy(slots.progress, slots.progress + slots.group_count, saved);
      const Eigen::Vector3f middle_direction =
          evaluate(middle, (float(i) + 0.5f) * step, start_direction, &middle_nearest);
      if ((middle_direction - 2.0f * last_middle + previous_middle).squaredNorm() <= smooth * smooth) {
        ++counts.predicted_steps;
        nearest = middle_nearest;
        points[i + 1] = advance(points[i], middle_direction);
        previous_middle = last_middle;
        last_middle = middle_direction;
        record_clearance(i + 1);
        return;
      }
      // The full step searches the guides from where they were.
      std::copy(saved, saved + slots.group_count, slots.progress);
    }
    full_step_from(i);
  }

  /// A full midpoint step from point i (step_from() counts it). Near a guide, at distance d below half a
  /// step, the blend is that guide's tangent T plus a part that grows with d: F ~ T + d V, a cone
  /// with its tip on the guide, which turns by about (h / 2) |F - T| / d over half a step. Along
  /// guides that run alike, V is small and a step resolves it as anywhere else. Where it turns by more
  /// than kConeTurning (another guide near and pointing elsewhere, guides meeting at an angle), the
  /// step is split into substeps of about d (at most max_substeps), and the point lands one segment
  /// length along their chord.
  void full_step_from(int i) {
    const Eigen::Vector3f direction = unit_or(points[i] - points[i - 1], last_middle);
    Eigen::Vector3f nearest_tangent = Eigen::Vector3f::Zero();
    Eigen::Vector3f start_direction = evaluate(points[i], float(i) * step, direction, &nearest, &nearest_tangent);
    const int substeps = near_a_guide(nearest) &&
                                 0.5f * step * (start_direction - nearest_tangent).norm() > kConeTurning * nearest
                             ? std::min(max_substeps, int(std::ceil(0.5f * step / nearest)))
                             : 1;
    if (substeps > 1) ++counts.substepped_steps;
    const float substep = step / float(substeps);
    Eigen::Vector3f p = points[i], last_direction = direction;
    for (int sub = 0; sub < substeps; ++sub) {
      const float arc = float(i) * step + float(sub) * substep;
      if (sub > 0) start_direction = evaluate(p, arc, last_direction, nullptr);
      const Eigen::Vector3f middle = p + (0.5f * substep) * start_direction;
      last_direction = evaluate(middle, arc + 0.5f * substep, start_direction, &nearest);
      p += substep * last_direction;
    }
    points[i + 1] = advance(points[i], substeps == 1 ? last_direction : unit_or(p - points[i], last_direction));
    // One whole step: the field at the midpoint before it extrapolates back from start and middle.
    history = substeps == 1;
    previous_middle = unit_or(2.0f * start_direction - last_direction, start_direction);
    last_middle = last_direction;
    record_clearance(i + 1);
  }
};

/// Four begun strands with the same number of guides, grown side by side, one per SIMD lane
/// (QuadField). Most steps are predicted midpoint steps whose field is smooth; the rest are mostly the
/// full steps after begin(), which all four strands take at once. Both are taken in lanes, each lane
/// doing its strand's own float operations in the same order, so the strands come out the same to the
/// bit as grown one by one; the skin guard of each strand looks at its new point where the guides do
/// not prove it outside. A strand's other steps (the full step after a failed prediction, a step split
/// near a guide, a hit guide) are handed to the strand (StreamlineStrand::step_from).
class StrandQuad {
 public:
  explicit StrandQuad(StreamlineStrand *const strands[4]) {
    for (int l = 0; l < 4; ++l) {
      strands_[l] = strands[l];
      const StreamlineStrand &strand = *strands[l];
      step_[l] = strand.step;
      for (int lane = l; lane < QuadField::W; lane += 4) {
        field_.window.half_arc[lane] = strand.field.window.half_arc[0];
        field_.window.lookahead[lane] = strand.field.window.lookahead[0];
        field_.window.tie_sq[lane] = strand.field.window.tie_sq[0];
      }
      field_.hit_distance_sq[l] = strand.field.hit_distance_sq;
    }
    field_.used = strands[0]->slots.used;
    field_.group_count = (field_.used + kSlotsPerGroup - 1) / kSlotsPerGroup;
    for (int s = 0; s < kSlotsPerGroup * field_.group_count; ++s)
      for (int l = 0; l < 4; ++l) {
        const int source = std::min(s, field_.used - 1);
        const GuideLanes<4> &slots = strands[l]->slots.groups[source / 4];
        GuideLanes<QuadField::W> &group = field_.groups[QuadField::group_of(s)];
        const int lane = QuadField::lane_of(s, l);
        group.segments[lane] = slots.segments[source % 4];
        group.clearances[lane] = slots.clearances[source % 4];
        group.segment_count[lane] = slots.segment_count[source % 4];
        group.influence[lane] = slots.influence[source % 4];
        group.arc_scale[lane] = slots.arc_scale[source % 4];
      }
    for (int l = 0; l < 4; ++l) take_back(l, 1);
  }

  /// Points 2 .. n - 1 of the four strands.
  void grow(int n) {
    for (int i = 1; i + 1 < n; ++i) take_step(i);
  }

 private:
  /// Point i + 1 of every strand.
  void take_step(int i) {
    if (!any(history_)) {
      take_full_steps(i);
      return;
    }
    // StreamlineStrand::step_from's predicted step, in lanes.
    const Float4 smooth = near_a_guide(nearest_) ? Float4{} + kNearSmoothTurning : Float4{} + kSmoothTurning;
    Float4 start_direction[3], middle[3];
    for (int c = 0; c < 3; ++c) start_direction[c] = 1.5f * last_middle_[c] - 0.5f * previous_middle_[c];
    unit_lanes(start_direction, last_middle_, start_direction);
    for (int c = 0; c < 3; ++c) middle[c] = point_[c] + (0.5f * step_) * start_direction[c];
    GuideProgress<QuadField::W> saved[QuadField::max_groups];
    std::copy(field_.progress, field_.progress + field_.group_count, saved);
    Float4 middle_direction[3], middle_nearest, middle_clearance;
    Int4 hit;
    field_(middle, (float(i) + 0.5f) * step_, start_direction, middle_direction, middle_nearest, middle_clearance, hit);
    Float4 turn[3];
    for (int c = 0; c < 3; ++c) turn[c] = middle_direction[c] - 2.0f * last_middle_[c] + previous_middle_[c];
    const Int4 smooth_enough = dot_lanes(turn, turn) <= smooth * smooth;
    const Int4 predicted = history_ & ~hit & smooth_enough;
    nearest_ = predicted ? middle_nearest : nearest_;
    for (int c = 0; c < 3; ++c) {
      previous_middle_[c] = predicted ? last_middle_[c] : previous_middle_[c];
      last_middle_[c] = predicted ? middle_direction[c] : last_middle_[c];
    }
    advance(i, predicted, middle_direction, middle, middle_clearance, saved, [&](int l) {
      if (predicted[l]) {
        ++strands_[l]->counts.evaluations;
        ++strands_[l]->counts.predicted_steps;
      }
      // A prediction that was looked at and failed is followed by a full step, as in step_from().
      return history_[l] && !hit[l];
    });
  }

  /// Point i + 1 of every strand when none has a prediction to make (after begin(), or after steps
  /// split near a guide): StreamlineStrand::full_step_from, in lanes, where the step is not split and
  /// no guide is hit; the other strands take it themselves.
  void take_full_steps(int i) {
    Float4 direction[3], start_direction[3], start_nearest, start_clearance, nearest_tangent[3];
    Float4 middle[3], middle_direction[3], middle_nearest, middle_clearance;
    Int4 start_hit, middle_hit;
    for (int c = 0; c < 3; ++c)
      direction[c] = point_[c] - Float4{strands_[0]->points[i - 1][c], strands_[1]->points[i - 1][c],
                                        strands_[2]->points[i - 1][c], strands_[3]->points[i - 1][c]};
    unit_lanes(direction, last_middle_, direction);
    GuideProgress<QuadField::W> saved[QuadField::max_groups];
    std::copy(field_.progress, field_.progress + field_.group_count, saved);
    field_(point_, float(i) * step_, direction, start_direction, start_nearest, start_clearance, start_hit,
           nearest_tangent);
    Float4 cone[3];
    for (int c = 0; c < 3; ++c) cone[c] = start_direction[c] - nearest_tangent[c];
    const Int4 split = near_a_guide(start_nearest) &
                       ((0.5f * step_) * lane_sqrt(dot_lanes(cone, cone)) > kConeTurning * start_nearest);
    for (int c = 0; c < 3; ++c) middle[c] = point_[c] + (0.5f * step_) * start_direction[c];
    field_(middle, float(i) * step_ + 0.5f * step_, start_direction, middle_direction, middle_nearest,
           middle_clearance, middle_hit);
    const Int4 whole = ~start_hit & ~split & ~middle_hit;
    // As full_step_from leaves a whole step: the field at the midpoint before it extrapolated back.
    Float4 previous_middle[3];
    for (int c = 0; c < 3; ++c) previous_middle[c] = 2.0f * start_direction[c] - middle_direction[c];
    unit_lanes(previous_middle, start_direction, previous_middle);
    nearest_ = whole ? middle_nearest : nearest_;
    history_ = whole;
    for (int c = 0; c < 3; ++c) {
      previous_middle_[c] = whole ? previous_middle[c] : previous_middle_[c];
      last_middle_[c] = whole ? middle_direction[c] : last_middle_[c];
    }
    advance(i, whole, middle_direction, middle, middle_clearance, saved, [&](int l) {
      strands_[l]->counts.evaluations += 2;
      return false;
    });
  }

  /// StreamlineStrand::advance in the lanes of `taken`: point i + 1 at step * direction from point i,
  /// with the lower bound of the signed distance `clearance` that the guides give at `evaluated_at`,
  /// up to the guard's own checks. `count(l)` counts lane l's evaluations; for a lane not taken, whose
  /// guides' progress goes back to `saved`, it says whether the strand's full step follows a failed
  /// prediction (hand_step's `looked_at`).
  template <class Count>
  void advance(int i, Int4 taken, const Float4 direction[3], const Float4 evaluated_at[3], Float4 clearance,
               const GuideProgress<QuadField::W> saved[], Count &&count) {
    const float margin = strands_[0]->skin_margin();
    const SkinGuard *const guards[4] = {&strands_[0]->guard, &strands_[1]->guard, &strands_[2]->guard,
                                        &strands_[3]->guard};
    const Float4 known_distance = {guards[0]->known_distance(), guards[1]->known_distance(),
                                   guards[2]->known_distance(), guards[3]->known_distance()};
    Float4 to[3], from_evaluated[3], from_known[3];
    for (int c = 0; c < 3; ++c) {
      const Float4 known_point = {guards[0]->known_point()[c], guards[1]->known_point()[c],
                                  guards[2]->known_point()[c], guards[3]->known_point()[c]};
      to[c] = point_[c] + step_ * direction[c];
      from_evaluated[c] = to[c] - evaluated_at[c];
      from_known[c] = to[c] - known_point;
    }
    const Float4 guided = clearance - lane_sqrt(dot_lanes(from_evaluated, from_evaluated));
    const Float4 known_bound = known_distance - lane_sqrt(dot_lanes(from_known, from_known));
    const Int4 guided_outside = (guided >= margin) & (guided > known_bound);
    if (any(~taken)) {
      const QuadField::Int kept = repeat_lanes<QuadField::W>(taken);
      for (int group = 0; group < field_.group_count; ++group) {
        field_.progress[group].segment = kept ? field_.progress[group].segment : saved[group].segment;
        field_.progress[group].pace = kept ? field_.progress[group].pace : saved[group].pace;
      }
    }
    for (int l = 0; l < 4; ++l) {
      StreamlineStrand &strand = *strands_[l];
      const bool looked_at = count(l);
      if (!taken[l]) {
        hand_step(l, i, looked_at);
        continue;
      }
      ++strand.counts.steps;
      const Eigen::Vector3f from(point_[0][l], point_[1][l], point_[2][l]);
      Eigen::Vector3f next(to[0][l], to[1][l], to[2][l]);
      if (!(guided_outside[l] && strand.guard.know_outside(next, guided[l])))
        next = strand.keep_out(from, Eigen::Vector3f(direction[0][l], direction[1][l], direction[2][l]), next);
      strand.points[i + 1] = next;
      strand.record_clearance(i + 1);
      for (int c = 0; c < 3; ++c) point_[c][l] = next[c];
    }
  }

  /// StreamlineStrand::near_a_guide in lanes.
  Int4 near_a_guide(Float4 distance) const { return (distance > 0.0f) & (distance < 0.5f * step_); }

  /// Strand l takes step i itself: the whole step, or (`looked_at`) the full step after a prediction
  /// that was evaluated in lanes and failed.
  void hand_step(int l, int i, bool looked_at) {
    hand_over(l);
    StreamlineStrand &strand = *strands_[l];
    if (looked_at) {
      ++strand.counts.steps;
      ++strand.counts.evaluations;
      strand.full_step_from(i);
    } else {
      strand.step_from(i);
    }
    take_back(l, i + 1);
  }
  /// Lane l's state to its strand.
  void hand_over(int l) {
    StreamlineStrand &strand = *strands_[l];
    strand.last_middle = Eigen::Vector3f(last_middle_[0][l], last_middle_[1][l], last_middle_[2][l]);
    strand.previous_middle = Eigen::Vector3f(previous_middle_[0][l], previous_middle_[1][l], previous_middle_[2][l]);
    strand.nearest = nearest_[l];
    strand.history = history_[l] != 0;
    StreamlineSlots &slots = strand.slots;
    for (int lane = 0; lane < 4 * slots.group_count; ++lane) {
      const int s = lane < slots.used ? lane : lane & ~3;
      const GuideProgress<QuadField::W> &progress = field_.progress[QuadField::group_of(s)];
      slots.progress[lane / 4].segment[lane % 4] = progress.segment[QuadField::lane_of(s, l)];
      slots.progress[lane / 4].pace[lane % 4] = progress.pace[QuadField::lane_of(s, l)];
    }
  }
  /// Strand l's state, at point i, to lane l.
  void take_back(int l, int i) {
    const StreamlineStrand &strand = *strands_[l];
    for (int c = 0; c < 3; ++c) {
      point_[c][l] = strand.points[i][c];
      last_middle_[c][l] = strand.last_middle[c];
      previous_middle_[c][l] = strand.previous_middle[c];
    }
    nearest_[l] = strand.nearest;
    history_[l] = strand.history ? -1 : 0;
    for (int s = 0; s < kSlotsPerGroup * field_.group_count; ++s) {
      const int source = std::min(s, field_.used - 1);
      GuideProgress<QuadField::W> &progress = field_.progress[QuadField::group_of(s)];
      progress.segment[QuadField::lane_of(s, l)] = strand.slots.progress[source / 4].segment[source % 4];
      progress.pace[QuadField::lane_of(s, l)] = strand.slots.progress[source / 4].pace[source % 4];
    }
  }

  StreamlineStrand *strands_[4];
  QuadField field_;
  Float4 step_;
  // Lane l: strand l's current point and StreamlineStrand's step state.
  Float4 point_[3], last_middle_[3], previous_middle_[3], nearest_;
  Int4 history_;
};

}  // namespace

GrowStats &GrowStats::operator+=(const GrowStats &other) {
  steps += other.steps;
  predicted_steps += other.predicted_steps;
  substepped_steps += other.substepped_steps;
  evaluations += other.evaluations;
  first_points += other.first_points;
  first_points_proven += other.first_points_proven;
  return *this;
}

std::string GrowStats::summary() const {
  const double per_step = steps > 0 ? 1.0 / double(steps) : 0.0;
  char text[200];
  std::snprintf(text, sizeof text,
                "%.3f field evaluations per step; steps predicted %.1f%%, split near a guide %.2f%%; first points "
                "proven from earlier strands %.1f%%",
                double(evaluations) * per_step, 100.0 * double(predicted_steps) * per_step,
                100.0 * double(substepped_steps) * per_step,
                first_points > 0 ? 100.0 * double(first_points_proven) / double(first_points) : 0.0);
  return text;
}

void grow(const Binding &binding, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
          const StrandSet &guides, const GrowOptions &options, StrandSet &r_strands,
          std::vector<float> *r_clearance, const SkinGrid *shared_skin_grid) {
  const int n = options.points_per_strand;
  if (n < 2) throw InputError("points_per_strand: expected at least 2, got " + std::to_string(n));
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

  const FrameGuides frame = prepare_guides(binding, mesh, guides, n);
  const InterpolationSettings &settings = binding.settings;
  const int k = binding.k;
  const float scale = mesh_scale(mesh);
  const bool streamline = settings.method == InterpolationSettings::Method::streamline;
  // Every method keeps its points out of the skin, through one grid of the skin per frame.
  std::unique_ptr<SkinGrid> own_skin_grid;
  if (!shared_skin_grid) own_skin_grid = std::make_unique<SkinGrid>(mesh, query);
  const SkinGrid *const skin_grid = shared_skin_grid ? shared_skin_grid : own_skin_grid.get();
  const std::vector<float> clearances = streamline ? guide_clearances(guides, binding.guide_roots, query, *skin_grid) : std::vector<float>();

  r_strands.resize_uniform(roots.size(), n, options.with_widths, StrandSet::Fill::unset);  // all written below
  r_strands.ids = roots.ids;
  if (r_clearance) {
    r_clearance->clear();
    if (streamline) r_clearance->resize(r_strands.positions.size());
  }
  const GrowScene scene{binding, query, roots, guides, frame, clearances, skin_grid, scale, n,
                        r_clearance && streamline ? r_clearance->data() : nullptr};
  // Roots are taken four at a time, so that streamline strands can grow side by side (StrandQuad).
  const int64_t root_count = int64_t(roots.size());
  const int64_t quad_count = (root_count + 3) / 4;
  GrowStats stats;
  bool finite = true;
#pragma omp parallel reduction(&& : finite)
  {
    RecentOutside recent_outside;  // this thread's last strands' first points
    GrowStats counts;  // this thread's
    StreamlineStrand strands[4] = {{scene, counts}, {scene, counts}, {scene, counts}, {scene, counts}};
#pragma omp for schedule(static)
    for (int64_t quad = 0; quad < quad_count; ++quad) {
      const int64_t first_root = 4 * quad, end_root = std::min(first_root + 4, root_count);
      for (int64_t r = first_root; r < end_root; ++r) {
        const SurfaceFrame root_frame = surface_frame(mesh, roots.points[size_t(r)]);
        const Eigen::Vector3f normal = root_frame.normal();
        Slot slots[max_guides_per_root];
        int used = 0;
        for (int s = 0; s < k; ++s) {
          const size_t slot = size_t(r) * size_t(k) + size_t(s);
          const int32_t g = binding.guide_ids[slot];
          if (g < 0) break;
          // Q_root(t) * rest rotation * Q_guide(t)^T: a rigid motion of the skin gives back the rest
          // rotation conjugated by that motion, so carried guides move exactly rigidly.
          slots[used++] = {g, binding.weights[slot], binding.influence[slot],
                           root_frame.basis * binding.rest_rotations[slot].toRotationMatrix() *
                               frame.frames[size_t(g)].transpose()};
        }
        Eigen::Vector3f *points = r_strands.positions.data() + r * n;

        // The root: on the skin, lifted along its normal by the height of the guides' own first points
        // above their surface points (carried), never below the skin. Only the height: a sideways part
        // would move the root off its place on the skin, and where the skin curves (round an ear) into it.
        Eigen::Vector3f lift = Eigen::Vector3f::Zero();
        for (int s = 0; s < used; ++s) {
          const size_t g = size_t(slots[s].guide);
          lift += slots[s].weight * (slots[s].rotation * (guides.points(g)[0] - frame.origins[g]));
        }
        const float height = std::max(lift.dot(normal), 0.0f);
        points[0] = root_frame.origin + height * normal;
        if (height > 1e-6f * scale) {
          // Strands stay out of the skin. Where the skin folds (a thin ear whose vertex
          // normals average its two sides) the normal can lead behind another part of the skin: then the
          // root stays on the skin. A lift within the skin guard's tolerance (a millionth of the mesh
          // size: guide roots on the skin up to rounding) cannot reach another part of it and needs no
          // query.
          SurfacePoint closest;
          if (skin_grid->signed_distance(points[0], roots.points[size_t(r)].triangle, closest) < 0.0f)
            points[0] = root_frame.origin;
        }

        if (settings.method == InterpolationSettings::Method::linear) {
          // Root-relative offsets of the resampled guides, blended as they are (no rotation), after
          // the root point the other methods start from; a point that falls inside the skin is moved
          // out to the margin.
          SkinGuard guard(query, binding.skin_margin, scale, skin_grid);
          guard.start(points[0], roots.points[size_t(r)].triangle);  // on the skin or lifted above it
          for (int i = 1; i < n; ++i) {
            Eigen::Vector3f p = root_frame.origin;
            for (int s = 0; s < used; ++s) {
              const size_t g = size_t(slots[s].guide);
              p += slots[s].weight * (frame.resampled[g * size_t(n) + size_t(i)] - frame.origins[g]);
            }
            guard.keep_out(p);
            points[i] = p;
          }
          continue;
        }

        if (settings.method == InterpolationSettings::Method::fur) {
          // Segment j: weighted length and weighted direction of the carried guides' segments j; a
          // point that falls inside the skin is moved out to the margin, and the strand goes on from there.
          SkinGuard guard(query, binding.skin_margin, scale, skin_grid);
          guard.start(points[0], roots.points[size_t(r)].triangle);  // on the skin or lifted above it
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
          }
          continue;
        }

        strands[r - first_root].begin(r, points, slots, used, root_frame, recent_outside);
      }
      if (streamline) {
        const int strand_count = int(end_root - first_root);
        bool side_by_side = strand_count == 4;
        for (int j = 1; j < strand_count; ++j) side_by_side &= strands[j].slots.used == strands[0].slots.used;
        if (side_by_side) {
          StreamlineStrand *const quad_strands[4] = {&strands[0], &strands[1], &strands[2], &strands[3]};
          StrandQuad(quad_strands).grow(n);
        } else {
          for (int j = 0; j < strand_count; ++j)
            for (int i = 1; i + 1 < n; ++i) strands[j].step_from(i);
        }
      }
      // The four strands' points, while they are in cache: finite, and their widths.
      for (int64_t i = first_root * n; i < end_root * n; ++i)
        finite = r_strands.positions[size_t(i)].allFinite() && finite;
      if (options.with_widths)
        for (int64_t r = first_root; r < end_root; ++r)
          for (int i = 0; i < n; ++i)
            r_strands.widths[size_t(r * n + i)] =
                options.width_root + (options.width_tip - options.width_root) * float(i) / float(n - 1);
    }
#pragma omp critical(plume_grow_stats)
    stats += counts;
  }

  if (options.r_stats) *options.r_stats = stats;
  if (!finite) throw InternalError("grow: a strand point is not finite");
}

}  // namespace plume::interp
