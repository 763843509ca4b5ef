// Which feather lies over which, as the checker sees a vane frame: along the skin's normal at every
// vane vertex, the feathers met outward before the skin. From it, layer-order violations against the
// frozen order (feathers/layering.h builds it) and, between two frames, order flips. Used by
// `plume check` on vane meshes and by the tests. Rules: docs/check.md, "Feathers".
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "groom/mesh.h"
#include "groom/mesh_query.h"

namespace plume::check {

struct OverlapOptions {
  /// As VaneCheckOptions: a vertex or triangle within this fraction of its feather's extent from its
  /// vane base is in the root disc (no ray from it, none stopped by it).
  double root_disc = 0.05;
  /// Hits closer than this fraction of the median feather extent are contacts, which check_vanes
  /// judges: they say nothing of which feather is outer.
  double thickness = 1e-4;
};

/// One feather over another somewhere: `outer` is met on the way out from a vertex of `inner`'s vane.
struct Overlap {
  uint64_t inner = 0, outer = 0;
  friend bool operator<(const Overlap &a, const Overlap &b) {
    return a.inner < b.inner || (a.inner == b.inner && a.outer < b.outer);
  }
  friend bool operator==(const Overlap &a, const Overlap &b) = default;
};

struct VaneOverlaps {
  /// Every (inner, outer) relation seen, sorted, each once. A pair may appear both ways (feathers
  /// crossing or interleaved).
  std::vector<Overlap> over;
  int64_t samples = 0;  // vertices a ray was cast from
  double median_extent = 0.0;
};

/// For every vertex p of a feather's vane outside its root disc, n the skin's normal at the skin
/// point closest to p: the segment from p along n, as long as the largest feather extent, is
/// followed outward until it enters the skin (crosses a skin triangle against its normal); every
/// other feather whose vane triangle (outside its root disc) it meets before that, farther than the
/// thickness from p and within that feather's extent, is outer to p's feather there. This is the
/// rule the layer order is built with at rest (a feather covers another's root), taken at every
/// vertex. `triangles` index `positions`; `triangle_feathers` names each triangle's feather, a
/// feather's triangles consecutive, its first triangle's first vertex its vane base (as
/// check_vanes). `skin` is the posed skin `skin_query` was built on, its vertex normals computed.
/// Deterministic for any thread count.
VaneOverlaps vane_overlaps(std::span<const Eigen::Vector3f> positions, std::span<const Eigen::Vector3i> triangles,
                           std::span<const uint64_t> triangle_feathers, const Mesh &skin, const MeshQuery &skin_query,
                           const OverlapOptions &options = {});

struct LayerOrderReport {
  int64_t overlapping_pairs = 0;  // feather pairs with an overlap, either way
  /// Pairs where a feather the order puts lower is met outside one it puts higher (somewhere).
  int64_t violations = 0;
  int64_t unranked_pairs = 0;  // overlapping pairs with a feather the order does not rank
  /// (lower, higher) by the order: the lower feather was found outside the higher one.
  std::vector<std::pair<uint64_t, uint64_t>> examples;
};

/// Layer-order violations: `rank` gives each feather's place in the order (0 the bottom, higher
/// above). A pair overlapping both ways is a violation too (one of its ways is wrong).
LayerOrderReport layer_order_violations(const VaneOverlaps &overlaps, const std::unordered_map<uint64_t, int64_t> &rank,
                                        size_t max_examples = 8);

struct OrderFlips {
  int64_t pairs_in_both = 0;  // feather pairs overlapping in both frames
  /// Pairs one way only in the previous frame (a over b) and the other way in this one (b over a,
  /// alone or with a over b).
  int64_t flips = 0;
  std::vector<std::pair<uint64_t, uint64_t>> examples;  // (outer before, outer now)
};

OrderFlips order_flips(const VaneOverlaps &previous, const VaneOverlaps &current, size_t max_examples = 8);

}  // namespace plume::check
