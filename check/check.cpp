#include "check/check.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <utility>

#include "groom/error.h"

namespace plume::check {

namespace {

using Eigen::Vector3f;

float mesh_diagonal(const Mesh &mesh) {
  if (mesh.positions.empty()) return 0.0f;
  Eigen::AlignedBox3f box;
  for (const Vector3f &p : mesh.positions) box.extend(p);
  return box.diagonal().norm();
}

/// Squared distance between segments p0-p1 and q0-q1 (closest points, clamped to both segments;
/// Ericson, Real-Time Collision Detection, 5.1.9).
float segment_distance_squared(const Vector3f &p0, const Vector3f &p1, const Vector3f &q0, const Vector3f &q1) {
  const Vector3f d1 = p1 - p0, d2 = q1 - q0, r = p0 - q0;
  const float a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  constexpr float tiny = 1e-20f;
  float s = 0.0f, t = 0.0f;
  if (a <= tiny && e <= tiny) return r.squaredNorm();
  if (a <= tiny) {
    t = std::clamp(f / e, 0.0f, 1.0f);
  } else {
    const float c = d1.dot(r);
    if (e <= tiny) {
      s = std::clamp(-c / a, 0.0f, 1.0f);
    } else {
      const float b = d1.dot(d2), denom = a * e - b * b;
      s = denom > tiny ? std::clamp((b * f - c * e) / denom, 0.0f, 1.0f) : 0.0f;
      t = (b * s + f) / e;
      if (t < 0.0f) {
        t = 0.0f;
        s = std::clamp(-c / a, 0.0f, 1.0f);
      } else if (t > 1.0f) {
        t = 1.0f;
        s = std::clamp((b - c) / a, 0.0f, 1.0f);
      }
    }
  }
  return ((p0 + d1 * s) - (q0 + d2 * t)).squaredNorm();
}

/// Point at arc length `s` along a polyline (its tip past the end).
Vector3f point_at_arc_length(std::span<const Vector3f> points, double s) {
  for (size_t i = 0; i + 1 < points.size(); ++i) {
    const double length = (points[i + 1] - points[i]).norm();
    if (s <= length) return length > 0.0 ? Vector3f(points[i] + float(s / length) * (points[i + 1] - points[i])) : points[i];
    s -= length;
  }
  return points.back();
}

}  // namespace

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
    if (inside_per_strand[s] && r_examples.size() < max_examples)
      r_examples.push_back(strands.ids.size() == size_t(strand_count) ? strands.ids[s] : s);
  }
  std::sort(r_examples.begin(), r_examples.end());
  return total;
}

CrossingCount count_crossings(const StrandSet &strands, float tolerance, size_t max_examples) {
  CrossingCount result;
  const size_t strand_count = strands.strand_count();
  // Segment i starts at point segment_start[i]; the last point of each strand starts none.
  std::vector<uint32_t> segment_start, segment_strand;
  segment_start.reserve(strands.point_count());
  segment_strand.reserve(strands.point_count());
  double length_sum = 0.0;
  for (size_t s = 0; s < strand_count; ++s)
    for (int64_t p = strands.offsets[s]; p + 1 < strands.offsets[s + 1]; ++p) {
      segment_start.push_back(uint32_t(p));
      segment_strand.push_back(uint32_t(s));
      length_sum += (strands.positions[size_t(p + 1)] - strands.positions[size_t(p)]).norm();
    }
  const size_t segment_count = segment_start.size();
  if (segment_count < 2) return result;
  Eigen::AlignedBox3f bounds;
  for (const Vector3f &p : strands.positions) bounds.extend(p);
  // Cells of a third of the mean segment length (at least twice the tolerance), and segments cut
  // into pieces no longer than a cell, so a dense bundle of long segments is still split finely
  // (finer cells examine fewer pairs but cost more in entries: a tenth of the segment length was
  // slower on the Sintel benchmark). The cell only sets the work: the count is the same for any. Cells are keyed by their
  // linear index in the grid over the strands' bounds, kept within 32 bits by growing the cell.
  float cell = std::max(2.0f * tolerance, float(length_sum / double(segment_count)) / 3.0f);
  if (!(cell > 0.0f) || !bounds.sizes().allFinite()) return result;
  const float half_tol = 0.5f * tolerance;
  const Vector3f origin = bounds.min().array() - (half_tol + cell);
  Eigen::Vector3i dims;
  for (;;) {
    for (int k = 0; k < 3; ++k) dims[k] = int(std::ceil((bounds.max()[k] + half_tol + cell - origin[k]) / cell)) + 1;
    if (double(dims.x()) * double(dims.y()) * double(dims.z()) < 4.0e9) break;
    cell *= 2.0f;
  }
  const float inv_cell = 1.0f / cell;
  const auto cell_of = [&](const Vector3f &p) -> Eigen::Vector3i {
    Eigen::Vector3i c;
    for (int k = 0; k < 3; ++k) c[k] = std::clamp(int((p[k] - origin[k]) * inv_cell), 0, dims[k] - 1);
    return c;
  };
  const auto key_of = [&](const Eigen::Vector3i &c) {
    return uint32_t((uint64_t(c.z()) * uint64_t(dims.y()) + uint64_t(c.y())) * uint64_t(dims.x()) + uint64_t(c.x()));
  };

  // Pieces: piece k of m of segment i is its stretch from k / m to (k + 1) / m.
  std::vector<uint32_t> piece_first(segment_count + 1, 0);
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < int64_t(segment_count); ++i) {
    const size_t p = segment_start[size_t(i)];
    const float length = (strands.positions[p + 1] - strands.positions[p]).norm();
    piece_first[size_t(i) + 1] = uint32_t(std::clamp(int(std::ceil(length / cell)), 1, 255));
  }
  for (size_t i = 0; i < segment_count; ++i) piece_first[i + 1] += piece_first[i];
  const size_t piece_count = piece_first[segment_count];
  std::vector<uint32_t> piece_segment(piece_count);
#pragma omp parallel for schedule(static)
  for (int64_t i = 0; i < int64_t(segment_count); ++i)
    for (uint32_t q = piece_first[size_t(i)]; q < piece_first[size_t(i) + 1]; ++q) piece_segment[q] = uint32_t(i);
  // A piece's box grown by half the tolerance: two pieces whose segments come within the tolerance
  // have overlapping boxes (a relative slack covers rounding, so the box test never decides a pair).
  std::vector<Vector3f> piece_low(piece_count), piece_high(piece_count);
  const auto compute_piece_box = [&](uint32_t q, Vector3f &r_low, Vector3f &r_high) {
    const uint32_t i = piece_segment[q];
    const Vector3f &a = strands.positions[segment_start[i]];
    const Vector3f d = strands.positions[segment_start[i] + 1] - a;
    const float m = float(piece_first[i + 1] - piece_first[i]), k = float(q - piece_first[i]);
    const Vector3f p0 = a + d * (k / m), p1 = a + d * ((k + 1.0f) / m);
    const Vector3f grow = Vector3f::Constant(half_tol) + 1e-6f * (p0.cwiseAbs().cwiseMax(p1.cwiseAbs()) + d.cwiseAbs());
    r_low = p0.cwiseMin(p1) - grow;
    r_high = p0.cwiseMax(p1) + grow;
  };
#pragma omp parallel for schedule(static)
  for (int64_t q = 0; q < int64_t(piece_count); ++q)
    compute_piece_box(uint32_t(q), piece_low[size_t(q)], piece_high[size_t(q)]);

  // (cell key, piece) entries for every cell a grown piece box touches, sorted by key with a
  // stable radix sort (pieces stay ascending within a cell).
  std::vector<size_t> entry_first(piece_count + 1, 0);
#pragma omp parallel for schedule(static)
  for (int64_t q = 0; q < int64_t(piece_count); ++q) {
    entry_first[size_t(q) + 1] =
        size_t((cell_of(piece_high[size_t(q)]) - cell_of(piece_low[size_t(q)]) + Eigen::Vector3i::Ones()).prod());
  }
  for (size_t q = 0; q < piece_count; ++q) entry_first[q + 1] += entry_first[q];
  const size_t entry_count = entry_first[piece_count];
  // A piece's box spans at most three cells per axis (a piece is no longer than a cell, and the
  // tolerance at most half of one), 27 entries, unless the slack for rounding is wider than a cell:
  // strands far from the origin, whose float coordinates are coarser than the tolerance. The
  // entries would then outgrow memory before any comparison: refuse.
  if (double(entry_count) > kCrossingEntriesPerPiece * double(piece_count)) {
    const float reach = std::max(bounds.min().cwiseAbs().maxCoeff(), bounds.max().cwiseAbs().maxCoeff());
    char message[400];
    std::snprintf(message, sizeof message,
                  "the strands reach %g from the origin, where float rounding (about %g) is coarser than the "
                  "tolerance and the crossing grid's cells (%g): %.0f grid entries per segment piece, over the "
                  "budget of %.0f (check strands placed near the origin, or with a tolerance above the rounding)",
                  double(reach), double(reach) * 6e-8, double(cell), double(entry_count) / double(piece_count),
                  kCrossingEntriesPerPiece);
    throw InputError(message);
  }
  std::vector<uint64_t> entries(entry_count), scratch(entry_count);  // key << 32 | piece
#pragma omp parallel for schedule(static)
  for (int64_t q = 0; q < int64_t(piece_count); ++q) {
    const Eigen::Vector3i lo = cell_of(piece_low[size_t(q)]), hi = cell_of(piece_high[size_t(q)]);
    size_t e = entry_first[size_t(q)];
    for (int z = lo.z(); z <= hi.z(); ++z)
      for (int y = lo.y(); y <= hi.y(); ++y)
        for (int x = lo.x(); x <= hi.x(); ++x) entries[e++] = uint64_t(key_of({x, y, z})) << 32 | uint64_t(q);
  }
  {
    const uint64_t largest_key = uint64_t(dims.x()) * uint64_t(dims.y()) * uint64_t(dims.z());
    int key_bits = 1;
    while (key_bits < 32 && (uint64_t(1) << key_bits) < largest_key) ++key_bits;
    constexpr int radix_bits = 11;
    std::vector<size_t> counts(size_t(1) << radix_bits);
    for (int shift = 32; shift < 32 + key_bits; shift += radix_bits) {
      std::fill(counts.begin(), counts.end(), 0);
      const uint64_t digit_mask = (uint64_t(1) << radix_bits) - 1;
      for (const uint64_t v : entries) ++counts[(v >> shift) & digit_mask];
      size_t sum = 0;
      for (size_t &c : counts) sum += std::exchange(c, sum);
      for (const uint64_t v : entries) scratch[counts[(v >> shift) & digit_mask]++] = v;
      entries.swap(scratch);
    }
  }
  std::vector<size_t> cell_first;  // runs of entries with one key, of two pieces or more
  for (size_t e = 0; e < entry_count;) {
    size_t end = e + 1;
    while (end < entry_count && entries[end] >> 32 == entries[e] >> 32) ++end;
    if (end - e >= 2) {
      cell_first.push_back(e);
      cell_first.push_back(end);
    }
    e = end;
  }
  const int64_t busy_cells = int64_t(cell_first.size() / 2);

  // The work is known before any comparison: a cell of n pieces compares at most n (n - 1) / 2
  // pairs. A tolerance that puts thousands of pieces side by side for every segment asks for
  // (nearly) all pairs, which no file of a useful size can afford: refuse it.
  for (int64_t c = 0; c < busy_cells; ++c) {
    const double n = double(cell_first[2 * size_t(c) + 1] - cell_first[2 * size_t(c)]);
    result.piece_pairs_binned += size_t(n * (n - 1.0) / 2.0);
  }
  const double budget = kCrossingPiecePairsPerSegment * double(segment_count);
  if (double(result.piece_pairs_binned) > budget) {
    char message[320];
    std::snprintf(message, sizeof message,
                  "crossing tolerance %g puts %.3g piece pairs side by side, %.0f per segment, over the budget of "
                  "%.0f per segment (the tolerance is meant to be far below the spacing of the strands)",
                  double(tolerance), double(result.piece_pairs_binned),
                  double(result.piece_pairs_binned) / double(segment_count), kCrossingPiecePairsPerSegment);
    throw InputError(message);
  }

  // Segment index of each strand's first segment (strands without a segment get an empty range).
  std::vector<uint32_t> strand_first_segment(strand_count + 1, uint32_t(segment_count));
  for (size_t i = segment_count; i-- > 0;) strand_first_segment[segment_strand[i]] = uint32_t(i);
  for (size_t s = strand_count; s-- > 0;)
    strand_first_segment[s] = std::min(strand_first_segment[s], strand_first_segment[s + 1]);

  // The crossing rule for segments i < j of different strands.
  const float tolerance_squared = tolerance * tolerance;
  const auto segments_cross = [&](uint32_t i, uint32_t j) {
    const Vector3f &a0 = strands.positions[segment_start[i]], &a1 = strands.positions[segment_start[i] + 1];
    const Vector3f &b0 = strands.positions[segment_start[j]], &b1 = strands.positions[segment_start[j] + 1];
    if (segment_distance_squared(a0, a1, b0, b1) > tolerance_squared) return false;
    const uint32_t sa = segment_strand[i], sb = segment_strand[j];
    const bool at_root = segment_start[i] == strands.offsets[sa] || segment_start[j] == strands.offsets[sb];
    return !(at_root && (strands.positions[size_t(strands.offsets[sa])] - strands.positions[size_t(strands.offsets[sb])])
                                .norm() < tolerance);
  };
  const auto boxes_overlap = [&](uint32_t p, uint32_t q) {
    return !(piece_low[p].array() > piece_high[q].array()).any() && !(piece_low[q].array() > piece_high[p].array()).any();
  };
  // The first crossing segment pair (i, j) of strands a < b in that order, or none. Strand b's
  // segments are scanned in blocks under one box each, so a segment of a far from most of b costs a
  // few box tests; a box is set aside when it is farther than the tolerance from the segment's box.
  struct FirstCrossing {
    uint64_t strands = ~uint64_t(0);  // a << 32 | b, or none
    uint32_t i = 0, j = 0;
  };
  constexpr uint32_t kBlock = 64;
  const auto first_crossing = [&](uint32_t sa, uint32_t sb, std::vector<Eigen::AlignedBox3f> &r_block_boxes) {
    const auto segment_box = [&](uint32_t i) {
      const Vector3f &a0 = strands.positions[segment_start[i]], &a1 = strands.positions[segment_start[i] + 1];
      return Eigen::AlignedBox3f(a0.cwiseMin(a1), a0.cwiseMax(a1));
    };
    const uint32_t b_first = strand_first_segment[sb], b_end = strand_first_segment[sb + 1];
    r_block_boxes.clear();
    for (uint32_t start = b_first; start < b_end; start += kBlock) {
      Eigen::AlignedBox3f box = segment_box(start);
      for (uint32_t j2 = start + 1; j2 < std::min(start + kBlock, b_end); ++j2) box.extend(segment_box(j2));
      r_block_boxes.push_back(box);
    }
    const auto far = [&](const Eigen::AlignedBox3f &box, const Eigen::Array3f &low, const Eigen::Array3f &high) {
      return (box.min().array() > high).any() || (box.max().array() < low).any();
    };
    for (uint32_t i2 = strand_first_segment[sa]; i2 < strand_first_segment[sa + 1]; ++i2) {
      const Eigen::AlignedBox3f a_box = segment_box(i2);
      const Eigen::Array3f low = a_box.min().array() - tolerance, high = a_box.max().array() + tolerance;
      for (size_t block = 0; block < r_block_boxes.size(); ++block) {
        if (far(r_block_boxes[block], low, high)) continue;
        const uint32_t start = b_first + uint32_t(block) * kBlock;
        for (uint32_t j2 = start; j2 < std::min(start + kBlock, b_end); ++j2)
          if (!far(segment_box(j2), low, high) && segments_cross(i2, j2))
            return FirstCrossing{uint64_t(sa) << 32 | uint64_t(sb), i2, j2};
      }
    }
    return FirstCrossing{};
  };
  // A strand pair is counted once, at its witness: the first crossing segment pair (i, j) of the
  // two strands in the order of (i, j), at the first of their piece pairs (p, q) whose boxes
  // overlap. Every piece pair with overlapping boxes is tested exactly once, and two segments
  // within the tolerance have overlapping piece boxes, so each crossing strand pair meets its
  // witness exactly once: the count needs no stored set of pairs, whatever it amounts to. The first
  // crossing of a strand pair is searched once and kept in a small per-thread table (a strand pair
  // that runs side by side is met at many segment pairs), so memory stays bounded.
  constexpr size_t kFirstCrossingSlots = 256;
  const auto is_witness = [&](uint32_t p, uint32_t q, uint32_t i, uint32_t j, std::vector<FirstCrossing> &r_known,
                              std::vector<Eigen::AlignedBox3f> &r_block_boxes) {
    for (uint32_t p2 = piece_first[i]; p2 <= p; ++p2)
      for (uint32_t q2 = piece_first[j]; q2 < piece_first[j + 1] && (p2 < p || q2 < q); ++q2)
        if (boxes_overlap(p2, q2)) return false;
    const uint64_t pair = uint64_t(segment_strand[i]) << 32 | uint64_t(segment_strand[j]);
    FirstCrossing &known = r_known[size_t(hash64(pair) % kFirstCrossingSlots)];
    if (known.strands != pair) known = first_crossing(segment_strand[i], segment_strand[j], r_block_boxes);
    return known.strands == pair && known.i == i && known.j == j;
  };

  // Compare the pieces of a cell pairwise. A pair is tested only in the cell holding the lowest
  // corner of the overlap of their boxes, the per-axis largest of their lowest cells, so it is
  // tested once whatever the number of cells they share. The distance is that of the whole
  // segments. Each thread keeps its count and its max_examples lowest pairs, so the memory stays
  // that of the pieces. An exception inside the parallel region would end the program: the first
  // one is kept and thrown after it.
  const int thread_count = omp_get_max_threads();
  std::vector<size_t> found_by(static_cast<size_t>(thread_count), 0), examined_by(static_cast<size_t>(thread_count), 0);
  std::vector<std::vector<uint64_t>> examples_by(static_cast<size_t>(thread_count));
  std::exception_ptr failure;
  bool failed = false;
#pragma omp parallel num_threads(thread_count)
  {
    const size_t thread = size_t(omp_get_thread_num());
    size_t examined = 0, found = 0;
    std::vector<uint64_t> &examples = examples_by[thread];
    std::vector<Vector3f> lows, highs;
    std::vector<Eigen::Vector3i> low_cells;
    std::vector<uint32_t> pieces, segments, owners;
    std::vector<std::pair<float, uint32_t>> sweep;
    std::vector<FirstCrossing> known_first(kFirstCrossingSlots);
    std::vector<Eigen::AlignedBox3f> block_boxes;
#pragma omp for schedule(dynamic, 256)
    for (int64_t c = 0; c < busy_cells; ++c) {
      bool stop = false;
#pragma omp atomic read
      stop = failed;
      if (stop) continue;
      try {
        const size_t begin = cell_first[2 * size_t(c)], end = cell_first[2 * size_t(c) + 1], n = end - begin;
        const uint32_t key = uint32_t(entries[begin] >> 32);
        lows.resize(n);
        highs.resize(n);
        low_cells.resize(n);
        pieces.resize(n);
        segments.resize(n);
        owners.resize(n);
        // Sweep along the axis where the boxes are thinnest: sorted by their low end on it, a piece
        // meets only the pieces that start before its high end there.
        Vector3f extent = Vector3f::Zero();
        for (size_t u = 0; u < n; ++u) {
          const uint32_t q = uint32_t(entries[begin + u]);
          extent += piece_high[q] - piece_low[q];
        }
        int axis = 0;
        extent.minCoeff(&axis);
        sweep.resize(n);
        for (size_t u = 0; u < n; ++u) {
          const uint32_t q = uint32_t(entries[begin + u]);
          sweep[u] = {piece_low[q][axis], q};
        }
        std::sort(sweep.begin(), sweep.end());
        for (size_t u = 0; u < n; ++u) {
          const uint32_t q = sweep[u].second;
          pieces[u] = q;
          lows[u] = piece_low[q];
          highs[u] = piece_high[q];
          low_cells[u] = cell_of(lows[u]);
          segments[u] = piece_segment[q];
          owners[u] = segment_strand[segments[u]];
        }
        for (size_t u = 0; u < n; ++u) {
          for (size_t w = u + 1; w < n && lows[w][axis] <= highs[u][axis]; ++w) {
            if (owners[u] == owners[w]) continue;
            ++examined;
            if ((lows[u].array() > highs[w].array()).any() || (lows[w].array() > highs[u].array()).any()) continue;
            if (key_of(low_cells[u].cwiseMax(low_cells[w])) != key) continue;
            // Lower segment first: the distance is then computed exactly as the rule defines it.
            const bool u_first = segments[u] < segments[w];
            const uint32_t i = u_first ? segments[u] : segments[w], j = u_first ? segments[w] : segments[u];
            const uint32_t p = u_first ? pieces[u] : pieces[w], q = u_first ? pieces[w] : pieces[u];
            if (!segments_cross(i, j) || !is_witness(p, q, i, j, known_first, block_boxes)) continue;
            ++found;
            const uint64_t pair = uint64_t(segment_strand[i]) << 32 | uint64_t(segment_strand[j]);
            if (examples.size() < max_examples || (!examples.empty() && pair < examples.back())) {
              examples.insert(std::lower_bound(examples.begin(), examples.end(), pair), pair);
              if (examples.size() > max_examples) examples.pop_back();
            }
          }
        }
      } catch (...) {
#pragma omp critical(plume_count_crossings_failure)
        if (!failure) failure = std::current_exception();
#pragma omp atomic write
        failed = true;
      }
    }
    examined_by[thread] = examined;
    found_by[thread] = found;
  }
  if (failure) std::rethrow_exception(failure);
  std::vector<uint64_t> examples;
  for (size_t t = 0; t < size_t(thread_count); ++t) {
    result.pairs += found_by[t];
    result.segment_pairs_examined += examined_by[t];
    examples.insert(examples.end(), examples_by[t].begin(), examples_by[t].end());
  }
  std::sort(examples.begin(), examples.end());
  const bool has_ids = strands.ids.size() == strand_count;
  for (size_t p = 0; p < examples.size() && p < max_examples; ++p) {
    const uint32_t a = uint32_t(examples[p] >> 32), b = uint32_t(examples[p]);
    result.examples.emplace_back(has_ids ? strands.ids[a] : a, has_ids ? strands.ids[b] : b);
  }
  return result;
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

Roots roots_of(const StrandSet &strands, const MeshQuery &query) {
  Roots roots;
  roots.points.resize(strands.strand_count());
  roots.ids.resize(strands.strand_count());
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < int64_t(strands.strand_count()); ++s) {
    roots.points[size_t(s)] = query.closest(strands.positions[size_t(strands.offsets[size_t(s)])]);
    roots.ids[size_t(s)] = strands.ids.size() == strands.strand_count() ? strands.ids[size_t(s)] : uint64_t(s);
  }
  return roots;
}

CheckReport check_strands(const StrandSet &strands, const MeshQuery &query, const CheckOptions &options,
                          const Guides *guides, const PartingField *partings, const Roots *roots,
                          const Binding *binding) {
  CheckReport report;
  report.strand_count = strands.strand_count();
  report.point_count = strands.point_count();
  report.points_inside_skin =
      count_points_inside(strands, query, options.skin_margin, options.max_examples, report.inside_examples);

  if (options.crossing_tolerance > 0.0f) {
    CrossingCount crossings = count_crossings(strands, options.crossing_tolerance, options.max_examples);
    report.crossings_checked = true;
    report.crossing_pairs = crossings.pairs;
    report.crossing_examples = std::move(crossings.examples);
    report.segment_pairs_examined = crossings.segment_pairs_examined;
    report.piece_pairs_binned = crossings.piece_pairs_binned;
  }

  if (partings && roots && binding) {
    report.zones_checked = true;
    report.cross_zone_influences =
        count_cross_zone_influences(*partings, *roots, *binding, options.max_examples, report.cross_zone_examples);
  }

  if (guides && guides->size() > 0) {
    report.guides_checked = true;
    const float tolerance =
        options.guide_root_tolerance > 0.0f ? options.guide_root_tolerance : 1e-4f * mesh_diagonal(query.mesh());
    const size_t guide_count = guides->strands.strand_count();
    std::vector<double> guide_lengths(guide_count);
    for (size_t g = 0; g < guide_count; ++g) guide_lengths[g] = guides->strands.length(g);
    const int64_t strand_count = int64_t(strands.strand_count());
    std::vector<double> deviation(size_t(strand_count), -1.0);
    std::vector<double> relative(size_t(strand_count), 0.0);
#pragma omp parallel for schedule(dynamic, 256)
    for (int64_t s = 0; s < strand_count; ++s) {
      const auto points = strands.points(size_t(s));
      for (size_t g = 0; g < guide_count; ++g) {
        const auto guide = guides->strands.points(g);
        if ((guide.front() - points.front()).norm() > tolerance) continue;
        double worst = 0.0, arc = 0.0;
        for (size_t j = 0; j < points.size(); ++j) {
          if (j > 0) arc += (points[j] - points[j - 1]).norm();
          worst = std::max(worst, double((points[j] - point_at_arc_length(guide, arc)).norm()));
        }
        deviation[size_t(s)] = worst;
        relative[size_t(s)] = guide_lengths[g] > 0.0 ? worst / guide_lengths[g] : 0.0;
        break;
      }
    }
    for (size_t s = 0; s < size_t(strand_count); ++s) {
      if (deviation[s] < 0.0) continue;
      ++report.strands_at_guide_roots;
      if (deviation[s] > report.max_guide_deviation) {
        report.max_guide_deviation = deviation[s];
        report.max_guide_deviation_relative = relative[s];
        report.worst_guide_strand = strands.ids.size() == size_t(strand_count) ? strands.ids[s] : s;
      }
    }
  }
  return report;
}

}  // namespace plume::check
