// A coat of feathers on a skin that moves (seed 001 sec. 4.4, carried to any mesh; seed 000 sec.
// 3.2.1): follicles with stable ids, each bound to its triangle by barycentric coordinates and a
// tangent frame from the UVs; key feathers blended over the surface; shape and direction from guide
// feathers' stems, blended per follicle as fur blends guides; every feather built each frame.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <vector>

#include "feathers/build.h"
#include "feathers/feather.h"
#include "feathers/layering.h"
#include "groom/feather_desc.h"
#include "groom/feather_frame.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/strand_set.h"

namespace plume::skin {
class SkinGrid;  // skin/skin_grid.h
}

namespace plume::feathers {

/// Where feathers grow: surface points of the rest mesh, each with a stable id.
struct Follicles {
  std::vector<SurfacePoint> points;
  std::vector<uint64_t> ids;
  size_t size() const { return points.size(); }
};

/// Follicles scattered as `settings` says (scatter only; a file's follicles come from the caller):
/// area-weighted over the tracts `settings.groups` (all faces when empty), `count` of them (or
/// density x area; `count_override` >= 0 replaces either), ids (face << 24) | j as for hair roots,
/// so a larger count keeps every follicle. `vertex_map` (empty, or one value in [0, 1] per vertex)
/// thins them: a follicle stays where the map, interpolated at it, exceeds a number hashed from its
/// id, so thinning too keeps every follicle that a smaller count had. Throws InputError naming the
/// follicles' settings for an unknown group or a tract without area.
Follicles scatter_follicles(const Mesh &rest_mesh, const FollicleSettings &settings,
                            const std::vector<float> &vertex_map, int64_t count_override = -1);

/// The key feathers' weights over the surface (sec. 4.4, carried from a grid to any mesh): key
/// feather k has weight exp(-(d_k / r_k)^2), normalised to sum 1, d_k the distance along the surface
/// from its tract (0 inside it) or its point: shortest paths along the rest mesh's edges (welded at
/// UV seams) to the vertices, interpolated over each triangle by barycentric weights (and, for a
/// point, never more than the straight distance to it). Every d_k is continuous over the surface,
/// so the weights are too.
class KeyFeatherField {
 public:
  /// Throws InputError at a key feather's loc for a face group the mesh does not have.
  KeyFeatherField(const Mesh &rest_mesh, const FeatherDesc &desc);
  size_t key_count() const { return radii_.size(); }
  /// The weights of every key feather at `point` (r_weights.size() == key_count()), summing to 1.
  void weights(const SurfacePoint &point, std::span<float> r_weights) const;
  /// The surface distance d_k from key feather k to `point` (scene units).
  double distance(size_t k, const SurfacePoint &point) const;

 private:
  const Mesh &mesh_;
  std::vector<uint32_t> welded_;                // per vertex: its welded representative
  std::vector<std::vector<double>> distances_;  // per key feather, per welded vertex
  std::vector<bool> at_point_;
  std::vector<Eigen::Vector3f> points_;         // snapped points of point key feathers
  std::vector<double> radii_;
};

/// What the skin pass decided at one frame, per feather in coat order, before the layering pass turns
/// feathers further: how far it turned each up about its root (radians, >= 0) and its size (1, or less
/// where it shrank it). The next frame's skin pass starts from it (its warm start, Coat::grow).
struct SkinPassState {
  std::vector<float> lifts;
  std::vector<float> scales;
  bool empty() const { return lifts.empty(); }
};

/// What a frame carries to the next: the skin pass's state and the layering pass's (empty when the
/// coat has no layers).
struct CoatState {
  SkinPassState skin_pass;
  LayeringState layers;
};

/// One frame of a coat, emitter object space: per feather (in coat order) its curves and its vane
/// meshes (feathers/build.h gives the order within a feather).
struct CoatFrame {
  FeatherCurves curves;
  VaneMesh vanes;
  /// Per feather: the skin frame at its follicle this frame (origin on the skin), how far the skin
  /// pass turned it up about its root (radians, >= 0), and its size (1, or less where no turn cleared
  /// the skin and the skin pass shrank it toward its root).
  std::vector<SurfaceFrame> root_frames;
  std::vector<float> lifts;
  std::vector<float> scales;
  /// The skin pass's own lifts and sizes (the layering pass's turns and shrinks not included).
  SkinPassState skin_pass;
  /// What keeping the feathers apart did this frame (zeros when the coat has no layers), and the
  /// layering pass's state, carried to the next frame (empty when the coat has no layers).
  LayeringStats layering;
  LayeringState layer_state;
};

/// A coat bound to its rest skin and guide stems. Bind once; grow() every frame (const, parallel,
/// the same bytes for any thread count: every feather is computed alone into its own place).
struct StemFrame;  // the stems of one frame, in their roots' skin frames (coat.cpp)

class Coat {
 public:
  /// Binds every follicle: its key-feather weights and blended template (with its seeded
  /// variation), its stems' weights and rest rotations, and its base frame in its skin frame.
  /// `rest_mesh` has normals; `stems` are the guide feathers bound to it (each at least 2 points).
  /// Throws InputError for an unknown face group, no stems, or a feather that cannot be built.
  /// `layer_map` (empty, or one value per rest vertex): the groom's `layers.map`, read by the caller.
  Coat(const Mesh &rest_mesh, const Guides &stems, const FeatherDesc &desc, Follicles follicles,
       std::span<const float> layer_map = {});

  size_t size() const { return ids_.size(); }
  const std::vector<uint64_t> &ids() const { return ids_; }
  const std::vector<SurfacePoint> &follicles() const { return points_; }
  const std::vector<FeatherShape> &shapes() const { return shapes_; }
  /// Per feather: the index of its heaviest key feather's template.
  const std::vector<int32_t> &templates() const { return templates_; }
  /// Per feather: the key-feather weights it was blended with (key_count() per feather).
  std::span<const float> key_weights(size_t feather) const {
    return {key_weights_.data() + feather * key_count_, key_count_};
  }
  const FeatherDetail &detail() const { return detail_; }
  /// Totals of one frame at the coat's detail.
  const FeatherCounts &counts() const { return total_; }

  /// One frame: `posed` (the emitter at this frame, normals computed, the rest mesh's topology),
  /// `query` on it, `stems` the guide stems at this frame (same count and point counts as at binding).
  /// `skin_grid` (on posed and query) is used by the skin pass when the coat lifts feathers; it may be
  /// null, then a grid is built. `previous`: the skin pass's state at the frame before (its
  /// warm start: each feather's turn stays in the interval of turns that clear it, falling back
  /// toward the smallest such turn by at most kFallBackWidths of its rachis width per frame at its
  /// farthest sample; pushed out of it, the feather moves to the smallest turn that clears when that
  /// is near, else stays while it keeps three quarters of its clearance; docs/feathers.md); null or
  /// empty at a first frame (each feather takes the smallest turn that clears it). `previous_layers`:
  /// the layering pass's state at the frame before (its warm start, lift_layers), null or empty at a
  /// first frame. Throws InputError when the stems, `previous` or `previous_layers` do not match the
  /// binding.
  void grow(const Mesh &posed, const MeshQuery &query, const StrandSet &stems, CoatFrame &r_frame,
            const skin::SkinGrid *skin_grid = nullptr, const SkinPassState *previous = nullptr,
            const LayeringState *previous_layers = nullptr) const;
  /// The skin pass alone (no curves, no vanes, no layering): the state grow() would leave in
  /// r_frame.skin_pass. For frames whose coat is not written (a simulation, skipped frames).
  void skin_pass(const Mesh &posed, const MeshQuery &query, const StrandSet &stems, const SkinPassState *previous,
                 SkinPassState &r_state, const skin::SkinGrid *skin_grid = nullptr) const;
  /// How far the warm start lets a lift fall back (and a shrunk feather grow back) per frame: the
  /// feather's farthest sample moves by at most this many rachis widths.
  static constexpr float kFallBackWidths = 0.25f;

  /// Per feather, its key in the groom's layer order (feathers/layering.h): empty when the groom gives
  /// no order of its own (no key feather's `layer`, no `layers.map`, `front` or `rear`). `desc` is the
  /// one the coat was bound with, `layer_map` its `layers.map` (empty, or one value per rest vertex).
  /// Throws InputError naming `layers.front` or `layers.rear` for an unknown face group.
  std::vector<LayerKey> order_keys(const Mesh &rest_mesh, const FeatherDesc &desc,
                                   std::span<const float> layer_map) const;
  /// The layer order frozen at binding (empty when the coat has no layers).
  const LayerOrder &layer_order() const { return order_; }
  /// Whether grow() keeps the feathers apart (the groom turns layers on and the coat has feathers).
  bool layered() const { return layers_ && !order_.bottom_up.empty(); }
  /// Where each feather's output lies in a frame.
  FeatherRanges ranges() const { return {first_point_, first_vertex_, first_triangle_}; }

 private:
  /// grow() without keeping feathers apart; with r_frame null, the skin pass alone.
  void grow_feathers(const Mesh &posed, const MeshQuery &query, const StrandSet &stems, const SkinPassState *previous,
                     SkinPassState &r_state, CoatFrame *r_frame, const skin::SkinGrid *skin_grid) const;
  struct Stem {
    int32_t guide = -1;
    float weight = 0.0f;
    Eigen::Quaternionf rest_rotation;  // Q_follicle(rest)^T M Q_guide(rest)
  };
  void bind_stems(const Mesh &rest_mesh, const Guides &stems);
  /// The key feather feather `feather` weighs most (the first of equal weights).
  size_t heaviest_key(size_t feather) const;
  /// Feather i's stems' directions at arc length z, blended by their weights and carried into the
  /// follicle's skin frame (not unit).
  Eigen::Vector3f blend_stems(const StemFrame &frames, size_t i, float z) const;

  FeatherDetail detail_;
  bool lift_ = true;
  float clearance_ = 0.02f;
  std::vector<SurfacePoint> points_;
  std::vector<uint64_t> ids_;
  std::vector<FeatherShape> shapes_;
  std::vector<float> rachis_widths_;  // per feather, its shape's (the layering pass's warm start's unit)
  std::vector<int32_t> templates_;
  size_t key_count_ = 0;
  std::vector<float> key_weights_;
  int k_ = 0;
  std::vector<Stem> stems_;  // k_ per feather
  std::vector<SurfacePoint> stem_roots_;
  std::vector<int64_t> stem_offsets_;  // the stems' point offsets at binding
  /// Per feather, its base frame in its follicle's rest skin frame (columns side, dorsal, shaft), with
  /// the seeded direction and lift variation applied.
  std::vector<Eigen::Quaternionf> base_frames_;
  /// Per feather, its stems' blended direction at the middle of its spine's first segment, in its
  /// follicle's skin frame, on the rest stems: a frame's stems turning away from it (a control's
  /// lift, the simulation) turn the feather's base frame with them.
  std::vector<Eigen::Vector3f> rest_first_;
  float falloff_ = 2.0f;
  bool layers_ = true;
  LayeringOptions layering_;
  LayerOrder order_;
  // Output layout, from the shapes and the detail: per feather its first curve, point, vane vertex
  // and vane triangle (size() + 1 entries each), and the curves' offsets.
  std::vector<int64_t> first_curve_, first_point_, first_vertex_, first_triangle_;
  std::vector<int64_t> curve_offsets_;
  FeatherCounts total_;
};

}  // namespace plume::feathers
