// Which controls drive each guide, and how much: the groom's controls placed on the rest pose
// (with their mirrored twins), and each guide's weights, computed once and kept for every frame.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "groom/control_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"

namespace plume::controls {

/// A control as the rig uses it: one of the groom's, or the mirrored twin of one.
struct RigControl {
  /// Index of its description in ControlSettings::controls.
  size_t desc = 0;
  bool twin = false;
  /// The other control of a mirror pair; -1 when not mirrored.
  int partner = -1;
  /// Rest-pose position (reflected for a twin), scene units.
  Eigen::Vector3f rest_position = Eigen::Vector3f::Zero();
  /// The keyed offset (reflected for a twin); empty: none.
  Keyed<Eigen::Vector3f> offset;
  /// Skin controls: the rest skin point closest to rest_position, the rest position in that point's
  /// rest surface frame (so its height above the skin is kept), and that frame's basis.
  SurfacePoint anchor;
  Eigen::Vector3f anchor_local = Eigen::Vector3f::Zero();
  Eigen::Matrix3f anchor_rest_basis = Eigen::Matrix3f::Identity();
};

/// The groom's controls in order, each mirrored one followed by its twin. Skin controls are bound
/// to the closest point of `rest_query`'s mesh (`rest_mesh`, normals computed).
std::vector<RigControl> place_controls(const ControlSettings &settings, const Mesh &rest_mesh,
                                       const MeshQuery &rest_query);

/// For each guide, the controls that drive it and their weights (compressed rows).
struct ControlBinding {
  /// guide_count() + 1 entries: the controls driving guide g are entries offsets[g] .. offsets[g + 1].
  std::vector<int64_t> offsets{0};
  /// Per entry: an index into the placed controls.
  std::vector<int32_t> controls;
  /// Per entry: the weight, in (0, 1]; the weights of a guide sum to at most 1.
  std::vector<float> weights;

  size_t guide_count() const { return offsets.size() - 1; }
  /// The sum of a guide's weights, in [0, 1]: 0 when no control drives it.
  float total_weight(size_t guide) const;
};

/// A control's weight at a guide root is the product of its falloff (1 at the control, 0 at its
/// radius, from the rest position to the root's rest position; 1 everywhere with no radius), its
/// face groups (0 off them) and its vertex map (interpolated at the root). Of a mirror pair a guide
/// sees only the member nearer its root (the side of the plane the normal points to takes a tie),
/// so a control on its own mirror plane does not count twice. nearest: the nearest control of
/// positive weight drives the guide with that weight (ties: the first); blend: every control of
/// positive weight, the weights scaled down to sum to 1 where they sum past it.
/// `vertex_maps`: empty, or one per ControlDesc (empty when it has none, else one value in [0, 1]
/// per rest vertex). Throws InputError at a control's `groups` for a face group the mesh lacks.
ControlBinding bind_controls(const ControlSettings &settings, const std::vector<RigControl> &controls,
                             const Mesh &rest_mesh, const Guides &guides,
                             const std::vector<std::vector<float>> &vertex_maps = {});

}  // namespace plume::controls
