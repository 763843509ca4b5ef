#include "controls/binding.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "groom/error.h"

namespace plume::controls {

namespace {

Eigen::Vector3f reflect_point(const Eigen::Vector3f &p, const ControlDesc &d) {
  return p - 2.0f * (p - d.mirror_point).dot(d.mirror_normal) * d.mirror_normal;
}

Eigen::Vector3f reflect_vector(const Eigen::Vector3f &v, const ControlDesc &d) {
  return v - 2.0f * v.dot(d.mirror_normal) * d.mirror_normal;
}

// The falloff of a control at distance `d` from it.
float falloff_weight(const ControlDesc &desc, float d) {
  if (!(desc.radius > 0.0f)) return 1.0f;
  const float x = d / desc.radius;
  if (!(x < 1.0f)) return 0.0f;
  switch (desc.falloff) {
    case ControlDesc::Falloff::constant:
      return 1.0f;
    case ControlDesc::Falloff::linear:
      return 1.0f - x;
    case ControlDesc::Falloff::smooth:
      break;
  }
  return 1.0f - x * x * (3.0f - 2.0f * x);
}

}  // namespace

float ControlBinding::total_weight(size_t guide) const {
  float total = 0.0f;
  for (int64_t e = offsets[guide]; e < offsets[guide + 1]; ++e) total += weights[size_t(e)];
  return std::min(total, 1.0f);
}

std::vector<RigControl> place_controls(const ControlSettings &settings, const Mesh &rest_mesh,
                                       const MeshQuery &rest_query) {
  std::vector<RigControl> placed;
  auto place = [&](RigControl c) {
    const ControlDesc &desc = settings.controls[c.desc];
    if (desc.place == ControlDesc::Place::skin) {
      c.anchor = rest_query.closest(c.rest_position);
      const SurfaceFrame frame = surface_frame(rest_mesh, c.anchor);
      c.anchor_local = frame.to_local(c.rest_position);
      c.anchor_rest_basis = frame.basis;
    }
    placed.push_back(std::move(c));
  };
  for (size_t i = 0; i < settings.controls.size(); ++i) {
    const ControlDesc &desc = settings.controls[i];
    RigControl control;
    control.desc = i;
    control.rest_position = desc.position;
    control.offset = desc.offset;
    if (desc.mirror) control.partner = int(placed.size()) + 1;
    place(control);
    if (!desc.mirror) continue;
    RigControl twin = control;
    twin.twin = true;
    twin.partner = int(placed.size()) - 1;
    twin.rest_position = reflect_point(desc.position, desc);
    for (Eigen::Vector3f &v : twin.offset.values) v = reflect_vector(v, desc);
    place(twin);
  }
  return placed;
}

ControlBinding bind_controls(const ControlSettings &settings, const std::vector<RigControl> &controls,
                             const Mesh &rest_mesh, const Guides &guides,
                             const std::vector<std::vector<float>> &vertex_maps) {
  if (!vertex_maps.empty() && vertex_maps.size() != settings.controls.size())
    throw InternalError("controls: one vertex map (or none) per control expected");
  // Face groups of each control, as a mask over the mesh's groups (empty: any group).
  std::vector<std::vector<bool>> group_masks(settings.controls.size());
  for (size_t i = 0; i < settings.controls.size(); ++i) {
    const ControlDesc &desc = settings.controls[i];
    if (!vertex_maps.empty() && !vertex_maps[i].empty() && vertex_maps[i].size() != rest_mesh.vertex_count())
      throw InternalError("controls: a vertex map must hold one value per vertex");
    if (desc.groups.empty()) continue;
    group_masks[i].assign(rest_mesh.group_names.size(), false);
    for (const std::string &name : desc.groups) {
      const int g = rest_mesh.group_index(name);
      if (g < 0)
        throw InputError(desc.groups_loc, desc.groups_key + ": no face group \"" + name +
                                              "\" in the emitter (groups: " + rest_mesh.group_list() + ")");
      group_masks[i][size_t(g)] = true;
    }
  }

  const size_t guide_num = guides.size();
  const size_t control_num = controls.size();
  ControlBinding binding;
  binding.offsets.assign(guide_num + 1, 0);
  std::vector<float> distance(control_num), weight(control_num);
  for (size_t g = 0; g < guide_num; ++g) {
    const SurfacePoint &root = guides.roots[g];
    const Eigen::Vector3f root_position = surface_position(rest_mesh, root);
    for (size_t c = 0; c < control_num; ++c) {
      const size_t d = controls[c].desc;
      const ControlDesc &desc = settings.controls[d];
      distance[c] = (root_position - controls[c].rest_position).norm();
      float w = falloff_weight(desc, distance[c]);
      if (w > 0.0f && !group_masks[d].empty())
        w = group_masks[d][size_t(rest_mesh.triangle_groups[size_t(root.triangle)])] ? w : 0.0f;
      if (w > 0.0f && !vertex_maps.empty() && !vertex_maps[d].empty()) {
        w *= std::clamp(surface_value(rest_mesh, vertex_maps[d], root), 0.0f, 1.0f);
      }
      weight[c] = w;
    }
    // Of a mirror pair, only the member nearer the root.
    for (size_t c = 0; c < control_num; ++c) {
      if (controls[c].twin || controls[c].partner < 0) continue;
      const size_t t = size_t(controls[c].partner);
      const ControlDesc &desc = settings.controls[controls[c].desc];
      bool keep_original = distance[c] < distance[t];
      if (distance[c] == distance[t])
        keep_original = (root_position - desc.mirror_point).dot(desc.mirror_normal) >= 0.0f;
      weight[keep_original ? t : c] = 0.0f;
    }
    if (settings.binding == ControlSettings::Binding::nearest) {
      size_t best = control_num;
      for (size_t c = 0; c < control_num; ++c)
        if (weight[c] > 0.0f && (best == control_num || distance[c] < distance[best])) best = c;
      if (best < control_num) {
        binding.controls.push_back(int32_t(best));
        binding.weights.push_back(weight[best]);
      }
    } else {
      float total = 0.0f;
      for (size_t c = 0; c < control_num; ++c) total += weight[c];
      const float scale = total > 1.0f ? 1.0f / total : 1.0f;
      for (size_t c = 0; c < control_num; ++c) {
        if (!(weight[c] > 0.0f)) continue;
        binding.controls.push_back(int32_t(c));
        binding.weights.push_back(weight[c] * scale);
      }
    }
    binding.offsets[g + 1] = int64_t(binding.controls.size());
  }
  return binding;
}

}  // namespace plume::controls
