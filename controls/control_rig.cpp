#include "controls/control_rig.h"

#include <algorithm>
#include <cmath>

#include "controls/keyframes.h"
#include "controls/swing.h"
#include "groom/error.h"
#include "groom/roots.h"

namespace plume::controls {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kRadians = kPi / 180.0f;
// Fewer guides than this are posed on one thread: a parallel region costs more than they do (a
// guide takes about a microsecond; a team of threads woken every frame spins between frames).
constexpr int64_t kParallelGuides = 4096;

// The random multiplier of a guide's twist, in [-1, 1): hashed from the control's seed and the
// guide's stable id, so it is the same in every frame, on every machine and in any order.
float twist_multiplier(uint64_t seed, uint64_t guide_id) {
  return 2.0f * hash_to_unit(hash_combine(hash64(seed), guide_id)) - 1.0f;
}

Eigen::Vector3f unit_or(const Eigen::Vector3f &v, const Eigen::Vector3f &fallback) {
  const float len = v.norm();
  return len > 0.0f && std::isfinite(len) ? Eigen::Vector3f(v / len) : fallback;
}

// A unit vector of the tangent plane along the horizontal part of `u`, else `fallback`.
Eigen::Vector3f azimuth_of(const Eigen::Vector3f &u, const Eigen::Vector3f &fallback) {
  return unit_or(Eigen::Vector3f(u.x(), u.y(), 0.0f), fallback);
}

}  // namespace

ControlRig::ControlRig(const Mesh &rest_mesh, const Guides &guides, const ControlSettings &settings,
                       const std::vector<std::vector<float>> &vertex_maps)
    : settings_(settings) {
  const MeshQuery rest_query(rest_mesh);
  controls_ = place_controls(settings_, rest_mesh, rest_query);
  binding_ = bind_controls(settings_, controls_, rest_mesh, guides, vertex_maps);

  const StrandSet &strands = guides.strands;
  const size_t guide_num = guides.size();
  ids_ = strands.ids;
  offsets_ = strands.offsets;
  roots_ = guides.roots;
  lift_axis_.resize(guide_num);
  elevation_.resize(guide_num);
  root_.resize(guide_num);
  tip_.resize(guide_num);
  arc_parameter_.assign(strands.point_count(), 0.0f);
  const Eigen::Vector3f z = Eigen::Vector3f::UnitZ();
  for (size_t g = 0; g < guide_num; ++g) {
    const SurfaceFrame frame = surface_frame(rest_mesh, guides.roots[g]);
    const std::span<const Eigen::Vector3f> points = strands.points(g);
    // The first segment of non-zero length.
    Eigen::Vector3f first = z;
    for (size_t j = 1; j < points.size(); ++j) {
      const Eigen::Vector3f d = frame.dir_to_local(points[j] - points[0]);
      if (d.squaredNorm() > 0.0f) {
        first = unit_or(d, z);
        break;
      }
    }
    root_[g] = frame.to_local(points[0]);
    tip_[g] = frame.dir_to_local(points.back() - points[0]);
    elevation_[g] = std::asin(std::clamp(first.z(), -1.0f, 1.0f));
    // d x z = (d.y, -d.x, 0): turning d about it moves d toward the normal. A guide straight up the
    // normal turns toward its tip's azimuth, or the frame's tangent.
    const Eigen::Vector3f lean = azimuth_of(first, azimuth_of(tip_[g], Eigen::Vector3f::UnitX()));
    lift_axis_[g] = Eigen::Vector3f(lean.y(), -lean.x(), 0.0f);

    const double length = strands.length(g);
    double arc = 0.0;
    for (size_t j = 1; j < points.size(); ++j) {
      arc += double((points[j] - points[j - 1]).norm());
      arc_parameter_[size_t(strands.offsets[g]) + j] = length > 0.0 ? float(arc / length) : 1.0f;
    }
  }
}

void ControlRig::pose(double frame, const Mesh &posed_mesh, GuidePose &r_pose) const {
  r_pose.frame = frame;
  r_pose.controls.resize(controls_.size());
  for (size_t c = 0; c < controls_.size(); ++c) {
    const RigControl &control = controls_[c];
    const ControlDesc &desc = settings_.controls[control.desc];
    ControlState &state = r_pose.controls[c];
    const Eigen::Vector3f offset = control.offset.empty() ? Eigen::Vector3f::Zero() : value_at(control.offset, frame);
    if (desc.place == ControlDesc::Place::skin) {
      const SurfaceFrame anchor = surface_frame(posed_mesh, control.anchor);
      state.displacement = anchor.dir_to_world(control.anchor_rest_basis.transpose() * offset);
      state.position = anchor.to_world(control.anchor_local) + state.displacement;
    } else {
      state.displacement = offset;
      state.position = control.rest_position + offset;
    }
    state.lift = desc.lift.empty() ? 0.0f : value_at(desc.lift, frame);
    if (desc.lift_by == ControlDesc::LiftBy::angle) state.lift *= kRadians;
    state.aim = desc.aim.empty() ? 0.0f : value_at(desc.aim, frame);
    state.direction = desc.direction.empty() ? 0.0f : value_at(desc.direction, frame);
    state.twist = desc.random_twist.empty() ? 0.0f : value_at(desc.random_twist, frame) * kRadians;
    state.blend = desc.dynamic_blend.empty() ? 0.0f : value_at(desc.dynamic_blend, frame);
  }

  const int64_t guide_num = int64_t(roots_.size());
  r_pose.frames.resize(size_t(guide_num));
  r_pose.turns.resize(size_t(guide_num));
  r_pose.turned.resize(size_t(guide_num));
  const Eigen::Vector3f z = Eigen::Vector3f::UnitZ();
#pragma omp parallel for schedule(static) if (guide_num >= kParallelGuides)
  for (int64_t gi = 0; gi < guide_num; ++gi) {
    const size_t g = size_t(gi);
    const SurfaceFrame frame = surface_frame(posed_mesh, roots_[g]);
    r_pose.frames[g] = frame;
    Eigen::Quaternionf q = Eigen::Quaternionf::Identity();
    bool turned = false;

    // Lift and twist: sums of the weighted amounts.
    float lift = 0.0f, twist = 0.0f;
    bool lifted = false;
    Eigen::Vector3f displacement = Eigen::Vector3f::Zero();
    const float elevation = elevation_[g];
    for (int64_t e = binding_.offsets[g]; e < binding_.offsets[g + 1]; ++e) {
      const size_t c = size_t(binding_.controls[size_t(e)]);
      const float w = binding_.weights[size_t(e)];
      const ControlState &state = r_pose.controls[c];
      const ControlDesc &desc = settings_.controls[controls_[c].desc];
      if (!desc.lift.empty()) {
        lifted = true;
        if (desc.lift_by == ControlDesc::LiftBy::angle)
          lift += w * state.lift;
        else
          lift += w * state.lift * (state.lift >= 0.0f ? 0.5f * kPi - elevation : std::max(elevation, 0.0f));
      }
      if (state.twist != 0.0f) twist += w * state.twist * twist_multiplier(desc.twist_seed, ids_[g]);
      if (state.direction != 0.0f) displacement += (w * state.direction) * state.displacement;
    }
    // From lying on the skin (elevation 0) over the normal to lying on it the other way (pi).
    if (lifted) lift = std::clamp(lift, -std::max(elevation, 0.0f), kPi - elevation);
    if (lift != 0.0f) {
      q = Eigen::Quaternionf(Eigen::AngleAxisf(lift, lift_axis_[g]));
      turned = true;
    }
    if (twist != 0.0f) {
      q = Eigen::Quaternionf(Eigen::AngleAxisf(twist, z)) * q;
      turned = true;
    }

    const float reach = tip_[g].norm();
    Eigen::Vector3f tip = turned ? Eigen::Vector3f(q * tip_[g]) : tip_[g];
    if (reach > 0.0f && displacement != Eigen::Vector3f::Zero()) {
      // Direction: toward where the tip would be if it followed the displacement.
      const Eigen::Vector3f target = tip + frame.dir_to_local(displacement);
      const float distance = target.norm();
      const float fade = std::min(1.0f, distance / (kNearRootFade * reach));
      if (fade > 0.0f) {
        const Eigen::Vector3f from = tip / reach;
        const Eigen::Vector3f to =
            at_least_elevation(target / distance, std::min(from.z(), 0.0f), azimuth_of(from, Eigen::Vector3f::UnitX()));
        Eigen::Quaternionf d = turn_between(from, to);
        if (fade < 1.0f) d = partial_turn(d, fade);
        q = d * q;
        tip = d * tip;
        turned = true;
      }
    }

    if (reach > 0.0f) {
      // Aim: a weighted mean of the swings to each control's direction and the swing to the tip.
      const Eigen::Vector3f from = tip / reach;
      Eigen::Vector4f mean = Eigen::Vector4f::Zero();
      float total = 0.0f;
      for (int64_t e = binding_.offsets[g]; e < binding_.offsets[g + 1]; ++e) {
        const size_t c = size_t(binding_.controls[size_t(e)]);
        const ControlState &state = r_pose.controls[c];
        if (state.aim == 0.0f) continue;
        const Eigen::Vector3f to_control = frame.to_local(state.position) - root_[g];
        const float distance = to_control.norm();
        const float a = binding_.weights[size_t(e)] * state.aim * std::min(1.0f, distance / (kNearRootFade * reach));
        if (!(a > 0.0f)) continue;
        const Eigen::Vector3f to = at_least_elevation(to_control / distance, std::min(from.z(), 0.0f),
                                                      azimuth_of(from, Eigen::Vector3f::UnitX()));
        mean += a * swing_from_normal(to).coeffs();
        total += a;
      }
      if (total > 0.0f) {
        const Eigen::Quaternionf from_swing = swing_from_normal(from);
        mean += std::max(0.0f, 1.0f - total) * from_swing.coeffs();
        Eigen::Quaternionf target(mean[3], mean[0], mean[1], mean[2]);  // coeffs() is (x, y, z, w)
        target.normalize();
        q = target * from_swing.conjugate() * q;
        turned = true;
      }
    }
    q.normalize();
    r_pose.turns[g] = turned ? q : Eigen::Quaternionf::Identity();
    r_pose.turned[g] = turned ? 1 : 0;
  }
}

void ControlRig::apply(const GuidePose &pose, StrandSet &r_guides) const {
  if (r_guides.offsets != offsets_) throw InternalError("controls: the guides do not match the rig's");
  const int64_t guide_num = int64_t(roots_.size());
#pragma omp parallel for schedule(static) if (guide_num >= kParallelGuides)
  for (int64_t gi = 0; gi < guide_num; ++gi) {
    const size_t g = size_t(gi);
    if (!pose.turned[g]) continue;
    const SurfaceFrame &frame = pose.frames[g];
    const Eigen::Matrix3f turn = frame.basis * pose.turns[g].toRotationMatrix() * frame.basis.transpose();
    const std::span<Eigen::Vector3f> points = r_guides.points_for_write(g);
    const Eigen::Vector3f root = points[0];
    for (Eigen::Vector3f &p : points.subspan(1)) p = root + turn * (p - root);
  }
}

void ControlRig::apply(double frame, const Mesh &posed_mesh, StrandSet &r_guides) const {
  GuidePose pose;
  this->pose(frame, posed_mesh, pose);
  apply(pose, r_guides);
}

void ControlRig::blend_dynamics(const GuidePose &pose, const StrandSet &simulated, StrandSet &r_guides) const {
  if (r_guides.offsets != offsets_ || simulated.offsets != offsets_)
    throw InternalError("controls: the guides do not match the rig's");
  const int64_t guide_num = int64_t(roots_.size());
#pragma omp parallel if (guide_num >= kParallelGuides)
  {
    std::vector<float> shares;  // the simulation's share at each point of one guide (reused)
#pragma omp for schedule(static)
    for (int64_t gi = 0; gi < guide_num; ++gi) {
      const size_t g = size_t(gi);
      const int64_t begin = offsets_[g], end = offsets_[g + 1];
      shares.assign(size_t(end - begin), 1.0f - binding_.total_weight(g));
      for (int64_t e = binding_.offsets[g]; e < binding_.offsets[g + 1]; ++e) {
        const size_t c = size_t(binding_.controls[size_t(e)]);
        const float blend = binding_.weights[size_t(e)] * pose.controls[c].blend;
        if (blend == 0.0f) continue;
        const Ramp &ramp = settings_.controls[controls_[c].desc].blend_ramp;
        for (int64_t p = begin; p < end; ++p) shares[size_t(p - begin)] += blend * ramp.at(arc_parameter_[size_t(p)]);
      }
      bool all_rig = true, all_simulated = true;
      for (float &s : shares) {
        s = std::clamp(s, 0.0f, 1.0f);
        all_rig = all_rig && s == 0.0f;
        all_simulated = all_simulated && s == 1.0f;
      }
      if (all_rig) continue;
      if (all_simulated) {
        std::copy(simulated.positions.begin() + begin, simulated.positions.begin() + end,
                  r_guides.positions.begin() + begin);
        continue;
      }
      // Rebuilt from the root: each segment keeps the rig's length and takes the mixed direction.
      Eigen::Vector3f *rig = r_guides.positions.data() + begin;
      const Eigen::Vector3f *sim = simulated.positions.data() + begin;
      Eigen::Vector3f previous_rig = rig[0];
      rig[0] += shares[0] * (sim[0] - rig[0]);
      for (int64_t p = 1; p < end - begin; ++p) {
        const float s = shares[size_t(p)];
        const Eigen::Vector3f rig_segment = rig[p] - previous_rig;
        const float length = rig_segment.norm();
        previous_rig = rig[p];
        if (!(length > 0.0f)) {
          rig[p] = rig[p - 1];
          continue;
        }
        const Eigen::Vector3f rig_direction = rig_segment / length;
        const Eigen::Vector3f sim_direction = unit_or(sim[p] - sim[p - 1], rig_direction);
        const Eigen::Vector3f mixed = unit_or((1.0f - s) * rig_direction + s * sim_direction, rig_direction);
        rig[p] = rig[p - 1] + length * mixed;
      }
    }
  }
}

}  // namespace plume::controls
