// Collision spheres and capsules attached to the skin: each centre is bound to its closest surface
// point on the rest mesh and carried by that point's surface frame; plus the push-out kernel.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <vector>

#include "groom/dynamics_desc.h"
#include "groom/mesh.h"

namespace plume::dynamics {

/// A rigid frame between two poses: origin lerped, rotation slerped (parameter s in [0, 1]).
struct FramePose {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();

  static FramePose from(const SurfaceFrame &frame);
  static FramePose interpolate(const FramePose &a, const FramePose &b, double s);
  Eigen::Vector3d to_world(const Eigen::Vector3d &local) const { return origin + rotation * local; }
};

/// A collision shape at one instant, emitter object space (scene units).
struct PosedShape {
  CollisionShape::Kind kind = CollisionShape::Kind::sphere;
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  // centre / capsule end
  Eigen::Vector3d b = Eigen::Vector3d::Zero();  // capsule other end (== a for a sphere)
  double radius = 1.0;
  double friction = 0.3;
};

/// Signed distance from `x` to the shape's surface (negative inside), with the outward unit
/// normal and the parameter along the capsule axis (0 at a, 1 at b; 0 for a sphere) of the
/// closest axis point.
double shape_distance(const PosedShape &shape, const Eigen::Vector3d &x, Eigen::Vector3d &r_normal,
                      double &r_axis_param);

class SkinShapes {
 public:
  SkinShapes() = default;
  /// Binds both ends of each shape to the closest surface point of `rest_mesh` (normals computed).
  SkinShapes(const Mesh &rest_mesh, const std::vector<CollisionShape> &shapes);

  size_t size() const { return shapes_.size(); }
  /// Frames of the bound surface points on a pose of the rest mesh: 2 per shape (a then b).
  void frames(const Mesh &posed_mesh, std::vector<FramePose> &r_frames) const;
  /// The shapes with their ends carried by frames interpolated between two poses' frames.
  void pose(const std::vector<FramePose> &frames_from, const std::vector<FramePose> &frames_to, double s,
            std::vector<PosedShape> &r_shapes) const;

 private:
  std::vector<CollisionShape> shapes_;
  std::vector<SurfacePoint> anchors_;       // 2 per shape
  std::vector<Eigen::Vector3d> local_ends_;  // 2 per shape: the end in its anchor's rest frame
};

}  // namespace plume::dynamics
