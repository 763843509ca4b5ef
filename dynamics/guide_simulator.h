// Guide dynamics: each guide is a chain of rigid segments (inextensible) with point masses at the
// joints, its root carried by the skin, stepped in time with a linear-time tridiagonal solve.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "groom/dynamics_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume::dynamics {

/// Work done by the simulator since construction: used to check that the cost of a step is
/// linear in the number of joints (counts, not time). Sums over all guides.
struct SimulationWork {
  int64_t substeps = 0;            // substeps taken (per simulator, not per guide)
  int64_t tridiagonal_solves = 0;  // one per guide per substep (plus post-stabilisation solves)
  int64_t tridiagonal_rows = 0;    // rows eliminated by those solves (one per segment)
  int64_t joint_updates = 0;       // joints integrated
  int64_t emitter_queries = 0;     // exact closest-point queries of the emitter (the rest are
                                   // skipped by a conservative clearance bound)
};

class GuideSimulator {
 public:
  /// rest_mesh: emitter rest pose (normals computed); guides: rest guides bound to it
  /// (each at least 2 points). The settings are copied. Collision shapes are bound to the rest
  /// mesh here (each shape end to its closest surface point). Compensated gravity, when enabled,
  /// is solved here from the rest shape. Throws InputError for invalid settings.
  GuideSimulator(const Mesh &rest_mesh, const Guides &guides, const DynamicsSettings &settings);
  ~GuideSimulator();
  GuideSimulator(const GuideSimulator &) = delete;
  GuideSimulator &operator=(const GuideSimulator &) = delete;

  /// Sets the state to the guides carried rigidly onto `posed_mesh` at rest (zero velocity).
  /// `posed_mesh` has the rest mesh's topology, normals computed. `root_turns`: empty, or one unit
  /// quaternion per guide that turns its root frame about the guide's first point (in the skin
  /// frame's coordinates: an animator control's pose); the guide is then simulated as if groomed
  /// turned by it, its root where it was. An identity turn leaves a guide as without one, to the bit.
  void reset(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns = {});
  /// Advances one frame (settings.substeps substeps, dt = 1 / fps / substeps each), roots
  /// following the skin, root frames (turned by `root_turns`, as for reset()) interpolated between
  /// the previous pose and `posed_mesh`. The first call after construction without reset() resets
  /// to `posed_mesh` first.
  void step_frame(const Mesh &posed_mesh, std::span<const Eigen::Quaternionf> root_turns = {});
  /// Current simulated guide strands (same offsets and ids as the rest guides), refreshed
  /// after each step.
  const StrandSet &guides() const { return view_; }
  /// Current joint positions in the solver's double precision, one per point of guides().
  std::span<const Eigen::Vector3d> positions() const;
  /// Current joint velocities (scene units / s), one per point of guides(), same order.
  std::span<const Eigen::Vector3d> velocities() const;
  /// Simulated time since the last reset, seconds.
  double time() const { return time_; }
  const SimulationWork &work() const { return work_; }

 private:
  struct State;
  std::unique_ptr<State> state_;
  StrandSet view_;
  double time_ = 0.0;
  SimulationWork work_;
};

}  // namespace plume::dynamics
