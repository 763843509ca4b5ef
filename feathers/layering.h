// Feathers in layers: an order decided once on the rest pose (which feather's vane covers which
// feather's root), then, every frame, each feather turned up about its root (turned aside, or bent
// along its shaft, where a turn is not enough), from the bottom of the order up, until its vanes keep
// an offset (relative to its size) from every lower feather's vanes.
// Each feather starts from the turn it had at the frame before (its warm start), so its turn changes
// little when the body moves little; the state is carried as the skin pass's is.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "groom/mesh_query.h"

namespace plume::skin {
class SkinGrid;  // skin/skin_grid.h
}

namespace plume::feathers {

struct CoatFrame;  // feathers/coat.h

/// Where each feather's output lies in a frame: per feather its first curve point and vane vertex
/// and triangle (feather count + 1 entries each), as Coat lays a frame out.
struct FeatherRanges {
  std::span<const int64_t> first_point, first_vertex, first_triangle;
  size_t size() const { return first_vertex.empty() ? 0 : first_vertex.size() - 1; }
};

/// A feather's place in an order the groom gives (docs/feathers.md, "Layers"): a feather with a
/// smaller key lies below one with a larger key, whatever covers what at rest; keys compare
/// lexicographically (tier, then layer, then map). Coverage orders feathers of equal keys.
struct LayerKey {
  int tier = 0;        // -1: a `rear` tract, below every other; 1: a `front` tract, above; 0: neither
  float layer = 0.0f;  // its heaviest key feather's `layer`
  float map = 0.0f;    // the `layers.map` vertex map at its follicle
  auto operator<=>(const LayerKey &) const = default;
};

/// The layer order, bottom first, frozen at rest.
struct LayerOrder {
  std::vector<int32_t> bottom_up;  // feather indices, bottom first
  std::vector<int32_t> rank;       // per feather: its place in bottom_up
  /// Feather i covers feather j when the ray from j's root along the skin normal meets i's vanes
  /// at rest: i lies above j. Coverings the order could not keep (cycles), as (covering, covered)
  /// feather indices: the rule that broke them is layer_order_from_coverage's.
  std::vector<std::pair<int32_t, int32_t>> broken;
  /// Coverings the given keys reverse (the covering feather has the smaller key, so it lies below),
  /// as (covering, covered) feather indices, ascending.
  std::vector<std::pair<int32_t, int32_t>> overridden;
  /// Beyond the roots: feather i lying over a vane vertex of j at rest (and not under j nearer its
  /// own root) puts i above j too. Those the order could not keep (cycles), as (over, under) feather
  /// indices, ascending.
  std::vector<std::pair<int32_t, int32_t>> loose;
  int64_t coverings = 0;
};

/// The order from coverage at rest (`rest`, the coat grown on the rest pose without layering).
/// Feather i lies above j when its vanes cover j's root (the ray from the root along its normal meets
/// them); with `rest_skin` (the rest skin's query), also when i's vanes are met on the way out from a
/// vane vertex of j outside its root disc (along the skin normal at the vertex's closest skin point,
/// as the checker takes it) and j's are not met from i's nearer i's root than that vertex is to j's
/// (of two feathers over each other in places, the one met nearer its root lies below: a turn about
/// its root cannot take that part out). Kahn's order, bottom up: the next feather is one that lies
/// above no remaining feather (the smallest index among them); when none is left (a cycle), the
/// remaining feather covering the fewest remaining roots, then lying above the fewest remaining
/// feathers, then the smallest index, goes next, and what it had to lie above is broken (the roots'
/// coverings in `broken`, the others in `loose`). Deterministic.
/// `keys` (empty, or one per feather): the groom's order. The next feather is then always one of the
/// smallest key left, and coverage (with the rule above) orders only feathers of equal keys; coverings
/// the keys reverse do not count (reported in `overridden`). Equal keys everywhere give the order
/// from coverage alone.
LayerOrder layer_order_from_coverage(const CoatFrame &rest, const FeatherRanges &ranges,
                                     std::span<const LayerKey> keys = {}, const MeshQuery *rest_skin = nullptr);

struct LayeringOptions {
  /// The gap kept between a feather's vanes and every lower feather's, as a fraction of the
  /// feather's extent (the largest distance from its root to its vanes).
  float offset = 0.002f;
  /// Triangles within this fraction of their feather's extent from its vane base are where the
  /// feather leaves the skin among the others: they are not kept apart (the checker's root disc,
  /// check/vanes.h, is larger).
  float root_disc = 0.04f;
  /// With a warm start, how far a turn that still clears falls back toward the template per frame (and
  /// a shrunk feather grows back): its vanes' farthest point moves by at most this many rachis widths.
  float fall_back = 0.25f;
};

/// What the layering pass decided at one frame, per feather in coat order: its turn on top of the skin
/// pass's (radians, >= 0), its size (1, or less where the pass shrank it), its yaw (radians, signed,
/// about the skin normal through its root; 0 unless turned aside: then the turn is about the axis
/// turned by the yaw) and its bend (radians at the tip, signed, positive toward the skin normal; 0
/// unless bent: then the part of its shaft beyond `bend_starts` of its length, a fraction, follows a
/// circular arc, and the turn comes after the bend). The next frame's pass starts from it
/// (lift_layers' warm start). `yaws`, and `bends` with `bend_starts`, may be empty in a state given as
/// the frame before: no feather turned aside, or bent.
struct LayeringState {
  std::vector<float> turns;
  std::vector<float> scales;
  std::vector<float> yaws;
  std::vector<float> bends;
  std::vector<float> bend_starts;
  bool empty() const { return turns.empty(); }
};

/// The layering pass's warm start: the state of the frame before (null or empty: none, a first frame)
/// and, with one, each feather's rachis width at its full size (feather count entries), the unit of
/// how far a turn falls back per frame.
struct LayeringWarmStart {
  const LayeringState *previous = nullptr;
  std::span<const float> rachis_widths;
};

struct LayeringStats {
  int64_t lifted = 0;      // feathers turned up
  int64_t unresolved = 0;  // feathers no turn up to the skin normal could clear: shrunk instead
  /// Feathers no turn up to the skin normal takes out from under every lower feather they overlap:
  /// kept clear of them only (the checker's layer-order violations come from these).
  int64_t left_under = 0;
  /// Feathers no turn about their axis took out from under the lower ones, turned aside (a yaw about
  /// the skin normal, then a turn) until none is over them (counted in `lifted`, not in `left_under`).
  int64_t turned_aside = 0;
  /// Feathers neither a turn nor a yaw took out from under the lower ones (or clear of their vanes),
  /// bent along their shaft and turned so that the same tests pass (counted in `lifted`; in
  /// `left_under` too, and named in `unordered`, when the bend leaves them under fewer lower
  /// feathers than a turn, or keeps them clear of the lower vanes instead of a shrink).
  int64_t bent = 0;
  /// The feathers left under a lower one or shrunk (indices, ascending): a higher feather found
  /// under a lower one anywhere on the frame is one of these.
  std::vector<int32_t> unordered;
  int waves = 0;           // the longest chain of feathers each waiting for the one below it
  float largest_lift = 0.0f;  // radians
};

/// One frame: from the bottom of `order` up, each feather (curves and vanes) turned about the axis
/// through its root across its shaft (shaft x skin normal) by the smallest angle, up to the skin
/// normal, at which no vane triangle of it comes within its offset of a lower feather's (triangles
/// of the root discs apart) and no lower feather is over it (the way out from a vane vertex outside
/// the root disc, along the skin normal at the skin point closest to it, meets no lower vane within
/// that feather's extent: check/feather_layers.h's rule); that angle is added to r_frame.lifts. A
/// feather no such turn exists for is turned clear of the lower feathers and under the fewest, and
/// named in `unordered`. Feathers whose spheres (root, twice the extent) meet no lower one's are
/// independent: a feather is lifted (in parallel with others) once every lower feather it may
/// touch or lie under is placed, and the result does not depend on the thread count or the
/// schedule.
/// `skin` (may be null) is the posed skin: a turn that takes a vane vertex below it is refused too.
/// `skin_grid` (may be null; then one is built) is the grid of that skin the growth used.
/// With `warm.previous`, each feather starts from its turn and size there (docs/feathers.md, "The
/// layering pass's warm start"): a turn that still clears falls back toward no turn by at most
/// options.fall_back rachis widths at its farthest point, staying among the turns that clear; a turn
/// that no longer clears moves to the nearest that does within 3 steps of the search (0.06 radians)
/// either way; a feather no turn takes out from under the lower ones stays at its turn (and its yaw,
/// where it had one) while that keeps it clear of their vanes and the skin, unless a step of the
/// search leaves it under fewer of them; a feather turned aside at the frame before drops its yaw where its turn about the
/// unturned axis, or one within 3 steps, clears; else it stays at its yaw and turn while they clear,
/// its yaw falling back toward none by at most options.fall_back rachis widths at its farthest point
/// (its turn instead where the yaw cannot fall), or takes the nearest turn that clears at that yaw
/// within 3 steps either way; else the search, and turning aside afresh tries the yaws nearest its
/// yaw of the frame before first; a feather bent at the frame before keeps its bend and turn while
/// they clear, the bend falling back toward none by at most options.fall_back rachis widths at its
/// farthest point; a feather neither a turn nor a yaw takes out from under the lower ones is bent
/// along its shaft where a bend, at turns near the one under the fewest, leaves it under fewer lower
/// feathers (or none), and one no turn or yaw keeps clear of the lower vanes is bent, where a bend
/// does, or else, where it was turned aside at the frame before, turned aside where a yaw and turn
/// keep it clear of their vanes (left under), before it is shrunk (to the largest size that clears: a scan down, then bisection); a shrunk feather grows
/// back unturned by at most options.fall_back rachis widths per frame, and where its size no longer
/// clears, takes the nearest size below that does; otherwise, the search above. Every answer passes the
/// same tests as the search's, so the promise (no vane within the offset of a lower one, none below
/// the skin) is the same.
/// `r_state` (may be null): the state to carry to the next frame.
/// Throws InputError when `warm.previous` does not hold one entry per feather (yaws, bends and
/// bend_starts: one, or none).
LayeringStats lift_layers(const LayerOrder &order, const FeatherRanges &ranges, const LayeringOptions &options,
                          const MeshQuery *skin, CoatFrame &r_frame, const skin::SkinGrid *skin_grid = nullptr,
                          const LayeringWarmStart &warm = {}, LayeringState *r_state = nullptr);

}  // namespace plume::feathers
