#include "interp/guide_field.h"

#include "groom/guide_curve.h"

#include <algorithm>
#include <cstring>

#include "skin/lanes.h"

namespace plume::interp {

namespace {

/// The most cells the search grid may have: a larger grid takes larger cells.
constexpr size_t max_cells = size_t(1) << 21;
/// The most shared cells (one pointer each until listed).
constexpr size_t max_shared_cells = size_t(1) << 22;
/// Lanes of the bounds' loops: one AVX register where the build has AVX2.
#ifdef __AVX2__
constexpr int lanes = 8;
#else
constexpr int lanes = 4;
#endif
/// Pieces per span (see GuideField::PieceSpan).
constexpr int32_t span_pieces = 8;
/// Up to this many spans, a list is gathered by measuring every span in one vectorised loop rather
/// than by walking the search grid.
constexpr size_t all_spans_limit = 4096;

using Float = skin::Lanes<lanes>::Float;

/// Lanes of N fields of packed records of `stride` floats: lane l of r_fields[k] is
/// records[ids[l] * stride + k] (`lanes` ids; N a multiple of the lanes). Each record's fields are
/// loaded as vectors and transposed, not gathered: gathers are slow where the processor's microcode
/// guards them.
template <int N>
[[gnu::always_inline]] inline void gather_lanes(const float *records, int stride, const int32_t *ids,
                                                Float (&r_fields)[N]) {
  static_assert(N % lanes == 0);
  for (int k = 0; k < N; k += lanes) {
#ifdef __AVX2__
    __m256 row[8];
    for (int l = 0; l < 8; ++l) row[l] = _mm256_loadu_ps(records + size_t(ids[l]) * size_t(stride) + size_t(k));
    __m256 low[4], high[4];
    for (int q = 0; q < 4; ++q) {
      low[q] = _mm256_unpacklo_ps(row[2 * q], row[2 * q + 1]);
      high[q] = _mm256_unpackhi_ps(row[2 * q], row[2 * q + 1]);
    }
    __m256 quad[8];
    for (int h = 0; h < 2; ++h) {
      quad[4 * h + 0] = _mm256_shuffle_ps(low[2 * h], low[2 * h + 1], _MM_SHUFFLE(1, 0, 1, 0));
      quad[4 * h + 1] = _mm256_shuffle_ps(low[2 * h], low[2 * h + 1], _MM_SHUFFLE(3, 2, 3, 2));
      quad[4 * h + 2] = _mm256_shuffle_ps(high[2 * h], high[2 * h + 1], _MM_SHUFFLE(1, 0, 1, 0));
      quad[4 * h + 3] = _mm256_shuffle_ps(high[2 * h], high[2 * h + 1], _MM_SHUFFLE(3, 2, 3, 2));
    }
    for (int c = 0; c < 4; ++c) {
      r_fields[k + c] = Float(_mm256_permute2f128_ps(quad[c], quad[4 + c], 0x20));
      r_fields[k + 4 + c] = Float(_mm256_permute2f128_ps(quad[c], quad[4 + c], 0x31));
    }
#else
    skin::Float4 row[4], column[4];
    for (int l = 0; l < 4; ++l)
      std::memcpy(&row[l], records + size_t(ids[l]) * size_t(stride) + size_t(k), sizeof(skin::Float4));
    skin::transpose4(row, column);
    for (int c = 0; c < 4; ++c) r_fields[k + c] = column[c];
#endif
  }
}

/// Distance from x to piece `p`. The parameter starts at the projection on the chord and takes three
/// Newton steps on (c(t) - x) . c'(t) (a piece turns by a few degrees: the distance has one minimum
/// on it), clamped to [0, 1]; the piece's end points are looked at too.
float distance_to_piece(const GuidePiece &p, const Eigen::Vector3f &x) {
  const Eigen::Vector3f chord = p.b + p.c + p.d;  // c(1) - c(0)
  const float chord_sq = chord.squaredNorm();
  float t = chord_sq > 0.0f ? std::clamp((x - p.a).dot(chord) / chord_sq, 0.0f, 1.0f) : 0.0f;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const Eigen::Vector3f at = p.a + t * (p.b + t * (p.c + t * p.d));
    const Eigen::Vector3f first = p.b + t * (2.0f * p.c + 3.0f * t * p.d);
    const Eigen::Vector3f second = 2.0f * p.c + 6.0f * t * p.d;
    const Eigen::Vector3f offset = at - x;
    const float slope = offset.dot(first), curvature = first.squaredNorm() + offset.dot(second);
    if (!(curvature > 0.0f)) break;
    t = std::clamp(t - slope / curvature, 0.0f, 1.0f);
  }
  float best = (p.a + t * (p.b + t * (p.c + t * p.d)) - x).squaredNorm();
  best = std::min({best, (p.a - x).squaredNorm(), (p.a + chord - x).squaredNorm()});
  return std::sqrt(best);
}

/// Cells of edge r_cell over a box of `extent`, per axis; the edge grows by half at a time until
/// there are at most `limit`.
Eigen::Vector3i fit_cells(const Eigen::Vector3f &extent, size_t limit, float &r_cell) {
  for (;;) {
    Eigen::Vector3i dims;
    for (int a = 0; a < 3; ++a) dims[a] = std::max(1, int(std::ceil(extent[a] / r_cell)));
    if (size_t(dims.x()) * size_t(dims.y()) * size_t(dims.z()) <= limit) return dims;
    r_cell *= 1.5f;
  }
}

}  // namespace

GuideField::GuideField(const StrandSet &guides, std::span<const int32_t> members,
                       const FieldShape &shape, float cell)
    : shape_(shape), cell_(cell) {
  // Pieces: the guide's curve (groom/guide_curve.h) through its distinct points (a point within a
  // millionth of a cell of the previous one is left out).
  const float tiny = 1e-6f * cell;
  std::vector<CurvePiece> curve;
  guide_begin_.assign(guides.strand_count(), 0);
  guide_end_.assign(guides.strand_count(), 0);
  for (const int32_t g : members) {
    guide_begin_[size_t(g)] = guide_end_[size_t(g)] = int32_t(pieces_.size());
    guide_curve(guides.points(size_t(g)), tiny, curve);
    for (const CurvePiece &cubic : curve) {
      const Eigen::Vector3f &p0 = cubic.a, m0 = cubic.b, p1 = cubic.end, m1 = cubic.derivative(1.0f);
      const float length = (p1 - p0).norm();
      GuidePiece piece;
      piece.a = cubic.a;
      piece.b = cubic.b;
      piece.c = cubic.c;
      piece.d = cubic.d;
      // The Bezier control points p0, p0 + m0/3, p1 - m1/3, p1 hold the piece (convex hull).
      const Eigen::Vector3f control[4] = {p0, p0 + m0 / 3.0f, p1 - m1 / 3.0f, p1};
      piece.centre = 0.25f * (control[0] + control[1] + control[2] + control[3]);
      for (const Eigen::Vector3f &q : control) piece.radius = std::max(piece.radius, (q - piece.centre).norm());
      piece.radius *= 1.0f + 1e-5f;  // rounding
      piece.chord = length;
      piece.axis = (p1 - p0) / length;
      for (const Eigen::Vector3f &q : control) {
        const float along = std::clamp((q - p0).dot(piece.axis), 0.0f, length);
        piece.sag = std::max(piece.sag, (q - p0 - along * piece.axis).norm());
      }
      piece.sag = piece.sag * (1.0f + 1e-5f) + 1e-6f * length;  // rounding
      piece.guide = g;
      max_sag_ = std::max(max_sag_, piece.sag);
      pieces_.push_back(piece);
    }
    guide_end_[size_t(g)] = int32_t(pieces_.size());
  }
  if (pieces_.empty()) return;
  balls_.reserve(pieces_.size());
  for (const GuidePiece &p : pieces_) {
    capsules_.push_back({p.a.x(), p.a.y(), p.a.z(), p.axis.x(), p.axis.y(), p.axis.z(), p.chord, p.sag});
    balls_.push_back({p.centre, p.radius});
    cubics_.push_back({p.a.x(), p.a.y(), p.a.z(), p.b.x(), p.b.y(), p.b.z(), p.c.x(), p.c.y(), p.c.z(), p.d.x(),
                       p.d.y(), p.d.z(), p.axis.x(), p.axis.y(), p.axis.z(), p.chord});
  }

  // Spans: runs of up to span_pieces consecutive pieces of one guide, each in a ball holding its
  // pieces' balls; searches look at spans first and at the pieces of the spans near enough.
  guide_span_begin_.assign(guides.strand_count(), 0);
  guide_span_end_.assign(guides.strand_count(), 0);
  for (const int32_t g : members) {
    guide_span_begin_[size_t(g)] = int32_t(spans_.size());
    for (int32_t begin = guide_begin_[size_t(g)]; begin < guide_end_[size_t(g)]; begin += span_pieces) {
      const int32_t end = std::min(begin + span_pieces, guide_end_[size_t(g)]);
      Eigen::Vector3f box_lo = Eigen::Vector3f::Constant(INFINITY), box_hi = -box_lo;
      for (int32_t i = begin; i < end; ++i) {
        const GuidePiece &p = pieces_[size_t(i)];
        box_lo = box_lo.cwiseMin(p.centre - Eigen::Vector3f::Constant(p.radius));
        box_hi = box_hi.cwiseMax(p.centre + Eigen::Vector3f::Constant(p.radius));
      }
      PieceSpan span;
      span.centre = 0.5f * (box_lo + box_hi);
      for (int32_t i = begin; i < end; ++i)
        span.radius = std::max(span.radius, (pieces_[size_t(i)].centre - span.centre).norm() + pieces_[size_t(i)].radius);
      span.radius *= 1.0f + 1e-5f;  // rounding
      span.guide = g;
      span.begin = begin;
      span.end = end;
      spans_.push_back(span);
    }
    guide_span_end_[size_t(g)] = int32_t(spans_.size());
  }
  for (const PieceSpan &span : spans_) {
    span_x_.push_back(span.centre.x());
    span_y_.push_back(span.centre.y());
    span_z_.push_back(span.centre.z());
    span_radius_.push_back(span.radius);
  }

  // The search grid: each span listed in every cell its ball's box meets.
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(INFINITY), hi = -lo;
  for (const PieceSpan &p : spans_) {
    lo = lo.cwiseMin(p.centre - Eigen::Vector3f::Constant(p.radius));
    hi = hi.cwiseMax(p.centre + Eigen::Vector3f::Constant(p.radius));
  }
  const Eigen::Vector3f extent = hi - lo;
  dims_ = fit_cells(extent, max_cells, cell_);
  origin_ = lo;
  const size_t cell_count = size_t(dims_.x()) * size_t(dims_.y()) * size_t(dims_.z());
  cell_offsets_.assign(cell_count + 1, 0);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<int32_t> fill;
    if (pass == 1) {
      for (size_t c = 0; c < cell_count; ++c) cell_offsets_[c + 1] += cell_offsets_[c];
      cell_spans_.resize(size_t(cell_offsets_.back()));
      fill.assign(cell_offsets_.begin(), cell_offsets_.end() - 1);
    }
    for (size_t i = 0; i < spans_.size(); ++i) {
      const PieceSpan &p = spans_[i];
      const Eigen::Vector3i from = cell_of(p.centre - Eigen::Vector3f::Constant(p.radius));
      const Eigen::Vector3i to = cell_of(p.centre + Eigen::Vector3f::Constant(p.radius));
      for (int z = from.z(); z <= to.z(); ++z)
        for (int y = from.y(); y <= to.y(); ++y)
          for (int x = from.x(); x <= to.x(); ++x) {
            const size_t c = cell_index(x, y, z);
            if (pass == 0)
              ++cell_offsets_[c + 1];
            else
              cell_spans_[size_t(fill[c]++)] = int32_t(i);
          }
    }
  }

  // The shared cells: half a search cell (larger when the box would need too many), over the
  // pieces' box and two search cells round it, where strands run beside their guides.
  shared_cell_ = 0.5f * cell_;
  const Eigen::Vector3f shared_lo = lo - Eigen::Vector3f::Constant(2.0f * cell_);
  const Eigen::Vector3f shared_extent = extent + Eigen::Vector3f::Constant(4.0f * cell_);
  shared_dims_ = fit_cells(shared_extent, max_shared_cells, shared_cell_);
  shared_origin_ = shared_lo;
  const size_t shared_count = size_t(shared_dims_.x()) * size_t(shared_dims_.y()) * size_t(shared_dims_.z());
  shared_ = std::make_unique<std::atomic<Candidates *>[]>(shared_count);
  for (size_t c = 0; c < shared_count; ++c) shared_[c].store(nullptr, std::memory_order_relaxed);
  parent_dims_ = (shared_dims_ + Eigen::Vector3i::Ones()) / 2;
  const size_t parent_count = size_t(parent_dims_.x()) * size_t(parent_dims_.y()) * size_t(parent_dims_.z());
  parents_ = std::make_unique<std::atomic<Candidates *>[]>(parent_count);
  for (size_t c = 0; c < parent_count; ++c) parents_[c].store(nullptr, std::memory_order_relaxed);
}

GuideField::~GuideField() {
  if (!shared_) return;
  const size_t shared_count = size_t(shared_dims_.x()) * size_t(shared_dims_.y()) * size_t(shared_dims_.z());
  for (size_t c = 0; c < shared_count; ++c) delete shared_[c].load(std::memory_order_relaxed);
  const size_t parent_count = size_t(parent_dims_.x()) * size_t(parent_dims_.y()) * size_t(parent_dims_.z());
  for (size_t c = 0; c < parent_count; ++c) delete parents_[c].load(std::memory_order_relaxed);
}

/// Publishes a list into a shared slot unless another thread did first; returns the slot's list.
const GuideField::Candidates *GuideField::publish(std::atomic<Candidates *> &slot, const Candidates &list) {
  // Kept for the frame: no spare capacity.
  auto made = std::make_unique<Candidates>(list);
  Candidates *expected = nullptr;
  if (slot.compare_exchange_strong(expected, made.get(), std::memory_order_acq_rel, std::memory_order_acquire))
    return made.release();
  return expected;
}

const GuideField::Candidates *GuideField::shared_candidates(const Eigen::Vector3f &x, Cache &cache) const {
  if (!shared_) return nullptr;
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) {
    const float at = std::floor((x[a] - shared_origin_[a]) / shared_cell_);
    if (!(at >= 0.0f && at < float(shared_dims_[a]))) return nullptr;  // outside (or NaN)
    c[a] = int(at);
  }
  std::atomic<Candidates *> &slot =
      shared_[(size_t(c.z()) * size_t(shared_dims_.y()) + size_t(c.y())) * size_t(shared_dims_.x()) + size_t(c.x())];
  const Candidates *list = slot.load(std::memory_order_acquire);
  if (!list) {
    // The parent cell's list (twice the edge, the cell's ball inside its own, with room for
    // rounding), gathered from the search grid; the cell's list narrowed from it. Each depends on
    // its cell alone: whichever thread fills it first, it is the same.
    const Eigen::Vector3i p = c / 2;
    std::atomic<Candidates *> &parent_slot =
        parents_[(size_t(p.z()) * size_t(parent_dims_.y()) + size_t(p.y())) * size_t(parent_dims_.x()) + size_t(p.x())];
    const Candidates *parent = parent_slot.load(std::memory_order_acquire);
    if (!parent) {
      const Eigen::Vector3f centre =
          shared_origin_ + 2.0f * shared_cell_ * (p.cast<float>() + Eigen::Vector3f::Constant(0.5f));
      gather(centre, std::sqrt(3.0f) * shared_cell_ * 1.001f, cache.making, cache.order, cache.lowers,
             cache.distances);
      parent = publish(parent_slot, cache.making);
    }
    const Eigen::Vector3f centre = shared_origin_ + shared_cell_ * (c.cast<float>() + Eigen::Vector3f::Constant(0.5f));
    narrow(*parent, centre, 0.5f * std::sqrt(3.0f) * shared_cell_ * (1.0f + 1e-5f), cache.making, cache.lowers);
    list = publish(slot, cache.making);
  }
  // Rounding can put a point on a cell's border just outside its ball: it takes its own list.
  return (x - list->centre).norm() <= list->valid ? list : nullptr;
}

void GuideField::narrow(const Candidates &from, const Eigen::Vector3f &x, float valid, Candidates &r_list,
                        std::vector<float> &lowers) const {
  // As gather(), over the pieces of a list valid over a ball holding this one (a piece that
  // matters here matters there, so it is listed there): the nearest listed piece's ball bounds the
  // nearest guide's distance (the nearest guide's nearest piece is listed), and a guide's listed
  // pieces hold its nearest ones.
  // The list's bounds hold within `offset` of x, less or more that: the nearest guide is nearer than
  // the least upper bound, and only a guide whose lower bound is below that can hold the nearest
  // piece.
  const float offset = (x - from.centre).norm();
  float upper = INFINITY;
  for (const Candidates::Guide &g : from.guides) upper = std::min(upper, g.upper + offset);
  for (const Candidates::Guide &g : from.guides) {
    if (g.lower - offset > upper) continue;
    for (int32_t e = g.begin; e < g.end; ++e) {
      const Ball &p = balls_[size_t(from.pieces[size_t(e)])];
      upper = std::min(upper, (x - p.centre).norm() + p.radius);
    }
  }
  const float radius = shape_.reach * (upper + valid + shape_.floor) + valid;
  r_list.guides.clear();
  r_list.pieces.clear();
  r_list.piece_lower.clear();
  for (const Candidates::Guide &g : from.guides) {
    if (g.lower - offset > radius) continue;  // farther than the radius everywhere
    bool near = false;
    for (int32_t e = g.begin; e < g.end && !near; ++e) {
      const Ball &p = balls_[size_t(from.pieces[size_t(e)])];
      near = (x - p.centre).norm() - p.radius <= radius;
    }
    if (!near) continue;
    float guide_upper = INFINITY, guide_lower = INFINITY;
    lowers.resize(size_t(g.end - g.begin));
    piece_lowers(x, from.pieces.data() + g.begin, lowers.size(), lowers.data());
    for (int32_t e = g.begin; e < g.end; ++e) {
      const float lower = lowers[size_t(e - g.begin)];
      guide_lower = std::min(guide_lower, lower);
      guide_upper = std::min(guide_upper, lower + 2.0f * capsules_[size_t(from.pieces[size_t(e)])].sag);
    }
    const float piece_radius = shape_.coil_reach * (guide_upper + valid + max_sag_) + valid;
    const int32_t begin = int32_t(r_list.pieces.size());
    for (int32_t e = g.begin; e < g.end; ++e)
      if (lowers[size_t(e - g.begin)] <= piece_radius) {
        r_list.pieces.push_back(from.pieces[size_t(e)]);
        r_list.piece_lower.push_back(lowers[size_t(e - g.begin)]);
      }
    r_list.guides.push_back({g.guide, begin, int32_t(r_list.pieces.size()), guide_lower, guide_upper});
  }
  r_list.centre = x;
  r_list.valid = valid;
}

Eigen::Vector3i GuideField::cell_of(const Eigen::Vector3f &p) const {
  Eigen::Vector3i c;
  for (int a = 0; a < 3; ++a) c[a] = std::clamp(int(std::floor((p[a] - origin_[a]) / cell_)), 0, dims_[a] - 1);
  return c;
}

void GuideField::piece_lowers(const Eigen::Vector3f &x, const int32_t *pieces, size_t count, float *r_lowers,
                              float *r_chords) const {
  // A lower bound of the distance from x to a piece: to its chord, less the sag, lane by lane with
  // Eigen's arithmetic for 3-vectors (a dot product is x0 y0 + (x1 y1 + x2 y2)): the same to the bit
  // as the scalar form. The last lanes repeat the last piece.
  constexpr int W = lanes;
  const Float px = Float{} + x.x(), py = Float{} + x.y(), pz = Float{} + x.z(), zero = Float{};
  const float *records = reinterpret_cast<const float *>(capsules_.data());
  for (size_t e = 0; e < count; e += W) {
    const bool full = e + W <= count;
    alignas(32) int32_t ids[W];
    if (full)
      std::memcpy(ids, pieces + e, sizeof(ids));
    else
      for (int l = 0; l < W; ++l) ids[l] = pieces[std::min(e + size_t(l), count - 1)];
    Float fields[8];
    gather_lanes(records, 8, ids, fields);
    const Float &ax = fields[0], &ay = fields[1], &az = fields[2], &ux = fields[3], &uy = fields[4], &uz = fields[5],
                &chord = fields[6], &sag = fields[7];
    const Float fx = px - ax, fy = py - ay, fz = pz - az;
    const Float dot = fx * ux + (fy * uy + fz * uz);
    const Float along = dot < zero ? zero : (chord < dot ? chord : dot);  // std::clamp
    const Float rx = fx - along * ux, ry = fy - along * uy, rz = fz - along * uz;
    const Float lower = skin::lane_sqrt(rx * rx + (ry * ry + rz * rz)) - sag;
    const Float chord_distance = lower + sag;
    if (full) {
      std::memcpy(r_lowers + e, &lower, sizeof(lower));
      if (r_chords) std::memcpy(r_chords + e, &chord_distance, sizeof(chord_distance));
    } else {
      for (size_t l = 0; e + l < count; ++l) r_lowers[e + l] = lower[l];
      if (r_chords)
        for (size_t l = 0; e + l < count; ++l) r_chords[e + l] = chord_distance[l];
    }
  }
}

void GuideField::piece_distances(const Eigen::Vector3f &x, const int32_t *pieces, size_t count, float *r_distances) const {
  // distance_to_piece() lane by lane, with its arithmetic in the same order (Eigen's for 3-vectors:
  // a sum of three is x0 + (x1 + x2)); a lane whose Newton step stops keeps its parameter.
  constexpr int W = lanes;
  using Int = skin::Lanes<W>::Int;
  const Float zero = Float{}, one = Float{} + 1.0f;
  const Float px = zero + x.x(), py = zero + x.y(), pz = zero + x.z();
  const auto dot = [](Float ux, Float uy, Float uz, Float vx, Float vy, Float vz) { return ux * vx + (uy * vy + uz * vz); };
  const auto clamp01 = [&](Float v) { return v < zero ? zero : (one < v ? one : v); };
  const float *records = reinterpret_cast<const float *>(cubics_.data());
  for (size_t e = 0; e < count; e += W) {
    alignas(32) int32_t ids[W];
    for (int l = 0; l < W; ++l) ids[l] = pieces[std::min(e + size_t(l), count - 1)];
    Float fields[16];
    gather_lanes(records, 16, ids, fields);
    const Float a[3] = {fields[0], fields[1], fields[2]}, b[3] = {fields[3], fields[4], fields[5]},
                c[3] = {fields[6], fields[7], fields[8]}, d[3] = {fields[9], fields[10], fields[11]};
    Float chord[3], from[3];
    for (int k = 0; k < 3; ++k) {
      chord[k] = b[k] + c[k] + d[k];
      from[k] = (k == 0 ? px : k == 1 ? py : pz) - a[k];
    }
    const Float chord_sq = dot(chord[0], chord[1], chord[2], chord[0], chord[1], chord[2]);
    Float t = chord_sq > zero ? clamp01(dot(from[0], from[1], from[2], chord[0], chord[1], chord[2]) / chord_sq) : zero;
    Int active = chord_sq == chord_sq;  // all lanes
    const Float p3[3] = {px, py, pz};
    for (int iteration = 0; iteration < 3; ++iteration) {
      Float offset[3], first[3], second[3];
      for (int k = 0; k < 3; ++k) {
        offset[k] = (a[k] + t * (b[k] + t * (c[k] + t * d[k]))) - p3[k];
        first[k] = b[k] + t * (2.0f * c[k] + (3.0f * t) * d[k]);
        second[k] = 2.0f * c[k] + (6.0f * t) * d[k];
      }
      const Float slope = dot(offset[0], offset[1], offset[2], first[0], first[1], first[2]);
      const Float curvature = dot(first[0], first[1], first[2], first[0], first[1], first[2]) +
                              dot(offset[0], offset[1], offset[2], second[0], second[1], second[2]);
      active = active & (curvature > zero);
      if (!skin::any(active)) break;
      t = active ? clamp01(t - slope / curvature) : t;
    }
    Float at[3], start[3], end[3];
    for (int k = 0; k < 3; ++k) {
      at[k] = (a[k] + t * (b[k] + t * (c[k] + t * d[k]))) - p3[k];
      start[k] = a[k] - p3[k];
      end[k] = (a[k] + chord[k]) - p3[k];
    }
    Float best = dot(at[0], at[1], at[2], at[0], at[1], at[2]);
    const Float to_start = dot(start[0], start[1], start[2], start[0], start[1], start[2]);
    const Float to_end = dot(end[0], end[1], end[2], end[0], end[1], end[2]);
    best = to_start < best ? to_start : best;  // std::min({best, to_start, to_end})
    best = to_end < best ? to_end : best;
    const Float distance = skin::lane_sqrt(best);
    for (size_t l = 0; l < size_t(W) && e + l < count; ++l) r_distances[e + l] = distance[l];
  }
}

void GuideField::piece_tangents(const Eigen::Vector3f &x, const int32_t *pieces, const float *fractions, size_t count,
                                float *r_shares, float *r_x, float *r_y, float *r_z) const {
  // Lane by lane, fade() and the unit tangent with their scalar arithmetic in the same order
  // (Eigen's for 3-vectors: a sum of three is x0 + (x1 + x2); a vector over a scalar is a division
  // per component): the same bits. The last lanes repeat the last piece.
  constexpr int W = lanes;
  const Float zero = Float{}, one = Float{} + 1.0f;
  const Float px = zero + x.x(), py = zero + x.y(), pz = zero + x.z();
  const float *records = reinterpret_cast<const float *>(cubics_.data());
  for (size_t e = 0; e < count; e += W) {
    alignas(32) int32_t ids[W];
    Float u;
    for (int l = 0; l < W; ++l) {
      const size_t at = std::min(e + size_t(l), count - 1);
      ids[l] = pieces[at];
      u[l] = fractions[at];
    }
    const Float share = u <= zero ? one : (u >= one ? zero : one - u * u * (3.0f - 2.0f * u));  // fade()
    Float fields[16];
    gather_lanes(records, 16, ids, fields);
    const Float fx = px - fields[0], fy = py - fields[1], fz = pz - fields[2];
    const Float &ux = fields[12], &uy = fields[13], &uz = fields[14], &chord = fields[15];
    const Float along = (fx * ux + (fy * uy + fz * uz)) / chord;
    const Float t = chord > zero ? (along < zero ? zero : (one < along ? one : along)) : zero;  // std::clamp
    Float first[3];
    for (int k = 0; k < 3; ++k) first[k] = fields[3 + k] + t * (2.0f * fields[6 + k] + (3.0f * t) * fields[9 + k]);
    const Float norm = skin::lane_sqrt(first[0] * first[0] + (first[1] * first[1] + first[2] * first[2]));
    const Float unit_x = norm > zero ? first[0] / norm : ux, unit_y = norm > zero ? first[1] / norm : uy,
                unit_z = norm > zero ? first[2] / norm : uz;
    std::memcpy(r_shares + e, &share, sizeof(Float));
    std::memcpy(r_x + e, &unit_x, sizeof(Float));
    std::memcpy(r_y + e, &unit_y, sizeof(Float));
    std::memcpy(r_z + e, &unit_z, sizeof(Float));
  }
}

float GuideField::span_distances(const Eigen::Vector3f &x, std::vector<float> &r_distances) const {
  // As Eigen's (x - centre).norm() for a 3-vector: dx^2 + (dy^2 + dz^2), the same to the bit; the
  // least of distance + radius is the same whichever order it is taken in.
  constexpr int W = lanes;
  const size_t count = spans_.size();
  r_distances.resize(count);
  const float *sx = span_x_.data(), *sy = span_y_.data(), *sz = span_z_.data(), *sr = span_radius_.data();
  float *out = r_distances.data();
  const Float px = Float{} + x.x(), py = Float{} + x.y(), pz = Float{} + x.z();
  Float least = Float{} + INFINITY;
  size_t i = 0;
  for (; i + W <= count; i += W) {
    Float cx, cy, cz, radius;
    std::memcpy(&cx, sx + i, sizeof(Float));
    std::memcpy(&cy, sy + i, sizeof(Float));
    std::memcpy(&cz, sz + i, sizeof(Float));
    std::memcpy(&radius, sr + i, sizeof(Float));
    const Float dx = px - cx, dy = py - cy, dz = pz - cz;
    const Float distance = skin::lane_sqrt(dx * dx + (dy * dy + dz * dz));
    std::memcpy(out + i, &distance, sizeof(Float));
    const Float far = distance + radius;
    least = far < least ? far : least;  // std::min(least, far)
  }
  float upper = INFINITY;
  for (int l = 0; l < W; ++l) upper = std::min(upper, least[l]);
  for (; i < count; ++i) {
    out[i] = (x - spans_[i].centre).norm();
    upper = std::min(upper, out[i] + sr[i]);
  }
  return upper;
}

void GuideField::spans_within(const std::vector<float> &distances, float radius, std::vector<int32_t> &r_found) const {
  constexpr int W = lanes;
  const size_t count = spans_.size();
  const float *sr = span_radius_.data();
  const Float reach = Float{} + radius;
  size_t i = 0;
  for (; i + W <= count; i += W) {
    Float distance, span_radius;
    std::memcpy(&distance, distances.data() + i, sizeof(Float));
    std::memcpy(&span_radius, sr + i, sizeof(Float));
    for (int bits = skin::lane_bits(distance - span_radius <= reach); bits != 0; bits &= bits - 1)
      r_found.push_back(int32_t(i) + __builtin_ctz(unsigned(bits)));
  }
  for (; i < count; ++i)
    if (distances[i] - sr[i] <= radius) r_found.push_back(int32_t(i));
}

void GuideField::gather(const Eigen::Vector3f &x, float valid_asked, Candidates &r_list, std::vector<int32_t> &found,
                        std::vector<float> &lowers, std::vector<float> &distances) const {
  // An upper bound of the nearest guide's distance: the nearest span's ball, found ring by ring of
  // cells round x (a span not met within ring k lies in cells of ring k + 1 or more, at least k
  // cells away), then the nearest piece's ball among the spans found below. Points outside the
  // grid's box, and fields of few spans, look at every span (the same bound: a span the rings do
  // not meet is at least as far as the nearest met).
  float upper = INFINITY;
  const Eigen::Vector3f box_lo = origin_, box_hi = origin_ + cell_ * dims_.cast<float>();
  const bool inside = (x.array() >= box_lo.array()).all() && (x.array() <= box_hi.array()).all();
  const bool all_spans = !inside || spans_.size() <= all_spans_limit;
  if (all_spans) {
    upper = span_distances(x, distances);
  } else {
    const Eigen::Vector3i c0 = cell_of(x);
    const int rings = dims_.maxCoeff();
    const auto scan = [&](int xi, int y, int z) {
      const size_t c = cell_index(xi, y, z);
      for (int32_t e = cell_offsets_[c]; e < cell_offsets_[c + 1]; ++e) {
        const PieceSpan &p = spans_[size_t(cell_spans_[size_t(e)])];
        upper = std::min(upper, (x - p.centre).norm() + p.radius);
      }
    };
    // Ring k: the cells at chessboard distance k, whole rows where z or y is on the ring, else the
    // row's two ends.
    for (int k = 0; k <= rings && !(float(k - 1) * cell_ >= upper); ++k)
      for (int z = std::max(c0.z() - k, 0); z <= std::min(c0.z() + k, dims_.z() - 1); ++z)
        for (int y = std::max(c0.y() - k, 0); y <= std::min(c0.y() + k, dims_.y() - 1); ++y) {
          if (std::abs(z - c0.z()) == k || std::abs(y - c0.y()) == k) {
            for (int xi = std::max(c0.x() - k, 0); xi <= std::min(c0.x() + k, dims_.x() - 1); ++xi) scan(xi, y, z);
          } else {
            if (c0.x() - k >= 0) scan(c0.x() - k, y, z);
            if (k > 0 && c0.x() + k < dims_.x()) scan(c0.x() + k, y, z);
          }
        }
  }
  // The bound of span i's ball at x.
  const auto span_bound = [&](int32_t i) {
    return (all_spans ? distances[size_t(i)] : (x - spans_[size_t(i)].centre).norm()) - spans_[size_t(i)].radius;
  };
  // Within `valid` of x: the nearest guide is nearer than upper + valid, so a guide weighs only if
  // some piece of it lies within reach * (upper + valid + floor) + valid of x; and a piece counts in
  // its guide's tangent only within coil_reach times the guide's distance, which is below the guide's
  // own bound plus valid. So the list keeps, of the guides near enough, the pieces near enough.
  const auto valid_for = [&](float bound) {
    return valid_asked >= 0.0f ? valid_asked : std::max(0.5f * bound, 0.5f * cell_);
  };
  float valid = valid_for(upper);
  float radius = shape_.reach * (upper + valid + shape_.floor) + valid;
  found.clear();
  const Eigen::Vector3i from = cell_of(x - Eigen::Vector3f::Constant(radius));
  const Eigen::Vector3i to = cell_of(x + Eigen::Vector3f::Constant(radius));
  const size_t cells = size_t(to.x() - from.x() + 1) * size_t(to.y() - from.y() + 1) * size_t(to.z() - from.z() + 1);
  auto consider = [&](int32_t i) {
    if (span_bound(i) <= radius) found.push_back(i);
  };
  if (!inside || cells > spans_.size() / 4) {
    if (all_spans)
      spans_within(distances, radius, found);
    else
      for (size_t i = 0; i < spans_.size(); ++i) consider(int32_t(i));
  } else {
    for (int z = from.z(); z <= to.z(); ++z)
      for (int y = from.y(); y <= to.y(); ++y)
        for (int xi = from.x(); xi <= to.x(); ++xi) {
          const size_t c = cell_index(xi, y, z);
          for (int32_t e = cell_offsets_[c]; e < cell_offsets_[c + 1]; ++e) consider(cell_spans_[size_t(e)]);
        }
    std::sort(found.begin(), found.end());
    found.erase(std::unique(found.begin(), found.end()), found.end());
  }
  // The nearest piece's ball: it lies in a span whose ball is nearer than `upper`, found above.
  for (const int32_t i : found) {
    const PieceSpan &span = spans_[size_t(i)];
    if (!(span_bound(i) < upper)) continue;
    for (int32_t j = span.begin; j < span.end; ++j)
      upper = std::min(upper, (x - balls_[size_t(j)].centre).norm() + balls_[size_t(j)].radius);
  }
  valid = valid_for(upper);
  radius = shape_.reach * (upper + valid + shape_.floor) + valid;

  // Per guide with a span within the radius: its pieces' capsule bounds, span by span, the span of
  // least ball bound first; a span whose ball lies beyond the pieces' radius holds no piece that
  // can count (its pieces' chords are farther too: the ball holds them).
  r_list.guides.clear();
  r_list.pieces.clear();
  r_list.piece_lower.clear();
  const float hit = 1e-6f * cell_;
  for (size_t f = 0; f < found.size();) {
    const int32_t g = spans_[size_t(found[f])].guide;
    bool near = false;
    for (; f < found.size() && spans_[size_t(found[f])].guide == g; ++f)
      near = near || span_bound(found[f]) <= radius;
    if (!near) continue;
    const int32_t span_begin = guide_span_begin_[size_t(g)], span_end = guide_span_end_[size_t(g)];
    const int32_t begin_piece = guide_begin_[size_t(g)], end_piece = guide_end_[size_t(g)];
    lowers.assign(size_t(end_piece - begin_piece), INFINITY);
    float guide_upper = INFINITY, guide_lower = INFINITY;
    int32_t first = span_begin;
    float first_bound = INFINITY;
    for (int32_t i = span_begin; i < span_end; ++i) {
      const float bound = span_bound(i);
      if (bound < first_bound) {
        first_bound = bound;
        first = i;
      }
    }
    const auto measure_span = [&](int32_t i) {
      const int32_t begin = spans_[size_t(i)].begin, end = spans_[size_t(i)].end;
      int32_t ids[span_pieces];
      for (int32_t j = begin; j < end; ++j) ids[j - begin] = j;
      piece_lowers(x, ids, size_t(end - begin), lowers.data() + (begin - begin_piece));
      for (int32_t j = begin; j < end; ++j) {
        const float lower = lowers[size_t(j - begin_piece)];
        guide_lower = std::min(guide_lower, lower);
        guide_upper = std::min(guide_upper, lower + 2.0f * capsules_[size_t(j)].sag);
      }
    };
    measure_span(first);
    for (int32_t i = span_begin; i < span_end; ++i) {
      if (i == first) continue;
      const float bound = span_bound(i);
      const float piece_radius = shape_.coil_reach * (guide_upper + valid + max_sag_) + valid + hit;
      if (bound <= piece_radius)
        measure_span(i);
      else
        guide_lower = std::min(guide_lower, bound);
    }
    const float piece_radius = shape_.coil_reach * (guide_upper + valid + max_sag_) + valid;
    const int32_t begin = int32_t(r_list.pieces.size());
    for (int32_t i = begin_piece; i < end_piece; ++i)
      if (lowers[size_t(i - begin_piece)] <= piece_radius) {
        r_list.pieces.push_back(i);
        r_list.piece_lower.push_back(lowers[size_t(i - begin_piece)]);
      }
    r_list.guides.push_back({g, begin, int32_t(r_list.pieces.size()), guide_lower, guide_upper});
  }
  r_list.centre = x;
  r_list.valid = valid;
}

GuideField::Sample GuideField::evaluate(const Eigen::Vector3f &x, Cache &cache,
                                        const GuideAttenuation *attenuation) const {
  Sample sample;
  if (pieces_.empty()) return sample;
  const Candidates *listed = shared_candidates(x, cache);
  if (!listed) {
    if (!((x - cache.own.centre).norm() <= cache.own.valid)) gather(x, -1.0f, cache.own, cache.order, cache.lowers, cache.distances);
    listed = &cache.own;
  }
  const Candidates &candidates = *listed;

  // Guide bounds at x from the cache's (1-Lipschitz): the nearest guide is nearer than the smallest
  // upper bound, and a guide every point of which is farther than reach times (that plus the floor)
  // does not weigh.
  // Within a weighing guide, every cached piece's chord distance and lower bound (capsule about its
  // chord) are computed, and the exact distance only to the pieces that can be the nearest.
  // Every listed piece takes at most one slot of `near` (each guide is measured once).
  if (cache.near.size() < candidates.pieces.size()) {
    cache.near.resize(candidates.pieces.size());
    cache.measured_lower.resize(candidates.pieces.size());
    cache.measured_chord.resize(candidates.pieces.size());
  }
  Cache::Near *near = cache.near.data();
  size_t count = 0;
  const float moved = (x - candidates.centre).norm();
  float upper = INFINITY;
  for (const Candidates::Guide &g : candidates.guides) upper = std::min(upper, g.upper + moved);
  // One guide's pieces into `near`, its slots and its slot of least lower bound into a group.
  const auto list = [&](const Candidates::Guide &g) {
    Cache::Group group{g.guide, count, count, count, INFINITY, INFINITY, INFINITY};
    // A piece whose bound keeps it beyond coil_reach times the guide's nearest chord (at most its
    // distance plus the largest sag) takes no share and cannot be the nearest: it is left out.
    const float skip = shape_.coil_reach * (g.upper + moved + max_sag_) + moved + 1e-6f * cell_;
    // (The bounds are computed lanes at a time for all the guide's listed pieces: a few more.)
    const int32_t *listed = candidates.pieces.data() + g.begin;
    const float *listed_lower = candidates.piece_lower.data() + g.begin;
    float *lowers = cache.measured_lower.data(), *chords = cache.measured_chord.data();
    piece_lowers(x, listed, size_t(g.end - g.begin), lowers, chords);
    size_t best = count;
    float best_lower = INFINITY, chord_min = INFINITY;
    for (int32_t e = 0; e < g.end - g.begin; ++e) {
      if (listed_lower[e] > skip) continue;
      near[count] = {listed[e], lowers[e], INFINITY, chords[e]};
      if (count == group.begin || lowers[e] < best_lower) {
        best = count;
        best_lower = lowers[e];
      }
      chord_min = std::min(chord_min, chords[e]);
      ++count;
    }
    group.end = count;
    group.best = best;
    group.chord_min = chord_min;
    return group;
  };
  // The guide's distance: the exact distance to the piece of least lower bound, then to every piece
  // whose bound lies below it (a piece whose bound is not below the best found cannot be nearer:
  // computing it or not leaves the smallest the same).
  const auto measure = [&](const Candidates::Guide &g) {
    Cache::Group group = list(g);
    float distance = distance_to_piece(pieces_[size_t(near[group.best].piece)], x);
    near[group.best].distance = distance;
    for (size_t j = group.begin; j < group.end; ++j) {
      Cache::Near &n = near[j];
      if (j == group.best || !(n.lower < distance)) continue;
      n.distance = distance_to_piece(pieces_[size_t(n.piece)], x);
      distance = std::min(distance, n.distance);
    }
    group.distance = distance;
    return group;
  };
  // Without attenuation a guide weighs nothing beyond reach times (the nearest guide's distance plus
  // the floor), so the guide of least bound is measured first and its distance tightens the limit:
  // the guides skipped for it would have had no weight, and the answer is the same to the bit.
  // Its group is put in its place in guide order below.
  const Candidates::Guide *first = nullptr;
  Cache::Group first_group{};
  if (!attenuation) {
    for (const Candidates::Guide &g : candidates.guides)
      if (g.begin != g.end && (!first || g.lower < first->lower)) first = &g;
    if (first) {
      first_group = measure(*first);
      upper = std::min(upper, first_group.distance);
    }
  }
  const float guide_limit = shape_.reach * (upper + shape_.floor);
  // The other guides within the limit, in guide order, their exact distances lanes at a time across
  // the guides: first each guide's piece of least bound, then every piece whose bound is below that
  // distance. Each guide's distance d_g is the smallest of its pieces'.
  std::vector<Cache::Group> &groups = cache.groups;
  groups.clear();
  for (const Candidates::Guide &g : candidates.guides) {
    if (&g == first || g.lower - moved >= guide_limit || g.begin == g.end) continue;
    const Cache::Group group = list(g);
    if (group.end > group.begin) groups.push_back(group);
  }
  std::vector<int32_t> &ids = cache.ids;
  std::vector<size_t> &slots = cache.slots;
  ids.clear();
  for (const Cache::Group &group : groups) ids.push_back(near[group.best].piece);
  cache.distances_out.resize(std::max(cache.distances_out.size(), ids.size()));
  piece_distances(x, ids.data(), ids.size(), cache.distances_out.data());
  for (size_t k = 0; k < groups.size(); ++k)
    near[groups[k].best].distance = groups[k].distance = cache.distances_out[k];
  ids.clear();
  slots.clear();
  for (const Cache::Group &group : groups) {
    const float distance = group.distance;
    for (size_t j = group.begin; j < group.end; ++j)
      if (j != group.best && near[j].lower < distance) {
        slots.push_back(j);
        ids.push_back(near[j].piece);
      }
  }
  cache.distances_out.resize(std::max(cache.distances_out.size(), ids.size()));
  piece_distances(x, ids.data(), ids.size(), cache.distances_out.data());
  for (size_t k = 0, g = 0; k < slots.size(); ++k) {
    while (slots[k] >= groups[g].end) ++g;
    near[slots[k]].distance = cache.distances_out[k];
    groups[g].distance = std::min(groups[g].distance, cache.distances_out[k]);
  }
  // The first guide's group in its place in guide order; per guide its effective distance, d_g /
  // factor with an attenuation; the nearest of both.
  if (first && first_group.end > first_group.begin) {
    size_t place = 0;
    while (place < groups.size() && groups[place].guide < first->guide) ++place;
    groups.insert(groups.begin() + ptrdiff_t(place), first_group);
  }
  float nearest = INFINITY, nearest_effective = INFINITY;
  for (Cache::Group &group : groups) {
    group.counted = group.distance;
    if (attenuation && group.distance < INFINITY) {
      const float factor = attenuation->factor(group.guide);
      group.counted = factor > 0.0f ? group.distance / factor : INFINITY;
    }
    nearest = std::min(nearest, group.distance);
    nearest_effective = std::min(nearest_effective, group.counted);
  }
  sample.nearest = nearest;
  const float hit = 1e-6f * cell_;
  // The floor at x: it grows from 0 on a guide to its full value (FieldShape::floor_slope).
  const float floor_here = std::min(shape_.floor, shape_.floor_slope * nearest_effective);
  const bool on_guide = nearest <= hit;
  // Per weighing guide: its weight and its pieces with a share, in order, each with u = e_j - e_min
  // over the span (its share fade(u)); the shares and unit tangents are computed lanes at a time over
  // all of them, then added guide by guide in the same order as one guide at a time.
  std::vector<int32_t> &shared = cache.ids;
  std::vector<float> &fractions = cache.fractions;
  std::vector<Cache::Weighing> &weighing = cache.weighing;
  shared.clear();
  fractions.clear();
  weighing.clear();
  for (const Cache::Group &group : groups) {
    const size_t begin = group.begin, end = group.end;
    const float distance = group.distance;
    // On a guide: that guide alone (or the guides meeting there). Elsewhere 1/d (effective), faded
    // out between (reach - 1) and reach times the nearest guide's plus the floor here.
    const float counted = group.counted;
    const float weight = on_guide ? (distance <= hit ? 1.0f : 0.0f)
                                  : (counted < INFINITY ? fade(counted / (nearest_effective + floor_here) - (shape_.reach - 1.0f)) / counted
                                                        : 0.0f);
    if (!(weight > 0.0f)) continue;
    // The guide's tangent: its pieces' chord tangents, each faded as its chord lies farther than
    // the guide's nearest chord (e_j against e_min, continuous in x; on the guide the piece under
    // x has the nearest chord).
    const float chord_min = group.chord_min;
    const float span = (shape_.coil_reach - 1.0f) * chord_min + hit;
    const size_t first_share = shared.size();
    for (size_t j = begin; j < end; ++j) {
      // A chord at least `span` beyond the nearest has u >= 1 (rounding keeps it so): no share.
      const float beyond = near[j].chord_distance - chord_min;
      if (beyond >= span) continue;
      shared.push_back(near[j].piece);
      fractions.push_back(beyond / span);
    }
    weighing.push_back({weight, first_share, shared.size()});
  }
  const size_t padded = (shared.size() + lanes - 1) / lanes * lanes;
  for (std::vector<float> *v : {&cache.shares, &cache.unit_x, &cache.unit_y, &cache.unit_z})
    if (v->size() < padded) v->resize(padded);
  piece_tangents(x, shared.data(), fractions.data(), shared.size(), cache.shares.data(), cache.unit_x.data(),
                 cache.unit_y.data(), cache.unit_z.data());
  Eigen::Vector3f sum = Eigen::Vector3f::Zero();
  float total = 0.0f;
  for (const Cache::Weighing &w : weighing) {
    Eigen::Vector3f tangent = Eigen::Vector3f::Zero();
    for (size_t e = w.begin; e < w.end; ++e) {
      const float share = cache.shares[e];
      if (share > 0.0f) tangent += share * Eigen::Vector3f(cache.unit_x[e], cache.unit_y[e], cache.unit_z[e]);
    }
    const float norm = tangent.norm();
    if (norm > 0.0f) {
      sum += (w.weight / norm) * tangent;
      total += w.weight;
    }
  }
  if (total > 0.0f) sample.direction = sum / total;
  return sample;
}

}  // namespace plume::interp
