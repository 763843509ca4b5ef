// Settings of the guide simulation, as the groom file gives them; dynamics/ uses them.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "groom/error.h"
#include "groom/ramp.h"

namespace plume {

/// A collision shape attached to the skin: its centres are given in the rest pose and follow the
/// nearest surface point's frame as the emitter moves.
struct CollisionShape {
  enum class Kind { sphere, capsule } kind = Kind::sphere;
  Eigen::Vector3f a = Eigen::Vector3f::Zero();  // sphere centre / capsule end
  Eigen::Vector3f b = Eigen::Vector3f::Zero();  // capsule other end
  float radius = 1.0f;
  float friction = 0.3f;
  FileLoc loc;
};

struct DynamicsSettings {
  bool enabled = false;
  int substeps = 4;                 // per frame
  float fps = 24.0f;
  int preroll_frames = 0;
  Eigen::Vector3f gravity = Eigen::Vector3f(0.0f, -981.0f, 0.0f);  // scene units / s^2
  bool compensate_gravity = true;
  Ramp stiffness = Ramp::linear(1.0f, 0.2f);  // bending stiffness toward the groomed shape, root to tip
  float stiffness_scale = 1.0f;
  float damping = 0.5f;             // 1/s
  float drag = 0.05f;               // air drag
  float mass_per_unit = 1.0f;
  Eigen::Vector3f wind = Eigen::Vector3f::Zero();  // direction * strength
  float wind_gust = 0.0f;           // relative gust amplitude
  float wind_gust_frequency = 0.5f; // Hz
  uint64_t seed = 1;
  bool collide_with_emitter = true;
  float emitter_friction = 0.3f;
  float collision_margin = 0.05f;   // scene units
  std::vector<CollisionShape> shapes;
  /// Where the simulated guides are cached (a pattern with ####), empty: next to the output.
  std::string cache_pattern;
  FileLoc loc;
};

}  // namespace plume
