// The animator's controls applied to the guides every frame: each guide is turned about its root
// by lift, random twist, direction and aim, and mixed with the simulated guide by dynamic blend.
// Bound once on the rest pose; every frame is a pure function of the frame and the posed skin.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "controls/binding.h"
#include "groom/control_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume::controls {

/// One placed control at one frame.
struct ControlState {
  /// Where it is (emitter object space of the posed mesh), and how far it has moved from where
  /// the skin alone would have carried it (its offset, turned with the skin for a skin control).
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f displacement = Eigen::Vector3f::Zero();
  /// The behaviours' amounts at this frame, 0 for an absent one: lift as a fraction or in radians
  /// (ControlDesc::lift_by), random twist in radians.
  float lift = 0.0f, aim = 0.0f, direction = 0.0f, twist = 0.0f, blend = 0.0f;
};

/// The controls at one frame, for every guide. Filled by ControlRig::pose; reusing one across
/// frames allocates nothing after the first.
struct GuidePose {
  double frame = 0.0;
  /// One per placed control.
  std::vector<ControlState> controls;
  /// One per guide: its posed skin frame at the root.
  std::vector<SurfaceFrame> frames;
  /// One per guide: the unit turn about the guide's first point (its root), in the skin frame's
  /// coordinates (a point p of the guide goes to p0 + B q B^T (p - p0), p0 the guide's first point
  /// and B the frame's basis: the root itself never moves).
  std::vector<Eigen::Quaternionf> turns;
  /// One per guide: 0 when the turn is the identity (the guide is left as it is, to the bit).
  std::vector<uint8_t> turned;
};

/// How far from a guide's root (as a fraction of its root-to-tip distance) aim and direction fade
/// out: a target that passes through the root would otherwise swing the guide round at once.
inline constexpr float kNearRootFade = 0.1f;

class ControlRig {
 public:
  /// Binds the guides (rest strands and roots on `rest_mesh`, normals computed) to the controls.
  /// `vertex_maps` as bind_controls takes them. Throws InputError for a face group the mesh lacks.
  ControlRig(const Mesh &rest_mesh, const Guides &guides, const ControlSettings &settings,
             const std::vector<std::vector<float>> &vertex_maps = {});

  const ControlSettings &settings() const { return settings_; }
  /// The placed controls (each mirrored one followed by its twin).
  const std::vector<RigControl> &controls() const { return controls_; }
  const ControlBinding &binding() const { return binding_; }

  /// The controls at `frame` on `posed_mesh` (the rest mesh's topology, normals computed), and the
  /// turn of every guide. In the root's skin frame (z the normal), with the rest guide's first
  /// segment d, its tip c (from its first point) and the weights w of its controls:
  ///   lift       L: about the fixed axis d x z by  sum w lift  (a fraction f of d's angle to the
  ///                 normal, of its elevation when f < 0, or an angle), kept between lying on the
  ///                 skin and lying on the skin the other way;
  ///   twist      T: about z by  sum w twist u,  u in [-1, 1] hashed from the seed and the guide id;
  ///   direction  D: the turn taking the tip c' = T L c toward c' + sum w direction displacement;
  ///   aim        A: the turn taking the tip toward each control's position, mixed by w aim;
  /// q = A D T L. Every turn between two directions goes through the normal (swing.h) and targets
  /// are kept above the tangent plane, so q is continuous in the frame: nothing flips.
  void pose(double frame, const Mesh &posed_mesh, GuidePose &r_pose) const;
  /// Turns `r_guides` (the rest guides carried onto the pose's mesh: same offsets) by the pose,
  /// each about its own first point. Guides whose turn is the identity are not touched.
  void apply(const GuidePose &pose, StrandSet &r_guides) const;
  /// pose() then apply().
  void apply(double frame, const Mesh &posed_mesh, StrandSet &r_guides) const;
  /// Dynamic blend: mixes `simulated` (the guides simulated with their roots turned by the pose,
  /// same offsets) into `r_guides` (the rig-driven guides). At a point t in [0, 1] from root to tip
  /// the share of the simulation is  s(t) = 1 - W + sum w blend ramp(t),  W the guide's total
  /// weight: a guide no control drives is the simulation, a fully driven one without dynamic blend
  /// is the rig. Segment directions are mixed and the guide rebuilt from the root with the rig's
  /// segment lengths. A guide with s = 0 (s = 1) everywhere is the rig (the simulation) to the bit.
  void blend_dynamics(const GuidePose &pose, const StrandSet &simulated, StrandSet &r_guides) const;

 private:
  ControlSettings settings_;
  std::vector<RigControl> controls_;
  ControlBinding binding_;
  std::vector<uint64_t> ids_;
  std::vector<int64_t> offsets_;
  std::vector<SurfacePoint> roots_;
  // Per guide, in its root's rest skin frame.
  std::vector<Eigen::Vector3f> lift_axis_;  // unit, in the tangent plane
  std::vector<float> elevation_;            // of the first segment above the tangent plane, radians
                                            // (pi/2 for a guide of no length)
  std::vector<Eigen::Vector3f> root_;       // the first point, from the root's surface point
  std::vector<Eigen::Vector3f> tip_;        // the tip, from the first point
  // Per point: the arc-length parameter on the rest guide, 0 at the root, 1 at the tip.
  std::vector<float> arc_parameter_;
};

}  // namespace plume::controls
