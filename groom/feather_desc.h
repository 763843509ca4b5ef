// Feathers as a groom describes them: templates with Streit and Heidrich's parameters (calamus,
// rachis, vanes, key barbs), the key feathers that place templates on the skin, where follicles
// grow, and how a coat's feathers vary and are output. feathers/ builds feathers from these.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "groom/error.h"
#include "groom/ramp.h"

namespace plume {

/// The most control vertices a key barb may have (a Bezier curve of degree 15).
inline constexpr int max_barb_control_points = 16;
/// The most barbs a vane may have (its spacing over its rachis length): beyond it, a typo.
inline constexpr int max_barbs_per_vane = 10000;

/// A key barb: a Bezier curve in barb space at a position on the rachis (sec. 4.2.1). Barb space:
/// x along the barb, away from the rachis; y out of the vane's plane, dorsal (away from the skin);
/// z in the vane's plane, toward the feather's tip. The same key barb mirrors onto both vanes.
struct KeyBarb {
  /// On the rachis: 0 at its base, 1 at its tip. A vane's key barbs are sorted by position (equal
  /// positions make a step in the vane).
  float position = 0.0f;
  /// Control vertices, at least 2 and at most max_barb_control_points. The first is moved to the
  /// origin; the distance from the first to the last is clamped to [0, 1] and the curve scaled by
  /// the barb's length, so a key barb shorter than 1 makes its barbs shorter than the silhouette.
  std::vector<Eigen::Vector3f> points;
  /// Blend toward the seeded random control vertices of a plumulaceous (downy) barb: 0 a
  /// pennaceous barb as drawn, 1 fully plumulaceous.
  float plumulaceous = 0.0f;
  /// How far the barb has opened from the sheath: 0 along the rachis, 1 at the vane's barb angle.
  /// Grown feathers use it (sec. 4.2.4); a template's key barbs are open.
  float open = 1.0f;
  FileLoc loc;
};

/// One vane (the barbs on one side of the rachis).
struct VaneDesc {
  /// Angle between a barb and the rachis toward the tip, degrees in [0, 180], at the rachis base
  /// and tip; linear in between.
  float angle_base = 45.0f;
  float angle_tip = 30.0f;
  /// Barb length (scene units) when the silhouette is empty.
  float barb_length = 1.0f;
  /// Barb length along the rachis: (t, length) points, t from 0 (base) to 1 (tip), linear between.
  /// Empty: the constant barb_length.
  Ramp silhouette;
  /// The key barbs, sorted by position. Missing ends are completed when a feather is built: a
  /// plumulaceous barb at the base (B^df1) and one with slight front-to-back curvature at the tip
  /// (B^df2); with no key barb at all the vane is entirely plumulaceous (a down feather).
  std::vector<KeyBarb> key_barbs;
};

/// A feather type: the parameters of Table 1. Lengths and widths in scene units.
struct FeatherTemplate {
  std::string name;
  float calamus_length = 0.1f;
  /// Calamus width at its base, as a fraction of the rachis base width (its top is the rachis width,
  /// so the shaft is continuous).
  float calamus_width_ratio = 0.8f;
  float rachis_length = 1.0f;
  /// Rachis width at its base; it tapers linearly to a point at the tip.
  float rachis_width = 0.02f;
  /// Rachis curvatures r_lc (side to side, toward the right vane) and r_vdc (front to back,
  /// dorsal), as fractions of the rachis length: the offsets of the Bezier rachis's inner control
  /// vertices (sec. 4.3.1).
  float curvature_side = 0.0f;
  float curvature_front = 0.0f;
  /// Distance between neighbouring barbs along the rachis at its base and tip, linear in between;
  /// the same on both vanes.
  float spacing_base = 0.05f;
  float spacing_tip = 0.05f;
  /// Barb width (diameter) at the rachis; barbs taper to a quarter of it at their tip.
  float barb_width = 0.002f;
  VaneDesc left;
  VaneDesc right;
  /// Size of the afterfeather, a second plumulaceous feather with the same parameters at the top
  /// of the calamus, relative to the main feather; 0: none.
  float afterfeather = 0.0f;
  FileLoc loc;
};

/// The positions of a vane's barbs on the rachis (the same on both vanes): from 0 toward the tip,
/// each next at the current spacing (linear from spacing_base to spacing_tip) over the rachis
/// length, while below 1 - 1e-5. Empty for a template without a positive rachis length and spacings. Throws
/// InputError at the template's loc beyond max_barbs_per_vane.
std::vector<float> barb_positions(const FeatherTemplate &feather);

/// A template placed on the skin: at a point, or over face groups (tracts). Every feather blends the
/// key feathers with weights that are continuous over the surface (docs/feathers.md).
struct KeyFeather {
  std::string template_name;
  int template_index = -1;  // into FeatherDesc::templates, resolved by the reader
  /// Tracts: the face groups this key feather covers; empty when placed at a point.
  std::vector<std::string> groups;
  FileLoc groups_loc;
  Eigen::Vector3f point = Eigen::Vector3f::Zero();  // rest pose, snapped to the surface
  /// The blend width: the key feather's weight is exp(-(d / radius)^2) at surface distance d from its
  /// point or tract. 0: 5% of the emitter's bounding-box diagonal.
  float radius = 0.0f;
  /// Development stage in [0, 1] of the feathers it places (1: adult).
  float stage = 1.0f;
  /// With layers: the feathers whose heaviest key feather this is lie above those of a key feather
  /// with a smaller layer (docs/feathers.md, "Layers").
  float layer = 0.0f;
  bool layer_given = false;
  FileLoc loc;
};

/// Where follicles (feather roots) grow.
struct FollicleSettings {
  enum class Source { scatter, file } source = Source::scatter;
  int64_t count = 0;                // scatter: total (0: density)
  double density = 0.0;             // scatter: follicles per unit area
  std::vector<std::string> groups;  // scatter: only on these face groups (tracts); empty: all
  /// scatter: a vertex map (one number in [0, 1] per emitter vertex): a follicle is kept where its
  /// value at the follicle exceeds a number hashed from the follicle's id.
  std::string map_path;
  std::string file;                 // fixed follicles: .txt x y z lines or a strand file's first points
  uint64_t seed = 1;
  FileLoc loc;
};

/// Per-feather variation, seeded from each feather's stable id.
struct FeatherVariation {
  float length = 0.0f;      // relative: lengths scaled by 1 +- length
  float direction = 0.0f;   // degrees: the feather turned about the skin normal by up to +- this
  float lift = 0.0f;        // degrees: raised or lowered from the skin by up to +- this
  float barb_angle = 0.0f;  // degrees added to both vanes' barb angles, up to +- this
  float stage = 0.0f;       // development stage lowered by up to this (moult)
  uint64_t seed = 1;
};

/// Level of detail at output: points are evaluated from the Bezier curves, never stored.
struct FeatherDetail {
  int rachis_points = 16;  // points of the rachis curve after the calamus base (>= 2)
  int barb_points = 8;     // points per barb curve (>= 2)
  int vane_rows = 16;      // vane mesh: barbs evaluated along the rachis (>= 2)
  int vane_columns = 4;    // vane mesh: segments across each vane (>= 1)
  /// Texture coordinates of the OBJ vane mesh: across the vane (the flat feather) or along each
  /// barb (u along the barb, v its attachment on the rachis); USD files get both.
  enum class Uv { vane, barb } uv = Uv::vane;
};

struct FeatherDesc {
  /// True when the groom has a `feathers` section: it grows feathers instead of hair strands.
  bool enabled = false;
  std::vector<FeatherTemplate> templates;
  std::vector<KeyFeather> key_feathers;
  FollicleSettings follicles;
  FeatherVariation variation;
  FeatherDetail detail;
  /// The template files the templates came from (absolute), besides the groom file.
  std::vector<std::string> template_files;
  /// Guide stems blended per follicle (as fur blends guides), in [1, 16].
  int guides_per_feather = 4;
  /// Stem weights ~ 1 / distance^falloff.
  float falloff = 2.0f;
  /// Keep feathers off the skin: a feather whose vane comes nearer the skin than `clearance` times a
  /// point's distance from the root is turned up about its root until it clears (and shrunk toward
  /// its root where no turn clears it).
  bool lift = true;
  float clearance = 0.03f;
  /// Keep feathers apart (feathers/layering.h): an order frozen at rest, and each feather turned up
  /// until its vanes keep `layer_offset` times its extent from every lower feather's. Off unless
  /// the groom asks (layers: {enabled: true}): its cost grows with the coat's density.
  bool layers = false;
  float layer_offset = 0.002f;
  /// The layer order's own sources besides coverage at rest (docs/feathers.md, "Layers"): a vertex
  /// map (one number in [0, 1] per emitter vertex; a feather lies above those with a smaller value at
  /// their follicles), and tracts whose feathers lie above (front) or below (rear) every other.
  std::string layer_map_path;
  std::vector<std::string> layer_front, layer_rear;
  FileLoc layer_front_loc, layer_rear_loc;
  FileLoc loc;

  /// Index of a template by name, or -1.
  int template_index(const std::string &name) const {
    for (size_t i = 0; i < templates.size(); ++i)
      if (templates[i].name == name) return int(i);
    return -1;
  }
};

}  // namespace plume
