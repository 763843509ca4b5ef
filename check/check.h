// The strand checker: the promises Plume's strands keep, measured on any strand set. Points inside
// the skin, crossing strands (transversal crossings apart from near-parallel
// touching), influence across hard partings, strands at guide roots that reproduce their guide, and
// requested roots that got a strand. Used by `plume check` and by the tests. Rules and defaults:
// docs/check.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
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

/// The default crossing tolerance, as a fraction of the strands' median segment length: a length
/// that scales with the strands, never an absolute one.
inline constexpr double kToleranceOfMedianSegment = 1e-3;
/// Two segments within the tolerance cross transversally when the angle between their lines is
/// above this (degrees); at or below it they touch side by side (near-parallel).
inline constexpr float kTransversalDegrees = 10.0f;
/// The largest deviation a strand rooted at a guide root may have from its guide, as a fraction
/// of the guide's length, before it is a violation.
inline constexpr double kGuideDeviationLimit = 1e-3;
/// Roots (a strand's first point against a guide root or a requested root) match within this
/// fraction of the mesh's bounding-box diagonal.
inline constexpr double kRootToleranceOfDiagonal = 1e-4;

struct CheckOptions {
  /// Two strands cross when a segment of one comes within this distance (scene units) of a segment
  /// of the other; <= 0: kToleranceOfMedianSegment x the median length of the checked strands'
  /// segments (of non-zero length). Segments touching a root are ignored for two strands whose
  /// roots are themselves closer than the tolerance.
  float crossing_tolerance = 0.0f;
  /// Crossings at a larger angle (degrees, between the segments' lines, in [0, 90]) are transversal.
  float transversal_degrees = kTransversalDegrees;
  /// Whether near-parallel touching pairs are violations (they are always counted).
  bool touching_is_violation = false;
  /// A point other than a root counts as inside when its signed distance to the skin is below
  /// skin_margin - eps (a root counts below -eps); eps = 1e-5 x the mesh's bounding-box diagonal.
  float skin_margin = 0.0f;
  /// Root matching distance (scene units); <= 0: kRootToleranceOfDiagonal x the mesh's diagonal.
  float root_tolerance = 0.0f;
  /// A strand rooted at a guide root deviating from its guide by more than this fraction of the
  /// guide's length is a violation.
  double guide_deviation_limit = kGuideDeviationLimit;
  /// How many examples each count keeps for messages.
  size_t max_examples = 8;
};

/// What the checker may know besides the strands and the skin. Every pointer may be null; each
/// check runs when its inputs are given.
struct CheckInputs {
  /// The guides at the strands' pose (strands) with their roots bound on the rest mesh (roots,
  /// surface points valid on the checked mesh, which has the rest mesh's topology).
  const Guides *guides = nullptr;
  /// The strands' roots: surface points of the checked mesh, one per strand, in the strands' order.
  /// With roots_grown they are the roots the strands grew from (a groom's, matched by regrowing
  /// them), and guide and requested roots are matched on them exactly; otherwise they are a guess
  /// (the surface points below the first points, surface_point_below()) that serves the zone check only.
  const Roots *roots = nullptr;
  bool roots_grown = false;
  /// The zone check: the partings, and the binding of `roots` with the groom's settings.
  const PartingField *partings = nullptr;
  const Binding *binding = nullptr;
  /// The same roots grown without the effects stack (same strand order): when given, the crossings
  /// and the guide deviation are judged on these, and the strands' own crossings are a figure (the
  /// effects bring strands together on purpose: clumps gather them, frizz and curls cross them).
  const StrandSet *interpolated = nullptr;
  /// Roots that must each have a strand: surface points of the checked mesh.
  const std::vector<SurfacePoint> *requested_roots = nullptr;
};

struct CrossingCount {
  float tolerance = 0.0f;  // scene units
  /// Unordered strand pairs with a segment of one within the tolerance of a segment of the other.
  size_t pairs = 0;
  /// Of those, the pairs with at least one such segment pair at an angle above transversal_degrees
  /// (their lines'); the others (pairs - transversal_pairs) touch, near-parallel, wherever they meet.
  size_t transversal_pairs = 0;
  size_t touching_pairs = 0;
  /// The largest angle (degrees, lines') between two segments within the tolerance, over all pairs.
  double largest_angle_degrees = 0.0;
  /// The max_examples lowest pairs (by strand index) of each kind, as strand ids.
  std::vector<std::pair<uint64_t, uint64_t>> transversal_examples;
  std::vector<std::pair<uint64_t, uint64_t>> touching_examples;
  /// With `before` given to count_crossings: the pairs (and the transversal ones) that do not cross
  /// in `before`, the same strands before a change (the effects stack): the crossings it made.
  size_t pairs_new = 0;
  size_t transversal_pairs_new = 0;
  /// Segment pairs the spatial grid put side by side (grows with local density, not all pairs).
  size_t segment_pairs_examined = 0;
  /// Piece pairs sharing a grid cell, sum over cells of n (n - 1) / 2: the bound on the work that
  /// the budget is checked against before any comparison.
  size_t piece_pairs_binned = 0;
};

struct GuideDeviation {
  size_t strands_at_guide_roots = 0;
  /// Largest deviation (scene units) of a strand rooted at a guide root from its guide, and the
  /// same divided by the guide's length (see guide_deviation()).
  double largest = 0.0;
  double largest_relative = 0.0;
  uint64_t worst_strand = 0;
  /// Strands over CheckOptions::guide_deviation_limit.
  size_t over_limit = 0;
  std::vector<uint64_t> over_limit_examples;  // strand ids, ascending
  /// Strands at the roots of guides whose curve, once risen above the skin band (twice the growth's
  /// skin margin), comes back into it, or goes into the skin: growth keeps strands at the margin
  /// there, so they leave such a guide where it runs that low, and are not held to the limit (nor in
  /// largest, worst_strand, over_limit). Their largest deviation, relative to the guide's length,
  /// and its strand.
  float skin_band = 0.0f;
  size_t near_skin = 0;
  double near_skin_largest_relative = 0.0;
  uint64_t near_skin_worst_strand = 0;
};

struct RootCoverage {
  size_t requested = 0;
  size_t missing = 0;                       // requested roots with no strand within the root tolerance
  std::vector<size_t> missing_examples;     // indices into the requested roots, ascending
};

struct CheckReport {
  size_t strand_count = 0;
  size_t point_count = 0;
  /// Median length of the strands' segments of non-zero length (scene units).
  double median_segment_length = 0.0;
  float root_tolerance = 0.0f;  // scene units

  float skin_margin = 0.0f;
  size_t points_inside_skin = 0;
  std::vector<uint64_t> inside_examples;  // strand ids, ascending

  float transversal_degrees = kTransversalDegrees;
  bool touching_is_violation = false;
  /// The crossings judged: of the interpolated strands when CheckInputs::interpolated was given
  /// (crossings_before_effects), else of the strands.
  CrossingCount crossings;
  bool crossings_before_effects = false;
  /// With CheckInputs::interpolated: the strands' own crossings, after the effects (a figure; its
  /// pairs_new are the pairs the effects made).
  CrossingCount crossings_after_effects;

  bool zones_checked = false;
  /// (root, guide) slots with a non-zero weight whose guide is in another hard zone.
  size_t cross_zone_influences = 0;
  std::vector<uint64_t> cross_zone_examples;  // strand ids

  bool guides_checked = false;
  bool guides_before_effects = false;  // judged on the interpolated strands
  double guide_deviation_limit = kGuideDeviationLimit;
  GuideDeviation guide_deviation;

  bool roots_checked = false;
  RootCoverage requested_roots;

  /// Each broken promise in one line ("3 points inside the skin"); empty when the strands keep
  /// every checked promise. Touching pairs are one only with touching_is_violation; the crossings
  /// after effects never are.
  std::vector<std::string> violations() const;
  bool clean() const { return violations().empty(); }
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

/// The crossing tolerance check_strands uses: `options.crossing_tolerance` when > 0, else
/// kToleranceOfMedianSegment x median_segment_length(strands). Throws InputError when that is 0
/// (no segment has a length).
float crossing_tolerance_for(const StrandSet &strands, const CheckOptions &options);

/// The root matching distance: `options.root_tolerance` when > 0, else kRootToleranceOfDiagonal x
/// the diagonal of `mesh`'s bounding box.
float root_tolerance_for(const Mesh &mesh, const CheckOptions &options);

/// Points inside the skin (see CheckOptions::skin_margin). Along a strand, a point that cannot have
/// come within the margin since the last queried point (its travel is less than that point's
/// distance to the skin minus the margin) is outside without a query: a strand gets inside only
/// through the skin. r_examples gets up to max_examples strand ids.
size_t count_points_inside(const StrandSet &strands, const MeshQuery &query, float skin_margin, size_t max_examples,
                           std::vector<uint64_t> &r_examples);

/// Crossing strand pairs at `tolerance` (scene units, > 0), each classed as transversal (some
/// segment pair within the tolerance at an angle above `transversal_degrees`) or touching.
/// Segments are cut into pieces no longer than a cell and binned in a uniform grid (cell = a third
/// of the mean segment length, at least twice the tolerance) by their bounding boxes grown by
/// tolerance / 2, entries radix-sorted by cell; within a cell a sweep along the thinnest axis
/// compares only overlapping pieces, each pair once (in the cell holding the lowest corner of the
/// overlap of their boxes). Cost grows with the number of segments times the local density, never
/// with all pairs. Memory is linear in the segments whatever the number of crossing pairs: each
/// strand pair is counted at one witness segment pair (its first crossing; the pair's class and
/// largest angle are found by one scan of the two strands, kept in a small per-thread table), no
/// set of pairs is stored. Throws InputError when the binned piece pairs exceed
/// kCrossingPiecePairsPerSegment per segment (a tolerance near or above the strands' spacing, where
/// nearly all pairs would be compared), or the grid's entries kCrossingEntriesPerPiece per piece
/// (strands so far from the origin that their rounding dwarfs the tolerance).
/// `before` (may be null): the same strands (same count and order) before a change; each crossing
/// pair is also tested there, by the same rule, for CrossingCount::pairs_new.
CrossingCount count_crossings(const StrandSet &strands, float tolerance, size_t max_examples,
                              float transversal_degrees = kTransversalDegrees, const StrandSet *before = nullptr);

/// (root, guide) slots of `binding` with a non-zero weight whose guide lies in another hard zone than
/// the root. `roots` are the bound roots, `ids` the strand ids reported for them.
size_t count_cross_zone_influences(const PartingField &partings, const Roots &roots, const Binding &binding,
                                   size_t max_examples, std::vector<uint64_t> &r_examples);

/// The largest distance (scene units) between a strand and the guide it should reproduce. The guide
/// runs from `guide_start` through `guide`'s points: a strand rooted below a guide whose first point
/// floats off the skin is compared with the guide joined to the strand's root by a straight segment
/// (guide_start = the strand's first point; Plume lifts such a root along its normal). Point j of
/// the strand, at fraction f_j of the strand's length, is compared with the guide near the same
/// fraction of its length (the stretch within one of the strand's neighbouring segments of it, so
/// a strand resampled to fewer points is not charged for its chords, and a coil is never matched to
/// the next one); the tips are compared with each other. A strand that stops early or overshoots
/// deviates by about the difference in length. r_guide_length gets the joined guide's length.
double guide_deviation(std::span<const Eigen::Vector3f> strand, const Eigen::Vector3f &guide_start,
                       std::span<const Eigen::Vector3f> guide, double &r_guide_length);

/// Strands rooted at a guide root, and their largest deviation from that guide (guide_deviation(),
/// from the strand's root): a strand at the guide's root (strands_at_roots(), on `mesh`, with
/// `strand_roots` when known) or whose first point is within `root_tolerance` of the guide's first
/// point. A deviation over `limit` x the guide's length is counted, except for strands at guides whose
/// curve comes back within `skin_band` of `query`'s skin or into it, counted apart (near_skin).
GuideDeviation measure_guide_deviation(const StrandSet &strands, const Roots *strand_roots, const MeshQuery &query,
                                       const Guides &guides, float root_tolerance, double limit, float skin_band,
                                       size_t max_examples);

/// For each root (surface points of `mesh`), the strand that grows from it, or -1. With
/// `strand_roots` (the roots the strands grew from, one per strand), the strand whose root lies
/// within `root_tolerance` of it. Without, the strand whose first point lies on the root's normal
/// line at or above the skin, within `root_tolerance` of c + h n(c) for some h >= 0 (streamline and
/// fur growth lift a root along its normal by its guides' height above the skin; linear growth, which
/// moves it sideways too, needs the strands' roots), the nearest to the line when several do. Two
/// roots at one place may name one strand.
std::vector<int64_t> strands_at_roots(const StrandSet &strands, const Roots *strand_roots, const Mesh &mesh,
                                      const std::vector<SurfacePoint> &roots, float root_tolerance);

/// Requested roots (surface points of `mesh`) without a strand (strands_at_roots()).
RootCoverage check_requested_roots(const StrandSet &strands, const Roots *strand_roots, const Mesh &mesh,
                                   const std::vector<SurfacePoint> &requested, float root_tolerance,
                                   size_t max_examples);

/// The surface points below the strands' first points (surface_point_below()), with the strands' ids: the roots to bind when
/// checking strands that come from a file.
Roots roots_of(const StrandSet &strands, const MeshQuery &query);

/// Every check its inputs allow, on strands at the pose of `query`'s mesh. Throws InputError when
/// the crossing tolerance is beyond the crossing count's budget (count_crossings) or cannot be
/// derived (crossing_tolerance_for), or when `inputs.interpolated` does not hold the strands' roots.
CheckReport check_strands(const StrandSet &strands, const MeshQuery &query, const CheckOptions &options,
                          const CheckInputs &inputs = {});

}  // namespace plume::check
