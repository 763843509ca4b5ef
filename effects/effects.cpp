#include "effects/effects.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>
#include <unordered_map>

#include "groom/error.h"
#include "skin/lanes.h"
#include "effects/noise.h"
#include "skin/skin_grid.h"
#include "skin/skin_guard.h"

namespace plume::effects {

using namespace skin;

namespace {

constexpr float kTwoPi = 6.28318530717958647692f;

// Salts that keep the random draws of one effect independent of each other.
constexpr uint64_t kSaltStray = 0x7374726179ull;       // "stray"
constexpr uint64_t kSaltFraction = 0x6672616374ull;    // "fract"
constexpr uint64_t kSaltLength = 0x6c656e677468ull;    // "length"
constexpr uint64_t kSaltPhase = 0x7068617365ull;       // "phase"
constexpr uint64_t kSaltOffset = 0x6f6666736574ull;    // "offset"

/// The shortest strand the length effect leaves, as a fraction of the strand's length before it.
constexpr float kMinLengthFraction = 0.05f;

float strand_param(int64_t j, int64_t n) { return float(j) / float(n - 1); }

/// Point of a polyline at index parameter t in [0, 1] (t * (n - 1) between points, linear).
Eigen::Vector3f sample_at(std::span<const Eigen::Vector3f> pts, float t, Eigen::Vector3f *r_direction) {
  const int64_t n = int64_t(pts.size());
  const float u = std::clamp(t, 0.0f, 1.0f) * float(n - 1);
  const int64_t k = std::min<int64_t>(int64_t(u), n - 2);
  const float a = u - float(k);
  if (r_direction) *r_direction = pts[k + 1] - pts[k];
  return pts[k] + a * (pts[k + 1] - pts[k]);
}

/// Point of a polyline at arc length `s` given its cumulative lengths `cum` (cum[0] = 0); past the
/// tip it continues straight along the last segment. `r_segment` is where the search starts, and is
/// left at the segment found: a strand sampled at growing `s` walks each segment once. It must not
/// be past the segment holding `s` (0 always works).
[[gnu::always_inline]] inline Eigen::Vector3f point_at_length(std::span<const Eigen::Vector3f> pts,
                                                               std::span<const float> cum, float s,
                                                               int64_t &r_segment) {
  const int64_t n = int64_t(pts.size());
  if (s >= cum[n - 1]) {
    const Eigen::Vector3f last = pts[n - 1] - pts[n - 2];
    const float seg = last.norm();
    return seg > 0.0f ? Eigen::Vector3f(pts[n - 1] + last * ((s - cum[n - 1]) / seg)) : pts[n - 1];
  }
  // The last point at or before s (past any zero-length segments there).
  int64_t k = r_segment;
  while (k + 1 < n && cum[k + 1] <= s) ++k;
  r_segment = k;
  const float seg = cum[k + 1] - cum[k];
  const float a = seg > 0.0f ? (s - cum[k]) / seg : 0.0f;
  return pts[k] + a * (pts[k + 1] - pts[k]);
}

/// v / |v| with one division instead of three (a zero vector stays zero).
Eigen::Vector3f unit(const Eigen::Vector3f &v) {
  const float length_sq = v.squaredNorm();
  return length_sq > 0.0f ? Eigen::Vector3f(v * (1.0f / std::sqrt(length_sq))) : v;
}

/// Sine and cosine of one angle, with skin/lanes.h's functions: no C library call, so the same
/// bits on every machine (as the stack promises).
void sin_cos(float x, float &r_sin, float &r_cos) {
  Float4 sine, cosine;
  sin_cos4(Float4{} + x, sine, cosine);
  r_sin = sine[0];
  r_cos = cosine[0];
}

/// Standard normal draw from two hashes (Box-Muller), with no C library call but the square root
/// (correctly rounded everywhere).
float normal_from_hash(uint64_t h) {
  const float u1 = std::max(hash_to_unit(h), 1e-7f);
  const float u2 = hash_to_unit(hash64(h));
  float sine = 0.0f, cosine = 0.0f;
  sin_cos(kTwoPi * u2, sine, cosine);
  return std::sqrt(-2.0f * log4(Float4{} + u1)[0]) * cosine;
}

/// Reads an emitter vertex map: one number in [0, 1] per line ('#' starts a comment, blank lines are
/// skipped), exactly `vertex_count` numbers.
std::vector<float> read_vertex_map(const std::string &path, size_t vertex_count, const FileLoc &effect_loc) {
  std::ifstream in(path);
  if (!in) throw InputError(effect_loc, "vertex_map: cannot open \"" + path + "\"");
  std::vector<float> values;
  values.reserve(vertex_count);
  std::string line;
  int line_number = 0;
  while (std::getline(in, line)) {
    ++line_number;
    const size_t hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos) continue;
    const size_t last = line.find_last_not_of(" \t\r");
    const std::string token = line.substr(first, last - first + 1);
    const FileLoc loc{path, line_number, int(first) + 1};
    size_t used = 0;
    float v = 0.0f;
    try {
      v = std::stof(token, &used);
    } catch (const std::exception &) {
      used = 0;
    }
    if (used != token.size()) throw InputError(loc, "expected one number per line, got \"" + token + "\"");
    if (!std::isfinite(v)) throw InputError(loc, "expected a finite number, got \"" + token + "\"");
    // A scale of the effect's strength, like amount and ramp: outside [0, 1] the strength could
    // turn a bounded twist or amplitude into angles and displacements beyond float arithmetic.
    if (!(v >= 0.0f && v <= 1.0f)) throw InputError(loc, "expected a number in [0, 1], got \"" + token + "\"");
    values.push_back(v);
  }
  if (values.size() != vertex_count)
    throw InputError(FileLoc{path, line_number, 0}, "expected " + std::to_string(vertex_count) +
                                                        " values (one per emitter vertex), got " +
                                                        std::to_string(values.size()));
  return values;
}

/// The strands in the order their roots arrive (Roots::arrival; ties, or roots without arrival
/// times, by id). Every subset of the roots that a proxy run or a lower count keeps is a prefix of
/// this order, so a choice made in this order from earlier strands only is the same in the subset.
std::vector<int32_t> arrival_order(const Roots &roots) {
  std::vector<int32_t> order(roots.size());
  std::iota(order.begin(), order.end(), 0);
  const bool timed = roots.arrival.size() == roots.size();
  std::sort(order.begin(), order.end(), [&](int32_t a, int32_t b) {
    if (timed && roots.arrival[a] != roots.arrival[b]) return roots.arrival[a] < roots.arrival[b];
    return roots.ids[a] < roots.ids[b];
  });
  return order;
}

/// Clump centres by greedy Poisson-disk selection over the rest root positions, in arrival order
/// (`order`): a strand becomes a centre when no earlier centre lies within `radius`, and otherwise
/// joins the nearest of the centres chosen before it (ties: smaller id). A strand's clump depends
/// only on strands that arrived before it, so adding roots never changes the clump of an existing
/// one, and it is the same on every frame.
std::vector<int32_t> poisson_clumps(const std::vector<Eigen::Vector3f> &rest_roots, const std::vector<uint64_t> &ids,
                                    const std::vector<int32_t> &order, float radius) {
  const size_t n = rest_roots.size();
  // Uniform grid of cell size `radius`: centres within `radius` of a point lie in its 27 neighbour cells.
  auto cell_of = [&](const Eigen::Vector3f &p) {
    return Eigen::Vector3i(int(std::floor(p.x() / radius)), int(std::floor(p.y() / radius)),
                           int(std::floor(p.z() / radius)));
  };
  auto key_of = [](const Eigen::Vector3i &c) {
    return (uint64_t(uint32_t(c.x()) & 0x1FFFFF) << 42) | (uint64_t(uint32_t(c.y()) & 0x1FFFFF) << 21) |
           uint64_t(uint32_t(c.z()) & 0x1FFFFF);
  };
  std::unordered_map<uint64_t, std::vector<int32_t>> grid;
  const float r2 = radius * radius;
  auto nearest_centre = [&](const Eigen::Vector3f &p) {
    const Eigen::Vector3i c = cell_of(p);
    int32_t best = -1;
    float best_d2 = r2;
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = grid.find(key_of(c + Eigen::Vector3i(dx, dy, dz)));
          if (it == grid.end()) continue;
          for (int32_t centre : it->second) {
            const float d2 = (rest_roots[centre] - p).squaredNorm();
            if (d2 < best_d2 || (d2 == best_d2 && best >= 0 && ids[centre] < ids[best])) {
              best = centre;
              best_d2 = d2;
            }
          }
        }
    return best;
  };
  std::vector<int32_t> centre_of(n, -1);
  for (int32_t i : order) {
    const int32_t c = nearest_centre(rest_roots[i]);
    if (c >= 0) {
      centre_of[i] = c;
    } else {
      centre_of[i] = i;
      grid[key_of(cell_of(rest_roots[i]))].push_back(i);
    }
  }
  return centre_of;
}

/// One clump per guide: the centre is the first strand, in arrival order (`order`), of those whose
/// nearest guide it is. Adding roots (which arrive later) never changes it.
std::vector<int32_t> guide_clumps(const std::vector<int32_t> &nearest_guide, const std::vector<int32_t> &order,
                                  size_t guide_count) {
  std::vector<int32_t> first(guide_count, -1);
  for (int32_t i : order) {
    const int32_t g = nearest_guide[i];
    if (g >= 0 && first[g] < 0) first[g] = i;
  }
  std::vector<int32_t> centre_of(nearest_guide.size(), -1);
  for (size_t i = 0; i < nearest_guide.size(); ++i)
    if (nearest_guide[i] >= 0) centre_of[i] = first[nearest_guide[i]];
  return centre_of;
}

/// Scratch arrays of one thread, reused from strand to strand (no allocation once grown).
struct Scratch {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> cum;
  std::vector<Eigen::Vector3f> guide_offsets;
  /// Curl's copies of a block's four strands and their points, tangents, arc lengths and squared
  /// segment lengths as lanes (see apply_curl).
  std::vector<Eigen::Vector3f> curl_points;
  std::vector<Float4> curl_lanes;
  /// Clump's twist angle's cosine and sine at each point of a strand.
  std::vector<float> twist_cos, twist_sin;
};

/// A strand's points laid out in r_copy[0 .. size) with one copy of the root before them and copies
/// of the tip after them (size >= pts.size() + 1), so that batches read the neighbours p_(j-1) and
/// p_(j+1) clamped at the ends without a test: point j is at index j + 1.
void pad_strand(std::span<const Eigen::Vector3f> pts, Eigen::Vector3f *r_copy, size_t size) {
  r_copy[0] = pts[0];
  std::copy(pts.begin(), pts.end(), r_copy + 1);
  std::fill(r_copy + 1 + pts.size(), r_copy + size, pts.back());
}

/// A strand's points padded (pad_strand) in scratch.points, with at least 5 copies of the tip: four-
/// point batches read past it.
const Eigen::Vector3f *padded_copy(std::span<const Eigen::Vector3f> pts, Scratch &scratch) {
  scratch.points.resize(((pts.size() + 3) & ~size_t(3)) + 6);
  pad_strand(pts, scratch.points.data(), scratch.points.size());
  return scratch.points.data();
}

/// Four consecutive points as lanes: r_axes[a][l] is coordinate a of points[l].
void load_lanes(const Eigen::Vector3f *points, Float4 r_axes[3]) {
  Float4 a, b, c;  // x0 y0 z0 x1 | y1 z1 x2 y2 | z2 x3 y3 z3
  const float *f = points->data();
  std::memcpy(&a, f, sizeof a);
  std::memcpy(&b, f + 4, sizeof b);
  std::memcpy(&c, f + 8, sizeof c);
  r_axes[0] = __builtin_shuffle(__builtin_shuffle(a, b, Int4{0, 3, 6, 0}), c, Int4{0, 1, 2, 5});
  r_axes[1] = __builtin_shuffle(__builtin_shuffle(a, b, Int4{1, 4, 7, 0}), c, Int4{0, 1, 2, 6});
  r_axes[2] = __builtin_shuffle(__builtin_shuffle(a, b, Int4{2, 5, 0, 0}), c, Int4{0, 1, 4, 7});
}

/// The inverse of load_lanes: coordinate a of points[l] from axes[a][l].
void store_lanes(const Float4 axes[3], Eigen::Vector3f *points) {
  const Float4 xy_low = __builtin_shufflevector(axes[0], axes[1], 0, 4, 1, 5);   // x0 y0 x1 y1
  const Float4 xy_high = __builtin_shufflevector(axes[0], axes[1], 2, 6, 3, 7);  // x2 y2 x3 y3
  const Float4 a = __builtin_shufflevector(xy_low, axes[2], 0, 1, 4, 2);        // x0 y0 z0 x1
  const Float4 b = __builtin_shufflevector(__builtin_shufflevector(xy_low, axes[2], 3, 5, 0, 0), xy_high, 0, 1, 4,
                                           5);                                  // y1 z1 x2 y2
  const Float4 c = __builtin_shufflevector(axes[2], xy_high, 2, 6, 7, 3);       // z2 x3 y3 z3
  float *f = points->data();
  std::memcpy(f, &a, sizeof a);
  std::memcpy(f + 4, &b, sizeof b);
  std::memcpy(f + 8, &c, sizeof c);
}

/// Four floats from memory (any alignment).
Float4 load_lane(const float *f) {
  Float4 v;
  std::memcpy(&v, f, sizeof v);
  return v;
}

/// Arc length at each point of a polyline (r_cum[0] = 0), the segment lengths four at a time.
void cumulative_lengths(std::span<const Eigen::Vector3f> pts, std::vector<float> &r_cum) {
  const size_t n = pts.size();
  r_cum.resize(n);
  r_cum[0] = 0.0f;
  size_t j = 1;
  for (; j + 4 <= n; j += 4) {
    Float4 from[3], to[3];
    load_lanes(pts.data() + j - 1, from);
    load_lanes(pts.data() + j, to);
    for (int a = 0; a < 3; ++a) to[a] -= from[a];
    const Float4 length = lane_sqrt(dot_lanes(to, to));
    for (size_t l = 0; l < 4; ++l) r_cum[j + l] = r_cum[j + l - 1] + length[l];
  }
  for (; j < n; ++j) r_cum[j] = r_cum[j - 1] + (pts[j] - pts[j - 1]).norm();
}

/// The points of a guide at the parameters of a strand of `count` points (j / (count - 1) of the
/// guide's length, whose cumulative lengths are `cum`), as offsets from the guide's first point.
void guide_offsets_at(std::span<const Eigen::Vector3f> guide, std::span<const float> cum, int64_t count,
                      Eigen::Vector3f *r_offsets) {
  int64_t segment = 0;
  for (int64_t j = 0; j < count; ++j)
    r_offsets[j] = point_at_length(guide, cum, strand_param(j, count) * cum.back(), segment) - guide[0];
}

/// An effect's ramp at the points of a strand, tabulated once per frame for the point count that
/// grown strands share; strands of other counts evaluate the ramp itself (same values).
struct RampSamples {
  const Ramp *ramp = nullptr;
  int64_t count = 0;
  /// The ramp at strand_param(j, count), j < count, then three zeros (a batch of four read past the tip).
  std::vector<float> values;

  RampSamples(const Ramp &r, int64_t point_count) : ramp(&r), count(point_count), values(size_t(point_count + 3)) {
    for (int64_t j = 0; j < count; ++j) values[size_t(j)] = r.at(strand_param(j, count));
  }
  /// The ramp at point j of a strand of n points.
  float at(int64_t j, int64_t n) const { return n == count ? values[size_t(j)] : ramp->at(strand_param(j, n)); }
  /// The ramp at points j .. j + 3 (j < n) of a strand of n points; lanes past the tip are unspecified.
  Float4 at4(int64_t j, int64_t n) const {
    if (n == count) return load_lane(values.data() + j);
    Float4 r;
    for (int64_t l = 0; l < 4; ++l) r[l] = at(std::min(j + l, n - 1), n);
    return r;
  }
};

}  // namespace

struct EffectStack::Prepared {
  EffectDesc desc;
  /// One per strand: amount x face-group mask x vertex map x (stray / fraction selection); 0 = untouched.
  std::vector<float> strength;
  /// Clumps only: one per strand, the index of its centre strand (-1: none).
  std::vector<int32_t> centre_of;
  /// Clumps only: the centre strands some strand is pulled toward (each once), and per strand the
  /// index of its centre in that list (-1: not pulled).
  std::vector<int32_t> centres;
  std::vector<int32_t> centre_slot;
  SimplexNoise3 noise;

  explicit Prepared(const EffectDesc &d) : desc(d), noise(d.seed) {}
};

/// Kept from one apply() to the next: the copy of the grown strands (tens of megabytes, which a
/// fresh allocation would fault in page by page every frame). One apply at a time uses it; a
/// concurrent one allocates its own.
struct EffectStack::FrameBuffers {
  std::mutex mutex;
  std::vector<Eigen::Vector3f> grown_positions;
};

EffectStack::EffectStack(const std::vector<EffectDesc> &effects, const Mesh &rest_mesh, const Roots &roots,
                         const Guides &guides, const std::vector<int32_t> &nearest_guide)
    : root_points_(roots.points),
      ids_(roots.ids),
      nearest_guide_(nearest_guide),
      guide_roots_(guides.roots),
      buffers_(std::make_unique<FrameBuffers>()) {
  const size_t n = roots.size();
  if (nearest_guide.size() != n || ids_.size() != n)
    throw InternalError("EffectStack: one id and one nearest guide per root expected");
  for (int32_t g : nearest_guide)
    if (g >= int32_t(guides.size())) throw InternalError("EffectStack: nearest guide out of range");

  rest_frames_.resize(n);
  std::vector<Eigen::Vector3f> rest_roots(n);
  for (size_t i = 0; i < n; ++i) {
    rest_frames_[i] = surface_frame(rest_mesh, root_points_[i]);
    rest_roots[i] = rest_frames_[i].origin;
  }

  std::vector<int32_t> order;  // the strands in arrival order, once a clump needs it
  for (const EffectDesc &desc : effects) {
    Prepared prepared(desc);
    const uint64_t seed = desc.seed;
    std::vector<float> &strength = prepared.strength;
    strength.assign(n, desc.amount);

    if (!desc.groups.empty()) {
      std::vector<bool> in_group(rest_mesh.group_names.size(), false);
      for (const std::string &name : desc.groups) {
        const int g = rest_mesh.group_index(name);
        if (g < 0)
          throw InputError(desc.groups_loc.file.empty() ? desc.loc : desc.groups_loc,
                           desc.groups_key + ": no face group \"" + name + "\" in the emitter (groups: " +
                               rest_mesh.group_list() + ")");
        in_group[g] = true;
      }
      for (size_t i = 0; i < n; ++i)
        if (!in_group[rest_mesh.triangle_groups[root_points_[i].triangle]]) strength[i] = 0.0f;
    }
    if (!desc.vertex_map_path.empty()) {
      const std::vector<float> map = read_vertex_map(desc.vertex_map_path, rest_mesh.vertex_count(), desc.loc);
      for (size_t i = 0; i < n; ++i) strength[i] *= surface_value(rest_mesh, map, root_points_[i]);
    }

    switch (desc.type) {
      case EffectType::clump: {
        if (order.empty()) order = arrival_order(roots);
        if (desc.clump_centers == EffectDesc::ClumpCenters::per_guide) {
          prepared.centre_of = guide_clumps(nearest_guide, order, guides.size());
        } else {
          if (!(desc.clump_radius > 0.0f)) throw InputError(desc.loc, "clump_radius: expected a positive number");
          prepared.centre_of = poisson_clumps(rest_roots, ids_, order, desc.clump_radius);
        }
        for (size_t i = 0; i < n; ++i) {
          const int32_t c = prepared.centre_of[i];
          // Centres are never written by their own clump pass (members read them concurrently).
          if (c < 0 || c == int32_t(i)) strength[i] = 0.0f;
          if (hash_to_unit(hash_combine(hash_combine(seed, kSaltStray), ids_[i])) < desc.stray_fraction)
            strength[i] = 0.0f;
        }
        std::vector<int32_t> slot_of_centre(n, -1);
        prepared.centre_slot.assign(n, -1);
        for (size_t i = 0; i < n; ++i) {
          if (strength[i] == 0.0f) continue;
          int32_t &slot = slot_of_centre[size_t(prepared.centre_of[i])];
          if (slot < 0) {
            slot = int32_t(prepared.centres.size());
            prepared.centres.push_back(prepared.centre_of[i]);
          }
          prepared.centre_slot[i] = slot;
        }
        break;
      }
      case EffectType::tension:
        for (size_t i = 0; i < n; ++i)
          if (nearest_guide[i] < 0) strength[i] = 0.0f;
        break;
      case EffectType::length:
        break;
      case EffectType::wave:
      case EffectType::frizz:
      case EffectType::curl:
        for (size_t i = 0; i < n; ++i)
          if (hash_to_unit(hash_combine(hash_combine(seed, kSaltFraction), ids_[i])) >= desc.fraction)
            strength[i] = 0.0f;
        break;
    }
    effects_.push_back(std::move(prepared));
  }
}

EffectStack::~EffectStack() = default;
EffectStack::EffectStack(EffectStack &&) noexcept = default;
EffectStack &EffectStack::operator=(EffectStack &&) noexcept = default;

bool EffectStack::empty() const { return effects_.empty(); }

const std::vector<int32_t> &EffectStack::clump_centres(size_t effect) const { return effects_.at(effect).centre_of; }

namespace {

/// The unit direction of a centre strand's segment at each of its `count` point indices (the segment
/// starting there, the last one at the tip; zero for a zero-length segment), shared by all the
/// strands of its clump.
void centre_axes(std::span<const Eigen::Vector3f> centre, Eigen::Vector3f *r_axes) {
  const int64_t n = int64_t(centre.size());
  for (int64_t j = 0; j < n; ++j) {
    const int64_t k = std::min(j, n - 2);
    r_axes[j] = unit(centre[size_t(k + 1)] - centre[size_t(k)]);
  }
}

/// Clump: d = P - C (C the centre strand at the same parameter t) becomes R(theta) (1 - w) d with
/// w = strength * ramp(t) clamped to [0, 1] and R a rotation about the centre's tangent by
/// theta = 2 pi * twist * strength * t. The centre strand is read as earlier effects left it.
///
/// `unit_axes`: when the centre has as many points as the strand, its unit segment directions at
/// each point index (see centre_axes), else null. Such strands are moved four points at a time in
/// lanes, each lane with the operations of one point, so with the same bits.
void apply_clump(const EffectStack::Prepared &e, const RampSamples &ramp, size_t i, const StrandSet &strands,
                 const Eigen::Vector3f *unit_axes, std::span<Eigen::Vector3f> pts, Scratch &scratch) {
  const float s = e.strength[i];
  const std::span<const Eigen::Vector3f> centre = strands.points(size_t(e.centre_of[i]));
  const int64_t n = int64_t(pts.size());
  const bool same_count = unit_axes && centre.size() == pts.size();
  // theta grows by the same angle from point to point: its cosine and sine follow by the
  // angle-addition formulas, one rotation of (cos, sin) per point instead of two calls.
  const float step_angle = kTwoPi * e.desc.clump_twist * s / float(n - 1);
  float cos_step = 1.0f, sin_step = 0.0f;
  sin_cos(step_angle, sin_step, cos_step);
  std::vector<float> &twist_cos = scratch.twist_cos, &twist_sin = scratch.twist_sin;
  twist_cos.resize(size_t(n));
  twist_sin.resize(size_t(n));
  float cos_theta = 1.0f, sin_theta = 0.0f;
  for (int64_t j = 1; j < n; ++j) {
    const float cos_next = cos_theta * cos_step - sin_theta * sin_step;
    sin_theta = sin_theta * cos_step + cos_theta * sin_step;
    cos_theta = cos_next;
    twist_cos[size_t(j)] = cos_theta;
    twist_sin[size_t(j)] = sin_theta;
  }
  int64_t j = 1;
  if (same_count)
    for (; j + 4 <= n; j += 4) {
      Float4 p[3], c[3], a[3], d[3];
      load_lanes(pts.data() + j, p);
      load_lanes(centre.data() + j, c);
      load_lanes(unit_axes + j, a);
      const Float4 weight = s * ramp.at4(j, n);
      const Float4 w = weight < 0.0f ? Float4{} : (1.0f < weight ? Float4{} + 1.0f : weight);  // std::clamp
      for (int k = 0; k < 3; ++k) d[k] = (1.0f - w) * (p[k] - c[k]);
      if (step_angle != 0.0f) {
        // Rodrigues' formula as below, with Eigen's cross and dot products' operations.
        const Float4 cos4 = load_lane(twist_cos.data() + j), sin4 = load_lane(twist_sin.data() + j);
        const Float4 cross[3] = {a[1] * d[2] - a[2] * d[1], a[2] * d[0] - a[0] * d[2], a[0] * d[1] - a[1] * d[0]};
        const Float4 along = (1.0f - cos4) * dot_lanes(a, d);
        const Int4 has_axis = dot_lanes(a, a) > 0.0f;
        for (int k = 0; k < 3; ++k) d[k] = has_axis ? cos4 * d[k] + sin4 * cross[k] + along * a[k] : d[k];
      }
      for (int k = 0; k < 3; ++k) p[k] = c[k] + d[k];
      store_lanes(p, pts.data() + j);
    }
  for (; j < n; ++j) {
    // The centre at the same parameter, and its segment there: point j itself when the counts match.
    Eigen::Vector3f axis, c;
    if (same_count) {
      c = centre[size_t(j)];
      axis = unit_axes[j];
    } else {
      c = sample_at(centre, strand_param(j, n), &axis);
      axis = unit(axis);
    }
    const float w = std::clamp(s * ramp.at(j, n), 0.0f, 1.0f);
    Eigen::Vector3f d = (1.0f - w) * (pts[j] - c);
    if (step_angle != 0.0f && axis.squaredNorm() > 0.0f) {
      // Rodrigues' formula on d alone (no matrix), about the unit axis.
      const Eigen::Vector3f &a = axis;
      d = twist_cos[size_t(j)] * d + twist_sin[size_t(j)] * a.cross(d) + ((1.0f - twist_cos[size_t(j)]) * a.dot(d)) * a;
    }
    pts[j] = c + d;
  }
}

/// Tension: the target is the nearest guide carried to the strand's root (minimal rotation taking the
/// guide root's normal to the root's normal, offsets scaled to the strand's length, sampled at the same
/// arc-length fraction); each point moves toward it by w = strength * ramp(t).
///
/// `guide_offsets`: the guide at the strand's point parameters, from its first point (see
/// guide_offsets_at), of `guide_length`; `rotation`: the minimal rotation above.
void apply_tension(const EffectStack::Prepared &e, const RampSamples &ramp, size_t i,
                   std::span<const Eigen::Vector3f> guide_offsets, float guide_length,
                   const Eigen::Matrix3f &rotation, std::span<Eigen::Vector3f> pts, Scratch &scratch) {
  const float s = e.strength[i];
  const int64_t n = int64_t(pts.size());
  cumulative_lengths(pts, scratch.cum);
  const float length = scratch.cum[n - 1];
  if (!(guide_length > 0.0f)) return;
  const float scale = length / guide_length;
  const Eigen::Vector3f root = pts[0];
  for (int64_t j = 1; j < n; ++j) {
    const Eigen::Vector3f target = root + rotation * (guide_offsets[size_t(j)] * scale);
    const float w = std::clamp(s * ramp.at(j, n), 0.0f, 1.0f);
    pts[j] += w * (target - pts[j]);
  }
}

/// Length: target L' = L + strength * (min(L * f, max_length, L_cut) - L), f = 1 + variation * X with X
/// uniform in [-1, 1] or standard normal, hashed from the id; L' >= 5% of L. The strand is then
/// resampled evenly by arc length over [0, L'], continuing straight past the tip when it grows.
void apply_length(const EffectStack::Prepared &e, size_t i, uint64_t id, const SurfaceFrame &rest_frame,
                  const SurfaceFrame &posed_frame, std::span<Eigen::Vector3f> pts, Scratch &scratch) {
  const EffectDesc &d = e.desc;
  const float s = e.strength[i];
  const int64_t n = int64_t(pts.size());
  scratch.points.assign(pts.begin(), pts.end());
  cumulative_lengths(scratch.points, scratch.cum);
  const float length = scratch.cum[n - 1];
  if (!(length > 0.0f)) return;

  const uint64_t h = hash_combine(hash_combine(d.seed, kSaltLength), id);
  const float x = d.length_distribution == EffectDesc::LengthDistribution::normal ? normal_from_hash(h)
                                                                                  : 2.0f * hash_to_unit(h) - 1.0f;
  float target = length * (1.0f + d.length_variation * x);
  if (d.max_length > 0.0f) target = std::min(target, d.max_length);
  if (d.cut_plane) {
    // The plane is given in rest-pose coordinates: test the strand as it sits in its root's rest frame,
    // so the cut does not slide along the hair when the head moves.
    auto side = [&](const Eigen::Vector3f &p) {
      return (rest_frame.to_world(posed_frame.to_local(p)) - d.cut_point).dot(d.cut_normal);
    };
    float previous = side(scratch.points[0]);
    float cut = previous > 0.0f ? 0.0f : length;
    for (int64_t j = 1; j < n && cut == length && previous <= 0.0f; ++j) {
      const float current = side(scratch.points[j]);
      if (current > 0.0f) cut = scratch.cum[j - 1] + (scratch.cum[j] - scratch.cum[j - 1]) * (-previous / (current - previous));
      previous = current;
    }
    target = std::min(target, cut);
  }
  float new_length = length + s * (target - length);
  new_length = std::max(new_length, kMinLengthFraction * length);
  if (new_length == length) return;
  int64_t segment = 0;
  for (int64_t j = 1; j < n; ++j)
    pts[j] = point_at_length(scratch.points, scratch.cum, new_length * strand_param(j, n), segment);
}

/// Wave and frizz: each point p (root excluded) is expressed in its root's rest frame, q = R_rest (F_posed^-1 p);
/// the displacement amplitude * strength * ramp(t) * noise(frequency * q + offset) is taken back to the posed
/// frame and made perpendicular to the strand. Frizz adds a per-strand offset in the noise field, so
/// neighbouring strands frizz independently; waves stay coherent between neighbours.
void apply_noise(const EffectStack::Prepared &e, const RampSamples &ramp, size_t i, uint64_t id,
                 const SurfaceFrame &rest_frame,
                 const SurfaceFrame &posed_frame, std::span<Eigen::Vector3f> pts, Scratch &scratch) {
  const EffectDesc &d = e.desc;
  const float amplitude = d.amplitude * e.strength[i];
  const int64_t n = int64_t(pts.size());
  Eigen::Vector3f offset = Eigen::Vector3f::Zero();
  if (d.type == EffectType::frizz) {
    const uint64_t h = hash_combine(hash_combine(d.seed, kSaltOffset), id);
    offset = Eigen::Vector3f(hash_to_unit(h), hash_to_unit(hash64(h)), hash_to_unit(hash64(h + 1))) * 256.0f;
  }
  // posed = posed_frame.basis * (rest_frame.basis^T (rest - rest_origin)) + posed_origin, so the noise
  // coordinates frequency * rest + offset are one affine map of the posed point: A p + b.
  const Eigen::Matrix3f rest_to_posed = posed_frame.basis * rest_frame.basis.transpose();
  const Eigen::Matrix3f to_noise = d.frequency * rest_to_posed.transpose();
  const Eigen::Vector3f noise_origin = d.frequency * rest_frame.origin + offset - to_noise * posed_frame.origin;
  Float4 to_noise4[3][3], rest_to_posed4[3][3], origin4[3];
  for (int r = 0; r < 3; ++r) {
    origin4[r] = Float4{} + noise_origin[r];
    for (int c = 0; c < 3; ++c) {
      to_noise4[r][c] = Float4{} + to_noise(r, c);
      rest_to_posed4[r][c] = Float4{} + rest_to_posed(r, c);
    }
  }
  // A matrix times a vector, lane by lane, each row added as Eigen adds a Vector3f product's.
  auto times = [](const Float4 m[3][3], const Float4 v[3], Float4 r_product[3]) {
    for (int r = 0; r < 3; ++r) r_product[r] = dot_lanes(m[r], v);
  };
  // Four points at a time (SIMD lanes); lanes past the tip repeat the tip and are not written.
  const Eigen::Vector3f *q = padded_copy(pts, scratch);
  for (int64_t batch = 1; batch < n; batch += 4) {
    Float4 prev[3], cur[3], next[3];
    load_lanes(q + batch, prev);
    load_lanes(q + batch + 1, cur);
    load_lanes(q + batch + 2, next);
    Float4 at[3], noise[3];
    times(to_noise4, cur, at);
    for (int r = 0; r < 3; ++r) at[r] += origin4[r];
    e.noise.vector_at4(at, noise);
    const Float4 a = amplitude * ramp.at4(batch, n);
    for (int c = 0; c < 3; ++c) noise[c] = a * noise[c];
    Float4 disp[3], chord[3];
    times(rest_to_posed4, noise, disp);
    // Perpendicular to the strand: the part along the chord through the neighbours removed (one
    // division; no square root).
    for (int r = 0; r < 3; ++r) chord[r] = next[r] - prev[r];
    const Float4 chord_sq = dot_lanes(chord, chord);
    const Float4 along = dot_lanes(chord, disp) / chord_sq;
    const Int4 has_chord = chord_sq > 0.0f;
    for (int r = 0; r < 3; ++r) cur[r] += has_chord ? disp[r] - chord[r] * along : disp[r];
    for (int64_t l = 0; l < 4 && batch + l < n; ++l)
      if (a[l] != 0.0f) pts[size_t(batch + l)] = Eigen::Vector3f(cur[0][l], cur[1][l], cur[2][l]);
  }
}

/// Curl: a helix around the strand. A rotation-minimising frame (U, V) is carried along the strand by
/// double reflection (Wang et al. 2008) from U_0 = the root's surface tangent made perpendicular to the
/// first tangent; point j moves by radius * strength * ramp(t) * (cos phi U + sin phi V) with
/// phi = phi_0 + 2 pi * turns_per_unit * s_j (s_j arc length, phi_0 hashed from the id).
///
/// The frame is carried from point to point, a chain that four points of one strand cannot share:
/// the (up to four) strands of a block go through it together instead, one strand per SIMD lane, every
/// lane doing the operations of one strand alone. `count` <= 4 strands starting at strand `first` of
/// r_strands; those of zero strength are left as they are. posed_frames[s] is strand first + s's root
/// frame (read when its strength is not zero).
void apply_curl(const EffectStack::Prepared &e, const RampSamples &ramp, int64_t first, int64_t count,
                const std::vector<uint64_t> &ids, const SurfaceFrame *posed_frames, StrandSet &r_strands,
                Scratch &scratch) {
  const EffectDesc &d = e.desc;
  int64_t longest = 0;
  Int4 point_count{};  // per lane; 0 for a strand left alone, so that no point of it is written
  for (int64_t s = 0; s < count; ++s)
    if (e.strength[size_t(first + s)] != 0.0f) {
      point_count[s] = int32_t(r_strands.points_in(size_t(first + s)));
      longest = std::max(longest, int64_t(point_count[s]));
    }
  if (longest == 0) return;
  // Each lane's strand as pad_strand lays it out (point j at index j + 1, the root repeated before,
  // the tip after), read at longest + 2 indices; lanes left alone read a moved strand of the block.
  const size_t stride = size_t(longest + 8);
  scratch.curl_points.resize(4 * stride);
  Eigen::Vector3f *copies = scratch.curl_points.data();
  int64_t source[4];
  for (int64_t s = 0; s < 4; ++s) source[s] = s < count && point_count[s] > 0 ? first + s : -1;
  for (int64_t s = 0; s < 4; ++s)
    if (source[s] < 0) source[s] = *std::max_element(source, source + 4);
  for (int64_t s = 0; s < 4; ++s) pad_strand(r_strands.points(size_t(source[s])), copies + size_t(s) * stride, stride);
  // q[k][a]: coordinate a of index k of the four copies, one per lane (a 4 x 4 transpose of each
  // point read with the float after it).
  const size_t index_count = size_t(longest + 2);
  scratch.curl_lanes.resize(index_count * 8);
  Float4(*q)[3] = reinterpret_cast<Float4(*)[3]>(scratch.curl_lanes.data());
  Float4(*tangents)[3] = q + index_count;
  Float4 *cum = reinterpret_cast<Float4 *>(tangents + index_count);
  Float4 *c1s = cum + index_count;
  for (size_t k = 0; k < index_count; ++k) {
    Float4 rows[4];
    for (size_t s = 0; s < 4; ++s) rows[s] = load_lane(copies[s * stride + k].data());
    Float4 lanes[4];
    transpose4(rows, lanes);
    for (int a = 0; a < 3; ++a) q[k][a] = lanes[a];
  }
  // Per point j: the unit tangent (central difference inside, one-sided at the ends), the squared
  // length c1 of the segment from point j - 1, and the arc length.
  for (int64_t j = 0; j < longest; ++j) {
    Float4 chord[3], v1[3];
    for (int a = 0; a < 3; ++a) {
      chord[a] = q[j + 2][a] - q[j][a];
      v1[a] = q[j + 1][a] - q[j][a];
    }
    const Float4 chord_sq = dot_lanes(chord, chord);
    const Float4 inverse = 1.0f / lane_sqrt(chord_sq);
    const Int4 nonzero = chord_sq > 0.0f;
    for (int a = 0; a < 3; ++a) tangents[j][a] = nonzero ? chord[a] * inverse : chord[a];
    c1s[j] = dot_lanes(v1, v1);
    cum[j] = j == 0 ? Float4{} : cum[j - 1] + lane_sqrt(c1s[j]);
  }
  // Past 1000 turns along the strand the helix angle would leave the range where sin_cos4 is accurate
  // (|x| < 1e4) and, far beyond, overflow its quadrant integer: such a strand takes each point's
  // turn count modulo one (the same helix). Every other strand keeps the direct product's bits.
  Float4 phase0{}, radius{};
  int wrap_turns = 0;
  Float4 u[3] = {Float4{} + 1.0f, Float4{}, Float4{}};
  for (int64_t s = 0; s < count; ++s) {
    const size_t i = size_t(first + s);
    if (point_count[s] == 0) continue;
    phase0[s] = kTwoPi * hash_to_unit(hash_combine(hash_combine(d.seed, kSaltPhase), ids[i]));
    radius[s] = d.curl_radius * e.strength[i];
    const float tip_length = cum[point_count[s] - 1][s];
    if (d.turns_per_unit * tip_length > 1000.0f) wrap_turns |= 1 << s;
    const Eigen::Vector3f t0(tangents[0][0][s], tangents[0][1][s], tangents[0][2][s]);
    const Eigen::Matrix3f &basis = posed_frames[s].basis;
    Eigen::Vector3f u0 = basis.col(0) - t0 * t0.dot(basis.col(0));
    if (u0.squaredNorm() < 1e-12f) u0 = t0.unitOrthogonal();
    u0 = unit(u0);
    for (int a = 0; a < 3; ++a) u[a][s] = u0[a];
  }
  // The ramp's table serves every lane whose strand has the tabulated point count.
  const bool same_ramp = lane_bits((point_count == int32_t(ramp.count)) | (point_count == 0)) == 15;
  for (int64_t j = 1; j < longest; ++j) {
    Float4 phi = phase0 + kTwoPi * d.turns_per_unit * cum[j];
    for (int s = 0; s < 4; ++s)
      if (wrap_turns >> s & 1) {
        const float turns = d.turns_per_unit * cum[j][s];
        phi[s] = phase0[s] + kTwoPi * (turns - std::floor(turns));
      }
    Float4 sine, cosine;
    sin_cos4(phi, sine, cosine);
    // Double reflection: reflect (u, t) in the bisecting plane of the segment v1, then in the plane
    // that takes the reflected tangent t_l onto the new one, along v2 = t_j - t_l. Reflections keep
    // lengths and angles, so u stays a unit vector perpendicular to the tangent (to rounding: about
    // 1e-7 per point) without normalising it again.
    const Float4(&t_prev)[3] = tangents[j - 1];
    const Float4(&t)[3] = tangents[j];
    Float4 v1[3], v2[3], reflected[3], twice[3];
    for (int a = 0; a < 3; ++a) v1[a] = q[j + 1][a] - q[j][a];
    const Float4 k1 = 2.0f / c1s[j];
    const Float4 along_t = k1 * dot_lanes(v1, t_prev);
    for (int a = 0; a < 3; ++a) v2[a] = t[a] - (t_prev[a] - along_t * v1[a]);
    const Float4 c2 = dot_lanes(v2, v2);
    const Float4 along = k1 * dot_lanes(v1, u);
    for (int a = 0; a < 3; ++a) reflected[a] = u[a] - along * v1[a];
    const Float4 across = (2.0f / c2) * dot_lanes(v2, reflected);
    for (int a = 0; a < 3; ++a) twice[a] = reflected[a] - across * v2[a];
    // A zero-length segment leaves u as it is; a second plane too thin to reflect in, after the first.
    const Int4 first_plane = c1s[j] > 0.0f, second_plane = c2 > 1e-12f;
    for (int a = 0; a < 3; ++a) u[a] = first_plane ? (second_plane ? twice[a] : reflected[a]) : u[a];
    Float4 fraction;
    if (same_ramp) {
      fraction = Float4{} + ramp.values[size_t(j)];
    } else {
      for (int s = 0; s < 4; ++s) fraction[s] = point_count[s] > j ? ramp.at(j, point_count[s]) : 0.0f;
    }
    const Float4 r = radius * fraction;
    const int written = lane_bits((Int4{} + int32_t(j) < point_count) & (r != 0.0f));
    if (written == 0) continue;
    // v = t x u; the point moves by r (cos phi u + sin phi v).
    const Float4 v[3] = {t[1] * u[2] - t[2] * u[1], t[2] * u[0] - t[0] * u[2], t[0] * u[1] - t[1] * u[0]};
    Float4 moved[3];
    for (int a = 0; a < 3; ++a) moved[a] = q[j + 1][a] + r * (cosine * u[a] + sine * v[a]);
    for (int s = 0; s < 4; ++s)
      if (written >> s & 1)
        r_strands.positions[size_t(r_strands.offsets[size_t(first + s)] + j)] =
            Eigen::Vector3f(moved[0][s], moved[1][s], moved[2][s]);
  }
}

}  // namespace

void EffectStack::apply(const Mesh &posed_mesh, const MeshQuery &posed_query, const StrandSet &guides_this_frame,
                        float skin_margin, StrandSet &r_strands, std::span<const float> clearance,
                        const SkinGrid *skin_grid) const {
  const int64_t n = int64_t(r_strands.strand_count());
  if (size_t(n) != ids_.size() || r_strands.ids != ids_)
    throw InternalError("EffectStack::apply: strands do not match the roots (count, order or ids)");
  for (int64_t i = 0; i < n; ++i)
    if (r_strands.points_in(size_t(i)) < 2) throw InternalError("EffectStack::apply: a strand has fewer than 2 points");

  if (effects_.empty()) return;
  // Each effect's ramp at the points of a strand of the first strand's count (all, when grown).
  std::vector<RampSamples> ramps;
  for (const Prepared &e : effects_) ramps.emplace_back(e.desc.ramp, n > 0 ? r_strands.points_in(0) : 2);
  // The strands as growth left them, for the skin pass at the end, in the kept buffer unless
  // another frame's apply holds it.
  std::unique_lock<std::mutex> buffers_lock;
  std::vector<Eigen::Vector3f> own_buffer;
  std::vector<Eigen::Vector3f> *grown_buffer = &own_buffer;
  if (buffers_) {
    buffers_lock = std::unique_lock<std::mutex>(buffers_->mutex, std::try_to_lock);
    if (buffers_lock.owns_lock()) grown_buffer = &buffers_->grown_positions;
  }
  std::vector<Eigen::Vector3f> &grown_positions = *grown_buffer;
  grown_positions.resize(r_strands.positions.size());  // filled strand by strand by the first pass

  // Tension needs each guide's arc lengths and posed root normal once per frame.
  const bool any_tension = std::any_of(effects_.begin(), effects_.end(),
                                       [](const Prepared &e) { return e.desc.type == EffectType::tension; });
  // Per guide: arc lengths, its length, its posed root normal, and its points at the parameters of
  // a strand of the common point count (all strands share them: looked up, not searched, per strand).
  const int64_t common_count = ramps.front().count;
  std::vector<float> guide_cum, guide_lengths;
  std::vector<Eigen::Vector3f> guide_normals, guide_offsets;
  if (any_tension) {
    if (guides_this_frame.strand_count() != guide_roots_.size())
      throw InternalError("EffectStack::apply: guide count differs from the binding");
    guide_cum.resize(guides_this_frame.point_count());
    guide_offsets.resize(guide_roots_.size() * size_t(common_count));
    std::vector<float> cum;
    for (size_t g = 0; g < guide_roots_.size(); ++g) {
      cumulative_lengths(guides_this_frame.points(g), cum);
      std::copy(cum.begin(), cum.end(), guide_cum.begin() + guides_this_frame.offsets[g]);
      guide_lengths.push_back(cum.back());
      guide_normals.push_back(surface_normal(posed_mesh, guide_roots_[g]));
      guide_offsets_at(guides_this_frame.points(g), cum, common_count, guide_offsets.data() + g * size_t(common_count));
    }
  }

  // The signed distance is 1-Lipschitz, sd(p') >= sd(p) - |p' - p|: a point the stack moved by less than
  // its clearance minus the margin is still outside by the margin, and the guard is only told so. The
  // others go through growth's skin guard (skin/skin_guard.h): the same bound from the last known
  // point, then the grid's block bound and a local search started from the last closest triangle (the
  // root's at first), and a push along the normal to the margin when closer.
  if (!clearance.empty() && clearance.size() != r_strands.positions.size())
    throw InternalError("EffectStack::apply: clearance count differs from the point count");
  std::optional<SkinGrid> own_grid;
  if (!skin_grid) own_grid.emplace(posed_mesh, posed_query);
  const SkinGrid &grid = skin_grid ? *skin_grid : *own_grid;
  const float scale = mesh_scale(posed_mesh);
  auto keep_out_of_skin = [&](int64_t i, std::span<Eigen::Vector3f> pts) {
    const size_t first = size_t(r_strands.offsets[i]);
    const Eigen::Vector3f *grown = grown_positions.data() + first;
    const int64_t count = int64_t(pts.size());
    SkinGuard guard(posed_query, skin_margin, scale, &grid);
    guard.start(pts[0], root_points_[i].triangle);  // the root never moves and lies on the skin
    // Four points at a time, the proof that needs no search: moved by at most before - margin, still
    // outside by the margin. The guard is told the grown point and its bound, from which its next
    // bounds follow at least as well as from this point (triangle inequality), with no square root
    // here; of a run of such points only the last one's matters (each replaces what the guard knew).
    // Moving a point changes no later point's test, so a batch is tested before any point of it moves.
    for (int64_t batch = 1; batch < count; batch += 4) {
      const int64_t lanes = std::min<int64_t>(4, count - batch);
      Float4 before = Float4{} + skin_margin, moved_sq = Float4{} + INFINITY;  // lanes past the end: never proven
      if (lanes == 4) {
        Float4 moved[3], from[3];
        load_lanes(pts.data() + batch, moved);
        load_lanes(grown + batch, from);
        for (int a = 0; a < 3; ++a) moved[a] -= from[a];
        moved_sq = dot_lanes(moved, moved);
        if (!clearance.empty()) before = load_lane(clearance.data() + first + size_t(batch));
      } else {
        for (int64_t l = 0; l < lanes; ++l) {
          moved_sq[l] = (pts[size_t(batch + l)] - grown[batch + l]).squaredNorm();
          if (!clearance.empty()) before[l] = clearance[first + size_t(batch + l)];
        }
      }
      const Float4 room = before - skin_margin;
      const int proven = lane_bits((room >= 0.0f) & (moved_sq <= room * room));
      if (proven == 15 && !grid.has_open_edges()) {
        guard.know(grown[batch + 3], before[3]);
        continue;
      }
      for (int64_t l = 0; l < lanes; ++l) {
        const int64_t j = batch + l;
        if ((proven >> l & 1) && !grid.near_open_edge(pts[size_t(j)])) {
          guard.know(grown[j], before[l]);
          continue;
        }
        // The first point after the root, moved from where growth proved it outside (often just at
        // the margin: pushed there). The guard knows only the root, on the skin, from which no bound
        // follows; but an empty ball of the margin's radius proves the point outside, on its way from
        // its grown place, far cheaper than the exact search. It fails for a point moved nearer the
        // skin: then the search.
        if (j == 1 && guard.clear_by_ball(pts[1], skin_margin, before[l], std::sqrt(moved_sq[l]))) continue;
        guard.keep_out(pts[size_t(j)]);
      }
    }
  };

  // A clump reads its centre strands as the previous effects left them, so it needs every strand done
  // with the effects before it: it runs as a pass of its own. The other effects only read and write
  // their own strand, so each run of them (up to the next clump) is one pass doing all of them strand
  // by strand while the strand sits in cache; the run that ends the stack also does the skin pass.
  const size_t effect_count = effects_.size();
  for (size_t first = 0; first < effect_count;) {
    size_t last = first + 1;
    if (effects_[first].desc.type != EffectType::clump)
      while (last < effect_count && effects_[last].desc.type != EffectType::clump) ++last;
    const bool ends_stack = last == effect_count;
    const bool clump_pass = effects_[first].desc.type == EffectType::clump;
    // A clump pass: each centre's unit segment directions once, for all its members (centres of
    // the common point count; members of others compute their own).
    std::vector<Eigen::Vector3f> axes;
    if (clump_pass) {
      const Prepared &e = effects_[first];
      axes.resize(e.centres.size() * size_t(common_count));
      const int64_t centre_count = int64_t(e.centres.size());
#pragma omp parallel for schedule(static, 64)
      for (int64_t c = 0; c < centre_count; ++c) {
        const std::span<const Eigen::Vector3f> centre = r_strands.points(size_t(e.centres[size_t(c)]));
        if (int64_t(centre.size()) == common_count) centre_axes(centre, axes.data() + c * common_count);
      }
    }
#pragma omp parallel
    {
      Scratch scratch;
      // Blocks of four strands: curl carries its frames along the four at once (apply_curl); every
      // other effect and the skin pass take them one by one.
      const int64_t block_count = (n + 3) / 4;
#pragma omp for schedule(static, 16)
      for (int64_t block = 0; block < block_count; ++block) {
        const int64_t begin = 4 * block, count = std::min<int64_t>(4, n - begin);
        if (first == 0)
          for (int64_t i = begin; i < begin + count; ++i) {
            const std::span<const Eigen::Vector3f> pts = r_strands.points(size_t(i));
            std::copy(pts.begin(), pts.end(), grown_positions.begin() + r_strands.offsets[size_t(i)]);
          }
        if (clump_pass) {
          const Prepared &e = effects_[first];
          for (int64_t i = begin; i < begin + count; ++i) {
            if (e.strength[i] == 0.0f) continue;
            const int64_t slot = e.centre_slot[size_t(i)];
            const bool tabulated = r_strands.points_in(size_t(e.centres[size_t(slot)])) == common_count;
            apply_clump(e, ramps[first], size_t(i), r_strands, tabulated ? axes.data() + slot * common_count : nullptr,
                        r_strands.points_for_write(size_t(i)), scratch);
          }
        } else {
          // The root frames on the posed mesh, computed for the strands some effect moves.
          SurfaceFrame posed_frames[4];
          bool frame_ready[4] = {};
          for (size_t k = first; k < last; ++k) {
            const Prepared &e = effects_[k];
            for (int64_t s = 0; s < count; ++s)
              if (e.strength[size_t(begin + s)] != 0.0f && !frame_ready[s]) {
                posed_frames[s] = surface_frame(posed_mesh, root_points_[size_t(begin + s)]);
                frame_ready[s] = true;
              }
            if (e.desc.type == EffectType::curl) {
              apply_curl(e, ramps[k], begin, count, ids_, posed_frames, r_strands, scratch);
              continue;
            }
            for (int64_t s = 0; s < count; ++s) {
              const int64_t i = begin + s;
              if (e.strength[i] == 0.0f) continue;
              const SurfaceFrame &posed_frame = posed_frames[s];
              const std::span<Eigen::Vector3f> pts = r_strands.points_for_write(size_t(i));
              switch (e.desc.type) {
                case EffectType::clump:
                case EffectType::curl:
                  break;
                case EffectType::tension: {
                  const size_t g = size_t(nearest_guide_[i]);
                  std::span<const Eigen::Vector3f> offsets(guide_offsets.data() + g * size_t(common_count),
                                                           size_t(common_count));
                  if (int64_t(pts.size()) != common_count) {
                    const std::span<const float> cum(guide_cum.data() + guides_this_frame.offsets[g],
                                                     size_t(guides_this_frame.points_in(g)));
                    scratch.guide_offsets.resize(pts.size());
                    guide_offsets_at(guides_this_frame.points(g), cum, int64_t(pts.size()), scratch.guide_offsets.data());
                    offsets = scratch.guide_offsets;
                  }
                  const Eigen::Matrix3f rotation =
                      Eigen::Quaternionf::FromTwoVectors(guide_normals[g], posed_frame.normal()).toRotationMatrix();
                  apply_tension(e, ramps[k], size_t(i), offsets, guide_lengths[g], rotation, pts, scratch);
                  break;
                }
                case EffectType::length:
                  apply_length(e, size_t(i), ids_[i], rest_frames_[i], posed_frame, pts, scratch);
                  break;
                case EffectType::wave:
                case EffectType::frizz:
                  apply_noise(e, ramps[k], size_t(i), ids_[i], rest_frames_[i], posed_frame, pts, scratch);
                  break;
              }
            }
          }
        }
        if (ends_stack)
          for (int64_t i = begin; i < begin + count; ++i) keep_out_of_skin(i, r_strands.points_for_write(size_t(i)));
      }
    }
    first = last;
  }
}

}  // namespace plume::effects
