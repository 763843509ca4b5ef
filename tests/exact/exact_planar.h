// An exact check of planar strands for the tests, independent of the checker (check/check.h): which
// strand pairs intersect in the plane, which come within a tolerance and at which angles, decided by
// CGAL's exact predicates and exact constructions, with no rounding anywhere. The strands' x and y are
// used; z is ignored (give planar scenes, z = 0).
#pragma once

#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "groom/strand_set.h"

namespace plume::test {

/// Strand index pairs (a < b, ascending) whose polylines share a point in the plane.
std::vector<std::pair<uint32_t, uint32_t>> exact_intersecting_pairs(const StrandSet &strands);

/// The checker's crossing rule (check::count_crossings) decided exactly. Two strands cross when a
/// segment of one comes within `tolerance` of a segment of the other, except that segments touching
/// a root are ignored when the two roots are closer than the tolerance; a crossing pair is
/// transversal when one of its crossing segment pairs has an angle between their lines above
/// `transversal_degrees`, else touching.
struct ExactCrossings {
  size_t pairs = 0;              // crossing pairs whose class is certain
  size_t transversal_pairs = 0;  // of those
  size_t touching_pairs = 0;     // of those
  /// Pairs where a distance or an angle lies within a relative `band` of its threshold (after the
  /// tolerance and the angle's cosine are rounded to double by the caller, either answer is right):
  /// the checker may count them either way.
  size_t uncertain_pairs = 0;
  size_t intersecting_pairs = 0;  // polylines sharing a point (exact_intersecting_pairs().size())
};
ExactCrossings exact_crossings(const StrandSet &strands, double tolerance, double transversal_degrees,
                               double band = 1e-6);

}  // namespace plume::test
