// Everything a groom file says, validated and with paths made absolute. io/ reads it from YAML;
// app/ composes meshes, guides, binding, growth, effects and dynamics from it.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/control_desc.h"
#include "groom/dynamics_desc.h"
#include "groom/effect_desc.h"
#include "groom/error.h"
#include "groom/feather_desc.h"
#include "groom/parting.h"

namespace plume {

/// One keyframe of a rigid emitter animation; between keys, translation and scale are
/// interpolated linearly and rotation by slerp.
struct RigidKey {
  double frame = 1.0;
  Eigen::Vector3f translate = Eigen::Vector3f::Zero();
  Eigen::Vector3f rotate_degrees = Eigen::Vector3f::Zero();  // XYZ Euler angles, applied X then Y then Z
  float scale = 1.0f;
};

struct EmitterAnimation {
  enum class Kind { none, obj_sequence, rigid } kind = Kind::none;
  /// obj_sequence: a path pattern with #### or %04d (absolute), same topology as the rest mesh.
  std::string sequence_pattern;
  /// rigid: keys sorted by frame, about `pivot` (rest-pose coordinates).
  std::vector<RigidKey> keys;
  Eigen::Vector3f pivot = Eigen::Vector3f::Zero();
  FileLoc loc;
};

/// The most roots a groom (roots.count, roots.density x area) or a run (--strands) may ask for:
/// beyond this a typo, not a groom.
inline constexpr int64_t max_root_count = 100'000'000;

struct RootSettings {
  enum class Source { scatter, file } source = Source::scatter;
  int64_t count = 0;           // scatter: total count (0: use density)
  double density = 0.0;        // scatter: roots per unit area (when count is 0)
  std::vector<std::string> groups;  // scatter: only these face groups (empty: all)
  /// scatter: only triangles within this distance of a guide root (0: off). Lets a groom emit on
  /// the scalp of a mesh that has no face groups.
  double near_guides = 0.0;
  uint64_t seed = 1;
  std::string file;            // file: .hair/.ply/.usda (first point of each strand) or .txt (x y z lines)
  FileLoc loc;
};

/// The most guides a root may blend (InterpolationSettings::k): growth keeps them in fixed slots.
inline constexpr int max_guides_per_root = 16;

/// The default strand width at the root as a fraction of the rest emitter's bounding-box diagonal
/// (Sintel's head and shoulders, 62 units across, get 0.031; the tip's default is a quarter of it).
inline constexpr float default_width_root_fraction = 5e-4f;

struct InterpolationSettings {
  enum class Method { streamline, fur, linear } method = Method::streamline;
  int k = 4;                   // guides per root, in [1, max_guides_per_root]
  double radius = 0.0;         // 0: unlimited
  float falloff = 2.0f;        // weight ~ 1 / d^falloff
  /// Scene units kept between strands and the skin; negative (the default): interp::
  /// default_margin_fraction of the rest guides' median segment length, so that the groom's scale
  /// does not matter.
  float skin_margin = -1.0f;
  /// Streamline: the separation pass over the written polylines (interp/separate.h). On by default:
  /// the field's exact curves do not cross, but its polylines can where it brings neighbours within a
  /// chord's sag. With it, a proxy's strands are within the pass's largest move of a run with more
  /// roots, not the same bytes (`separate: false` gives those back).
  bool separate = true;
  FileLoc loc;
};

/// The largest preview, in pixels a side: its image (3 bytes a pixel, 201 MB) and PNG are held whole.
inline constexpr int max_preview_size = 8192;

struct OutputSettings {
  std::string path_pattern;    // e.g. out/hair.####.usda (absolute); empty: none
  std::string vanes_pattern;   // feathers: vane meshes, e.g. out/vanes.####.obj (absolute); empty: none
  std::string frames;          // e.g. "1-48" (empty: 1)
  std::string preview_pattern; // e.g. out/preview.####.png
  int preview_every = 0;       // write a preview every N frames (0: first frame only)
  int preview_size = 800;     // [16, max_preview_size]
  /// USD layer metadata of the outputs: metres per scene unit (output.units) and the up axis,
  /// "Y" or "Z" (output.up_axis). Metadata only: the points are written as the groom has them.
  double meters_per_unit = 0.01;
  std::string up_axis = "Y";
  /// The top-level USD stage of a .usda sequence (output.stage, absolute); empty: derived from
  /// the output pattern (app/usd_stage_output.h).
  std::string stage_path;
  FileLoc loc;
};

struct GroomDesc {
  std::string source;          // the groom file's path
  std::string name;
  std::string emitter_path;    // absolute
  FileLoc emitter_loc;
  EmitterAnimation animation;
  std::string guides_path;     // absolute
  FileLoc guides_loc;
  RootSettings roots;
  int points_per_strand = 32;
  /// Strand widths (diameters) at the root and the tip, scene units; negative (the default):
  /// default_width_root_fraction of the rest emitter's bounding-box diagonal at the root and a
  /// quarter of that at the tip, so that the groom's scale does not matter.
  float width_root = -1.0f;
  float width_tip = -1.0f;
  InterpolationSettings interpolation;
  PartingSettings partings;
  std::vector<EffectDesc> effects;
  DynamicsSettings dynamics;
  /// Enabled when the groom grows feathers (then roots, strands, interpolation, partings and effects
  /// are not used: follicles, templates and stems say everything).
  FeatherDesc feathers;
  ControlSettings controls;
  OutputSettings output;

  /// The hair groups of a groom file with a `groups` list (scalp, brows, lashes...), each a full
  /// description (guides, roots, strands, interpolation, partings, effects, dynamics, controls) that
  /// shares this groom's source, name, emitter, animation and output; the fields above are then
  /// those of the first group. Empty for a groom file without groups: this description is its one
  /// group. A group's own `groups` is empty.
  std::vector<GroomDesc> groups;
  /// For a hair group: its name (a USD prim name, unique in the groom) and its index in `groups`;
  /// empty and 0 for a groom without groups.
  std::string group_name;
  int group_index = 0;
  FileLoc group_loc;

  /// Where the dynamics section is written, or the groom file when it has none (for messages).
  FileLoc dynamics_loc() const { return dynamics.loc.file.empty() ? FileLoc{source} : dynamics.loc; }
};

}  // namespace plume
