#include "interp/check.h"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <limits>


namespace plume::interp {

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

uint64_t cell_hash(int x, int y, int z) {
  return hash_combine(hash_combine(uint64_t(uint32_t(x)), uint64_t(uint32_t(y))), uint64_t(uint32_t(z)));
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
  // Segment i starts at point i; the last point of each strand starts none.
  std::vector<uint32_t> segment_start, segment_strand;
  double length_sum = 0.0;
  for (size_t s = 0; s < strand_count; ++s)
    for (int64_t p = strands.offsets[s]; p + 1 < strands.offsets[s + 1]; ++p) {
      segment_start.push_back(uint32_t(p));
      segment_strand.push_back(uint32_t(s));
      length_sum += (strands.positions[size_t(p + 1)] - strands.positions[size_t(p)]).norm();
    }
  const size_t segment_count = segment_start.size();
  if (segment_count < 2) return result;
  // Cells of a third of the mean segment length (at least twice the tolerance), and segments cut
  // into pieces no longer than a cell, so a dense bundle of long segments is still split finely.
  const float cell = std::max(2.0f * tolerance, float(length_sum / double(segment_count)) / 3.0f);
  if (!(cell > 0.0f)) return result;
  const float half_tol = 0.5f * tolerance;
  std::vector<uint32_t> piece_segment;
  std::vector<uint8_t> piece_index, piece_total;  // piece k of m of its segment
  for (size_t i = 0; i < segment_count; ++i) {
    const float length = (strands.positions[segment_start[i] + 1] - strands.positions[segment_start[i]]).norm();
    const int m = std::clamp(int(std::ceil(length / cell)), 1, 255);
    for (int k = 0; k < m; ++k) {
      piece_segment.push_back(uint32_t(i));
      piece_index.push_back(uint8_t(k));
      piece_total.push_back(uint8_t(m));
    }
  }
  const size_t piece_count = piece_segment.size();
  const auto piece_box = [&](size_t q, Vector3f &r_low, Vector3f &r_high) {
    const Vector3f &a = strands.positions[segment_start[piece_segment[q]]];
    const Vector3f d = strands.positions[segment_start[piece_segment[q]] + 1] - a;
    const float m = float(piece_total[q]);
    const Vector3f p0 = a + d * (float(piece_index[q]) / m), p1 = a + d * (float(piece_index[q] + 1) / m);
    r_low = p0.cwiseMin(p1).array() - half_tol;
    r_high = p0.cwiseMax(p1).array() + half_tol;
  };
  const auto cell_range = [&](size_t q, Eigen::Vector3i &lo, Eigen::Vector3i &hi) {
    Vector3f low, high;
    piece_box(q, low, high);
    for (int k = 0; k < 3; ++k) {
      lo[k] = int(std::floor(low[k] / cell));
      hi[k] = int(std::floor(high[k] / cell));
    }
  };

  // Bucket table: a counting sort of (cell hash -> piece) entries into CSR arrays.
  size_t entry_count = 0;
#pragma omp parallel for reduction(+ : entry_count)
  for (int64_t q = 0; q < int64_t(piece_count); ++q) {
    Eigen::Vector3i lo, hi;
    cell_range(size_t(q), lo, hi);
    entry_count += size_t((hi - lo + Eigen::Vector3i::Ones()).prod());
  }
  size_t bucket_count = 1;
  while (bucket_count < entry_count) bucket_count <<= 1;
  const uint64_t mask = bucket_count - 1;
  std::vector<uint32_t> bucket_offsets(bucket_count + 1, 0);
  std::vector<uint32_t> entries(entry_count);
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<uint32_t> fill;
    if (pass == 1) {
      for (size_t b = 0; b < bucket_count; ++b) bucket_offsets[b + 1] += bucket_offsets[b];
      fill.assign(bucket_offsets.begin(), bucket_offsets.end() - 1);
    }
    for (size_t q = 0; q < piece_count; ++q) {
      Eigen::Vector3i lo, hi;
      cell_range(q, lo, hi);
      for (int x = lo.x(); x <= hi.x(); ++x)
        for (int y = lo.y(); y <= hi.y(); ++y)
          for (int z = lo.z(); z <= hi.z(); ++z) {
            const size_t b = size_t(cell_hash(x, y, z) & mask);
            if (pass == 0)
              ++bucket_offsets[b + 1];
            else
              entries[fill[b]++] = uint32_t(q);
          }
    }
  }

  // Compare pieces sharing a bucket. A pair is tested only in the bucket of the cell holding the
  // lowest corner of the overlap of their grown boxes, so it is tested once whatever the number of
  // cells they share (and hash collisions only add cheap rejections). The distance is that of the
  // whole segments; a segment pair met through several pieces is counted once at the end.
  std::vector<std::vector<std::pair<uint32_t, uint32_t>>> found(static_cast<size_t>(omp_get_max_threads()));
  size_t examined = 0;
#pragma omp parallel reduction(+ : examined)
  {
    auto &mine = found[size_t(omp_get_thread_num())];
    std::vector<uint32_t> members;
    std::vector<Vector3f> lows, highs;
#pragma omp for schedule(dynamic, 1024)
    for (int64_t b = 0; b < int64_t(bucket_count); ++b) {
      members.assign(entries.begin() + bucket_offsets[size_t(b)], entries.begin() + bucket_offsets[size_t(b) + 1]);
      if (members.size() < 2) continue;
      std::sort(members.begin(), members.end());
      members.erase(std::unique(members.begin(), members.end()), members.end());
      lows.resize(members.size());
      highs.resize(members.size());
      for (size_t u = 0; u < members.size(); ++u) piece_box(members[u], lows[u], highs[u]);
      for (size_t u = 0; u < members.size(); ++u) {
        const uint32_t i = piece_segment[members[u]];
        for (size_t w = u + 1; w < members.size(); ++w) {
          const uint32_t j = piece_segment[members[w]];
          if (segment_strand[i] == segment_strand[j]) continue;
          ++examined;
          if ((lows[u].array() > highs[w].array()).any() || (lows[w].array() > highs[u].array()).any()) continue;
          const Vector3f corner = lows[u].cwiseMax(lows[w]);
          const uint64_t owner = cell_hash(int(std::floor(corner.x() / cell)), int(std::floor(corner.y() / cell)),
                                           int(std::floor(corner.z() / cell))) & mask;
          if (owner != uint64_t(b)) continue;
          const Vector3f &a0 = strands.positions[segment_start[i]], &a1 = strands.positions[segment_start[i] + 1];
          const Vector3f &b0 = strands.positions[segment_start[j]], &b1 = strands.positions[segment_start[j] + 1];
          if (segment_distance_squared(a0, a1, b0, b1) > tolerance * tolerance) continue;
          const uint32_t sa = segment_strand[i], sb = segment_strand[j];
          const bool at_root = segment_start[i] == strands.offsets[sa] || segment_start[j] == strands.offsets[sb];
          if (at_root && (strands.positions[size_t(strands.offsets[sa])] - strands.positions[size_t(strands.offsets[sb])])
                                 .norm() < tolerance)
            continue;
          mine.emplace_back(std::min(sa, sb), std::max(sa, sb));
        }
      }
    }
  }
  std::vector<std::pair<uint32_t, uint32_t>> pairs;
  for (const auto &f : found) pairs.insert(pairs.end(), f.begin(), f.end());
  std::sort(pairs.begin(), pairs.end());
  pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
  result.pairs = pairs.size();
  result.segment_pairs_examined = examined;
  const bool has_ids = strands.ids.size() == strand_count;
  for (size_t p = 0; p < pairs.size() && p < max_examples; ++p)
    result.examples.emplace_back(has_ids ? strands.ids[pairs[p].first] : pairs[p].first,
                                 has_ids ? strands.ids[pairs[p].second] : pairs[p].second);
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

}  // namespace plume::interp
