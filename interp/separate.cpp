#include "interp/separate.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "groom/error.h"
#include "groom/mesh_query.h"
#include "groom/segment_distance.h"
#include "skin/skin_grid.h"

namespace plume::interp {

namespace {

using Vec = Eigen::Vector3d;

Vec to_d(const Eigen::Vector3f &v) { return v.cast<double>(); }

/// The written strands and their exact curves, with the state of the pass.
class Separator {
 public:
  Separator(std::span<Eigen::Vector3f> positions, int n, const ExactCurves &curves, float tolerance, float margin,
            const Mesh &mesh, const skin::SkinGrid &skin_grid, std::span<float> lower,
            std::span<const uint8_t> at_guide_root)
      : mesh_(mesh), positions_(positions), n_(n), curves_(curves), tolerance_(tolerance), margin_(margin), grid_(skin_grid),
        lower_(lower), original_(positions.begin(), positions.end()), searched_(original_) {
    strand_count_ = positions.size() / size_t(n);
    // Each strand's largest move: a strand at a guide root keeps to its guide; another may move a
    // tenth of its own segment, within the bounds of the median segment (1e3 tolerances).
    const float median = tolerance / 1e-3f;
    largest_move_.resize(strand_count_);
    for (size_t c = 0; c < strand_count_; ++c) {
      float length = 0.0f;
      for (int j = 1; j < n; ++j) length += (point(c, j) - point(c, j - 1)).norm();
      const float own = separation_largest_move * length / float(n - 1);
      largest_move_[c] = !at_guide_root.empty() && at_guide_root[c]
                             ? separation_largest_move_at_guide * median
                             : std::clamp(own, separation_largest_move_at_guide * median, separation_largest_move * median);
    }
    // Each curve's arc lengths, for the windows round a meeting.
    arcs_.resize(curves.points.size());
    for (size_t c = 0; c < strand_count_; ++c) {
      float arc = 0.0f;
      for (size_t p = curves.offsets[c]; p < curves.offsets[c + 1]; ++p) {
        if (p > curves.offsets[c]) arc += (curves.points[p] - curves.points[p - 1]).norm();
        arcs_[p] = arc;
      }
    }
    // The floor of each point's signed distance is the margin, or half its bound when growth left it
    // nearer (a root climbing out, a strand ended at the skin): never inside the skin.
    moved_.assign(strand_count_ * size_t(n - 1), 0);
    travel_.assign(strand_count_ * size_t(n - 1), 0.0);
    floor_.resize(lower.size());
    for (size_t k = 0; k < lower.size(); ++k) floor_[k] = lower[k] >= margin ? margin : 0.5f * lower[k];
  }

  using Pair = std::pair<uint32_t, uint32_t>;

  /// The first search: the candidates are every pair of segments of different strands nearer than
  /// `reach` at any angle (indices strand * (n - 1) + j, first < second, sorted), found over all
  /// segments; then measured: which are nearer than `detect` at an angle above the pass's.
  void search_all(float reach, float detect) {
    const size_t segments = strand_count_ * size_t(n_ - 1);
    reach_ = reach;
    // A uniform grid of cells about a median segment wide, kept for the searches that follow.
    std::vector<float> lengths;
    lengths.reserve(segments);
    for (size_t u = 0; u < segments; ++u) lengths.push_back((end(u, 1) - end(u, 0)).norm());
    std::nth_element(lengths.begin(), lengths.begin() + segments / 2, lengths.end());
    cell_ = std::max(lengths[segments / 2], 1e-20f) + 2.0f * reach;
    box_lo_.resize(segments), box_hi_.resize(segments), cell_lo_.resize(segments), cell_hi_.resize(segments);
#pragma omp parallel for schedule(static, 4096)
    for (int64_t u = 0; u < int64_t(segments); ++u) box(size_t(u));
    everything_ = grid_of(nullptr);
    std::vector<Pair> found;
#pragma omp parallel
    {
      std::vector<Pair> mine;
#pragma omp for schedule(dynamic, 256)
      for (int64_t su = 0; su < int64_t(segments); ++su) {
        const uint32_t u = uint32_t(su);
        // Each pair from its first segment; the segments after u's own strand's are of other strands.
        const uint32_t strand_end = uint32_t((strand_of(u) + 1) * size_t(n_ - 1));
        const Eigen::Array3f lo = box_lo_[u] - reach, hi = box_hi_[u] + reach;
        for_cells(u, [&](int x, int y, int z) {
          const std::span<const Listed> listed = everything_.at(x, y, z);
          for (auto it = after(listed, u); it != listed.end(); ++it)
            if (it->segment >= strand_end && meets(lo, hi, it->lo, it->hi) && first_cell(u, it->segment, x, y, z) &&
                near(u, it->segment, reach, 2.0f))
              mine.emplace_back(u, it->segment);
        });
      }
#pragma omp critical(plume_separate_pairs)
      found.insert(found.end(), mine.begin(), mine.end());
    }
    std::sort(found.begin(), found.end());
    candidates_ = std::move(found);
    near_flags_.assign(candidates_.size(), 0);
    clear_.assign(candidates_.size(), 0.0);
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
#pragma omp parallel for schedule(static, 1024)
    for (int64_t c = 0; c < int64_t(candidates_.size()); ++c) measure(size_t(c), detect, cos_angle);
    stale_.assign(segments, 0);
    candidates_changed();
    mark_searched();
  }

  /// A search again, at the points' places now: the pairs with a segment that moved since the last
  /// search are searched anew from those segments (against the first search's grid for the segments
  /// that never moved, and the moved ones' as they are now) and measured; the other candidates stay
  /// as they were found and measured (a pair nearer than the reach now that has neither was as near
  /// at the last search).
  void search_again(float detect) {
    const size_t segments = box_lo_.size();
    std::vector<uint32_t> moving, stale;
    std::vector<uint8_t> is_moving(segments, 0);
    for (size_t u = 0; u < segments; ++u) {
      const size_t k = strand_of(u) * size_t(n_) + size_t(index_in_strand(u));
      if (positions_[k] != searched_[k] || positions_[k + 1] != searched_[k + 1]) {
        moving.push_back(uint32_t(u));
        is_moving[u] = stale_[u] = 1;
      }
      if (stale_[u]) stale.push_back(uint32_t(u));
    }
    // The searches again are many and often small: below a few thousand segments a team of threads
    // costs more in waking and waiting than the work (the answers do not depend on the thread count).
#pragma omp parallel for schedule(static, 1024) if (moving.size() > 4096)
    for (int64_t i = 0; i < int64_t(moving.size()); ++i) box(moving[size_t(i)]);
    const Grid stale_grid = grid_of(&stale);
    const float reach = reach_;
    std::vector<Pair> found;
#pragma omp parallel if (moving.size() > 256)
    {
      std::vector<Pair> mine;
#pragma omp for schedule(dynamic, 64)
      for (int64_t i = 0; i < int64_t(moving.size()); ++i) {
        const uint32_t u = moving[size_t(i)];
        const uint32_t strand_first = uint32_t(strand_of(u) * size_t(n_ - 1)), strand_end = strand_first + uint32_t(n_ - 1);
        const Eigen::Array3f u_lo = box_lo_[u], u_hi = box_hi_[u];
        const Eigen::Array3f lo = u_lo - reach, hi = u_hi + reach;
        for_cells(u, [&](int x, int y, int z) {
          // With a segment that never moved: from that segment, its box as it was.
          for (const Listed &v : everything_.at(x, y, z))
            if (meets(v.lo - reach, v.hi + reach, u_lo, u_hi) && (v.segment < strand_first || v.segment >= strand_end) &&
                !stale_[v.segment] && first_cell(v.segment, u, x, y, z) && near(v.segment, u, reach, 2.0f))
              mine.emplace_back(std::min(u, v.segment), std::max(u, v.segment));
          // With a segment that moved before (as it is now), or since (from the first of the two).
          for (const Listed &v : stale_grid.at(x, y, z))
            if ((v.segment < strand_first || v.segment >= strand_end) && !(is_moving[v.segment] && v.segment < u) &&
                meets(lo, hi, v.lo, v.hi) && first_cell(u, v.segment, x, y, z) && near(u, v.segment, reach, 2.0f))
              mine.emplace_back(std::min(u, v.segment), std::max(u, v.segment));
        });
      }
#pragma omp critical(plume_separate_pairs)
      found.insert(found.end(), mine.begin(), mine.end());
    }
    std::sort(found.begin(), found.end());
    // Merged with the candidates without a moving segment (disjoint, both sorted).
    std::vector<Pair> merged;
    std::vector<uint8_t> flags;
    std::vector<double> clear;
    std::vector<uint32_t> fresh;  // the merged indices of the pairs found now
    merged.reserve(found.size() + candidates_.size());
    flags.reserve(found.size() + candidates_.size());
    clear.reserve(found.size() + candidates_.size());
    size_t f = 0;
    for (size_t c = 0; c <= candidates_.size(); ++c) {
      const bool last = c == candidates_.size();
      if (!last && (is_moving[candidates_[c].first] || is_moving[candidates_[c].second])) continue;
      for (; f < found.size() && (last || found[f] < candidates_[c]); ++f) {
        fresh.push_back(uint32_t(merged.size()));
        merged.push_back(found[f]);
        flags.push_back(0);
        clear.push_back(0.0);
      }
      if (last) break;
      merged.push_back(candidates_[c]);
      flags.push_back(near_flags_[c]);
      clear.push_back(clear_[c]);
    }
    candidates_ = std::move(merged);
    near_flags_ = std::move(flags);
    clear_ = std::move(clear);
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
#pragma omp parallel for schedule(static, 1024) if (fresh.size() > 4096)
    for (int64_t i = 0; i < int64_t(fresh.size()); ++i) measure(fresh[size_t(i)], detect, cos_angle);
    candidates_changed();
    mark_searched();
  }

  /// Measures again the candidates with a segment that moved since they were measured, each once.
  void measure_moved(float detect) {
    std::vector<uint32_t> again;
    for (size_t u = 0; u < moved_.size(); ++u)
      if (moved_[u])
        again.insert(again.end(), listed_.begin() + std::ptrdiff_t(listed_first_[u]),
                     listed_.begin() + std::ptrdiff_t(listed_first_[u + 1]));
    std::fill(moved_.begin(), moved_.end(), 0);
    std::sort(again.begin(), again.end());
    again.erase(std::unique(again.begin(), again.end()), again.end());
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
#pragma omp parallel for schedule(static, 256) if (again.size() > 4096)
    for (int64_t i = 0; i < int64_t(again.size()); ++i) {
      const size_t c = again[size_t(i)];
      // A pair far at its last measure whose segments have not moved enough since to come within
      // `detect` is not measured again: it is not near.
      const auto &[u, v] = candidates_[c];
      if (!near_flags_[c] && clear_[c] - travel_[u] - travel_[v] > double(detect) * (1.0 + 1e-6)) continue;
      measure(c, detect, cos_angle);
    }
    // The near candidates: those not measured again as they were, and those measured again now near.
    std::vector<uint32_t> near_now;
    near_now.reserve(near_.size() + again.size());
    size_t a = 0;
    for (size_t i = 0; i <= near_.size(); ++i) {
      const uint32_t c = i < near_.size() ? near_[i] : UINT32_MAX;
      for (; a < again.size() && again[a] <= c; ++a)
        if (near_flags_[again[a]]) near_now.push_back(again[a]);
      if (i < near_.size() && (a == 0 || again[a - 1] != c)) near_now.push_back(c);
    }
    near_ = std::move(near_now);
  }

  /// The candidates nearer than `detect` at their last measure, sorted.
  std::vector<Pair> near_pairs() const {
    std::vector<Pair> pairs;
    pairs.reserve(near_.size());
    for (const uint32_t c : near_) pairs.push_back(candidates_[c]);
    return pairs;
  }
  /// The largest distance from its place at the last search at which a point was put since: at
  /// least the largest distance of a point from it now.
  float drift() const { return std::sqrt(drift_squared_); }
  /// How many of `pairs` are nearer than `distance` at an angle above the pass's.
  int64_t count_near(const std::vector<Pair> &pairs, float distance) const {
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
    int64_t count = 0;
    for (const auto &[u, v] : pairs) count += near(u, v, distance, cos_angle);
    return count;
  }
  /// The strand of segment u (indices strand * (n - 1) + j) and u's index j along it.
  size_t strand_of(size_t u) const { return u / size_t(n_ - 1); }
  int index_in_strand(size_t u) const { return int(u % size_t(n_ - 1)); }
  /// The strand of point k (indices strand * n + j).
  size_t strand_of_point(size_t k) const { return k / size_t(n_); }
  /// Pushes the pair's segments apart (one step of a sweep); returns false when nothing could move.
  bool push(uint32_t u, uint32_t v, SeparationStats &stats) {
    const float detect = separation_detect * tolerance_, goal = double(separation_goal) * tolerance_;
    const Vec a0 = to_d(end(u, 0)), a1 = to_d(end(u, 1)), b0 = to_d(end(v, 0)), b1 = to_d(end(v, 1));
    double s = 0.0, t = 0.0;
    closest_segment_parameters(a0, a1, b0, b1, s, t);
    const Vec pa = a0 + s * (a1 - a0), pb = b0 + t * (b1 - b0);
    if ((pa - pb).norm() >= double(detect)) return true;
    const size_t sa = strand_of(u), sb = strand_of(v);
    const int ia = index_in_strand(u), ib = index_in_strand(v);
    // The exact side, e: from b's curve to a's, at their closest points within a segment of the
    // meeting; where the curves meet there, the segments' own. A pair's push direction is chosen
    // from e at its first push and kept (below), so e is needed again only to tell whether the pair
    // can move at all (no side at all: the curves and the segments meet, and the segments are
    // parallel).
    const uint64_t key = (uint64_t(u) << 32) | v;
    auto chosen = directions_.find(key);
    const bool without_own_side =
        (pa - pb).squaredNorm() == 0.0 && (a1 - a0).cross(b1 - b0).cross(a1 - a0).squaredNorm() == 0.0;
    if (chosen == directions_.end() || without_own_side) {
      Vec e = exact_side(sa, (double(ia) + s) / double(n_ - 1), sb, (double(ib) + t) / double(n_ - 1));
      if (e.squaredNorm() == 0.0) {
        ++stats.undecided;
        e = pa - pb;
        // The segments meet: perpendicular to a's segment, in the plane of the two (a planar scene's).
        if (e.squaredNorm() == 0.0) e = (a1 - a0).cross(b1 - b0).cross(a1 - a0);
        if (e.squaredNorm() == 0.0) return false;
        e.normalize();
      }
      // Skew segments are pushed along their common normal, on e's side (where e lies nearly in the
      // segments' plane the curves are beside each other there, and either side of the plane parts
      // the segments); segments in one plane with e (a planar scene) along e itself, which keeps them
      // in it.
      // The direction is chosen at the pair's first push and kept: the segments turn a little as they
      // move, and a side taken from a nearly planar e could otherwise flip back and forth.
      if (chosen == directions_.end()) {
        const Vec ua = (a1 - a0).normalized(), ub = (b1 - b0).normalized();
        const Vec normal = ua.cross(ub);
        const bool skew = normal.norm() > 1e-3 && std::abs(e.dot(normal.normalized())) >= 1e-3;
        const double side = e.dot(normal);
        chosen = directions_.emplace(key, Chosen{skew ? Vec(side >= 0.0 ? normal.normalized()
                                                                         : Vec(-normal.normalized()))
                                                      : e,
                                                 skew}).first;
      }
    }
    const Vec direction = chosen->second.direction;
    const bool skew = chosen->second.skew;
    // Each of the four vertices' wanted move along `direction` (a's positive, b's negative): its share
    // of the deficit at the closest points, spread over the segment's two ends (least squares; a root
    // stays, its other end takes the whole), and in the planar case at least its own deficit where it
    // lies on the wrong side of the other segment, near it.
    const double deficit = goal - (pa - pb).dot(direction);
    double want[4] = {0.0, 0.0, 0.0, 0.0};  // a0, a1, b0, b1
    auto spread = [&](double share, double param, bool fixed_first, double *r_ends) {
      if (fixed_first) {
        r_ends[1] = share / std::max(param, 0.25);
        return;
      }
      const double w0 = 1.0 - param, w1 = param, norm = w0 * w0 + w1 * w1;
      r_ends[0] = share * w0 / norm;
      r_ends[1] = share * w1 / norm;
    };
    if (deficit > 0.0) {
      spread(0.5 * deficit, s, ia == 0, want);
      spread(0.5 * deficit, t, ib == 0, want + 2);
    }
    if (!skew) {
      const Vec ends[4] = {a0, a1, b0, b1};
      for (int k = 0; k < 4; ++k) {
        const bool of_a = k < 2;
        const Vec &q0 = of_a ? b0 : a0, &q1 = of_a ? b1 : a1;
        const double length = (q1 - q0).norm();
        double r = 0.0, unused = 0.0;
        closest_segment_parameters(q0, q1, ends[k], ends[k], r, unused);
        const Vec offset = ends[k] - (q0 + r * (q1 - q0));
        if (offset.norm() > 0.5 * length) continue;
        const double side = (of_a ? 1.0 : -1.0) * offset.dot(direction);
        if (side < goal) want[k] = std::max(want[k], goal - side);
      }
    }
    // Move what can move; what one strand cannot take (the part of its move the skin or its largest
    // move refused, at its closest point), the other takes.
    const size_t index[4] = {sa * size_t(n_) + size_t(ia), sa * size_t(n_) + size_t(ia) + 1,
                             sb * size_t(n_) + size_t(ib), sb * size_t(n_) + size_t(ib) + 1};
    const bool is_root[4] = {ia == 0, false, ib == 0, false};
    // A tip met at its end (s or t at 1 on a last segment): when it cannot move aside (a strand ended
    // at the skin), it moves back along its own last segment, which parts it from the other strand.
    const bool tip_met[4] = {false, ia == n_ - 2 && s >= 0.99, false, ib == n_ - 2 && t >= 0.99};
    bool moved_any = false;
    double left[4] = {0.0, 0.0, 0.0, 0.0};
    for (int k = 0; k < 4; ++k) {
      if (want[k] <= 0.0 || is_root[k]) continue;
      const double sign = k < 2 ? 1.0 : -1.0;
      const double achieved = try_move(index[k], (sign * want[k] * direction).cast<float>(), stats);
      if (achieved > 0.0) moved_any = true;
      if (achieved < 0.5 && tip_met[k] && retract(index[k], want[k] * (1.0 - achieved), stats)) {
        moved_any = true;
        continue;
      }
      left[k] = want[k] * (1.0 - achieved);
    }
    const double left_a = (1.0 - s) * left[0] + s * left[1], left_b = (1.0 - t) * left[2] + t * left[3];
    if (left_a > 0.0) {
      double ends[2] = {0.0, 0.0};
      spread(left_a, t, ib == 0, ends);
      for (int e = 0; e < 2; ++e)
        if (ends[e] > 0.0) moved_any = try_move(index[2 + e], (-ends[e] * direction).cast<float>(), stats) > 0.0 || moved_any;
    }
    if (left_b > 0.0) {
      double ends[2] = {0.0, 0.0};
      spread(left_b, s, ia == 0, ends);
      for (int e = 0; e < 2; ++e)
        if (ends[e] > 0.0) moved_any = try_move(index[e], (ends[e] * direction).cast<float>(), stats) > 0.0 || moved_any;
    }
    return moved_any;
  }

  float largest_move() const {
    float largest = 0.0f;
    for (size_t k = 0; k < original_.size(); ++k) largest = std::max(largest, (positions_[k] - original_[k]).norm());
    return largest;
  }
  int64_t points_moved() const {
    int64_t count = 0;
    for (size_t k = 0; k < original_.size(); ++k) count += positions_[k] != original_[k];
    return count;
  }

 private:
  /// A segment listed in a cell, with its box (read in the cells' order, not the segments').
  struct Listed {
    Eigen::Array3f lo, hi;
    uint32_t segment;
  };
  /// Cells listing segments: slot s of a cell holds listed[first[s] .. first[s + 1]), in index order.
  struct Grid {
    std::unordered_map<uint64_t, uint32_t> slots;  // cell key -> slot
    std::vector<uint32_t> first;                   // #slots + 1
    std::vector<Listed> listed;

    std::span<const Listed> at(int x, int y, int z) const {
      const auto found = slots.find(key(x, y, z));
      if (found == slots.end()) return {};
      return {listed.data() + first[found->second], listed.data() + first[found->second + 1]};
    }
  };
  static uint64_t key(int64_t x, int64_t y, int64_t z) {
    return uint64_t(x & 0x1fffff) | (uint64_t(y & 0x1fffff) << 21) | (uint64_t(z & 0x1fffff) << 42);
  }
  /// The grid of the segments `listed` (sorted; all when null), each in the cells its box grown by
  /// the reach meets.
  Grid grid_of(const std::vector<uint32_t> *listed) const {
    const size_t count = listed ? listed->size() : box_lo_.size();
    Grid grid;
    std::vector<uint32_t> slot_of;  // per listing, in order
    std::vector<uint32_t> sizes;
    for (size_t i = 0; i < count; ++i) {
      const uint32_t u = listed ? (*listed)[i] : uint32_t(i);
      for_cells(u, [&](int x, int y, int z) {
        const auto [at, added] = grid.slots.try_emplace(key(x, y, z), uint32_t(sizes.size()));
        if (added) sizes.push_back(0);
        ++sizes[at->second];
        slot_of.push_back(at->second);
      });
    }
    grid.first.assign(sizes.size() + 1, 0);
    for (size_t s = 0; s < sizes.size(); ++s) grid.first[s + 1] = grid.first[s] + sizes[s];
    grid.listed.resize(slot_of.size());
    std::vector<uint32_t> next(grid.first.begin(), grid.first.end() - 1);
    size_t listing = 0;
    for (size_t i = 0; i < count; ++i) {
      const uint32_t u = listed ? (*listed)[i] : uint32_t(i);
      const size_t cells = size_t((cell_hi_[u] - cell_lo_[u] + 1).prod());
      for (size_t c = 0; c < cells; ++c) grid.listed[next[slot_of[listing++]]++] = Listed{box_lo_[u], box_hi_[u], u};
    }
    return grid;
  }
  /// Segment u's box, and the cells that box grown by the reach meets.
  void box(size_t u) {
    const Eigen::Vector3f a = end(u, 0), b = end(u, 1);
    box_lo_[u] = a.cwiseMin(b).array();
    box_hi_[u] = a.cwiseMax(b).array();
    cell_lo_[u] = ((box_lo_[u] - reach_) / cell_).floor().cast<int>();
    cell_hi_[u] = ((box_hi_[u] + reach_) / cell_).floor().cast<int>();
  }
  template <class Visit>
  void for_cells(size_t u, Visit &&visit) const {
    const Eigen::Array3i &lo = cell_lo_[u], &hi = cell_hi_[u];
    for (int x = lo.x(); x <= hi.x(); ++x)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int z = lo.z(); z <= hi.z(); ++z) visit(x, y, z);
  }
  /// Whether a box (lo, hi) meets a segment's box grown by the reach (grown_lo, grown_hi): the test
  /// is from the side of the pair's segment that finds the other, as the pair is measured.
  static bool meets(const Eigen::Array3f &grown_lo, const Eigen::Array3f &grown_hi, const Eigen::Array3f &lo,
                    const Eigen::Array3f &hi) {
    return !((lo > grown_hi).any() || (hi < grown_lo).any());
  }
  /// Whether cell (x, y, z) is the first both segments' grown boxes meet (so that each pair is
  /// counted in one cell).
  bool first_cell(uint32_t u, uint32_t v, int x, int y, int z) const {
    const Eigen::Array3i first = cell_lo_[u].max(cell_lo_[v]);
    return first.x() == x && first.y() == y && first.z() == z;
  }
  /// The segments listed after u in a cell.
  static std::span<const Listed>::iterator after(std::span<const Listed> listed, uint32_t u) {
    return std::upper_bound(listed.begin(), listed.end(), u,
                            [](uint32_t segment, const Listed &entry) { return segment < entry.segment; });
  }
  /// The candidates changed: each strand's candidates listed again, and the near ones.
  void candidates_changed() {
    listed_first_.assign(moved_.size() + 1, 0);
    for (const auto &[u, v] : candidates_) ++listed_first_[u + 1], ++listed_first_[v + 1];
    for (size_t u = 0; u < moved_.size(); ++u) listed_first_[u + 1] += listed_first_[u];
    listed_.resize(listed_first_.back());
    std::vector<size_t> next(listed_first_.begin(), listed_first_.end() - 1);
    for (size_t c = 0; c < candidates_.size(); ++c) {
      listed_[next[candidates_[c].first]++] = uint32_t(c);
      listed_[next[candidates_[c].second]++] = uint32_t(c);
    }
    near_.clear();
    for (size_t c = 0; c < candidates_.size(); ++c)
      if (near_flags_[c]) near_.push_back(uint32_t(c));
    std::fill(moved_.begin(), moved_.end(), 0);
  }
  /// Point k moves to `to`: the segments it ends are flagged for measuring again, and travel as far.
  void mark_moved(size_t k, const Eigen::Vector3f &to) {
    const size_t strand = strand_of_point(k), j = k - strand * size_t(n_);
    const size_t first = strand * size_t(n_ - 1);
    const double distance = (to_d(to) - to_d(positions_[k])).norm();
    if (j > 0) moved_[first + j - 1] = 1, travel_[first + j - 1] += distance;
    if (j + 1 < size_t(n_)) moved_[first + j] = 1, travel_[first + j] += distance;
  }
  /// Measures candidate c: near or not, and how far its segments may travel before they can be near
  /// (their distance now, plus their travel so far: a point of a segment moves at most as far as
  /// the farther of its ends, so the distance of two segments falls at most by what each travels).
  void measure(size_t c, float detect, float cos_angle) {
    const auto &[u, v] = candidates_[c];
    double gap = 0.0;
    near_flags_[c] = near(u, v, detect, cos_angle, &gap);
    clear_[c] = gap + travel_[u] + travel_[v];
  }
  void mark_searched() {
    searched_.assign(positions_.begin(), positions_.end());
    drift_squared_ = 0.0f;
  }

  Eigen::Vector3f point(size_t strand, int j) const { return positions_[strand * size_t(n_) + size_t(j)]; }
  /// End `which` (0, 1) of segment u.
  Eigen::Vector3f end(size_t u, int which) const {
    return point(strand_of(u), index_in_strand(u) + which);
  }

  /// Whether segments u and v are nearer than `distance` at an angle whose cosine is below
  /// `cos_angle` (any angle when it is above 1), or in one plane.
  bool near(size_t u, size_t v, float distance, float cos_angle, double *r_gap = nullptr) const {
    const Vec a0 = to_d(end(u, 0)), a1 = to_d(end(u, 1)), b0 = to_d(end(v, 0)), b1 = to_d(end(v, 1));
    double s = 0.0, t = 0.0;
    closest_segment_parameters(a0, a1, b0, b1, s, t);
    const double gap = ((a0 + s * (a1 - a0)) - (b0 + t * (b1 - b0))).norm();
    if (r_gap) *r_gap = gap;
    if (gap >= double(distance)) return false;
    if (cos_angle > 1.0f) return true;  // at any angle
    const Vec da = a1 - a0, db = b1 - b0;
    const double la = da.norm(), lb = db.norm();
    if (la <= 0.0 || lb <= 0.0) return true;
    // Segments in one plane with each other (a planar scene's) count at any angle: in the plane,
    // near-parallel segments that meet still pass through each other.
    if (da.cross(db).dot(b0 - a0) == 0.0 && da.cross(db).dot(b1 - a0) == 0.0) return true;
    return std::abs(da.dot(db)) / (la * lb) < double(cos_angle);
  }

  /// The unit direction from curve b's point nearest curve a to curve a's point nearest curve b,
  /// within one written segment of arc length round the fractions fa and fb of their lengths; zero
  /// when the curves themselves meet there.
  Vec exact_side(size_t a, double fa, size_t b, double fb) const {
    size_t a_first = 0, a_last = 0, b_first = 0, b_last = 0;
    window(a, fa, a_first, a_last);
    window(b, fb, b_first, b_last);
    double best = INFINITY;
    Vec side = Vec::Zero();
    for (size_t p = a_first; p < a_last; ++p)
      for (size_t q = b_first; q < b_last; ++q) {
        const Vec p0 = to_d(curves_.points[p]), p1 = to_d(curves_.points[p + 1]);
        const Vec q0 = to_d(curves_.points[q]), q1 = to_d(curves_.points[q + 1]);
        double s = 0.0, t = 0.0;
        closest_segment_parameters(p0, p1, q0, q1, s, t);
        const Vec d = (p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0));
        if (d.squaredNorm() < best) {
          best = d.squaredNorm();
          side = d;
        }
      }
    if (!(best > 0.0)) return Vec::Zero();
    return side.normalized();
  }
  /// The fine segments [r_first, r_last) of curve c within one written segment of its fraction f.
  void window(size_t c, double f, size_t &r_first, size_t &r_last) const {
    const size_t first = curves_.offsets[c], last = curves_.offsets[c + 1];
    if (last - first < 2) {
      r_first = r_last = first;
      return;
    }
    const double cut = curves_.cuts[c], reach = cut / double(n_ - 1);
    const double from = f * cut - reach, to = f * cut + reach;
    const auto begin = arcs_.begin() + std::ptrdiff_t(first), stop = arcs_.begin() + std::ptrdiff_t(last);
    size_t lo = size_t(std::upper_bound(begin, stop, float(from)) - arcs_.begin());
    size_t hi = size_t(std::lower_bound(begin, stop, float(to)) - arcs_.begin());
    lo = lo > first ? lo - 1 : first;
    hi = std::min(hi, last - 1);
    if (hi <= lo) hi = std::min(lo + 1, last - 1), lo = hi - 1;
    r_first = lo;
    r_last = hi;
  }

  /// Moves tip k back along its strand's last segment by `distance` (at most a tenth of that
  /// segment per call); false when the move is refused.
  bool retract(size_t k, double distance, SeparationStats &stats) {
    const Eigen::Vector3f back = positions_[k - 1] - positions_[k];
    const float length = back.norm();
    if (!(length > 0.0f)) return false;
    const float step = std::min(float(distance), 0.1f * length);
    if (try_move(k, back * (step / length), stats) < 0.5) return false;
    ++stats.retracted;
    return true;
  }

  /// Puts point k at `to`, its signed distance to the skin at least `bound`.
  void place(size_t k, const Eigen::Vector3f &to, float bound) {
    mark_moved(k, to);
    positions_[k] = to;
    drift_squared_ = std::max(drift_squared_, (to - searched_[k]).squaredNorm());
    lower_[k] = bound;
  }

  /// Moves point k by `delta` when it stays within its strand's largest move and out of the skin
  /// by its floor; its bound follows. Returns the part of `delta` achieved (along it): 1 when moved
  /// as asked, less when the skin took a part, 0 when refused.
  double try_move(size_t k, const Eigen::Vector3f &delta, SeparationStats &stats) {
    const Eigen::Vector3f to = positions_[k] + delta;
    const size_t strand = strand_of_point(k);
    const float largest = largest_move_[strand];
    if (!to.allFinite() || !(delta.squaredNorm() > 0.0f) || (to - original_[k]).norm() > largest) return 0.0;
    float bound = lower_[k] - delta.norm();
    if (bound >= floor_[k]) {
      place(k, to, bound);
      return 1.0;
    }
    // Near the skin: queried; a move into it loses its part along the skin's normal there (the
    // offset from the closest point) and rises by a tenth of its length, so that a strand lying
    // along the skin slides along it.
    SurfacePoint closest;
    const Eigen::Vector3f from = positions_[k];
    const float at = grid_.signed_distance(from, -1, closest);
    const Eigen::Vector3f offset = from - surface_position(mesh_, closest);
    Eigen::Vector3f moved = delta;
    if (offset.norm() > 0.0f && at > 0.0f) {
      const Eigen::Vector3f normal = offset.normalized();
      moved -= std::min(0.0f, moved.dot(normal)) * normal;
      moved += 0.1f * moved.norm() * normal;  // and rises a little, so that the skin's turn cannot take it in
    }
    const Eigen::Vector3f target = from + moved;
    if (!target.allFinite() || (target - original_[k]).norm() > largest) return 0.0;
    bound = grid_.signed_distance(target, closest.triangle, closest);
    if (!(bound >= floor_[k])) return 0.0;
    ++stats.slid;
    place(k, target, bound);
    return std::clamp(double(moved.dot(delta)) / double(delta.squaredNorm()), 0.0, 1.0);
  }

  struct Chosen {
    Vec direction;
    bool skew;
  };
  std::unordered_map<uint64_t, Chosen> directions_;
  const Mesh &mesh_;
  std::span<Eigen::Vector3f> positions_;
  int n_;
  const ExactCurves &curves_;
  float tolerance_;
  float margin_;
  const skin::SkinGrid &grid_;
  std::span<float> lower_;
  std::vector<Eigen::Vector3f> original_;
  std::vector<Eigen::Vector3f> searched_;  // the points at the last search over all segments
  float drift_squared_ = 0.0f;             // drift(), squared
  std::vector<float> largest_move_;        // per strand
  // The search: the reach, the cell size, each segment's box and the cells it meets grown by the
  // reach (as at the last search that saw the segment move), the grid of the first search, and
  // the segments moved since it (one flag each).
  float reach_ = 0.0f;
  float cell_ = 1.0f;
  std::vector<Eigen::Array3f> box_lo_, box_hi_;
  std::vector<Eigen::Array3i> cell_lo_, cell_hi_;
  Grid everything_;
  std::vector<uint8_t> stale_;
  // The candidate pairs (sorted), flagged when nearer than the detection distance at their last
  // measure; each segment's candidates (indices into candidates_):
  // listed_[listed_first_[u] .. listed_first_[u + 1]); and the near ones (indices, sorted).
  std::vector<Pair> candidates_;
  std::vector<uint8_t> near_flags_;
  std::vector<size_t> listed_first_;
  std::vector<uint32_t> listed_;
  std::vector<uint32_t> near_;
  size_t strand_count_ = 0;
  std::vector<float> arcs_;
  std::vector<float> floor_;
  std::vector<uint8_t> moved_;  // per segment: moved since its candidates were measured
  std::vector<double> travel_;  // per segment: how far its ends have moved, summed over every move
  std::vector<double> clear_;   // per candidate: its distance at its last measure plus its segments' travel then
};

}  // namespace

SeparationStats separate_strands(std::span<Eigen::Vector3f> positions, int n, const ExactCurves &curves,
                                 float tolerance, float margin, const Mesh &mesh, const skin::SkinGrid &skin_grid,
                                 std::span<float> lower, std::span<const uint8_t> at_guide_root) {
  SeparationStats stats;
  if (n < 2 || positions.size() < 2 * size_t(n) || !(tolerance > 0.0f)) return stats;
  if (!at_guide_root.empty() && at_guide_root.size() != positions.size() / size_t(n))
    throw InternalError("separate_strands: one guide-root flag per strand expected");
  Separator separator(positions, n, curves, tolerance, margin, mesh, skin_grid, lower, at_guide_root);
  constexpr int max_sweeps = 1000;
  const float detect = separation_detect * tolerance;
  // Every pair that can come within `detect` while each point moves at most `slack` (30 tolerances:
  // on Sintel, fewer searches cost more in pairs measured, more cost more in searches), found over
  // all segments; each sweep measures again those of the segments that moved, until a point has
  // drifted farther than `slack` since the last search: then those of the segments that moved since
  // are found again. Every pair within `detect` at a sweep is so among the candidates, whenever the
  // searches run.
  const float slack = 30.0f * tolerance;
  separator.search_all(detect + 2.0f * slack, detect);
  stats.searches = 1;
  std::vector<std::pair<uint32_t, uint32_t>> pairs = separator.near_pairs();
  stats.pairs_found = int64_t(pairs.size());
  while (!pairs.empty() && stats.sweeps < max_sweeps) {
    ++stats.sweeps;
    bool moved = false;
    for (const auto &[u, v] : pairs) moved = separator.push(u, v, stats) || moved;
    if (separator.drift() > slack) {
      separator.search_again(detect);
      ++stats.searches;
    } else {
      separator.measure_moved(detect);
    }
    pairs = separator.near_pairs();
    if (!moved) break;
  }
  // `pairs` are those nearer than `detect` now, and any pair nearer than the tolerance is one of them.
  stats.pairs_left = separator.count_near(pairs, tolerance);
  stats.points_moved = separator.points_moved();
  stats.largest_move = separator.largest_move();
  return stats;
}

}  // namespace plume::interp
