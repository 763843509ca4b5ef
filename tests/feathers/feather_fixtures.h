// Feather templates for the tests: the gallery's types, and random templates drawn from a seed
// (unequal vanes, steps, silhouettes, key barbs of any degree, tiny and huge scales); and the bird
// of grooms/bird/ with a coat of its feathers, for the coat's and the layering pass's tests.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "feathers/build.h"
#include "feathers/coat.h"
#include "groom/feather_desc.h"
#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

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

/// The template's lengths times `s` (a groom modelled in other units).
inline void scale_template(FeatherTemplate &t, float s) {
  for (float *v : {&t.calamus_length, &t.rachis_length, &t.rachis_width, &t.spacing_base, &t.spacing_tip, &t.barb_width})
    *v *= s;
  for (VaneDesc *vane : {&t.left, &t.right}) {
    vane->barb_length *= s;
    for (float &v : vane->silhouette.value) v *= s;
  }
}

/// The bird of grooms/bird/ at rest, its stems bound to the skin and a coat of `follicles` of its
/// groom's feathers (the groom's 5,000 when < 0); the groom scaled by `scale` (mesh, stems, templates
/// and key-feather radii), then its feathers changed by `edit` (e.g. layering on or off).
struct BirdCoat {
  inline static const std::string kDirectory = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";

  GroomDesc groom;
  Mesh rest;
  Guides stems;
  std::unique_ptr<feathers::Coat> coat;

  template <class Edit>
  BirdCoat(int64_t follicles, Edit edit, float scale = 1.0f) : groom(io::read_groom_file(kDirectory + "bird.groom.yaml")) {
    rest = io::read_obj_mesh(kDirectory + "bird.obj");
    StrandSet stem_strands = io::read_strands(kDirectory + "stems.obj");
    if (scale != 1.0f) {
      for (Eigen::Vector3f &p : rest.positions) p *= scale;
      rest.compute_normals();
      for (Eigen::Vector3f &p : stem_strands.positions) p *= scale;
      for (FeatherTemplate &t : groom.feathers.templates) scale_template(t, scale);
      for (KeyFeather &k : groom.feathers.key_feathers) k.radius *= scale;
    }
    edit(groom.feathers);
    const MeshQuery query(rest);
    stems = bind_guides(query, stem_strands, "stems.obj");
    coat = std::make_unique<feathers::Coat>(rest, stems, groom.feathers,
                                            feathers::scatter_follicles(rest, groom.feathers.follicles, {}, follicles));
  }
  /// The bird's animated skin at `frame` (grooms/bird/anim/).
  Mesh pose(int frame) const {
    char name[32];
    std::snprintf(name, sizeof name, "anim/bird.%04d.obj", frame);
    return io::read_obj_pose(kDirectory + name, rest);
  }
  /// The pose a fraction `t` of the way from `a` to `b` (vertices blended linearly).
  static Mesh blend(const Mesh &a, const Mesh &b, float t) {
    Mesh posed = a;
    for (size_t v = 0; v < posed.positions.size(); ++v) posed.positions[v] = (1.0f - t) * a.positions[v] + t * b.positions[v];
    posed.compute_normals();
    return posed;
  }
  /// The coat on `posed`, stateless, or from the frame `before` (its skin pass's state, and with
  /// `layers_warm` its layering pass's too).
  feathers::CoatFrame grow(const Mesh &posed, const feathers::CoatFrame *before = nullptr, bool layers_warm = true) const {
    const MeshQuery query(posed);
    feathers::CoatFrame frame;
    coat->grow(posed, query, carry_guides(rest, posed, stems), frame, nullptr, before ? &before->skin_pass : nullptr,
               before && layers_warm ? &before->layer_state : nullptr);
    return frame;
  }
};

/// Feathers' layering on or off in a BirdCoat's groom.
inline void layers_on(FeatherDesc &d) { d.layers = true; }
inline void layers_off(FeatherDesc &d) { d.layers = false; }

/// How many vane vertices of `frame` lie deeper than `eps` below the skin `posed`.
inline size_t vane_points_below_skin(const Mesh &posed, const feathers::CoatFrame &frame, float eps) {
  const MeshQuery query(posed);
  size_t below = 0;
  for (const Eigen::Vector3f &p : frame.vanes.positions)
    if (query.signed_distance(p) < -eps) ++below;
  return below;
}

}  // namespace plume::test
