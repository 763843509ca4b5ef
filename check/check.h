// The strand checker: points inside the skin, crossing strands, influence across hard partings,
// and how far strands rooted at guide roots stray from their guide. Used by `plume check` and by
// the interpolation tests. Rules are documented in docs/partings.md ("The checker").
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/strand_set.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"

namespace plume::check {

using interp::Binding;
using partings::PartingField;

struct CheckOptions {
  /// Two strands cross when a segment of one comes within this distance (scene units) of a segment
  /// of the other; <= 0 skips the crossing count. Segments touching a root are ignored for two
  /// strands whose roots are themselves closer than the tolerance.
  float crossing_tolerance = 0.0f;
  /// A point other than a root counts as inside when its signed distance to the skin is below
  /// skin_margin - eps (a root counts below -eps); eps = 1e-5 x the mesh's bounding-box diagonal.
  float skin_margin = 0.0f;
  /// A strand is "rooted at a guide root" when its first point is within this distance of the
  /// guide's first point; 0 means 1e-4 x the mesh's bounding-box diagonal.
  float guide_root_tolerance = 0.0f;
  /// How many example strand ids each count keeps for messages.
  size_t max_examples = 8;
};

struct CheckReport {
  size_t strand_count = 0;
  size_t point_count = 0;

  size_t points_inside_skin = 0;
  std::vector<uint64_t> inside_examples;  // strand ids, ascending

  bool crossings_checked = false;
  size_t crossing_pairs = 0;  // unordered strand pairs
  std::vector<std::pair<uint64_t, uint64_t>> crossing_examples;
  /// Segment pairs the spatial grid put side by side (grows with local density, not all pairs).
  size_t segment_pairs_examined = 0;
  /// Piece pairs sharing a grid cell (see CrossingCount::piece_pairs_binned).
  size_t piece_pairs_binned = 0;

  bool zones_checked = false;
  /// (root, guide) slots with a non-zero weight whose guide is in another hard zone.
  size_t cross_zone_influences = 0;
  std::vector<uint64_t> cross_zone_examples;  // strand ids

  bool guides_checked = false;
  size_t strands_at_guide_roots = 0;
  /// Largest distance (scene units) between a strand rooted at a guide root and that guide, points
  /// paired by arc length from the root (past the guide's end, its tip).
  double max_guide_deviation = 0.0;
  /// The same divided by the guide's length.
  double max_guide_deviation_relative = 0.0;
  uint64_t worst_guide_strand = 0;

  /// True when none of the checked counts found a violation (guide deviation is a figure, not a
  /// violation).
  bool clean() const { return points_inside_skin == 0 && crossing_pairs == 0 && cross_zone_influences == 0; }
};

/// The crossing count's budget: count_crossings refuses a tolerance whose grid puts more than this
/// many piece pairs side by side (sum over cells of n (n - 1) / 2) per segment. The shipped checks
/// bin about 200 per segment (185 and 210 at tolerance 0.001 and 0.01 on the demo's 30k x 12
/// Sintel strands); near the budget the work is still linear in the segments (12.8 CPU seconds,
/// 110 MB for those 330k segments at tolerance 0.28), where a tolerance near the strands' spacing would compare nearly all pairs.
inline constexpr double kCrossingPiecePairsPerSegment = 2000.0;
/// The crossing grid's memory budget: a segment piece's grown box spans at most 27 cells (3 per
/// axis) unless the slack for float rounding is wider than a cell (strands far from the origin
/// checked with a tolerance below their coordinates' rounding). count_crossings refuses more than
/// this many cell entries per piece, before allocating them.
inline constexpr double kCrossingEntriesPerPiece = 64.0;

struct CrossingCount {
  size_t pairs = 0;  // unordered strand pairs
  std::vector<std::pair<uint64_t, uint64_t>> examples;  // the max_examples lowest pairs (by strand index)
  size_t segment_pairs_examined = 0;
  /// Piece pairs sharing a grid cell, sum over cells of n (n - 1) / 2: the bound on the work that
  /// the budget is checked against before any comparison.
  size_t piece_pairs_binned = 0;
};

/// Points inside the skin (see CheckOptions::skin_margin). Along a strand, a point that cannot have
/// come within the margin since the last queried point (its travel is less than that point's
/// distance to the skin minus the margin) is outside without a query: a strand gets inside only
/// through the skin. r_examples gets up to max_examples strand ids.
size_t count_points_inside(const StrandSet &strands, const MeshQuery &query, float skin_margin, size_t max_examples,
                           std::vector<uint64_t> &r_examples);

/// Crossing strand pairs: segments are cut into pieces no longer than a cell and binned in a uniform
/// grid (cell = a third of the mean segment length, at least twice the tolerance) by their bounding
/// boxes grown by tolerance / 2, entries radix-sorted by cell; within a cell a sweep along the
/// thinnest axis compares only overlapping pieces, each pair once (in the cell holding the lowest
/// corner of the overlap of their boxes). Cost grows with the number of segments times the local
/// density, never with all pairs. Memory is linear in the segments whatever the number of crossing
/// pairs: each strand pair is counted at one witness segment pair (its first crossing, searched once
/// per strand pair with block boxes and kept in a small per-thread table), no set of pairs is stored.
/// Throws InputError when the binned piece pairs exceed kCrossingPiecePairsPerSegment per segment
/// (a tolerance near or above the strands' spacing, where nearly all pairs would be compared), or the
/// grid's entries kCrossingEntriesPerPiece per piece (strands so far from the origin that their
/// rounding dwarfs the tolerance).
CrossingCount count_crossings(const StrandSet &strands, float tolerance, size_t max_examples);

/// (root, guide) slots of `binding` with a non-zero weight whose guide lies in another hard zone than
/// the root. `roots` are the bound roots, `ids` the strand ids reported for them.
size_t count_cross_zone_influences(const PartingField &partings, const Roots &roots, const Binding &binding,
                                   size_t max_examples, std::vector<uint64_t> &r_examples);

/// The surface points of the strands' first points, with the strands' ids: the roots to bind when
/// checking strands that come from a file.
Roots roots_of(const StrandSet &strands, const MeshQuery &query);

/// Every check at once. The guide deviation needs `guides`; the zone check needs `partings`,
/// `roots` and `binding` (the binding of these strands' roots). Throws InputError (from
/// count_crossings) when options.crossing_tolerance is beyond the crossing count's budget.
CheckReport check_strands(const StrandSet &strands, const MeshQuery &query, const CheckOptions &options,
                          const Guides *guides = nullptr, const PartingField *partings = nullptr,
                          const Roots *roots = nullptr, const Binding *binding = nullptr);

}  // namespace plume::check
