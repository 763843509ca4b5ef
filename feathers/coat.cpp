#include "feathers/coat.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numeric>
#include <optional>
#include <queue>

#include "feathers/blend.h"
#include "groom/error.h"
#include "groom/roots.h"
#include "skin/skin_grid.h"

namespace plume::feathers {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kRadiansPerDegree = kPi / 180.0f;
/// Segments of the polyline a feather's shaft follows (its spine), whatever the output's detail: the
/// feather's shape does not depend on how finely it is written.
constexpr int kSpineSegments = 16;
/// Rows of barbs the skin pass samples per vane (tips, midpoints and rachis points).
constexpr int kSkinRows = 11;
/// A plumulaceous barb's fuzz moves it dorsally only, but also in the vane's plane by up to 0.35 of
/// its length, which lowers a point where the vane slopes down to the skin: the skin pass keeps this
/// much of the barb's length more room under fuzzy barbs.
constexpr float kFuzzMargin = 0.1f;
/// The skin pass's iterations: each turns the feather up by what the worst sample needs, seen
/// through the skin's tangent plane there (a Newton step on the clearance).
constexpr int kLiftIterations = 12;

/// Channels of a feather's seeded variation.
enum VariationChannel : uint64_t { kLength = 1, kBarbAngle, kStage, kDirection, kLift, kThinning };

float hashed_unit(uint64_t seed, uint64_t id, uint64_t channel) {
  return hash_to_unit(hash_combine(hash_combine(seed, id), channel));
}

std::vector<bool> group_mask(const Mesh &mesh, const std::vector<std::string> &groups, const FileLoc &loc,
                             const std::string &what) {
  std::vector<bool> mask;
  if (groups.empty()) return mask;
  std::vector<bool> wanted(mesh.group_names.size(), false);
  for (const std::string &name : groups) {
    const int g = mesh.group_index(name);
    if (g < 0)
      throw InputError(loc, what + ": no face group \"" + name + "\" in the emitter (groups: " + mesh.group_list() + ")");
    wanted[size_t(g)] = true;
  }
  mask.resize(mesh.triangle_count());
  for (size_t f = 0; f < mesh.triangle_count(); ++f) mask[f] = wanted[size_t(mesh.triangle_groups[f])];
  return mask;
}

/// The minimal rotation taking unit vector a to unit vector b (a . b > -1).
Eigen::Matrix3f minimal_rotation(const Eigen::Vector3f &a, const Eigen::Vector3f &b) {
  const Eigen::Vector3f w = a.cross(b);
  const float c = a.dot(b);
  if (c <= -1.0f + 1e-6f) {
    // Opposite: a half turn about any axis perpendicular to a.
    const Eigen::Vector3f axis = a.unitOrthogonal();
    return 2.0f * axis * axis.transpose() - Eigen::Matrix3f::Identity();
  }
  Eigen::Matrix3f wx;
  wx << 0.0f, -w.z(), w.y(), w.z(), 0.0f, -w.x(), -w.y(), w.x(), 0.0f;
  return Eigen::Matrix3f::Identity() + wx + wx * wx / (1.0f + c);
}

/// The turn taking unit vector a to unit vector b about their common normal, eased in below
/// kEasedTurn radians (the angle becomes angle^2 / kEasedTurn there, continuously): directions
/// read from a skin's float frames differ by rounding (about 1e-6 radians) when nothing turned, and
/// a feather a rigid motion carries must not take that noise as a turn.
constexpr float kEasedTurn = 1e-4f;
Eigen::Matrix3f eased_turn(const Eigen::Vector3f &a, const Eigen::Vector3f &b) {
  const Eigen::Vector3f w = a.cross(b);
  const float sine = w.norm();
  const float angle = std::atan2(sine, a.dot(b));
  if (!(sine > 1e-30f)) return angle > 1.0f ? minimal_rotation(a, b) : Eigen::Matrix3f::Identity();
  const float eased = angle < kEasedTurn ? angle * angle / kEasedTurn : angle;
  return Eigen::AngleAxisf(eased, w / sine).toRotationMatrix();
}

Eigen::Vector3f unit_or(const Eigen::Vector3f &v, const Eigen::Vector3f &fallback) {
  const float n = v.norm();
  return n > 1e-20f ? Eigen::Vector3f(v / n) : fallback;
}

}  // namespace

/// A guide stem at this frame: its segments' unit directions in its root's skin frame, and the arc
/// length where each segment starts.
struct StemFrame {
  std::vector<Eigen::Vector3f> local_directions;  // per segment, stems' offsets minus one per stem
  std::vector<float> arc;                         // per segment: arc length at its start
  std::vector<int64_t> first;                     // per stem: its first segment, stems + 1 entries
};

namespace {

StemFrame stem_frame(const Mesh &posed, const StrandSet &stems, const std::vector<SurfacePoint> &roots) {
  StemFrame frame;
  const size_t n = stems.strand_count();
  frame.first.assign(n + 1, 0);
  for (size_t g = 0; g < n; ++g) frame.first[g + 1] = frame.first[g] + stems.points_in(g) - 1;
  frame.local_directions.resize(size_t(frame.first[n]));
  frame.arc.resize(size_t(frame.first[n]));
  for (size_t g = 0; g < n; ++g) {
    const Eigen::Matrix3f basis_t = surface_frame(posed, roots[g]).basis.transpose();
    const std::span<const Eigen::Vector3f> points = stems.points(g);
    Eigen::Vector3f previous = basis_t.col(2);  // a zero-length first segment points along the normal
    float arc = 0.0f;
    for (size_t i = 0; i + 1 < points.size(); ++i) {
      const Eigen::Vector3f d = points[i + 1] - points[i];
      const size_t at = size_t(frame.first[g]) + i;
      frame.local_directions[at] = previous = unit_or(basis_t * d, previous);
      frame.arc[at] = arc;
      arc += d.norm();
    }
  }
  return frame;
}

/// The direction of stem g at arc length z, in its root's skin frame: its segment holding z (the
/// last one beyond its end).
Eigen::Vector3f stem_direction(const StemFrame &frame, size_t g, float z) {
  const auto begin = frame.arc.begin() + frame.first[g], end = frame.arc.begin() + frame.first[g + 1];
  const auto after = std::upper_bound(begin + 1, end, z);
  return frame.local_directions[size_t(after - frame.arc.begin()) - 1];
}

/// A feather's shaft this frame: the spine's points (relative to the feather's root) and the frames
/// at its joints, and the pose at any height along it (feathers/build.h's ShaftPose, root-relative).
struct Spine {
  float step = 0.0f;  // spine segment length; 0 for a feather without a shaft yet
  std::array<Eigen::Vector3f, kSpineSegments + 1> points;
  std::array<Eigen::Vector3f, kSpineSegments> directions;
  std::array<Eigen::Quaternionf, kSpineSegments + 1> joints;
  /// The feather's size relative to its own (the skin pass shrinks a feather that no lift clears).
  float scale = 1.0f;

  ShaftPose operator()(float z) const {
    ShaftPose pose = unscaled(z);
    pose.origin *= scale;
    pose.rotation *= scale;
    return pose;
  }

  ShaftPose unscaled(float z) const {
    if (!(step > 0.0f)) return {points[0], joints[0].toRotationMatrix()};
    const float s = z / step;
    const int j = std::clamp(int(std::floor(s)), 0, kSpineSegments - 1);
    const float f = std::clamp(s - float(j), 0.0f, 1.0f);
    ShaftPose pose;
    pose.origin = points[size_t(j)] + (z - float(j) * step) * directions[size_t(j)];
    // Between joints the frame is the normalised blend of theirs: continuous along the shaft.
    const Eigen::Quaternionf &a = joints[size_t(j)], &b = joints[size_t(j) + 1];
    Eigen::Vector4f q = (1.0f - f) * a.coeffs() + f * b.coeffs();
    pose.rotation = Eigen::Quaternionf(q / q.norm()).toRotationMatrix();
    return pose;
  }

  /// Turns the whole spine by `rotation` about the root.
  void turn(const Eigen::Matrix3f &rotation) {
    const Eigen::Quaternionf q(rotation);
    for (Eigen::Vector3f &p : points) p = rotation * p;
    for (Eigen::Vector3f &d : directions) d = rotation * d;
    for (Eigen::Quaternionf &joint : joints) joint = (q * joint).normalized();
  }
};

/// One sample of the skin pass: a feather point (relative to the root) and the clearance it needs,
/// and up to two samples before it nearby (-1: none), whose distances bound its own (the signed
/// distance is 1-Lipschitz): the rachis point below it, or the barb point nearer the rachis, and the
/// same point of the row below.
struct SkinSample {
  Eigen::Vector3f point;
  float clearance;
  std::array<int, 2> near = {-1, -1};
};

/// The points the skin pass checks, in the world at the spine's pose: the calamus's middle, and per
/// vane and row the rachis point, the barb's midpoint and its tip (the afterfeather's too). Each must
/// clear the skin by `clearance` times its distance from the root (a feather leaves the skin at its
/// root), plus room for fuzz.
int skin_samples(const FeatherShape &shape, const Spine &spine, float clearance, SkinSample *r_samples) {
  int count = 0;
  // As emit_curves places points: a barb's points follow the shaft's pose at the barb's attachment.
  auto add = [&](const Eigen::Vector3f &p_feather, float attach_z, float extra, int near_a, int near_b) {
    const ShaftPose pose = spine(attach_z);
    const Eigen::Vector3f p =
        pose.origin + pose.rotation * (p_feather - Eigen::Vector3f(0.0f, 0.0f, attach_z));
    r_samples[count] = {p, clearance * p.norm() + extra, {near_a, near_b}};
    return count++;
  };
  const int calamus =
      add(Eigen::Vector3f(0.0f, 0.0f, 0.5f * shape.main.calamus_length), 0.5f * shape.main.calamus_length, 0.0f, -1, -1);
  for (const bool after : {false, true}) {
    if (after && !shape.has_after) break;
    const FeatherTemplate &f = after ? shape.after : shape.main;
    const Eigen::Vector3f offset = after ? afterfeather_offset(shape.main) : Eigen::Vector3f::Zero();
    const int rows = after ? 3 : kSkinRows;
    const std::array<std::vector<KeyBarb>, 2> &keys = after ? shape.after_keys : shape.main_keys;
    std::array<VaneBarbs, 2> barbs = {VaneBarbs(f, keys[0], Vane::left, 0), VaneBarbs(f, keys[1], Vane::right, 0)};
    // The previous row's samples: rachis, then per vane the barb's midpoint and tip.
    std::array<int, 5> below = {calamus, -1, -1, -1, -1};
    for (int r = 0; r < rows; ++r) {
      const float rp = float(r) / float(rows - 1);
      const BarbAttachment attachment = barb_attachment(f, rp);
      const Eigen::Vector3f rachis = attachment.point + offset;
      std::array<int, 5> row;
      row[0] = add(rachis, rachis.z(), 0.0f, below[0], -1);
      for (const Vane vane : {Vane::left, Vane::right}) {
        const Barb barb = barbs[size_t(vane)](rp, -1, attachment);
        const float extra = kFuzzMargin * barb.plumulaceous * barb.length;
        const Eigen::Vector3f attach = barb.attach + offset;
        const size_t at = 1 + 2 * size_t(vane);
        row[at] = add(attach + barb.frame * bezier_point(barb.polygon.view(), 0.5f), attach.z(), extra, row[0], below[at]);
        row[at + 1] = add(attach + barb.frame * bezier_point(barb.polygon.view(), 1.0f), attach.z(), extra, row[at],
                          below[at + 1]);
      }
      below = row;
    }
  }
  return count;
}
constexpr int kMaxSkinSamples = 1 + 5 * kSkinRows + 5 * 3;

/// The skin pass's search for one feather: turns `a` about `axis` (through `root`, raising the
/// feather) in [0, max_lift] after which every sample clears the skin by its clearance. Each sample's
/// deficit (clearance - signed distance) is measured in the turn it asks for: divided by the rate at
/// which lifting raises it, n . (axis x p) (n the skin's side normal at its closest point), but never
/// by less than kMinimumRate times its distance p from the root. That keeps the answer well
/// conditioned: a rigid motion of the skin changes the distances by their rounding only, and the turn
/// by at most that over kMinimumRate |p|. Queries are skipped for samples that a bound shows to clear
/// (the distance is 1-Lipschitz): their last distance less the way they moved since, or, on a closed
/// skin, a nearby sample's distance at this angle less how far apart the two are (a turn keeps that).
/// Only the sign of a clearing answer is used, and a sample that does not clear is always queried, so
/// the skips change no result.
struct Lift {
  float angle = 0.0f;
  float scale = 1.0f;
};

class LiftSearch {
 public:
  LiftSearch(const SkinSample *samples, int count, const Eigen::Vector3f &root, const Eigen::Vector3f &axis,
             float max_lift, const skin::SkinGrid &grid, const MeshQuery &query, int hint)
      : samples_(samples), count_(count), root_(root), axis_(axis), max_lift_(max_lift), grid_(grid), query_(query),
        hint_(hint), closed_(!grid.has_open_edges()), rounding_(1e-5f * root.cwiseAbs().maxCoeff()) {
    known_distance_.fill(-INFINITY);
    known_at_.fill(0.0f);
    known_rate_.fill(1.0f);
    known_triangle_.fill(-1);
    for (int s = 0; s < count; ++s)
      for (size_t k = 0; k < 2; ++k) {
        const int other = samples[s].near[k];
        apart_[size_t(s)][k] = other >= 0 ? (samples[s].point - samples[other].point).norm() : INFINITY;
      }
  }

  /// The largest turn the samples ask for at `angle` (not positive when they all clear by hold_ times
  /// their clearance).
  float evaluate(float angle);
  bool clears(float angle) { return !(evaluate(angle) > 0.0f); }

  /// The stateless answer: the smallest turn that clears; where none does, the feather shrunk toward
  /// its root at the turn of the smallest worst deficit until it clears.
  Lift smallest() {
    float best = 0.0f;
    if (const std::optional<float> angle = first_clearing(0.0f, best)) return {*angle, 1.0f};
    return shrunk_at(best);
  }

  /// The warm start from the previous frame's turn `previous` and size `previous_scale`: while
  /// `previous` still clears, the turn falls toward the smallest that clears by at most `fall` (radians)
  /// and stays in the interval of clearing turns it was in. When it no longer clears, the smallest turn
  /// that clears when that is within kFollow of it; else the feather stays where it is while its
  /// samples keep kHold of their clearance; else the smallest turn that clears, or, with none, the
  /// feather shrunk at the turn of the smallest worst deficit, as without a warm start. A feather that
  /// was shrunk grows back by at most `fall` of its size per frame, where that size clears.
  Lift warm(float previous, float previous_scale, float fall);

 private:
  /// The smallest turn in [from, max_lift] that clears: from below by Newton steps on the largest
  /// deficit, to 1e-6 radians by bisection (finer, the distances' float rounding would not resolve);
  /// where that does not converge (a sample in a fold of the skin, whose closest point is on another
  /// part), a scan of the range for the first turn that clears, refined by bisection. None when no
  /// turn clears; r_best is then the turn of the smallest worst deficit the scan saw.
  std::optional<float> first_clearing(float from, float &r_best);
  /// Whether every sample clears at `angle` with the feather at `scale` of its size (clearances
  /// shrink with it).
  bool clears_scaled(float angle, float scale) const;
  /// The largest size that clears at `angle` (bisection).
  Lift shrunk_at(float angle) const;

  static constexpr float kMinimumRate = 0.3f;
  /// The warm start keeps a feather where it is, rather than move it farther than kFollow radians,
  /// while its samples keep kHold of their clearance.
  static constexpr float kHold = 0.75f;
  static constexpr float kFollow = 0.2f;
  const SkinSample *samples_;
  int count_;
  Eigen::Vector3f root_, axis_;
  float max_lift_;
  const skin::SkinGrid &grid_;
  const MeshQuery &query_;
  int hint_;
  /// The part of their clearance the samples must keep (1, or kHold where a feather stays put).
  float hold_ = 1.0f;
  bool closed_;
  // The rounding a bound through nearby samples must beat: the distances are floats at the skin's
  // coordinates.
  float rounding_;
  std::array<float, kMaxSkinSamples> known_distance_, known_at_, known_rate_;
  // How far each sample is from its nearby ones (a turn about the root keeps it).
  std::array<std::array<float, 2>, kMaxSkinSamples> apart_;
  // A lower bound of each sample's signed distance at the angle being evaluated.
  std::array<float, kMaxSkinSamples> lower_;
  // Per sample, its closest triangle when last queried, and at this angle (-1: not queried).
  std::array<int, kMaxSkinSamples> known_triangle_, near_triangle_;
};

float LiftSearch::evaluate(float angle) {
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(angle, axis_).toRotationMatrix();
  near_triangle_.fill(-1);
  float worst = -INFINITY;
  for (int s = 0; s < count_; ++s) {
    const size_t si = size_t(s);
    const float clearance = hold_ * samples_[s].clearance;
    const float reach = samples_[s].point.norm();
    const float moved = std::abs(angle - known_at_[si]) * reach;
    if (known_distance_[si] - moved - clearance > 0.0f) {
      lower_[si] = known_distance_[si] - moved;
      worst = std::max(worst, (clearance - lower_[si]) / known_rate_[si]);
      continue;
    }
    if (closed_) {
      float bound = -INFINITY;
      for (size_t k = 0; k < 2; ++k)
        if (samples_[s].near[k] >= 0) bound = std::max(bound, lower_[size_t(samples_[s].near[k])] - apart_[si][k]);
      if (bound - clearance > rounding_ + 1e-5f * reach) {
        lower_[si] = bound;
        worst = std::max(worst, (clearance - bound) / known_rate_[si]);
        continue;
      }
    }
    const Eigen::Vector3f relative = turn * samples_[s].point;
    // The search starts from the sample's last closest triangle, else its nearby sample's at this
    // angle, else the follicle's: the nearer the start, the fewer cells searched.
    const int near = samples_[s].near[0];
    const int start = known_triangle_[si] >= 0                             ? known_triangle_[si]
                      : near >= 0 && near_triangle_[size_t(near)] >= 0 ? near_triangle_[size_t(near)]
                                                                         : hint_;
    SurfacePoint closest;
    const float distance = grid_.signed_distance(root_ + relative, start, closest);
    known_triangle_[si] = closest.triangle;
    near_triangle_[si] = closest.triangle;
    const float rate = std::max(query_.side_normal(closest).dot(axis_.cross(relative)), kMinimumRate * reach);
    known_distance_[si] = distance;
    known_at_[si] = angle;
    known_rate_[si] = std::max(rate, 1e-30f);
    lower_[si] = distance;
    worst = std::max(worst, (clearance - distance) / known_rate_[si]);
  }
  return worst;
}

std::optional<float> LiftSearch::first_clearing(float from, float &r_best) {
  float needed = evaluate(from);
  r_best = from;
  if (!(needed > 0.0f)) return from;
  float below = from, above = INFINITY;
  for (int iteration = 0; iteration < 4 * kLiftIterations && !(above - below < 1e-6f); ++iteration) {
    float next = std::min(below + needed, max_lift_);
    if (next >= above || !(next > below)) next = 0.5f * (below + (above < INFINITY ? above : max_lift_));
    if (!(next > below)) break;
    const float f = evaluate(next);
    // Within a micro-radian of the root: the distances' rounding cannot resolve more.
    if (f > 0.0f && f < 1e-6f && next + f <= max_lift_) return next + f;
    if (f > 0.0f) {
      below = next;
      needed = f;
      if (below >= max_lift_) break;
    } else {
      above = next;
      needed = 0.5f * (above - below);
    }
  }
  if (above < INFINITY) return above;
  constexpr int kScanSteps = 24;
  float best = below, best_deficit = evaluate(below);
  float previous = from;
  for (int k = 1; k <= kScanSteps; ++k) {
    const float angle = from + (max_lift_ - from) * float(k) / float(kScanSteps);
    const float deficit = evaluate(angle);
    if (!(deficit > 0.0f)) {
      float lo = previous, hi = angle;
      while (hi - lo > 1e-6f) {
        const float mid = 0.5f * (lo + hi);
        (evaluate(mid) > 0.0f ? lo : hi) = mid;
      }
      return hi;
    }
    if (deficit < best_deficit) {
      best_deficit = deficit;
      best = angle;
    }
    previous = angle;
  }
  r_best = best;
  return std::nullopt;
}

bool LiftSearch::clears_scaled(float angle, float scale) const {
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(angle, axis_).toRotationMatrix();
  for (int s = 0; s < count_; ++s) {
    SurfacePoint closest;
    if (grid_.signed_distance(root_ + scale * (turn * samples_[s].point), hint_, closest) < scale * samples_[s].clearance)
      return false;
  }
  return true;
}

// No turn clears it (two parts of the skin close on it, as a folding wing over the back): at the
// best turn, the feather is shrunk toward its root until it clears (the largest such size, by
// bisection; clearances shrink with it).
Lift LiftSearch::shrunk_at(float angle) const {
  float lo = 0.0f, hi = 1.0f;
  for (int b = 0; b < 16; ++b) {
    const float mid = 0.5f * (lo + hi);
    (clears_scaled(angle, mid) ? lo : hi) = mid;
  }
  return {angle, lo};
}

Lift LiftSearch::warm(float previous, float previous_scale, float fall) {
  const float from = std::clamp(previous, 0.0f, max_lift_);
  Lift lift;
  if (clears(from)) {
    // Down toward the smallest turn that clears, by at most `fall`, without leaving the interval.
    const float target = std::max(from - fall, 0.0f);
    lift.angle = from;
    if (target < from) {
      if (clears(target)) {
        lift.angle = target;
      } else {
        float lo = target, hi = from;
        while (hi - lo > 1e-6f) {
          const float mid = 0.5f * (lo + hi);
          (clears(mid) ? hi : lo) = mid;
        }
        lift.angle = hi;
      }
    }
  } else {
    // Pushed out of its interval: the smallest turn that clears, as without a warm start, but a
    // feather that would move farther than kFollow stays where it is while its samples keep kHold of
    // their clearance (it leaves its interval only when it must).
    const auto holds = [&] {
      hold_ = kHold;
      const bool kept = clears(from);
      hold_ = 1.0f;
      return kept;
    };
    float best = 0.0f;
    const std::optional<float> smallest_turn = first_clearing(0.0f, best);
    if (smallest_turn && std::abs(*smallest_turn - from) <= kFollow) {
      lift.angle = *smallest_turn;
    } else if (holds()) {
      lift.angle = from;
    } else if (smallest_turn) {
      lift.angle = *smallest_turn;
    } else {
      return shrunk_at(best);
    }
  }
  // A shrunk feather grows back gradually, at a turn that clears it whole.
  if (previous_scale < 1.0f) {
    const float scale = std::min(1.0f, previous_scale + fall);
    if (scale < 1.0f && clears_scaled(lift.angle, scale)) lift.scale = scale;
  }
  return lift;
}

}  // namespace

Follicles scatter_follicles(const Mesh &rest_mesh, const FollicleSettings &settings,
                            const std::vector<float> &vertex_map, int64_t count_override) {
  const std::vector<bool> mask = group_mask(rest_mesh, settings.groups, settings.loc, "feathers.follicles.groups");
  int64_t count = settings.count;
  if (count_override >= 0) {
    count = count_override;
  } else if (count <= 0) {
    const double wanted = settings.density * masked_area(rest_mesh, mask);
    if (!(wanted <= 1e8))
      throw InputError(settings.loc, "feathers.follicles.density: density x area gives " + std::to_string(wanted) +
                                         " follicles, more than 100000000");
    count = int64_t(std::llround(wanted));
    if (count <= 0) throw InputError(settings.loc, "feathers.follicles.density: density x area gives no follicle");
  }
  Roots roots = scatter_roots(rest_mesh, count, settings.seed, mask, settings.loc);
  Follicles follicles;
  follicles.points.reserve(roots.size());
  follicles.ids.reserve(roots.size());
  for (size_t i = 0; i < roots.size(); ++i) {
    if (!vertex_map.empty()) {
      const float value = surface_value(rest_mesh, vertex_map, roots.points[i]);
      if (!(value > hashed_unit(settings.seed, roots.ids[i], kThinning))) continue;
    }
    follicles.points.push_back(roots.points[i]);
    follicles.ids.push_back(roots.ids[i]);
  }
  return follicles;
}

KeyFeatherField::KeyFeatherField(const Mesh &rest_mesh, const FeatherDesc &desc) : mesh_(rest_mesh) {
  welded_ = welded_vertices(rest_mesh, weld_distance(rest_mesh));
  const size_t vertex_count = rest_mesh.vertex_count();
  // Edges between welded vertices, both ways (CSR).
  std::vector<std::vector<std::pair<uint32_t, double>>> edges(vertex_count);
  for (const Eigen::Vector3i &t : rest_mesh.triangles)
    for (int k = 0; k < 3; ++k) {
      const uint32_t a = welded_[size_t(t[k])], b = welded_[size_t(t[(k + 1) % 3])];
      if (a == b) continue;
      const double length = (rest_mesh.positions[a] - rest_mesh.positions[b]).cast<double>().norm();
      edges[a].emplace_back(b, length);
      edges[b].emplace_back(a, length);
    }
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f &p : rest_mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double default_radius = 0.05 * double((hi - lo).norm());
  const MeshQuery query(rest_mesh);
  for (const KeyFeather &key : desc.key_feathers) {
    std::vector<double> distance(vertex_count, INFINITY);
    using Entry = std::pair<double, uint32_t>;
    std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> queue;
    Eigen::Vector3f point = Eigen::Vector3f::Zero();
    if (!key.groups.empty()) {
      const std::vector<bool> mask = group_mask(rest_mesh, key.groups, key.groups_loc.known() ? key.groups_loc : key.loc,
                                                "feathers.key_feathers: groups");
      for (size_t f = 0; f < rest_mesh.triangle_count(); ++f)
        if (mask[f])
          for (int k = 0; k < 3; ++k) distance[welded_[size_t(rest_mesh.triangles[f][k])]] = 0.0;
    } else {
      const SurfacePoint snapped = query.closest(key.point);
      point = surface_position(rest_mesh, snapped);
      const Eigen::Vector3i &t = rest_mesh.triangles[size_t(snapped.triangle)];
      for (int k = 0; k < 3; ++k) {
        const uint32_t v = welded_[size_t(t[k])];
        distance[v] = std::min(distance[v], double((rest_mesh.positions[v] - point).norm()));
      }
    }
    for (uint32_t v = 0; v < vertex_count; ++v)
      if (distance[v] < INFINITY) queue.emplace(distance[v], v);
    // Dijkstra along the edges.
    while (!queue.empty()) {
      const auto [d, v] = queue.top();
      queue.pop();
      if (d > distance[v]) continue;
      for (const auto &[w, length] : edges[v])
        if (d + length < distance[w]) {
          distance[w] = d + length;
          queue.emplace(distance[w], w);
        }
    }
    distances_.push_back(std::move(distance));
    at_point_.push_back(key.groups.empty());
    points_.push_back(point);
    radii_.push_back(key.radius > 0.0f ? double(key.radius) : default_radius);
  }
}

double KeyFeatherField::distance(size_t k, const SurfacePoint &sp) const {
  const Eigen::Vector3i &t = mesh_.triangles[size_t(sp.triangle)];
  double d = 0.0;
  for (int i = 0; i < 3; ++i) d += double(sp.bary[i]) * distances_[k][welded_[size_t(t[i])]];
  // A vertex no path reaches (another part of the mesh) is infinitely far; a point key feather is
  // never farther than the straight line to it.
  if (at_point_[k]) d = std::min(d, double((surface_position(mesh_, sp) - points_[k]).norm()));
  return d;
}

void KeyFeatherField::weights(const SurfacePoint &point, std::span<float> r_weights) const {
  const size_t n = radii_.size();
  std::vector<double> exponent(n);
  double smallest = INFINITY;
  for (size_t k = 0; k < n; ++k) {
    const double x = distance(k, point) / radii_[k];
    exponent[k] = x * x;
    smallest = std::min(smallest, exponent[k]);
  }
  // Normalised exp(-(d/r)^2), shifted by the smallest exponent so that far from every key feather the
  // weights still sum to 1 instead of all underflowing to 0.
  double sum = 0.0;
  for (size_t k = 0; k < n; ++k) {
    exponent[k] = std::isfinite(smallest) ? std::exp(-(exponent[k] - smallest)) : 1.0;
    sum += exponent[k];
  }
  for (size_t k = 0; k < n; ++k) r_weights[k] = float(exponent[k] / sum);
}

Coat::Coat(const Mesh &rest_mesh, const Guides &stems, const FeatherDesc &desc, Follicles follicles,
           std::span<const float> layer_map)
    : detail_(desc.detail), lift_(desc.lift), clearance_(desc.clearance), falloff_(desc.falloff), layers_(desc.layers) {
  layering_.offset = desc.layer_offset;
  layering_.fall_back = kFallBackWidths;
  if (stems.size() == 0) throw InputError(desc.loc, "feathers: the guides hold no stems");
  if (desc.key_feathers.empty()) throw InputError(desc.loc, "feathers.key_feathers: expected at least one key feather");
  points_ = std::move(follicles.points);
  ids_ = std::move(follicles.ids);
  k_ = std::min<int>(desc.guides_per_feather, int(stems.size()));
  const size_t n = points_.size();

  // Templates: each feather blends the key feathers' templates by its weights, then varies.
  const KeyFeatherField field(rest_mesh, desc);
  key_count_ = field.key_count();
  key_weights_.resize(n * key_count_);
  std::vector<const FeatherTemplate *> key_templates(key_count_);
  for (size_t k = 0; k < key_count_; ++k) key_templates[k] = &desc.templates[size_t(desc.key_feathers[k].template_index)];
  shapes_.resize(n);
  templates_.resize(n);
  std::vector<float> stages(n);
  const FeatherVariation &v = desc.variation;
  for (size_t i = 0; i < n; ++i) {
    const std::span<float> w(key_weights_.data() + i * key_count_, key_count_);
    field.weights(points_[i], w);
    templates_[i] = desc.key_feathers[heaviest_key(i)].template_index;
    FeatherTemplate t = blend_templates(key_templates, w);
    float stage = 0.0f;
    for (size_t k = 0; k < key_count_; ++k) stage += w[k] * desc.key_feathers[k].stage;
    // Seeded variation from the feather's stable id.
    const uint64_t id = ids_[i];
    const float scale = 1.0f + v.length * (2.0f * hashed_unit(v.seed, id, kLength) - 1.0f);
    for (float *length : {&t.calamus_length, &t.rachis_length, &t.rachis_width, &t.spacing_base, &t.spacing_tip,
                          &t.barb_width})
      *length *= scale;
    const float angle = v.barb_angle * (2.0f * hashed_unit(v.seed, id, kBarbAngle) - 1.0f);
    for (VaneDesc *vane : {&t.left, &t.right}) {
      vane->barb_length *= scale;
      for (float &value : vane->silhouette.value) value *= scale;
      vane->angle_base = std::clamp(vane->angle_base + angle, 0.0f, 180.0f);
      vane->angle_tip = std::clamp(vane->angle_tip + angle, 0.0f, 180.0f);
    }
    stage = std::clamp(stage - v.stage * hashed_unit(v.seed, id, kStage), 0.0f, 1.0f);
    stages[i] = stage;
    shapes_[i] = make_shape(t, id, stage);
  }

  bind_stems(rest_mesh, stems);

  // Base frames: the stems' first segments and sides, blended and carried to the follicle's frame.
  base_frames_.resize(n);
  std::vector<Eigen::Matrix3f> stem_basis(stems.size());
  std::vector<Eigen::Vector3f> stem_first(stems.size()), stem_side(stems.size());
  for (size_t g = 0; g < stems.size(); ++g) {
    stem_basis[g] = surface_frame(rest_mesh, stems.roots[g]).basis;
    const std::span<const Eigen::Vector3f> p = stems.strands.points(g);
    const Eigen::Vector3f normal = stem_basis[g].col(2);
    const Eigen::Vector3f first = unit_or(p[1] - p[0], normal);
    stem_first[g] = stem_basis[g].transpose() * first;
    stem_side[g] = stem_basis[g].transpose() * unit_or(normal.cross(first), stem_basis[g].col(0));
  }
  for (size_t i = 0; i < n; ++i) {
    Eigen::Vector3f shaft = Eigen::Vector3f::Zero(), side = Eigen::Vector3f::Zero();
    for (int s = 0; s < k_; ++s) {
      const Stem &stem = stems_[i * size_t(k_) + size_t(s)];
      if (stem.guide < 0) continue;
      const Eigen::Matrix3f carry = stem.rest_rotation.toRotationMatrix();
      shaft += stem.weight * (carry * stem_first[size_t(stem.guide)]);
      side += stem.weight * (carry * stem_side[size_t(stem.guide)]);
    }
    // In the follicle's skin frame (z its normal).
    shaft = unit_or(shaft, Eigen::Vector3f::UnitZ());
    side = side - side.dot(shaft) * shaft;
    side = unit_or(side, unit_or(Eigen::Vector3f::UnitZ().cross(shaft), shaft.unitOrthogonal()));
    Eigen::Matrix3f base;
    base.col(0) = side;
    base.col(1) = shaft.cross(side);
    base.col(2) = shaft;
    // Seeded direction (about the normal) and lift (about the horizontal axis across the shaft).
    const uint64_t id = ids_[i];
    const float turn = v.direction * (2.0f * hashed_unit(v.seed, id, kDirection) - 1.0f) * kRadiansPerDegree;
    const float raise = v.lift * (2.0f * hashed_unit(v.seed, id, kLift) - 1.0f) * kRadiansPerDegree;
    const Eigen::Vector3f across = shaft.cross(Eigen::Vector3f::UnitZ());
    Eigen::Matrix3f variation = Eigen::AngleAxisf(turn, Eigen::Vector3f::UnitZ()).toRotationMatrix();
    if (across.norm() > 1e-6f) variation = variation * Eigen::AngleAxisf(raise, across.normalized()).toRotationMatrix();
    base_frames_[i] = Eigen::Quaternionf(variation * base).normalized();
  }

  // The output layout.
  first_curve_.assign(n + 1, 0);
  first_point_.assign(n + 1, 0);
  first_vertex_.assign(n + 1, 0);
  first_triangle_.assign(n + 1, 0);
  for (size_t i = 0; i < n; ++i) {
    const FeatherCounts c = feather_counts(shapes_[i], detail_);
    first_curve_[i + 1] = first_curve_[i] + c.curves;
    first_point_[i + 1] = first_point_[i] + c.points;
    first_vertex_[i + 1] = first_vertex_[i] + c.vane_vertices;
    first_triangle_[i + 1] = first_triangle_[i] + c.vane_triangles;
  }
  total_ = {first_curve_[n], first_point_[n], first_vertex_[n], first_triangle_[n]};
  if (total_.vane_vertices > int64_t(std::numeric_limits<int32_t>::max()))
    throw InputError(desc.loc, "feathers: " + std::to_string(total_.vane_vertices) +
                                   " vane vertices, more than a mesh's 32-bit indices hold (fewer follicles or vane_rows)");
  curve_offsets_.resize(size_t(total_.curves) + 1);
  curve_offsets_[0] = 0;
  for (size_t i = 0; i < n; ++i) {
    int64_t c = first_curve_[i], p = first_point_[i];
    const auto rachis = [&](bool calamus) {
      p += detail_.rachis_points + (calamus ? 1 : 0);
      curve_offsets_[size_t(++c)] = p;
    };
    const auto barbs = [&](size_t positions) {
      for (size_t b = 0; b < 2 * positions; ++b) {
        p += detail_.barb_points;
        curve_offsets_[size_t(++c)] = p;
      }
    };
    rachis(true);
    barbs(shapes_[i].main_positions.size());
    if (shapes_[i].has_after) {
      rachis(false);
      barbs(shapes_[i].after_positions.size());
    }
  }
  stem_offsets_ = stems.strands.offsets;

  // The rest stems' direction at each feather's first spine segment, as grow() blends it.
  const StemFrame rest_stems = stem_frame(rest_mesh, stems.strands, stem_roots_);
  rest_first_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const float step = (shapes_[i].main.calamus_length + shapes_[i].main.rachis_length) / float(kSpineSegments);
    const Eigen::Vector3f shaft = base_frames_[i].toRotationMatrix().col(2);
    rest_first_[i] = unit_or(blend_stems(rest_stems, i, 0.5f * step), shaft);
  }

  // The layer order, from which feather covers which at rest.
  rachis_widths_.resize(n);
  for (size_t i = 0; i < n; ++i) rachis_widths_[i] = shapes_[i].main.rachis_width;
  if (layers_ && n > 0) {
    const MeshQuery rest_query(rest_mesh);
    CoatFrame rest;
    grow_feathers(rest_mesh, rest_query, stems.strands, nullptr, rest.skin_pass, &rest, nullptr);
    order_ = layer_order_from_coverage(rest, ranges(), order_keys(rest_mesh, desc, layer_map), &rest_query);
  }
}

size_t Coat::heaviest_key(size_t feather) const {
  const std::span<const float> w = key_weights(feather);
  return size_t(std::max_element(w.begin(), w.end()) - w.begin());
}

std::vector<LayerKey> Coat::order_keys(const Mesh &rest_mesh, const FeatherDesc &desc,
                                       std::span<const float> layer_map) const {
  const bool by_key = std::any_of(desc.key_feathers.begin(), desc.key_feathers.end(),
                                  [](const KeyFeather &k) { return k.layer_given; });
  if (!by_key && layer_map.empty() && desc.layer_front.empty() && desc.layer_rear.empty()) return {};
  if (!layer_map.empty() && layer_map.size() != rest_mesh.vertex_count())
    throw InternalError("Coat: " + std::to_string(layer_map.size()) + " layer map values for " +
                        std::to_string(rest_mesh.vertex_count()) + " vertices");
  const std::vector<bool> front = group_mask(rest_mesh, desc.layer_front, desc.layer_front_loc, "feathers.layers.front");
  const std::vector<bool> rear = group_mask(rest_mesh, desc.layer_rear, desc.layer_rear_loc, "feathers.layers.rear");
  const size_t n = points_.size();
  std::vector<LayerKey> keys(n);
  for (size_t i = 0; i < n; ++i) {
    const SurfacePoint &p = points_[i];
    const size_t face = size_t(p.triangle);
    LayerKey &key = keys[i];
    if (!front.empty() && front[face]) key.tier = 1;
    if (!rear.empty() && rear[face]) key.tier = -1;
    // The heaviest key feather's layer (the one whose template the feather takes).
    key.layer = desc.key_feathers[heaviest_key(i)].layer;
    if (!layer_map.empty()) key.map = surface_value(rest_mesh, layer_map, p);
  }
  return keys;
}

void Coat::bind_stems(const Mesh &rest_mesh, const Guides &stems) {
  const size_t n = points_.size(), guide_count = stems.size();
  stem_roots_ = stems.roots;
  stems_.assign(n * size_t(k_), Stem{});
  std::vector<Eigen::Vector3f> root_positions(guide_count);
  std::vector<Eigen::Matrix3f> root_frames(guide_count);
  for (size_t g = 0; g < guide_count; ++g) {
    const SurfaceFrame frame = surface_frame(rest_mesh, stems.roots[g]);
    root_positions[g] = frame.origin;
    root_frames[g] = frame.basis;
  }
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f &p : rest_mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double hit = 1e-6 * double((hi - lo).norm());
  std::vector<std::pair<double, int32_t>> nearest(guide_count);
  for (size_t i = 0; i < n; ++i) {
    const SurfaceFrame frame = surface_frame(rest_mesh, points_[i]);
    for (size_t g = 0; g < guide_count; ++g)
      nearest[g] = {(root_positions[g] - frame.origin).cast<double>().norm(), int32_t(g)};
    const size_t kept = size_t(k_);
    std::partial_sort(nearest.begin(), nearest.begin() + std::min(kept + 1, guide_count), nearest.end());
    // As fur binds guides (docs/interpolation.md): score 1/d^p faded by the first score left out, so a
    // stem's weight reaches 0 exactly when it stops being among the k nearest. A stem root on the
    // follicle takes all the weight.
    std::array<double, max_barb_control_points> weight{};
    double sum = 0.0;
    if (nearest[0].first <= hit) {
      for (size_t s = 0; s < kept; ++s) weight[s] = nearest[s].first <= hit ? 1.0 : 0.0;
    } else {
      const double cut = kept < guide_count ? std::pow(nearest[kept].first, -double(falloff_)) : 0.0;
      for (size_t s = 0; s < kept; ++s) weight[s] = std::pow(nearest[s].first, -double(falloff_)) - cut;
      if (std::all_of(weight.begin(), weight.begin() + long(kept), [](double w) { return !(w > 0.0); }))
        for (size_t s = 0; s < kept; ++s) weight[s] = std::pow(nearest[s].first, -double(falloff_));
    }
    for (size_t s = 0; s < kept; ++s) sum += weight[s];
    for (size_t s = 0; s < kept; ++s) {
      Stem &stem = stems_[i * kept + s];
      const int32_t g = nearest[s].second;
      stem.guide = g;
      stem.weight = float(weight[s] / sum);
      // Q_C^T M Q_H: from the stem root's frame to the follicle's, M taking normal to normal.
      const Eigen::Matrix3f m = minimal_rotation(root_frames[size_t(g)].col(2), frame.basis.col(2));
      stem.rest_rotation = Eigen::Quaternionf(frame.basis.transpose() * m * root_frames[size_t(g)]).normalized();
    }
  }
}

Eigen::Vector3f Coat::blend_stems(const StemFrame &frames, size_t i, float z) const {
  Eigen::Vector3f blend = Eigen::Vector3f::Zero();
  for (int s = 0; s < k_; ++s) {
    const Stem &stem = stems_[i * size_t(k_) + size_t(s)];
    if (stem.guide < 0 || stem.weight == 0.0f) continue;
    blend += stem.weight * (stem.rest_rotation * stem_direction(frames, size_t(stem.guide), z));
  }
  return blend;
}

void Coat::grow(const Mesh &posed, const MeshQuery &query, const StrandSet &stems, CoatFrame &r_frame,
                const skin::SkinGrid *skin_grid, const SkinPassState *previous,
                const LayeringState *previous_layers) const {
  // One grid of the posed skin serves the skin pass and the layering pass.
  std::optional<skin::SkinGrid> own_grid;
  if (!skin_grid && (lift_ || layered())) skin_grid = &own_grid.emplace(posed, query);
  grow_feathers(posed, query, stems, previous, r_frame.skin_pass, &r_frame, skin_grid);
  r_frame.layering = {};
  r_frame.layer_state = {};
  if (layered())
    r_frame.layering = lift_layers(order_, ranges(), layering_, &query, r_frame, skin_grid,
                                   LayeringWarmStart{previous_layers, rachis_widths_}, &r_frame.layer_state);
}

void Coat::skin_pass(const Mesh &posed, const MeshQuery &query, const StrandSet &stems, const SkinPassState *previous,
                     SkinPassState &r_state, const skin::SkinGrid *skin_grid) const {
  grow_feathers(posed, query, stems, previous, r_state, nullptr, skin_grid);
}

void Coat::grow_feathers(const Mesh &posed, const MeshQuery &query, const StrandSet &stems,
                         const SkinPassState *previous, SkinPassState &r_state, CoatFrame *r_frame,
                         const skin::SkinGrid *skin_grid) const {
  if (stems.offsets != stem_offsets_)
    throw InputError("feathers: the guide stems of this frame (" + std::to_string(stems.strand_count()) +
                     " stems, " + std::to_string(stems.point_count()) +
                     " points) do not match the stems the coat was bound to");
  if (previous && previous->empty()) previous = nullptr;
  if (previous && (previous->lifts.size() != size() || previous->scales.size() != size()))
    throw InputError("feathers: the skin pass's state of the frame before holds " +
                     std::to_string(previous->lifts.size()) + " feathers, expected the coat's " +
                     std::to_string(size()));
  const SkinPassState *const before = previous;
  std::optional<skin::SkinGrid> own_grid;
  if (lift_ && !skin_grid) skin_grid = &own_grid.emplace(posed, query);
  const StemFrame stem_frames = stem_frame(posed, stems, stem_roots_);

  const size_t n = size();
  r_state.lifts.resize(n);
  r_state.scales.resize(n);
  if (r_frame) {
    FeatherCurves &curves = r_frame->curves;
    VaneMesh &vanes = r_frame->vanes;
    curves.curves.offsets = curve_offsets_;
    curves.curves.positions.resize(size_t(total_.points));
    curves.curves.widths.resize(size_t(total_.points));
    curves.curves.ids.resize(size_t(total_.curves));
    curves.parts.resize(size_t(total_.curves));
    curves.templates.resize(size_t(total_.curves));
    curves.feathers.resize(size_t(total_.curves));
    curves.uv_barb.resize(size_t(total_.points));
    curves.uv_vane.resize(size_t(total_.points));
    vanes.positions.resize(size_t(total_.vane_vertices));
    vanes.uv_barb.resize(size_t(total_.vane_vertices));
    vanes.uv_vane.resize(size_t(total_.vane_vertices));
    vanes.triangles.resize(size_t(total_.vane_triangles));
    vanes.triangle_feathers.resize(size_t(total_.vane_triangles));
    vanes.triangle_templates.resize(size_t(total_.vane_triangles));
    r_frame->root_frames.resize(n);
    r_frame->lifts.resize(n);
    r_frame->scales.resize(n);
  }

  bool finite = true;
#pragma omp parallel for schedule(dynamic, 16) reduction(&& : finite)
  for (int64_t fi = 0; fi < int64_t(n); ++fi) {
    const size_t i = size_t(fi);
    const FeatherShape &shape = shapes_[i];
    const SurfaceFrame skin = surface_frame(posed, points_[i]);
    Spine spine;
    const float length = shape.main.calamus_length + shape.main.rachis_length;
    spine.step = length / float(kSpineSegments);
    // Blend the stems' directions at each spine segment's middle, in the follicle's skin frame.
    std::array<Eigen::Vector3f, kSpineSegments> local;
    for (int j = 0; j < kSpineSegments; ++j) local[size_t(j)] = blend_stems(stem_frames, i, (float(j) + 0.5f) * spine.step);
    const Eigen::Vector3f first_local = local[0];
    // The base frame turns as the stems' first direction turned from rest (identity at rest).
    const Eigen::Matrix3f base = skin.basis * eased_turn(rest_first_[i], unit_or(first_local, rest_first_[i])) *
                                 base_frames_[i].toRotationMatrix();
    spine.points[0] = Eigen::Vector3f::Zero();
    spine.directions[0] = base.col(2);
    // The spine follows the stems' bends relative to their first segment, starting from the base frame:
    // each segment's blended direction is turned by the rotation that takes the first one to the
    // base's shaft, so a feather whose stems are straight is straight along its (varied) base.
    const Eigen::Vector3f base_local = skin.basis.transpose() * base.col(2);
    const Eigen::Matrix3f align = minimal_rotation(unit_or(first_local, base_local), base_local);
    for (int j = 1; j < kSpineSegments; ++j)
      spine.directions[size_t(j)] =
          skin.basis * unit_or(align * local[size_t(j)], skin.basis.transpose() * spine.directions[size_t(j - 1)]);
    for (int j = 0; j < kSpineSegments; ++j)
      spine.points[size_t(j + 1)] = spine.points[size_t(j)] + spine.step * spine.directions[size_t(j)];
    // Joint frames, parallel-transported along the joints' tangents from the base frame: no twist.
    spine.joints[0] = Eigen::Quaternionf(base).normalized();
    Eigen::Vector3f previous = spine.directions[0];
    for (int j = 1; j <= kSpineSegments; ++j) {
      const Eigen::Vector3f tangent =
          j < kSpineSegments ? unit_or(spine.directions[size_t(j - 1)] + spine.directions[size_t(j)], previous)
                             : spine.directions[size_t(kSpineSegments - 1)];
      spine.joints[size_t(j)] =
          (Eigen::Quaternionf(minimal_rotation(previous, tangent)) * spine.joints[size_t(j - 1)]).normalized();
      previous = tangent;
    }

    // The skin pass: turn the feather up about its root, about the horizontal axis across its shaft,
    // until every sample clears the skin by its margin.
    float lift = 0.0f;
    if (lift_ && length > 0.0f) {
      const Eigen::Vector3f normal = skin.normal();
      const Eigen::Vector3f shaft = spine.directions[0];
      const Eigen::Vector3f axis_raw = shaft.cross(normal);
      if (axis_raw.norm() > 1e-6f) {
        const Eigen::Vector3f axis = axis_raw.normalized();
        const float max_lift = std::acos(std::clamp(shaft.dot(normal), -1.0f, 1.0f));
        SkinSample samples[kMaxSkinSamples];
        const int count = skin_samples(shape, spine, clearance_, samples);
        LiftSearch search(samples, count, skin.origin, axis, max_lift, *skin_grid, query, points_[i].triangle);
        float reach = 0.0f;
        for (int s = 0; s < count; ++s) reach = std::max(reach, samples[s].point.norm());
        const Lift found = before ? search.warm(before->lifts[i], before->scales[i],
                                                kFallBackWidths * shape.main.rachis_width / reach)
                                  : search.smallest();
        lift = found.angle;
        spine.scale = found.scale;
        if (lift > 0.0f) spine.turn(Eigen::AngleAxisf(lift, axis).toRotationMatrix());
      }
    }
    r_state.lifts[i] = lift;
    r_state.scales[i] = spine.scale;
    if (!r_frame) continue;
    r_frame->root_frames[i] = skin;
    r_frame->lifts[i] = lift;
    r_frame->scales[i] = spine.scale;
    FeatherCurves &curves = r_frame->curves;
    VaneMesh &vanes = r_frame->vanes;

    const int64_t first_curve = first_curve_[i], first_point = first_point_[i], end_curve = first_curve_[i + 1];
    emit_curves(shape, detail_, spine,
                CurvesOut{curves.curves.positions.data() + first_point, curves.curves.widths.data() + first_point,
                          curves.uv_barb.data() + first_point, curves.uv_vane.data() + first_point,
                          curves.parts.data() + first_curve, skin.origin});
    std::fill(curves.curves.ids.begin() + first_curve, curves.curves.ids.begin() + end_curve, ids_[i]);
    std::fill(curves.templates.begin() + first_curve, curves.templates.begin() + end_curve, templates_[i]);
    std::fill(curves.feathers.begin() + first_curve, curves.feathers.begin() + end_curve, uint32_t(i));
    const int64_t first_vertex = first_vertex_[i], first_triangle = first_triangle_[i], end_triangle = first_triangle_[i + 1];
    emit_vanes(shape, detail_, spine,
               VanesOut{vanes.positions.data() + first_vertex, vanes.uv_barb.data() + first_vertex,
                        vanes.uv_vane.data() + first_vertex, vanes.triangles.data() + first_triangle, first_vertex,
                        skin.origin});
    std::fill(vanes.triangle_feathers.begin() + first_triangle, vanes.triangle_feathers.begin() + end_triangle, ids_[i]);
    std::fill(vanes.triangle_templates.begin() + first_triangle, vanes.triangle_templates.begin() + end_triangle,
              templates_[i]);
    for (int64_t p = first_point; p < first_point_[i + 1]; ++p)
      finite = finite && curves.curves.positions[size_t(p)].allFinite();
  }
  if (!finite) throw InternalError("feathers: a feather point is not finite");
}

}  // namespace plume::feathers
