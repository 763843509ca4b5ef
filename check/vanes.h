// The feather checker: no vane through another. Vanes are triangle meshes (rachis plus outline, each
// feather's triangles tagged with its id); every pair of triangles of two different feathers that
// intersects, or comes closer than a small thickness, is found with exact predicates (CGAL) after a
// uniform-grid broad phase. Used by `plume check` on vane meshes and by the tests. Rules:
// docs/check.md, "Feathers".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace plume::check {

struct VaneCheckOptions {
  /// Vanes are thickened by this fraction of the median feather extent (the largest distance from a
  /// feather's vane base to its vane vertices): two triangles closer than that count as touching
  /// (never an absolute unit).
  double thickness = 1e-4;
  /// A triangle lying entirely within this fraction of its feather's extent from its feather's vane
  /// base is in the root disc, where a feather leaves the skin among the others: its pairs are skipped.
  double root_disc = 0.05;
  size_t max_examples = 8;
};

/// Two feathers' vanes that meet: their ids (a < b), and one triangle of each.
struct VanePair {
  uint64_t a = 0, b = 0;
  int64_t triangle_a = -1, triangle_b = -1;
};

struct VaneCheckReport {
  size_t feathers = 0;
  size_t triangles = 0;
  double median_extent = 0.0;
  double thickness = 0.0;  // scene units
  int64_t triangle_pairs_tested = 0;
  /// Triangle pairs that intersect (exact), and those that do not but lie within the thickness.
  int64_t intersecting_triangle_pairs = 0;
  int64_t touching_triangle_pairs = 0;
  /// Feather pairs with at least one intersecting or touching triangle pair (sorted by ids).
  int64_t feather_pairs = 0;
  std::vector<VanePair> examples;
  bool clean() const { return feather_pairs == 0; }
};

/// Every pair of vanes of different feathers that meets. `triangles` index `positions`;
/// `triangle_feathers` (one per triangle) names each triangle's feather; a feather's triangles are
/// consecutive, and its first triangle's first vertex is its vane base (as feathers/ writes them).
/// Deterministic for any thread count.
VaneCheckReport check_vanes(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3i> triangles,
                            std::span<const uint64_t> triangle_feathers, const VaneCheckOptions &options = {});

}  // namespace plume::check
