#include "feathers/growth.h"

#include <algorithm>
#include <vector>

#include "feathers/blend.h"
#include "feathers/feather.h"

namespace plume::feathers {

namespace {

float ramp_up(float stage, float begin, float end) { return std::clamp((stage - begin) / (end - begin), 0.0f, 1.0f); }

KeyBarb straight_key_barb(float position, float open) {
  KeyBarb key;
  key.position = position;
  key.points = {Eigen::Vector3f::Zero(), Eigen::Vector3f(1.0f, 0.0f, 0.0f)};
  key.open = open;
  return key;
}

/// The three temporary key barbs while the sheath sheds: at the base, closed; at the sheath's
/// front, open; at the tip, open.
std::vector<KeyBarb> sheath_key_barbs(float front) {
  return {straight_key_barb(0.0f, 0.0f), straight_key_barb(front, 1.0f), straight_key_barb(1.0f, 1.0f)};
}

}  // namespace

FeatherTemplate grown_template(const FeatherTemplate &adult, float stage) {
  if (stage >= 1.0f) return adult;
  FeatherTemplate grown = adult;
  const float shaft = ramp_up(stage, 0.0f, growth_shaft_end);
  const float barbs = ramp_up(stage, growth_shaft_end, growth_barbs_end);
  const float shed = ramp_up(stage, growth_shaft_end, growth_sheath_end);
  const float shape = ramp_up(stage, growth_sheath_end, 1.0f);
  grown.calamus_length *= shaft;
  grown.rachis_length *= shaft;
  grown.rachis_width *= shaft;
  grown.curvature_side *= shape;
  grown.curvature_front *= shape;
  const std::vector<KeyBarb> sheath = sheath_key_barbs(1.0f - shed);
  for (VaneDesc FeatherTemplate::*vane_field : {&FeatherTemplate::left, &FeatherTemplate::right}) {
    VaneDesc &vane = grown.*vane_field;
    vane.barb_length *= barbs;
    for (float &v : vane.silhouette.value) v *= barbs;
    if (shape > 0.0f) {
      const std::vector<KeyBarb> lists[2] = {sheath, complete_key_barbs((adult.*vane_field).key_barbs)};
      const float weights[2] = {1.0f - shape, shape};
      vane.key_barbs = blend_key_barbs(lists, weights);
    } else {
      vane.key_barbs = sheath;
    }
  }
  return grown;
}

}  // namespace plume::feathers
