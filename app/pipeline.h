// What the `plume` command does with a groom: load it once (rest mesh, guides, roots, partings,
// binding, effects, simulator), then produce any frame: the posed emitter, the guides at that
// frame (carried, simulated or read from a guide cache) and the dense strands grown from them.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "app/frame_range.h"
#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/roots.h"
#include "groom/strand_set.h"

namespace plume {

namespace interp {
struct Binding;
}
namespace partings {
class PartingField;
}
namespace effects {
class EffectStack;
}
namespace dynamics {
class GuideSimulator;
}
namespace controls {
class ControlRig;
}

/// The emitter's rigid transform at `frame` (identity when the animation is not rigid or has no
/// keys): p' = pivot + translate + R * (scale * (p - pivot)), R from XYZ Euler angles (X first).
/// Between keys translation and scale are linear and rotation is a slerp; outside the keys the
/// nearest key holds.
Eigen::Affine3f rigid_pose_at(const EmitterAnimation &animation, double frame);

/// The emitter of `groom` at `frame`, from `rest_mesh` (the groom's emitter as read): an OBJ of the
/// sequence (InputError when it is missing or does not match), the rest mesh rigidly moved, or the
/// rest mesh. Normals computed.
Mesh posed_emitter(const GroomDesc &groom, const Mesh &rest_mesh, int frame);

/// The roots `groom` grows on `rest_mesh` (its roots.file, or scattered as its roots settings say;
/// `guides` bound on the rest mesh), `count_override` of them when >= 0 (a subset of the full set).
/// Throws InputError for bad settings, or more roots than memory holds.
Roots groom_roots(const GroomDesc &groom, const Mesh &rest_mesh, const Guides &guides, int64_t count_override);

struct PipelineOptions {
  /// Overrides the groom's root count when >= 0 (proxy runs); a smaller count keeps a subset of the
  /// full groom's roots (scattering is stable under the count).
  int64_t strand_count = -1;
  /// With dynamics: a guide cache pattern (#### or %0Nd) to read the guides of every frame from
  /// instead of simulating; empty: simulate.
  std::string guides_cache;
  /// With dynamics and no cache: the frame the simulation starts from, at rest (before any pre-roll).
  int simulation_start = 1;
  /// When set, these roots (surface points of the emitter, with their ids) are grown instead of
  /// the groom's own, and strand_count is ignored: `plume check` regrows the roots of a strand file.
  std::optional<Roots> roots;
};

/// One produced frame, emitter object space.
struct FrameResult {
  int frame = 0;
  Mesh mesh;          // the posed emitter, normals computed
  StrandSet guides;   // the guides at this frame
  StrandSet strands;  // the dense strands, widths root to tip, ids = root ids
  /// Segment pairs the separation pass left nearer than plume check's crossing tolerance (0 without
  /// the pass): interp::GrowStats::unseparated_pairs.
  int64_t unseparated_pairs = 0;
};

class Pipeline {
 public:
  /// Loads and binds everything the groom describes. Throws InputError for any bad input
  /// (missing or malformed files, unknown face groups, empty zones, an empty root set).
  Pipeline(const GroomDesc &groom, const PipelineOptions &options);
  ~Pipeline();
  Pipeline(const Pipeline &) = delete;
  Pipeline &operator=(const Pipeline &) = delete;

  const GroomDesc &groom() const { return groom_; }
  const Mesh &rest_mesh() const { return rest_mesh_; }
  const Guides &guides() const { return guides_; }
  const Roots &roots() const { return roots_; }
  bool dynamic() const { return groom_.dynamics.enabled; }
  /// One UV per root (root's UV on the emitter), empty when the emitter has no UVs.
  const std::vector<Eigen::Vector2f> &root_uvs() const { return root_uvs_; }
  /// The partings (empty when the groom has none) and the binding of the roots.
  const partings::PartingField &partings() const { return *partings_; }
  const interp::Binding &binding() const { return *binding_; }
  /// The effects stack (its clumps, for pictures that show them).
  const effects::EffectStack &effects() const { return *effects_; }

  /// The emitter at `frame`: an OBJ of the sequence, the rest mesh rigidly moved, or the rest mesh.
  Mesh posed_mesh(int frame) const;
  /// The guides at `frame` on `posed` (= posed_mesh(frame)). Without dynamics: carried by the skin,
  /// then posed by the groom's controls. With a cache: read from it (InputError when the file is
  /// missing or does not match the guides); the cache holds the guides after the controls.
  /// Otherwise simulated from options.simulation_start - preroll, the roots turned by the controls
  /// at every frame, and mixed with the rig-driven guides by their dynamic blend: frames should be
  /// asked for in increasing order; asking for an earlier frame restarts the simulation.
  StrandSet guides_at(int frame, const Mesh &posed);
  /// The whole frame: posed mesh, guides, grown strands with effects applied and pushed out of the skin.
  /// `with_effects` false: the strands as growth leaves them, before the effects stack.
  FrameResult produce(int frame, bool with_effects = true);
  /// The frame's posed mesh and guides, and each strand's first point alone (one-point strands, ids
  /// = root ids), as produce() would start them, without growing them.
  FrameResult produce_starts(int frame);
  /// Reads and checks, one file at a time, every per-frame input that producing the frames of
  /// `range` reads, so that bad input is found before the first output is written: with a guide
  /// cache, the pattern and every needed cache file (exists, parses, matches the guides); with an
  /// emitter OBJ sequence, every needed frame (parses, has the rest mesh's topology), including the
  /// frames simulated before the range. Nothing is kept: memory does not grow with the range.
  /// Throws InputError naming the file.
  void check_frame_inputs(const FrameRange &range) const;

 private:
  /// The guides of `frame` read from the guide cache, checked against the rest guides.
  StrandSet read_cached_guides(int frame) const;

  GroomDesc groom_;
  PipelineOptions options_;
  Mesh rest_mesh_;
  Guides guides_;
  Roots roots_;
  std::vector<Eigen::Vector2f> root_uvs_;
  std::unique_ptr<partings::PartingField> partings_;
  std::unique_ptr<interp::Binding> binding_;
  std::unique_ptr<effects::EffectStack> effects_;
  std::unique_ptr<dynamics::GuideSimulator> simulator_;
  std::unique_ptr<controls::ControlRig> controls_;  // null when the groom has no controls
  std::optional<int> simulated_frame_;  // the frame the simulator's state is at
};

/// The memory this process may use, in bytes: the machine's physical memory, or less when a
/// control group (cgroup v2, as farm schedulers set per task) limits it. 0 when unknown.
double usable_memory_bytes();

/// Writes a guide cache frame (one file, format from the extension of `path`).
void write_guide_cache(const std::string &path, const StrandSet &guides, int frame);

}  // namespace plume
