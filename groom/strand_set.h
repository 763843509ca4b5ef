// A set of strands stored as flat arrays plus offsets: the points of strand i are
// positions[offsets[i] .. offsets[i+1]). Guides, dense strands and every output use it.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace plume {

struct StrandSet {
  /// strand_count() + 1 entries, offsets[0] == 0, non-decreasing, back() == point_count().
  std::vector<int64_t> offsets{0};
  /// One per point, scene units (object space of the emitter unless said otherwise).
  std::vector<Eigen::Vector3f> positions;
  /// Empty, or one diameter per point (scene units).
  std::vector<float> widths;
  /// One stable id per strand: the same root always has the same id, whatever the count.
  std::vector<uint64_t> ids;

  size_t strand_count() const { return offsets.size() - 1; }
  size_t point_count() const { return positions.size(); }
  int64_t points_in(size_t strand) const { return offsets[strand + 1] - offsets[strand]; }

  std::span<const Eigen::Vector3f> points(size_t strand) const {
    return {positions.data() + offsets[strand], size_t(points_in(strand))};
  }
  std::span<Eigen::Vector3f> points_for_write(size_t strand) {
    return {positions.data() + offsets[strand], size_t(points_in(strand))};
  }

  /// Appends one strand; widths_of may be empty only if this set has no widths.
  void append(std::span<const Eigen::Vector3f> points_of, uint64_t id,
              std::span<const float> widths_of = {});
  /// What resize_uniform leaves in the points and widths: zeros, or whatever was there (for a caller
  /// that writes every one).
  enum class Fill { zeros, unset };
  /// Sets `strand_count` strands of `points_per_strand` points each, ids 0..n-1.
  void resize_uniform(size_t strand_count, int points_per_strand, bool with_widths, Fill fill = Fill::zeros);
  /// Sum of segment lengths of one strand.
  double length(size_t strand) const;
  /// Throws InternalError when an invariant is broken (offsets, sizes, non-finite values).
  void check_invariants() const;
};

/// Median length of the segments of non-zero, finite length (scene units); 0 when there is none.
/// The strands' length unit: defaults that must scale with a groom are fractions of it.
double median_segment_length(const StrandSet &strands);

}  // namespace plume
