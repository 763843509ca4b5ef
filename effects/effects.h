// The effects stack (Hair Designer "hair effects"): clumps, tension, length, waviness, frizz and curl,
// applied in order to the strands grown each frame, stable from frame to frame.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "groom/effect_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "groom/strand_set.h"

namespace plume::skin {
class SkinGrid;  // skin/skin_grid.h
}

namespace plume::effects {

using skin::SkinGrid;

/// The rest-pose data a stack needs, computed once: clump assignment, per-root rest frames,
/// per-root scale (face groups x vertex map). Apply it every frame; `apply` is const and may be
/// called from several frames concurrently. Between calls a stack keeps one buffer the size of the
/// strands' positions (12 bytes per point), so that frame after frame needs no fresh memory.
///
/// Stability: every random choice is hashed from (effect seed, strand id), and noise is evaluated
/// in each root's rest frame, so a frame regrown alone, with any thread count, gives the same bits.
class EffectStack {
 public:
  /// `effects`: the ordered stack (empty is allowed). `roots`: the dense roots on `rest_mesh`, one per
  /// strand, ids stable. `guides`: rest guides. `nearest_guide`: one guide index per root (from the
  /// binding; -1 when the root has none). Throws InputError when a vertex map cannot be read or its
  /// count differs from the mesh's vertex count, or when a group name is not a face group of the mesh.
  EffectStack(const std::vector<EffectDesc> &effects, const Mesh &rest_mesh, const Roots &roots,
              const Guides &guides, const std::vector<int32_t> &nearest_guide);
  ~EffectStack();
  EffectStack(EffectStack &&) noexcept;
  EffectStack &operator=(EffectStack &&) noexcept;

  /// Applies the stack in order to `r_strands`, grown this frame (strand i has id roots.ids[i], same
  /// order as the roots; every strand has at least 2 points). `posed_mesh` is the emitter at this frame
  /// (same topology as the rest mesh) and `posed_query` a query on it; `guides_this_frame` the guides at
  /// this frame (same order as the rest guides). Point counts never change. `clearance`: one lower
  /// bound per point of its signed distance to the skin before the stack, as grow() gives it; when
  /// empty, every point is taken to be `skin_margin` (scene units) outside, as grow() leaves them. The
  /// stack ends with no point inside the skin: a point it moved by d is still at least clearance - d
  /// outside (the signed distance is 1-Lipschitz), and only where that bound falls below `skin_margin`
  /// is the skin looked at, and the point pushed out along the normal to the margin when closer. An
  /// empty stack leaves the strands as they are.
  /// `skin_grid` (may be null): a SkinGrid built on `posed_mesh` and `posed_query`, as growth used
  /// this frame; when null, the stack builds its own.
  void apply(const Mesh &posed_mesh, const MeshQuery &posed_query, const StrandSet &guides_this_frame,
             float skin_margin, StrandSet &r_strands, std::span<const float> clearance = {},
             const SkinGrid *skin_grid = nullptr) const;

  /// True when the stack has no effect (apply then leaves strands untouched).
  bool empty() const;
  /// For effect `effect` of the stack, a clump: one entry per strand, the index of its clump's centre
  /// strand (a centre is its own centre; -1: no clump, e.g. no guide). Empty for other effect types.
  const std::vector<int32_t> &clump_centres(size_t effect) const;

  struct Prepared;  // one per effect, defined in effects.cpp
  struct FrameBuffers;  // memory apply() keeps from one frame to the next, defined in effects.cpp

 private:
  std::vector<Prepared> effects_;
  std::vector<SurfacePoint> root_points_;  // one per strand (rest binding)
  std::vector<uint64_t> ids_;              // one per strand
  std::vector<int32_t> nearest_guide_;     // one per strand, -1: none
  std::vector<SurfaceFrame> rest_frames_;  // one per strand: the root's surface frame on the rest mesh
  std::vector<SurfacePoint> guide_roots_;  // one per guide (rest binding)
  std::unique_ptr<FrameBuffers> buffers_;
};

}  // namespace plume::effects
