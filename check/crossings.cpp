// count_crossings: crossing strand pairs through a uniform grid of segment pieces, each pair
// counted once at a witness and classed as transversal or touching (check.h).
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <limits>
#include <utility>

#include "check/check.h"
#include "groom/error.h"
#include "groom/segment_distance.h"

namespace plume::check {

namespace {

using Eigen::Vector3f;

/// |cos| of the angle between the lines of segments p0-p1 and q0-q1; 1 (parallel) when either has
/// no length, so a segment without a direction never makes a crossing transversal.
double segment_abs_cos(const Vector3f &p0, const Vector3f &p1, const Vector3f &q0, const Vector3f &q1) {
  const Eigen::Vector3d d1 = (p1 - p0).cast<double>(), d2 = (q1 - q0).cast<double>();
  const double lengths = d1.norm() * d2.norm();
  return lengths > 0.0 ? std::min(1.0, std::abs(d1.dot(d2)) / lengths) : 1.0;
}

}  // namespace

CrossingCount count_crossings(const StrandSet &strands, float tolerance, size_t max_examples, float transversal_degrees,
                              const StrandSet *before) {
  CrossingCount result;
  result.tolerance = tolerance;
  if (before && before->offsets != strands.offsets)
    throw InternalError("count_crossings: the strands before hold other strands (" +
                        std::to_string(before->strand_count()) + " for " + std::to_string(strands.strand_count()) + ")");
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
  const double tolerance_squared = double(tolerance) * double(tolerance);
  const auto segments_cross = [&](uint32_t i, uint32_t j) {
    const Vector3f &a0 = strands.positions[segment_start[i]], &a1 = strands.positions[segment_start[i] + 1];
    const Vector3f &b0 = strands.positions[segment_start[j]], &b1 = strands.positions[segment_start[j] + 1];
    if (segment_distance_squared(a0, a1, b0, b1) > tolerance_squared) return false;
    const uint32_t sa = segment_strand[i], sb = segment_strand[j];
    const bool at_root = segment_start[i] == strands.offsets[sa] || segment_start[j] == strands.offsets[sb];
    return !(at_root && (strands.positions[size_t(strands.offsets[sa])] - strands.positions[size_t(strands.offsets[sb])])
                                .norm() < tolerance);
  };
  const auto abs_cos = [&](uint32_t i, uint32_t j) {
    return segment_abs_cos(strands.positions[segment_start[i]], strands.positions[segment_start[i] + 1],
                           strands.positions[segment_start[j]], strands.positions[segment_start[j] + 1]);
  };
  // A pair is transversal when some crossing segment pair's |cos| is below this.
  const double transversal_cos = std::cos(double(transversal_degrees) * 3.14159265358979323846 / 180.0);
  const auto boxes_overlap = [&](uint32_t p, uint32_t q) {
    return !(piece_low[p].array() > piece_high[q].array()).any() && !(piece_low[q].array() > piece_high[p].array()).any();
  };
  // What a crossing strand pair a < b is: its first crossing segment pair (i, j) in that order (the
  // witness), and the smallest |cos| over all its crossing segment pairs (transversal below
  // transversal_cos). One scan of the two strands: strand b's segments are scanned in blocks under
  // one box each, so a segment of a far from most of b costs a few box tests; a box is set aside
  // when it is farther than the tolerance (and a slack for rounding) from the segment's box.
  struct PairCrossing {
    uint64_t strands = ~uint64_t(0);  // a << 32 | b, or none
    uint32_t i = 0, j = 0;
    double smallest_cos = 1.0;
  };
  constexpr uint32_t kBlock = 64;
  const auto scan_pair = [&](uint32_t sa, uint32_t sb, std::vector<Eigen::AlignedBox3f> &r_block_boxes) {
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
    PairCrossing found;
    for (uint32_t i2 = strand_first_segment[sa]; i2 < strand_first_segment[sa + 1]; ++i2) {
      const Eigen::AlignedBox3f a_box = segment_box(i2);
      const Eigen::Array3f reach =
          tolerance + 1e-6f * a_box.min().array().abs().max(a_box.max().array().abs()) + 1e-6f * a_box.sizes().array();
      const Eigen::Array3f low = a_box.min().array() - reach, high = a_box.max().array() + reach;
      for (size_t block = 0; block < r_block_boxes.size(); ++block) {
        if (far(r_block_boxes[block], low, high)) continue;
        const uint32_t start = b_first + uint32_t(block) * kBlock;
        for (uint32_t j2 = start; j2 < std::min(start + kBlock, b_end); ++j2) {
          if (far(segment_box(j2), low, high) || !segments_cross(i2, j2)) continue;
          if (found.strands == ~uint64_t(0)) found = PairCrossing{uint64_t(sa) << 32 | uint64_t(sb), i2, j2, 1.0};
          found.smallest_cos = std::min(found.smallest_cos, abs_cos(i2, j2));
        }
      }
    }
    return found;
  };
  // A strand pair is counted once, at its witness: the first crossing segment pair (i, j) of the
  // two strands in the order of (i, j), at the first of their piece pairs (p, q) whose boxes
  // overlap. Every piece pair with overlapping boxes is tested exactly once, and two segments
  // within the tolerance have overlapping piece boxes, so each crossing strand pair meets its
  // witness exactly once: the count needs no stored set of pairs, whatever it amounts to. A strand
  // pair is scanned once and kept in a small per-thread table (a strand pair that runs side by side
  // is met at many segment pairs), so memory stays bounded. Returns the pair's scan at its witness,
  // or null.
  constexpr size_t kPairSlots = 256;
  const auto witness_of = [&](uint32_t p, uint32_t q, uint32_t i, uint32_t j, std::vector<PairCrossing> &r_known,
                              std::vector<Eigen::AlignedBox3f> &r_block_boxes) -> const PairCrossing * {
    for (uint32_t p2 = piece_first[i]; p2 <= p; ++p2)
      for (uint32_t q2 = piece_first[j]; q2 < piece_first[j + 1] && (p2 < p || q2 < q); ++q2)
        if (boxes_overlap(p2, q2)) return nullptr;
    const uint64_t pair = uint64_t(segment_strand[i]) << 32 | uint64_t(segment_strand[j]);
    PairCrossing &known = r_known[size_t(hash64(pair) % kPairSlots)];
    if (known.strands != pair) known = scan_pair(segment_strand[i], segment_strand[j], r_block_boxes);
    return known.strands == pair && known.i == i && known.j == j ? &known : nullptr;
  };
  // Whether strands a and b cross in `before`, by the same rule (all segment pairs, boxes first).
  const auto crosses_before = [&](uint32_t sa, uint32_t sb) {
    const auto a = before->points(sa), b = before->points(sb);
    const bool roots_close = !a.empty() && !b.empty() && (a.front() - b.front()).norm() < tolerance;
    for (size_t i = 1; i < a.size(); ++i) {
      const Eigen::Array3f reach = tolerance + 1e-6f * a[i].array().abs().max(a[i - 1].array().abs()) +
                                   1e-6f * (a[i] - a[i - 1]).array().abs();
      const Eigen::Array3f low = a[i].array().min(a[i - 1].array()) - reach;
      const Eigen::Array3f high = a[i].array().max(a[i - 1].array()) + reach;
      for (size_t j = 1; j < b.size(); ++j) {
        if ((b[j].array().min(b[j - 1].array()) > high).any() || (b[j].array().max(b[j - 1].array()) < low).any())
          continue;
        if (roots_close && (i == 1 || j == 1)) continue;
        if (segment_distance_squared(a[i - 1], a[i], b[j - 1], b[j]) <= tolerance_squared) return true;
      }
    }
    return false;
  };
  // Keeps the max_examples lowest pairs in `examples` (ascending).
  const auto keep_example = [&](std::vector<uint64_t> &examples, uint64_t pair) {
    if (examples.size() < max_examples || (!examples.empty() && pair < examples.back())) {
      examples.insert(std::lower_bound(examples.begin(), examples.end(), pair), pair);
      if (examples.size() > max_examples) examples.pop_back();
    }
  };

  // Compare the pieces of a cell pairwise. A pair is tested only in the cell holding the lowest
  // corner of the overlap of their boxes, the per-axis largest of their lowest cells, so it is
  // tested once whatever the number of cells they share. The distance is that of the whole
  // segments. Each thread keeps its counts and its max_examples lowest pairs of each kind, so the
  // memory stays that of the pieces. An exception inside the parallel region would end the program:
  // the first one is kept and thrown after it.
  struct ThreadCount {
    size_t examined = 0, found = 0, transversal = 0, found_new = 0, transversal_new = 0;
    double smallest_cos = 1.0;
    std::vector<uint64_t> transversal_examples, touching_examples;
  };
  const int thread_count = omp_get_max_threads();
  std::vector<ThreadCount> counts_by(static_cast<size_t>(thread_count));
  std::exception_ptr failure;
  bool failed = false;
#pragma omp parallel num_threads(thread_count)
  {
    ThreadCount &counts = counts_by[size_t(omp_get_thread_num())];
    std::vector<Vector3f> lows, highs;
    std::vector<Eigen::Vector3i> low_cells;
    std::vector<uint32_t> pieces, segments, owners;
    std::vector<std::pair<float, uint32_t>> sweep;
    std::vector<PairCrossing> known(kPairSlots);
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
            ++counts.examined;
            if ((lows[u].array() > highs[w].array()).any() || (lows[w].array() > highs[u].array()).any()) continue;
            if (key_of(low_cells[u].cwiseMax(low_cells[w])) != key) continue;
            // Lower segment first: the distance is then computed exactly as the rule defines it.
            const bool u_first = segments[u] < segments[w];
            const uint32_t i = u_first ? segments[u] : segments[w], j = u_first ? segments[w] : segments[u];
            const uint32_t p = u_first ? pieces[u] : pieces[w], q = u_first ? pieces[w] : pieces[u];
            if (!segments_cross(i, j)) continue;
            const PairCrossing *witness = witness_of(p, q, i, j, known, block_boxes);
            if (!witness) continue;
            ++counts.found;
            counts.smallest_cos = std::min(counts.smallest_cos, witness->smallest_cos);
            const bool transversal = witness->smallest_cos < transversal_cos;
            if (transversal) {
              ++counts.transversal;
              keep_example(counts.transversal_examples, witness->strands);
            } else {
              keep_example(counts.touching_examples, witness->strands);
            }
            if (before && !crosses_before(segment_strand[i], segment_strand[j])) {
              ++counts.found_new;
              counts.transversal_new += transversal;
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
  }
  if (failure) std::rethrow_exception(failure);
  std::vector<uint64_t> transversal_examples, touching_examples;
  double smallest_cos = 1.0;
  for (const ThreadCount &counts : counts_by) {
    result.pairs += counts.found;
    result.transversal_pairs += counts.transversal;
    result.pairs_new += counts.found_new;
    result.transversal_pairs_new += counts.transversal_new;
    result.segment_pairs_examined += counts.examined;
    smallest_cos = std::min(smallest_cos, counts.smallest_cos);
    transversal_examples.insert(transversal_examples.end(), counts.transversal_examples.begin(),
                                counts.transversal_examples.end());
    touching_examples.insert(touching_examples.end(), counts.touching_examples.begin(), counts.touching_examples.end());
  }
  result.touching_pairs = result.pairs - result.transversal_pairs;
  if (result.pairs > 0) result.largest_angle_degrees = std::acos(smallest_cos) * 180.0 / 3.14159265358979323846;
  const bool has_ids = strands.ids.size() == strand_count;
  const auto to_ids = [&](std::vector<uint64_t> &pairs, std::vector<std::pair<uint64_t, uint64_t>> &r_examples) {
    std::sort(pairs.begin(), pairs.end());
    for (size_t e = 0; e < pairs.size() && e < max_examples; ++e) {
      const uint32_t a = uint32_t(pairs[e] >> 32), b = uint32_t(pairs[e]);
      r_examples.emplace_back(has_ids ? strands.ids[a] : a, has_ids ? strands.ids[b] : b);
    }
  };
  to_ids(transversal_examples, result.transversal_examples);
  to_ids(touching_examples, result.touching_examples);
  return result;
}

}  // namespace plume::check
