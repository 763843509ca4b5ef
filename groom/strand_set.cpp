#include "groom/strand_set.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "groom/error.h"

namespace plume {

void StrandSet::append(std::span<const Eigen::Vector3f> points_of, uint64_t id,
                       std::span<const float> widths_of) {
  const bool has_widths = !widths.empty() || (positions.empty() && !widths_of.empty());
  if (has_widths && widths_of.size() != points_of.size())
    throw InternalError("StrandSet::append: widths must match points");
  positions.insert(positions.end(), points_of.begin(), points_of.end());
  if (has_widths) widths.insert(widths.end(), widths_of.begin(), widths_of.end());
  offsets.push_back(int64_t(positions.size()));
  ids.push_back(id);
}

void StrandSet::resize_uniform(size_t strand_count, int points_per_strand, bool with_widths, Fill fill) {
  offsets.resize(strand_count + 1);
  for (size_t i = 0; i <= strand_count; ++i) offsets[i] = int64_t(i) * points_per_strand;
  const size_t point_count = strand_count * size_t(points_per_strand);
  if (fill == Fill::zeros) {
    positions.assign(point_count, Eigen::Vector3f::Zero());
    widths.assign(with_widths ? point_count : 0, 0.0f);
  } else {
    positions.resize(point_count);  // Eigen's vectors are not initialised: no pass over the memory
    widths.resize(with_widths ? point_count : 0);
  }
  ids.resize(strand_count);
  for (size_t i = 0; i < strand_count; ++i) ids[i] = i;
}

double StrandSet::length(size_t strand) const {
  double total = 0.0;
  for (int64_t p = offsets[strand] + 1; p < offsets[strand + 1]; ++p)
    total += double((positions[p] - positions[p - 1]).norm());
  return total;
}

void StrandSet::check_invariants() const {
  if (offsets.empty() || offsets.front() != 0) throw InternalError("StrandSet: offsets[0] must be 0");
  for (size_t i = 1; i < offsets.size(); ++i)
    if (offsets[i] < offsets[i - 1]) throw InternalError("StrandSet: offsets decrease at " + std::to_string(i));
  if (size_t(offsets.back()) != positions.size()) throw InternalError("StrandSet: offsets.back() != point count");
  if (!widths.empty() && widths.size() != positions.size())
    throw InternalError("StrandSet: widths must be empty or one per point");
  if (ids.size() != strand_count()) throw InternalError("StrandSet: one id per strand");
  for (size_t p = 0; p < positions.size(); ++p)
    if (!positions[p].allFinite()) throw InternalError("StrandSet: non-finite point " + std::to_string(p));
}

double median_segment_length(const StrandSet &strands) {
  std::vector<float> lengths;
  lengths.reserve(strands.point_count());
  for (size_t s = 0; s < strands.strand_count(); ++s) {
    const auto points = strands.points(s);
    for (size_t j = 1; j < points.size(); ++j) {
      const float length = (points[j] - points[j - 1]).norm();
      if (length > 0.0f && std::isfinite(length)) lengths.push_back(length);
    }
  }
  if (lengths.empty()) return 0.0;
  const auto middle = lengths.begin() + std::ptrdiff_t(lengths.size() / 2);
  std::nth_element(lengths.begin(), middle, lengths.end());
  return double(*middle);
}

}  // namespace plume
