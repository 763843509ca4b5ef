#include "dynamics/skin_shapes.h"

#include <algorithm>
#include <cmath>

#include "groom/error.h"
#include "groom/mesh_query.h"

namespace plume::dynamics {

FramePose FramePose::from(const SurfaceFrame &frame) {
  FramePose pose;
  pose.origin = frame.origin.cast<double>();
  pose.rotation = Eigen::Quaterniond(frame.basis.cast<double>());
  pose.rotation.normalize();
  return pose;
}

FramePose FramePose::interpolate(const FramePose &a, const FramePose &b, double s) {
  // The ends are the poses themselves (what slerp gives there, without its trigonometry): at one
  // substep per frame every interpolation is at an end.
  if (s == 0.0) return a;
  if (s == 1.0) return b;
  FramePose pose;
  pose.origin = a.origin + s * (b.origin - a.origin);
  pose.rotation = a.rotation.slerp(s, b.rotation);
  return pose;
}

double shape_distance(const PosedShape &shape, const Eigen::Vector3d &x, Eigen::Vector3d &r_normal,
                      double &r_axis_param) {
  // Closest point of the core segment [a, b]: c = a + t (b - a), t = clamp((x - a).(b - a) / |b - a|^2).
  const Eigen::Vector3d axis = shape.b - shape.a;
  const double axis2 = axis.squaredNorm();
  double t = 0.0;
  if (shape.kind == CollisionShape::Kind::capsule && axis2 > 0.0) t = std::clamp((x - shape.a).dot(axis) / axis2, 0.0, 1.0);
  const Eigen::Vector3d core = shape.a + t * axis;
  const Eigen::Vector3d offset = x - core;
  const double dist = offset.norm();
  if (dist > 1e-12) {
    r_normal = offset / dist;
  } else {
    // On the axis itself: any direction perpendicular to the axis is outward.
    r_normal = axis2 > 0.0 ? Eigen::Vector3d(axis.unitOrthogonal()) : Eigen::Vector3d::UnitY();
  }
  r_axis_param = t;
  return dist - shape.radius;
}

SkinShapes::SkinShapes(const Mesh &rest_mesh, const std::vector<CollisionShape> &shapes) : shapes_(shapes) {
  if (shapes.empty()) return;
  const MeshQuery query(rest_mesh);
  for (const CollisionShape &shape : shapes) {
    if (!(shape.radius > 0.0f) || !std::isfinite(shape.radius))
      throw InputError(shape.loc, "collision shape radius: expected a positive number, got " + std::to_string(shape.radius));
    if (!(shape.friction >= 0.0f))
      throw InputError(shape.loc, "collision shape friction: expected >= 0, got " + std::to_string(shape.friction));
    const Eigen::Vector3f ends[2] = {shape.a, shape.kind == CollisionShape::Kind::capsule ? shape.b : shape.a};
    for (const Eigen::Vector3f &end : ends) {
      const SurfacePoint anchor = query.closest(end);
      anchors_.push_back(anchor);
      local_ends_.push_back(surface_frame(rest_mesh, anchor).to_local(end).cast<double>());
    }
  }
}

void SkinShapes::frames(const Mesh &posed_mesh, std::vector<FramePose> &r_frames) const {
  r_frames.resize(anchors_.size());
  for (size_t i = 0; i < anchors_.size(); ++i) r_frames[i] = FramePose::from(surface_frame(posed_mesh, anchors_[i]));
}

void SkinShapes::pose(const std::vector<FramePose> &frames_from, const std::vector<FramePose> &frames_to, double s,
                      std::vector<PosedShape> &r_shapes) const {
  r_shapes.resize(shapes_.size());
  for (size_t i = 0; i < shapes_.size(); ++i) {
    PosedShape &posed = r_shapes[i];
    posed.kind = shapes_[i].kind;
    posed.radius = shapes_[i].radius;
    posed.friction = shapes_[i].friction;
    posed.a = FramePose::interpolate(frames_from[2 * i], frames_to[2 * i], s).to_world(local_ends_[2 * i]);
    posed.b = FramePose::interpolate(frames_from[2 * i + 1], frames_to[2 * i + 1], s).to_world(local_ends_[2 * i + 1]);
  }
}

}  // namespace plume::dynamics
