// Animator controls (after AnimFur): a few regional controls that pose the guides every frame with
// five keyframed behaviours, as the groom file describes them. controls/ binds and applies them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/error.h"
#include "groom/ramp.h"

namespace plume {

/// How a keyed value moves between two keys. Before the first key and after the last it holds.
enum class KeyInterpolation {
  linear,
  /// A monotone cubic (Fritsch-Butland tangents, flat at the first and last key): smooth through
  /// the keys, never past the values of the two keys around it.
  smooth,
};

/// A value keyframed over frames. One key is a constant.
template <class T>
struct Keyed {
  KeyInterpolation interpolation = KeyInterpolation::linear;
  /// Strictly increasing; empty when the value is not given.
  std::vector<double> frames;
  /// One per frame.
  std::vector<T> values;

  bool empty() const { return frames.empty(); }
  static Keyed constant(const T &value) { return Keyed{KeyInterpolation::linear, {0.0}, {value}}; }
};

/// One control: a place, the guides it reaches, and its behaviours. Behaviours whose keys are
/// empty are absent; each present one is an amount keyed over frames.
struct ControlDesc {
  std::string name;
  FileLoc loc;

  /// skin: the rest `position` is bound to the closest skin point and moves with the skin, keeping
  /// its height above it; space: a point of the emitter's object space that the body moves past.
  enum class Place { skin, space } place = Place::skin;
  /// Rest-pose position, scene units.
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  /// The animated translation from `position` (the control's "translate" channel), scene units:
  /// rest-pose axes turned with the skin at the control's skin point (skin), or object axes (space).
  /// Empty: none.
  Keyed<Eigen::Vector3f> offset;

  /// Reach, scene units, from `position` to a guide's root on the rest pose; 0: unlimited.
  float radius = 0.0f;
  /// The weight from 1 at the control to 0 at `radius`: 1 - smoothstep(d / r), 1 - d / r, or 1.
  enum class Falloff { smooth, linear, constant } falloff = Falloff::smooth;
  /// Only guides rooted on these face groups (empty: any).
  std::vector<std::string> groups;
  FileLoc groups_loc;
  std::string groups_key = "groups";
  /// Optional per-vertex weight of the emitter in [0, 1] (a text file, one number per vertex),
  /// multiplied into the weight at each guide root. Empty: none.
  std::string vertex_map_path;
  FileLoc vertex_map_loc;

  /// A twin control mirrored across the plane through `mirror_point` with unit normal `mirror_normal`:
  /// position and offsets reflected, behaviours the same.
  bool mirror = false;
  Eigen::Vector3f mirror_point = Eigen::Vector3f::Zero();
  Eigen::Vector3f mirror_normal = Eigen::Vector3f::UnitX();

  /// Lift toward the skin normal: a fraction of the first segment's angle to the normal in [-1, 1]
  /// (1: along the normal; -1: down onto the skin), or an angle in degrees in [-180, 180].
  enum class LiftBy { fraction, angle } lift_by = LiftBy::fraction;
  Keyed<float> lift;
  /// Aim the guide (root to tip) at the control's current position: [0, 1].
  Keyed<float> aim;
  /// Move the tip by the control's displacement since rest times this: [-10, 10].
  Keyed<float> direction;
  /// The largest random turn about the skin normal at the root, in degrees [0, 180]; each guide
  /// turns by it times a number in [-1, 1] hashed from `twist_seed` and the guide's stable id.
  Keyed<float> random_twist;
  uint64_t twist_seed = 0;
  /// Mix of the simulated guide into the rig-driven one, [0, 1], times `blend_ramp` from root (t = 0)
  /// to tip (t = 1). Needs dynamics.
  Keyed<float> dynamic_blend;
  Ramp blend_ramp = Ramp::linear(0.0f, 1.0f);
};

struct ControlSettings {
  /// nearest: each guide follows the nearest control that reaches it (AnimFur); blend: every
  /// control that reaches it, by weight (weights summing past 1 are scaled to sum to 1).
  enum class Binding { nearest, blend } binding = Binding::blend;
  std::vector<ControlDesc> controls;
  FileLoc loc;

  bool empty() const { return controls.empty(); }
};

}  // namespace plume
