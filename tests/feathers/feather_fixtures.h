// Feather templates for the tests: the gallery's types, and random templates drawn from a seed
// (unequal vanes, steps, silhouettes, key barbs of any degree, tiny and huge scales).
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "feathers/build.h"
#include "groom/feather_desc.h"
#include "groom/roots.h"

namespace plume::test {

/// Uniform draws from a hashed stream.
struct Draw {
  uint64_t state;
  explicit Draw(uint64_t seed) : state(hash64(seed)) {}
  float unit() {
    state = hash64(state);
    return hash_to_unit(state);
  }
  float in(float lo, float hi) { return lo + (hi - lo) * unit(); }
  int integer(int lo, int hi) { return std::min(hi, lo + int(unit() * float(hi - lo + 1))); }
};

/// A contour feather: pennaceous tip, plumulaceous base, slightly curved, 3 units long.
inline FeatherTemplate contour_template() {
  FeatherTemplate t;
  t.name = "contour";
  t.calamus_length = 0.3f;
  t.calamus_width_ratio = 0.7f;
  t.rachis_length = 3.0f;
  t.rachis_width = 0.06f;
  t.curvature_side = 0.02f;
  t.curvature_front = 0.06f;
  t.spacing_base = 0.05f;
  t.spacing_tip = 0.04f;
  t.barb_width = 0.006f;
  for (VaneDesc *vane : {&t.left, &t.right}) {
    vane->angle_base = 60.0f;
    vane->angle_tip = 30.0f;
    vane->silhouette = Ramp{{0.0f, 0.3f, 0.8f, 1.0f}, {0.6f, 1.2f, 0.9f, 0.0f}};
    KeyBarb key;
    key.position = 0.35f;
    key.points = {Eigen::Vector3f(0, 0, 0), Eigen::Vector3f(0.35f, 0.05f, 0.05f), Eigen::Vector3f(0.7f, 0.02f, 0.12f),
                  Eigen::Vector3f(0.98f, -0.1f, 0.15f)};
    vane->key_barbs = {key};
  }
  t.right.angle_base = 55.0f;
  return t;
}

/// A random template: any key-barb count and degree, steps, silhouettes or constant lengths,
/// unequal vanes; lengths scaled by `scale`.
inline FeatherTemplate random_template(uint64_t seed, float scale = 1.0f) {
  Draw d(seed);
  FeatherTemplate t;
  t.name = "random" + std::to_string(seed);
  t.calamus_length = d.unit() < 0.2f ? 0.0f : d.in(0.0f, 0.5f) * scale;
  t.calamus_width_ratio = d.in(0.2f, 1.5f);
  t.rachis_length = d.in(0.5f, 5.0f) * scale;
  t.rachis_width = d.in(0.0f, 0.1f) * scale;
  t.curvature_side = d.in(-0.2f, 0.2f);
  t.curvature_front = d.in(-0.3f, 0.3f);
  t.spacing_base = t.rachis_length / d.in(5.0f, 60.0f);
  t.spacing_tip = t.rachis_length / d.in(5.0f, 60.0f);
  t.barb_width = d.in(0.0f, 0.01f) * scale;
  t.afterfeather = d.unit() < 0.3f ? d.in(0.1f, 1.0f) : 0.0f;
  for (VaneDesc *vane : {&t.left, &t.right}) {
    vane->angle_base = d.in(0.0f, 120.0f);
    vane->angle_tip = d.in(0.0f, 90.0f);
    vane->barb_length = d.in(0.0f, 2.0f) * scale;
    if (d.unit() < 0.5f) {
      const int n = d.integer(1, 5);
      float t_at = 0.0f;
      for (int i = 0; i < n; ++i) {
        t_at = i == 0 ? (d.unit() < 0.5f ? 0.0f : d.in(0.0f, 0.3f)) : std::min(1.0f, t_at + (d.unit() < 0.15f ? 0.0f : d.in(0.0f, 0.4f)));
        vane->silhouette.t.push_back(t_at);
        vane->silhouette.value.push_back(d.in(0.0f, 2.0f) * scale);
      }
    }
    const int keys = d.integer(0, 4);
    float position = 0.0f;
    for (int k = 0; k < keys; ++k) {
      KeyBarb key;
      // Steps (equal positions) now and then.
      position = k == 0 ? d.in(0.0f, 0.6f) : std::min(1.0f, position + (d.unit() < 0.2f ? 0.0f : d.in(0.0f, 0.4f)));
      if (d.unit() < 0.1f) position = k == 0 ? 0.0f : 1.0f;
      if (k > 0 && position < vane->key_barbs.back().position) position = vane->key_barbs.back().position;
      key.position = position;
      const int count = d.integer(2, 9);
      Eigen::Vector3f p = Eigen::Vector3f::Zero();
      const float reach = d.in(0.3f, 1.6f);
      for (int i = 0; i < count; ++i) {
        key.points.push_back(p);
        p += Eigen::Vector3f(reach / float(count - 1), d.in(-0.2f, 0.2f), d.in(-0.2f, 0.3f));
      }
      key.plumulaceous = d.unit() < 0.3f ? d.unit() : 0.0f;
      vane->key_barbs.push_back(key);
    }
  }
  return t;
}

/// Largest distance between corresponding points of two geometries of the same layout.
inline float max_point_difference(const feathers::FeatherGeometry &a, const feathers::FeatherGeometry &b) {
  if (a.curves.positions.size() != b.curves.positions.size()) return INFINITY;
  float worst = 0.0f;
  for (size_t i = 0; i < a.curves.positions.size(); ++i)
    worst = std::max(worst, (a.curves.positions[i] - b.curves.positions[i]).norm());
  for (size_t i = 0; i < a.vane_positions.size(); ++i)
    worst = std::max(worst, (a.vane_positions[i] - b.vane_positions[i]).norm());
  return worst;
}

}  // namespace plume::test
