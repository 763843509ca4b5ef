// One feather (Streit and Heidrich, seed 001 sec. 4.1-4.3): the rachis Bezier and the calamus, barbs
// interpolated between key barbs (eq. 1) with degree elevation, the clamp and scale by barb length,
// the tilt into the vane's plane, and the afterfeather. Everything here is in feather space:
//   x  side to side, toward the right vane;  y  front to back, dorsal (away from the skin);
//   z  along the shaft, from the calamus base (the follicle, z = 0) toward the tip.
// Growth and type blending live in feathers/growth.h and feathers/blend.h; a coat places feathers
// on the skin (feathers/coat.h).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "feathers/bezier.h"
#include "groom/feather_desc.h"

namespace plume::feathers {

enum class Vane : int { left = 0, right = 1 };

/// Throws InputError at the template's loc, naming the field, for a value no feather can have:
/// negative or non-finite lengths and widths, a rachis length or a spacing that is not positive,
/// angles outside [0, 180], curvatures outside [-1, 1], key barbs unsorted or with fewer than 2 or
/// more than max_barb_control_points vertices, a silhouette with no point or with t unsorted, or more
/// than max_barbs_per_vane barbs. The groom reader checks the same rules with the line of each value.
void validate_template(const FeatherTemplate &feather);

/// B^df1: a plumulaceous key barb (random control vertices from the feather's seeded table).
KeyBarb plumulaceous_key_barb(float position);
/// B^df2: a straight barb with slight front-to-back curvature.
KeyBarb curved_key_barb(float position);
/// The vane's key barbs with the missing ends completed (sec. 4.2.1): B^df1 at the base when no key
/// barb is at position 0, B^df2 at the tip when none is at 1; with no key barb at all, B^df1 at both
/// ends (an entirely plumulaceous vane, a down feather).
std::vector<KeyBarb> complete_key_barbs(std::span<const KeyBarb> key_barbs);

/// The blend of eq. 1 at rachis position `rp`, before the barb is shaped: the completed key barbs
/// below and above rp, the one of lower degree elevated to the other's, every control vertex (and
/// the plumulaceous and open factors) linear in t = (rp - p_below) / (p_above - p_below). At a key
/// barb's position it is that key barb (the upper one of a step). `completed` is a sorted,
/// completed list (complete_key_barbs).
struct KeyBarbBlend {
  ControlPolygon polygon;
  float plumulaceous = 0.0f;
  float open = 1.0f;
};
KeyBarbBlend interpolate_key_barbs(std::span<const KeyBarb> completed, float rp);

/// A plumulaceous barb (B^df1) is the mean shape below with a random jitter added after the barb is
/// shaped (scaled, tilted): the jitter of barb `index` of a vane comes from the table seeded by
/// `seed` (the feather's), so the same barb gets the same fuzz on every frame. Its 4 vertices (the
/// first 0) move a vertex along the barb by up to +-0.1, in the vane's plane by up to +-0.35, and out
/// of it dorsally only, by up to plumulaceous_reach, per unit of barb length: fuzz never takes a barb
/// toward the skin.
ControlPolygon plumulaceous_jitter(uint64_t seed, Vane vane, int index);
inline constexpr float plumulaceous_reach = 0.25f;
/// The mean plumulaceous shape (the vane meshes draw it: a card shows no fuzz).
ControlPolygon mean_plumulaceous_polygon();

/// The rachis's 4 control vertices (sec. 4.3.1): from (0, 0, c_l) to (0, 0, c_l + r_l), the inner
/// ones offset by (r_lc r_l, r_vdc r_l) at a third and two thirds of the length.
std::array<Eigen::Vector3f, 4> rachis_control_points(const FeatherTemplate &feather);
/// The rachis point at parameter t in [0, 1]; its z is c_l + r_l t.
Eigen::Vector3f rachis_point(const FeatherTemplate &feather, float t);
/// The vane's frame at rachis parameter t, columns (side toward the right vane, dorsal, tangent):
/// the feather-space axes turned by the minimal rotation taking z to the rachis tangent.
Eigen::Matrix3f rachis_frame(const FeatherTemplate &feather, float t);
/// The shaft's width at height z: the calamus widens from c_wr r_w at z = 0 to r_w at z = c_l, where
/// the rachis takes r_w and tapers linearly to 0 at its tip; 0 beyond.
float shaft_width(const FeatherTemplate &feather, float z);
/// A vane's barb length at rachis position t: the silhouette, or the constant length.
float barb_length(const VaneDesc &vane, float t);

/// A barb as built (sec. 4.2.1, 4.3.1), before it is sampled: the point = attach + frame * p for
/// each point p of the Bezier curve of `polygon`.
struct Barb {
  Eigen::Vector3f attach = Eigen::Vector3f::Zero();  // on the rachis, feather space
  /// Columns: barb-space x (the barb's direction at its barb angle in the vane's plane), y (dorsal),
  /// z (in the plane, toward the tip), in feather space. Mirrored on the left vane.
  Eigen::Matrix3f frame = Eigen::Matrix3f::Identity();
  /// Barb space: the blend, blended toward the mean plumulaceous shape by its plumulaceous factor,
  /// the first vertex moved to the origin, the end-to-end distance clamped to [0, 1], scaled by the
  /// barb length and turned about barb z so that the curve's midpoint lies in the vane's plane (the
  /// barb leaves the rachis in the plane: "This rotation ensures continuity across the rachis");
  /// then the plumulaceous jitter added.
  ControlPolygon polygon;
  /// The barb's angle to the rachis, radians (after the open factor).
  float angle = 0.0f;
  /// Its plumulaceous factor and length (the jitter is plumulaceous * length * the table's entry).
  float plumulaceous = 0.0f;
  float length = 0.0f;
  /// The same barb on the flat feather (rachis straight along z, no curvature), for vane texture
  /// coordinates: point_flat = attach_flat + frame_flat * p.
  Eigen::Vector3f attach_flat = Eigen::Vector3f::Zero();
  Eigen::Matrix3f frame_flat = Eigen::Matrix3f::Identity();
};

/// A feather ready to build: its parameters (grown and varied), each vane's completed key barbs,
/// its barb positions, and its afterfeather. Made once (make_shape); building a frame reads it.
struct FeatherShape {
  FeatherTemplate main;
  std::array<std::vector<KeyBarb>, 2> main_keys;  // completed, per Vane
  std::vector<float> main_positions;
  bool has_after = false;
  FeatherTemplate after;
  std::array<std::vector<KeyBarb>, 2> after_keys;
  std::vector<float> after_positions;
  /// Seeds the plumulaceous barbs (the feather's stable id, or a template's).
  uint64_t seed = 0;
};

/// Afterfeathers smaller than this (relative to the feather) are left out.
inline constexpr float kSmallestAfterfeather = 0.01f;

/// The afterfeather's parameters: the main feather's, lengths and widths scaled by its size, no
/// calamus, no key barbs (entirely plumulaceous, as afterfeathers are).
FeatherTemplate afterfeather_template(const FeatherTemplate &main);
/// Where the afterfeather's feather space sits in the main feather's: at the top of the calamus,
/// on its ventral side (one rachis width below).
Eigen::Vector3f afterfeather_offset(const FeatherTemplate &main);

/// A feather of `adult`'s type at development stage `stage` (feathers/growth.h; 1 the adult):
/// barb positions come from the adult, so a feather keeps its barbs as it grows. Calls
/// validate_template(adult).
FeatherShape make_shape(const FeatherTemplate &adult, uint64_t seed, float stage = 1.0f);

/// Barb `index` of `vane` at rachis position `rp` of `feather` (main or afterfeather), with the
/// completed key barbs `keys` of that vane. index < 0 takes the mean plumulaceous polygon.
Barb build_barb(const FeatherTemplate &feather, std::span<const KeyBarb> keys, Vane vane, float rp, int index,
                uint64_t seed);

/// What the two barbs at rachis position rp share: the rachis point they leave from
/// (rachis_point(feather, rp)) and the vane's frame there (rachis_frame(feather, rp)).
struct BarbAttachment {
  Eigen::Vector3f point = Eigen::Vector3f::Zero();
  Eigen::Matrix3f frame = Eigen::Matrix3f::Identity();
};
BarbAttachment barb_attachment(const FeatherTemplate &feather, float rp);

/// The barbs of one vane built in turn, as build_barb builds them (the same barbs, to the bit), with
/// the work they share done once: the attachment at rp is passed in (both vanes' barbs there share
/// it), and the two key barbs' polygons around the last rp, elevated to one degree, are kept for the
/// next barb, which mostly lies between the same two (and the mean plumulaceous polygon too).
class VaneBarbs {
 public:
  /// `feather` and `keys` (the vane's completed key barbs) must outlive this.
  VaneBarbs(const FeatherTemplate &feather, std::span<const KeyBarb> keys, Vane vane, uint64_t seed)
      : feather_(feather), keys_(keys), vane_(vane), seed_(seed) {}
  /// build_barb(feather, keys, vane, rp, index, seed), `attachment` = barb_attachment(feather, rp).
  Barb operator()(float rp, int index, const BarbAttachment &attachment);

 private:
  /// interpolate_key_barbs(keys, rp).
  KeyBarbBlend blend(float rp);

  const FeatherTemplate &feather_;
  std::span<const KeyBarb> keys_;
  Vane vane_;
  uint64_t seed_;
  size_t above_ = 0;  // the key barb above the kept pair (0: none kept)
  ControlPolygon below_, upper_;
  ControlPolygon mean_;  // the mean plumulaceous polygon, elevated as the last barb needed it

};

}  // namespace plume::feathers
