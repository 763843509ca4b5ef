// Descriptions of the effects stack (Hair Designer "Hair effects"): what the groom file says;
// effects/ applies them.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/error.h"
#include "groom/ramp.h"

namespace plume {

enum class EffectType { clump, tension, length, wave, frizz, curl };

/// One entry of the stack. Fields not used by `type` keep their defaults.
struct EffectDesc {
  EffectType type = EffectType::clump;
  FileLoc loc;
  uint64_t seed = 0;
  /// Overall strength in [0, 1] (0 leaves strands bit-identical).
  float amount = 1.0f;
  /// Strength along the strand, root (t = 0) to tip (t = 1).
  Ramp ramp;
  /// Limit to these face groups / zones (empty: everywhere).
  std::vector<std::string> groups;
  /// Where `groups` is written and its key path ("effects[2].groups"), for messages.
  FileLoc groups_loc;
  std::string groups_key = "groups";
  /// Optional per-vertex scale map of the emitter: a text file with one number per vertex.
  std::string vertex_map_path;

  // clump
  enum class ClumpCenters { poisson, per_guide } clump_centers = ClumpCenters::poisson;
  float clump_radius = 1.0f;
  float clump_twist = 0.0f;        // turns of the clump from root to tip
  float stray_fraction = 0.0f;     // fraction of strands left out

  // length
  enum class LengthDistribution { uniform, normal } length_distribution = LengthDistribution::uniform;
  float length_variation = 0.0f;   // relative, e.g. 0.2 = +-20%
  bool cut_plane = false;
  Eigen::Vector3f cut_point = Eigen::Vector3f::Zero();
  Eigen::Vector3f cut_normal = Eigen::Vector3f::UnitY();
  float max_length = 0.0f;         // 0: no per-zone maximum

  // wave / frizz / curl
  float frequency = 1.0f;          // cycles per scene unit
  float amplitude = 0.0f;          // scene units
  float fraction = 1.0f;           // fraction of strands affected (frizz)
  float curl_radius = 0.0f;        // scene units
  float turns_per_unit = 0.0f;     // helix turns per scene unit of strand length
};

}  // namespace plume
