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
    moved_.assign(strand_count_, 0);
    floor_.resize(lower.size());
    for (size_t k = 0; k < lower.size(); ++k) floor_[k] = lower[k] >= margin ? margin : 0.5f * lower[k];
  }

  /// Of `candidates`, the pairs nearer than `distance` at an angle above the pass's; `r_near` holds
  /// one flag per candidate, measured again only where a strand of the pair moved since it was
  /// (`moved`, one flag per strand; all when empty).
  std::vector<std::pair<uint32_t, uint32_t>> near_among(const std::vector<std::pair<uint32_t, uint32_t>> &candidates,
                                                        float distance, const std::vector<uint8_t> &moved,
                                                        std::vector<uint8_t> &r_near) {
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
    r_near.resize(candidates.size(), 0);
    if (moved.empty()) {
      // Every candidate, and each strand's candidates listed for the sweeps that follow.
#pragma omp parallel for schedule(static, 1024)
      for (int64_t c = 0; c < int64_t(candidates.size()); ++c) {
        const auto &[u, v] = candidates[size_t(c)];
        r_near[size_t(c)] = near(u, v, distance, cos_angle);
      }
      listed_first_.assign(strand_count_ + 1, 0);
      for (const auto &[u, v] : candidates) ++listed_first_[strand_of(u) + 1], ++listed_first_[strand_of(v) + 1];
      for (size_t c = 0; c < strand_count_; ++c) listed_first_[c + 1] += listed_first_[c];
      listed_.resize(listed_first_.back());
      std::vector<size_t> next(listed_first_.begin(), listed_first_.end() - 1);
      for (size_t c = 0; c < candidates.size(); ++c) {
        listed_[next[strand_of(candidates[c].first)]++] = uint32_t(c);
        listed_[next[strand_of(candidates[c].second)]++] = uint32_t(c);
      }
    } else {
      // The candidates of the strands that moved, each once, in order.
      std::vector<uint32_t> again;
      for (size_t strand = 0; strand < strand_count_; ++strand)
        if (moved[strand])
          again.insert(again.end(), listed_.begin() + std::ptrdiff_t(listed_first_[strand]),
                       listed_.begin() + std::ptrdiff_t(listed_first_[strand + 1]));
      std::sort(again.begin(), again.end());
      again.erase(std::unique(again.begin(), again.end()), again.end());
#pragma omp parallel for schedule(static, 256) if (again.size() > 4096)
      for (int64_t i = 0; i < int64_t(again.size()); ++i) {
        const auto &[u, v] = candidates[again[size_t(i)]];
        r_near[again[size_t(i)]] = near(u, v, distance, cos_angle);
      }
    }
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    for (size_t c = 0; c < candidates.size(); ++c)
      if (r_near[c]) pairs.push_back(candidates[c]);
    return pairs;
  }
  /// One flag per strand, set when a point of it has moved since the last call.
  std::vector<uint8_t> take_moved() {
    std::vector<uint8_t> moved(strand_count_, 0);
    std::swap(moved, moved_);
    moved_.assign(strand_count_, 0);
    return moved;
  }
  /// The largest distance from its place at the last search over all segments (mark_searched) at
  /// which a point was put since: at least the largest distance of a point from it now.
  float drift() const { return std::sqrt(drift_squared_); }
  void mark_searched() {
    searched_.assign(positions_.begin(), positions_.end());
    drift_squared_ = 0.0f;
  }
  /// How many of `pairs` are nearer than `distance` at an angle above the pass's.
  int64_t count_near(const std::vector<std::pair<uint32_t, uint32_t>> &pairs, float distance) const {
    const float cos_angle = std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
    int64_t count = 0;
    for (const auto &[u, v] : pairs) count += near(u, v, distance, cos_angle);
    return count;
  }
  /// One flag per strand, set when a point of it is not where growth put it.
  std::vector<uint8_t> ever_moved() const {
    std::vector<uint8_t> flags(strand_count_, 0);
    for (size_t k = 0; k < original_.size(); ++k)
      if (positions_[k] != original_[k]) flags[strand_of_point(k)] = 1;
    return flags;
  }
  /// The strand of segment u (indices strand * (n - 1) + j) and u's index j along it.
  size_t strand_of(size_t u) const { return u / size_t(n_ - 1); }
  int index_in_strand(size_t u) const { return int(u % size_t(n_ - 1)); }
  /// The strand of point k (indices strand * n + j).
  size_t strand_of_point(size_t k) const { return k / size_t(n_); }

  /// Segment pairs (indices strand * (n - 1) + j, first < second) of different strands nearer than
  /// `distance` (at an angle above the pass's unless `any_angle`), sorted; with `active` (one flag per
  /// strand), only the pairs with a segment of a flagged strand.
  std::vector<std::pair<uint32_t, uint32_t>> near_pairs(float distance, bool any_angle = false,
                                                        const std::vector<uint8_t> *active = nullptr) const {
    const size_t segments = strand_count_ * size_t(n_ - 1);
    // A uniform grid of cells about a median segment wide; each segment listed in the cells its box
    // (grown by `distance`) meets, in index order.
    std::vector<float> lengths;
    lengths.reserve(segments);
    for (size_t u = 0; u < segments; ++u) lengths.push_back((end(u, 1) - end(u, 0)).norm());
    std::nth_element(lengths.begin(), lengths.begin() + segments / 2, lengths.end());
    const float cell = std::max(lengths[segments / 2], 1e-20f) + 2.0f * distance;
    auto key = [](int64_t x, int64_t y, int64_t z) {
      return uint64_t(x & 0x1fffff) | (uint64_t(y & 0x1fffff) << 21) | (uint64_t(z & 0x1fffff) << 42);
    };
    // Each segment's box and the cells its box grown by `distance` meets.
    std::vector<Eigen::Array3f> box_lo(segments), box_hi(segments);
    std::vector<Eigen::Array3i> cell_lo(segments), cell_hi(segments);
#pragma omp parallel for schedule(static, 4096)
    for (int64_t su = 0; su < int64_t(segments); ++su) {
      const size_t u = size_t(su);
      const Eigen::Vector3f a = end(u, 0), b = end(u, 1);
      box_lo[u] = a.cwiseMin(b).array();
      box_hi[u] = a.cwiseMax(b).array();
      cell_lo[u] = ((box_lo[u] - distance) / cell).floor().cast<int>();
      cell_hi[u] = ((box_hi[u] + distance) / cell).floor().cast<int>();
    }
    // The cells list every segment (of an active strand, with `active`), in index order; each
    // segment looks up the cells its own box meets.
    auto listed = [&](size_t u) { return !active || (*active)[strand_of(u)] != 0; };
    std::unordered_map<uint64_t, std::vector<uint32_t>> cells;
    for (size_t u = 0; u < segments; ++u) {
      if (!listed(u)) continue;
      const Eigen::Array3i &lo = cell_lo[u], &hi = cell_hi[u];
      for (int x = lo.x(); x <= hi.x(); ++x)
        for (int y = lo.y(); y <= hi.y(); ++y)
          for (int z = lo.z(); z <= hi.z(); ++z) cells[key(x, y, z)].push_back(uint32_t(u));
    }
    const float cos_angle = any_angle ? 2.0f : std::cos(separation_angle_degrees * float(M_PI) / 180.0f);
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
#pragma omp parallel
    {
      std::vector<std::pair<uint32_t, uint32_t>> mine;
#pragma omp for schedule(dynamic, 256)
      for (int64_t su = 0; su < int64_t(segments); ++su) {
        const size_t u = size_t(su);
        const size_t strand = strand_of(u);
        const bool u_listed = listed(u);
        const Eigen::Array3i lo = cell_lo[u], hi = cell_hi[u];
        const Eigen::Array3f ulo = box_lo[u] - distance, uhi = box_hi[u] + distance;
        for (int x = lo.x(); x <= hi.x(); ++x)
          for (int y = lo.y(); y <= hi.y(); ++y)
            for (int z = lo.z(); z <= hi.z(); ++z) {
              const auto found = cells.find(key(x, y, z));
              if (found == cells.end()) continue;
              for (const uint32_t v : found->second) {
                const size_t other = strand_of(v);
                // Each pair once: from its first segment when both are listed.
                if (other == strand || (u_listed && v <= u)) continue;
                // The segments' own boxes, grown by the distance, must meet (a cheap test first).
                if ((box_lo[v] > uhi).any() || (box_hi[v] < ulo).any()) continue;
                // Counted in the first cell both boxes share, so each pair once.
                const Eigen::Array3i first = lo.max(cell_lo[v]);
                if (first.x() != x || first.y() != y || first.z() != z) continue;
                if (near(u, v, distance, cos_angle))
                  mine.emplace_back(uint32_t(std::min<size_t>(u, v)), uint32_t(std::max<size_t>(u, v)));
              }
            }
      }
#pragma omp critical(plume_separate_pairs)
      pairs.insert(pairs.end(), mine.begin(), mine.end());
    }
    std::sort(pairs.begin(), pairs.end());
    return pairs;
  }

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
    // The exact side: from b's curve to a's, at their closest points within a segment of the meeting.
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
    const uint64_t key = (uint64_t(u) << 32) | v;
    auto chosen = directions_.find(key);
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
  Eigen::Vector3f point(size_t strand, int j) const { return positions_[strand * size_t(n_) + size_t(j)]; }
  /// End `which` (0, 1) of segment u.
  Eigen::Vector3f end(size_t u, int which) const {
    return point(strand_of(u), index_in_strand(u) + which);
  }

  bool near(size_t u, size_t v, float distance, float cos_angle) const {
    const Vec a0 = to_d(end(u, 0)), a1 = to_d(end(u, 1)), b0 = to_d(end(v, 0)), b1 = to_d(end(v, 1));
    double s = 0.0, t = 0.0;
    closest_segment_parameters(a0, a1, b0, b1, s, t);
    if (((a0 + s * (a1 - a0)) - (b0 + t * (b1 - b0))).norm() >= double(distance)) return false;
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
      moved_[strand] = 1;
      positions_[k] = to;
      drift_squared_ = std::max(drift_squared_, (to - searched_[k]).squaredNorm());
      lower_[k] = bound;
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
    moved_[strand] = 1;
    positions_[k] = target;
    drift_squared_ = std::max(drift_squared_, (target - searched_[k]).squaredNorm());
    lower_[k] = bound;
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
  // The candidates of each strand (indices into the candidate pairs), from near_among's full pass:
  // listed_[listed_first_[s] .. listed_first_[s + 1]).
  std::vector<size_t> listed_first_;
  std::vector<uint32_t> listed_;
  size_t strand_count_ = 0;
  std::vector<float> arcs_;
  std::vector<float> floor_;
  std::vector<uint8_t> moved_;
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
  // all segments; each sweep measures these alone, until a point has drifted farther than `slack`
  // since: then they are found again.
  const float slack = 30.0f * tolerance;
  const std::vector<std::pair<uint32_t, uint32_t>> initial = separator.near_pairs(detect + 2.0f * slack, true);
  std::vector<std::pair<uint32_t, uint32_t>> candidates = initial;
  stats.searches = 1;
  std::vector<uint8_t> is_near;
  std::vector<std::pair<uint32_t, uint32_t>> pairs = separator.near_among(candidates, detect, {}, is_near);
  stats.pairs_found = int64_t(pairs.size());
  while (!pairs.empty() && stats.sweeps < max_sweeps) {
    ++stats.sweeps;
    bool moved = false;
    for (const auto &[u, v] : pairs) moved = separator.push(u, v, stats) || moved;
    if (separator.drift() > slack) {
      // Found again: the pairs of two strands that never moved are as they were at the first
      // search; those with a moved strand are searched at the points' places now.
      const std::vector<uint8_t> active = separator.ever_moved();
      candidates = separator.near_pairs(detect + 2.0f * slack, true, &active);
      for (const auto &pair : initial)
        if (!active[separator.strand_of(pair.first)] && !active[separator.strand_of(pair.second)])
          candidates.push_back(pair);
      std::sort(candidates.begin(), candidates.end());
      separator.mark_searched();
      ++stats.searches;
      is_near.clear();
      separator.take_moved();
      pairs = separator.near_among(candidates, detect, {}, is_near);
    } else {
      pairs = separator.near_among(candidates, detect, separator.take_moved(), is_near);
    }
    if (!moved) break;
  }
  // `pairs` are those nearer than `detect` now, and any pair nearer than the tolerance is one of them.
  stats.pairs_left = separator.count_near(pairs, tolerance);
  stats.points_moved = separator.points_moved();
  stats.largest_move = separator.largest_move();
  return stats;
}

}  // namespace plume::interp
