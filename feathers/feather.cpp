#include "feathers/feather.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "feathers/growth.h"
#include "groom/error.h"
#include "groom/roots.h"

namespace plume::feathers {

namespace {

constexpr float kPi = 3.14159265358979f;
constexpr float kRadiansPerDegree = kPi / 180.0f;
/// The barb angle inside the sheath: along the rachis, toward the tip.
constexpr float kSheathAngle = 0.0f;

std::string number_text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", v);
  return text;
}

/// The control polygon of a key barb (at most max_barb_control_points vertices, checked by
/// validate_template and the reader).
ControlPolygon polygon_of(const KeyBarb &key) {
  ControlPolygon polygon;
  polygon.count = int(std::min<size_t>(key.points.size(), max_barb_control_points));
  for (int i = 0; i < polygon.count; ++i) polygon.points[size_t(i)] = key.points[size_t(i)];
  return polygon;
}

/// a + t (b - a), vertex by vertex, after elevating the one of lower degree. Exactly a at t = 0.
ControlPolygon lerp_polygons(ControlPolygon a, ControlPolygon b, float t) {
  const int count = std::max(a.count, b.count);
  elevate_to(a, count);
  elevate_to(b, count);
  for (int i = 0; i < count; ++i) a.points[size_t(i)] += t * (b.points[size_t(i)] - a.points[size_t(i)]);
  return a;
}

/// The minimal rotation taking unit vector z = (0, 0, 1) to unit vector t (t.z > -1).
Eigen::Matrix3f rotation_from_z(const Eigen::Vector3f &t) {
  // R = I + [w]x + [w]x^2 / (1 + c), w = z x t = (-t.y, t.x, 0), c = t.z.
  const float c = t.z();
  const Eigen::Vector3f w(-t.y(), t.x(), 0.0f);
  Eigen::Matrix3f wx;
  wx << 0.0f, -w.z(), w.y(), w.z(), 0.0f, -w.x(), -w.y(), w.x(), 0.0f;
  return Eigen::Matrix3f::Identity() + wx + wx * wx / (1.0f + c);
}

}  // namespace

void validate_template(const FeatherTemplate &f) {
  const std::string who = "feather template \"" + f.name + "\": ";
  auto fail = [&](const std::string &field, const std::string &expected, double got) {
    throw InputError(f.loc, who + field + ": expected " + expected + ", got " + number_text(got));
  };
  auto non_negative = [&](const std::string &field, float v) {
    if (!(v >= 0.0f) || !std::isfinite(v)) fail(field, "a finite number >= 0", v);
  };
  auto positive = [&](const std::string &field, float v) {
    if (!(v > 0.0f) || !std::isfinite(v)) fail(field, "a finite number > 0", v);
  };
  auto within = [&](const std::string &field, float v, float lo, float hi) {
    if (!(v >= lo && v <= hi)) fail(field, "a number in [" + number_text(lo) + ", " + number_text(hi) + "]", v);
  };
  non_negative("calamus.length", f.calamus_length);
  non_negative("calamus.width_ratio", f.calamus_width_ratio);
  positive("rachis.length", f.rachis_length);
  non_negative("rachis.width", f.rachis_width);
  within("rachis.curvature.side", f.curvature_side, -1.0f, 1.0f);
  within("rachis.curvature.front", f.curvature_front, -1.0f, 1.0f);
  positive("barbs.spacing.base", f.spacing_base);
  positive("barbs.spacing.tip", f.spacing_tip);
  non_negative("barbs.width", f.barb_width);
  within("afterfeather", f.afterfeather, 0.0f, 1.0f);
  for (const Vane vane : {Vane::left, Vane::right}) {
    const VaneDesc &v = vane == Vane::left ? f.left : f.right;
    const std::string at = std::string("barbs.") + (vane == Vane::left ? "left." : "right.");
    within(at + "angle.base", v.angle_base, 0.0f, 180.0f);
    within(at + "angle.tip", v.angle_tip, 0.0f, 180.0f);
    non_negative(at + "length", v.barb_length);
    if (v.silhouette.t.size() != v.silhouette.value.size())
      throw InputError(f.loc, who + at + "silhouette: expected one length per point");
    for (size_t i = 0; i < v.silhouette.t.size(); ++i) {
      within(at + "silhouette[" + std::to_string(i) + "] t", v.silhouette.t[i], i ? v.silhouette.t[i - 1] : 0.0f, 1.0f);
      non_negative(at + "silhouette[" + std::to_string(i) + "] length", v.silhouette.value[i]);
    }
    for (size_t k = 0; k < v.key_barbs.size(); ++k) {
      const KeyBarb &key = v.key_barbs[k];
      const std::string kat = at + "key_barbs[" + std::to_string(k) + "].";
      const std::string where = key.loc.known() ? key.loc.str() + ": " : "";
      within(kat + "position", key.position, k ? v.key_barbs[k - 1].position : 0.0f, 1.0f);
      within(kat + "plumulaceous", key.plumulaceous, 0.0f, 1.0f);
      within(kat + "open", key.open, 0.0f, 1.0f);
      if (key.points.size() < 2 || key.points.size() > size_t(max_barb_control_points))
        fail(kat + "points (count)", "2 to " + std::to_string(max_barb_control_points) + " control vertices",
             double(key.points.size()));
      for (const Eigen::Vector3f &p : key.points)
        if (!p.allFinite() || p.cwiseAbs().maxCoeff() > 1e6f)
          throw InputError(f.loc, who + where + kat + "points: expected finite coordinates within [-1e6, 1e6]");
    }
  }
  // The barb count, bounded before anything allocates per barb.
  barb_positions(f);
}

KeyBarb plumulaceous_key_barb(float position) {
  KeyBarb key;
  key.position = position;
  const ControlPolygon mean = mean_plumulaceous_polygon();
  key.points.assign(mean.points.begin(), mean.points.begin() + mean.count);
  key.plumulaceous = 1.0f;
  return key;
}

KeyBarb curved_key_barb(float position) {
  KeyBarb key;
  key.position = position;
  // A cubic whose middle vertices rise by 6% of the barb: a barb curving slightly front to back.
  key.points = {Eigen::Vector3f(0.0f, 0.0f, 0.0f), Eigen::Vector3f(1.0f / 3.0f, 0.06f, 0.0f),
                Eigen::Vector3f(2.0f / 3.0f, 0.06f, 0.0f), Eigen::Vector3f(1.0f, 0.0f, 0.0f)};
  return key;
}

std::vector<KeyBarb> complete_key_barbs(std::span<const KeyBarb> key_barbs) {
  std::vector<KeyBarb> completed;
  completed.reserve(key_barbs.size() + 2);
  if (key_barbs.empty()) {
    completed.push_back(plumulaceous_key_barb(0.0f));
    completed.push_back(plumulaceous_key_barb(1.0f));
    return completed;
  }
  if (key_barbs.front().position > 0.0f) completed.push_back(plumulaceous_key_barb(0.0f));
  completed.insert(completed.end(), key_barbs.begin(), key_barbs.end());
  if (key_barbs.back().position < 1.0f) completed.push_back(curved_key_barb(1.0f));
  return completed;
}

KeyBarbBlend interpolate_key_barbs(std::span<const KeyBarb> completed, float rp) {
  KeyBarbBlend blend;
  if (completed.empty()) return blend;
  // The first key barb above rp: keys [0, above) are at or below rp.
  size_t above = 0;
  while (above < completed.size() && completed[above].position <= rp) ++above;
  if (above == 0 || (above < completed.size() && completed[above - 1].position == rp) || above == completed.size()) {
    // At a key barb's position (the last of a step), or beyond the ends: that key barb as it is.
    const KeyBarb &key = completed[above == 0 ? 0 : above - 1];
    blend.polygon = polygon_of(key);
    blend.plumulaceous = key.plumulaceous;
    blend.open = key.open;
    return blend;
  }
  const KeyBarb &below = completed[above - 1], &upper = completed[above];
  const float t = (rp - below.position) / (upper.position - below.position);
  blend.polygon = lerp_polygons(polygon_of(below), polygon_of(upper), t);
  blend.plumulaceous = below.plumulaceous + t * (upper.plumulaceous - below.plumulaceous);
  blend.open = below.open + t * (upper.open - below.open);
  return blend;
}

ControlPolygon mean_plumulaceous_polygon() {
  ControlPolygon polygon;
  polygon.count = 4;
  polygon.points[0] = Eigen::Vector3f::Zero();
  polygon.points[1] = Eigen::Vector3f(0.35f, 0.0f, 0.0f);
  polygon.points[2] = Eigen::Vector3f(0.65f, 0.0f, 0.0f);
  polygon.points[3] = Eigen::Vector3f(0.85f, 0.0f, 0.0f);
  return polygon;
}

ControlPolygon plumulaceous_jitter(uint64_t seed, Vane vane, int index) {
  // The table of random vertices (sec. 4.3.1), hashed rather than stored: entry (seed, vane, index)
  // is the same on every frame, machine and thread.
  ControlPolygon jitter;
  jitter.count = 4;
  jitter.points[0] = Eigen::Vector3f::Zero();
  const uint64_t barb = hash_combine(hash_combine(seed ^ 0xB4B5ull, uint64_t(vane)), uint64_t(uint32_t(index)));
  static constexpr float kInPlane[4] = {0.0f, 0.3f, 0.35f, 0.25f};
  static constexpr float kDorsal[4] = {0.0f, 0.8f * plumulaceous_reach, plumulaceous_reach, 0.8f * plumulaceous_reach};
  for (int i = 1; i < 4; ++i) {
    uint64_t h = hash_combine(barb, uint64_t(i));
    float r[3];
    for (float &value : r) {
      value = hash_to_unit(h);
      h = hash64(h);
    }
    jitter.points[size_t(i)] =
        Eigen::Vector3f(0.1f * (2.0f * r[0] - 1.0f), kDorsal[i] * r[1], kInPlane[i] * (2.0f * r[2] - 1.0f));
  }
  return jitter;
}

std::array<Eigen::Vector3f, 4> rachis_control_points(const FeatherTemplate &f) {
  const float c = f.calamus_length, r = f.rachis_length;
  const float side = f.curvature_side * r, front = f.curvature_front * r;
  return {Eigen::Vector3f(0.0f, 0.0f, c), Eigen::Vector3f(side, front, c + r / 3.0f),
          Eigen::Vector3f(side, front, c + r * 2.0f / 3.0f), Eigen::Vector3f(0.0f, 0.0f, c + r)};
}

namespace {

Eigen::Vector3f rachis_point_of(const FeatherTemplate &f, const std::array<Eigen::Vector3f, 4> &cv, float t) {
  Eigen::Vector3f p = bezier_point(cv, t);
  // z is linear in t (evenly spaced control heights); set it exactly, as the barbs' heights are used
  // to find their place on the shaft.
  p.z() = f.calamus_length + f.rachis_length * t;
  return p;
}

Eigen::Matrix3f rachis_frame_of(const std::array<Eigen::Vector3f, 4> &cv, float t) {
  Eigen::Vector3f tangent = bezier_derivative(cv, t);
  // dz/dt = r_l > 0: the tangent always points tip-ward, so the rotation from z is well defined; a
  // zero-length rachis (a growing feather's first instant) keeps the shaft's axes.
  if (!(tangent.z() > 0.0f)) return Eigen::Matrix3f::Identity();
  tangent.normalize();
  return rotation_from_z(tangent);
}

}  // namespace

Eigen::Vector3f rachis_point(const FeatherTemplate &f, float t) { return rachis_point_of(f, rachis_control_points(f), t); }

Eigen::Matrix3f rachis_frame(const FeatherTemplate &f, float t) { return rachis_frame_of(rachis_control_points(f), t); }

BarbAttachment barb_attachment(const FeatherTemplate &f, float rp) {
  const std::array<Eigen::Vector3f, 4> cv = rachis_control_points(f);
  return {rachis_point_of(f, cv, rp), rachis_frame_of(cv, rp)};
}

float shaft_width(const FeatherTemplate &f, float z) {
  const float c = f.calamus_length, w = f.rachis_width;
  if (z >= c + f.rachis_length) return 0.0f;  // the tip: a point
  if (z <= c) {
    if (!(c > 0.0f)) return w;
    const float a = std::max(z, 0.0f) / c;
    return w * (f.calamus_width_ratio + (1.0f - f.calamus_width_ratio) * a);
  }
  if (!(f.rachis_length > 0.0f)) return 0.0f;
  return w * std::max(0.0f, 1.0f - (z - c) / f.rachis_length);
}

float barb_length(const VaneDesc &vane, float t) {
  return vane.silhouette.t.empty() ? vane.barb_length : vane.silhouette.at(t);
}

FeatherTemplate afterfeather_template(const FeatherTemplate &main) {
  FeatherTemplate after = main;
  const float size = main.afterfeather;
  after.name = main.name + " afterfeather";
  after.calamus_length = 0.0f;
  after.rachis_length = main.rachis_length * size;
  after.rachis_width = main.rachis_width * size;
  after.barb_width = main.barb_width * size;
  after.afterfeather = 0.0f;
  for (VaneDesc *vane : {&after.left, &after.right}) {
    vane->barb_length *= size;
    for (float &v : vane->silhouette.value) v *= size;
    vane->key_barbs.clear();
  }
  return after;
}

Eigen::Vector3f afterfeather_offset(const FeatherTemplate &main) {
  return Eigen::Vector3f(0.0f, -main.rachis_width, main.calamus_length);
}

FeatherShape make_shape(const FeatherTemplate &adult, uint64_t seed, float stage) {
  validate_template(adult);
  FeatherShape shape;
  shape.seed = seed;
  shape.main = grown_template(adult, stage);
  shape.main_positions = barb_positions(adult);
  for (const Vane vane : {Vane::left, Vane::right})
    shape.main_keys[size_t(vane)] =
        complete_key_barbs(vane == Vane::left ? shape.main.left.key_barbs : shape.main.right.key_barbs);
  // A blend of types with and without one leaves a vanishing afterfeather near the border: below 1%
  // of the feather there is none (a size of 1e-9 would give a feather a barb of nothing).
  shape.has_after = adult.afterfeather >= kSmallestAfterfeather;
  if (shape.has_after) {
    shape.after = afterfeather_template(shape.main);
    shape.after_positions = barb_positions(afterfeather_template(adult));
    for (const Vane vane : {Vane::left, Vane::right}) shape.after_keys[size_t(vane)] = complete_key_barbs({});
  }
  return shape;
}

Barb build_barb(const FeatherTemplate &f, std::span<const KeyBarb> keys, Vane vane, float rp, int index,
                uint64_t seed) {
  return VaneBarbs(f, keys, vane, seed)(rp, index, barb_attachment(f, rp));
}

KeyBarbBlend VaneBarbs::blend(float rp) {
  // interpolate_key_barbs's steps, with the elevated pair kept.
  const std::span<const KeyBarb> completed = keys_;
  size_t above = 0;
  while (above < completed.size() && completed[above].position <= rp) ++above;
  if (above == 0 || (above < completed.size() && completed[above - 1].position == rp) || above == completed.size())
    return interpolate_key_barbs(completed, rp);
  const KeyBarb &below = completed[above - 1], &upper = completed[above];
  if (above != above_) {
    below_ = polygon_of(below);
    upper_ = polygon_of(upper);
    const int count = std::max(below_.count, upper_.count);
    elevate_to(below_, count);
    elevate_to(upper_, count);
    above_ = above;
  }
  const float t = (rp - below.position) / (upper.position - below.position);
  KeyBarbBlend blend;
  blend.polygon = below_;
  for (int i = 0; i < blend.polygon.count; ++i)
    blend.polygon.points[size_t(i)] += t * (upper_.points[size_t(i)] - blend.polygon.points[size_t(i)]);
  blend.plumulaceous = below.plumulaceous + t * (upper.plumulaceous - below.plumulaceous);
  blend.open = below.open + t * (upper.open - below.open);
  return blend;
}

Barb VaneBarbs::operator()(float rp, int index, const BarbAttachment &attachment) {
  const FeatherTemplate &f = feather_;
  const Vane vane = vane_;
  const uint64_t seed = seed_;
  Barb barb;
  const VaneDesc &desc = vane == Vane::left ? f.left : f.right;
  const KeyBarbBlend blend = this->blend(rp);
  ControlPolygon polygon = blend.polygon;
  if (blend.plumulaceous > 0.0f) {
    // lerp_polygons(polygon, mean_plumulaceous_polygon(), plumulaceous), the mean's elevation kept.
    const int count = std::max(polygon.count, mean_plumulaceous_polygon().count);
    if (mean_.count != count) {
      mean_ = mean_plumulaceous_polygon();
      elevate_to(mean_, count);
    }
    elevate_to(polygon, count);
    for (int i = 0; i < count; ++i)
      polygon.points[size_t(i)] += blend.plumulaceous * (mean_.points[size_t(i)] - polygon.points[size_t(i)]);
  }
  // The first vertex at the origin; the end-to-end distance clamped to [0, 1]; then the barb's length.
  const Eigen::Vector3f first = polygon.points[0];
  for (int i = 0; i < polygon.count; ++i) polygon.points[size_t(i)] -= first;
  const float reach = polygon.points[size_t(polygon.count - 1)].norm();
  barb.length = barb_length(desc, rp);
  barb.plumulaceous = blend.plumulaceous;
  const float scale = barb.length / std::max(reach, 1.0f);
  for (int i = 0; i < polygon.count; ++i) polygon.points[size_t(i)] *= scale;
  // Turn about barb z so that the curve's midpoint has no dorsal offset: the vector from the barb's
  // root to it then lies in the vane's plane. (The paper takes the control vertex cv_{n/2}; the
  // curve's midpoint B(1/2) does the same for a cubic and does not change when a barb's degree is
  // elevated to blend it with another, so neither does the barb.)
  const Eigen::Vector3f half = bezier_point(polygon.view(), 0.5f);
  const float in_plane = std::sqrt(half.x() * half.x() + half.y() * half.y());
  if (in_plane > 1e-12f) {
    const float c = half.x() / in_plane, s = half.y() / in_plane;
    for (int i = 0; i < polygon.count; ++i) {
      Eigen::Vector3f &p = polygon.points[size_t(i)];
      p = Eigen::Vector3f(c * p.x() + s * p.y(), -s * p.x() + c * p.y(), p.z());
    }
  }
  // The plumulaceous fuzz, after the shaping, so that it only ever moves barbs dorsally.
  if (blend.plumulaceous > 0.0f && index >= 0) {
    ControlPolygon jitter = plumulaceous_jitter(seed, vane, index);
    const float amount = blend.plumulaceous * barb.length;
    const int count = std::max(polygon.count, jitter.count);
    elevate_to(polygon, count);
    elevate_to(jitter, count);
    for (int i = 0; i < count; ++i) polygon.points[size_t(i)] += amount * jitter.points[size_t(i)];
  }
  barb.polygon = polygon;

  const float vane_angle = desc.angle_base + (desc.angle_tip - desc.angle_base) * rp;
  barb.angle = (kSheathAngle + blend.open * (vane_angle - kSheathAngle)) * kRadiansPerDegree;
  const float cos_a = std::cos(barb.angle), sin_a = std::sin(barb.angle);
  const float sigma = vane == Vane::right ? 1.0f : -1.0f;
  // In the vane's frame (side S, dorsal U, tangent T): the barb's direction cos a T + sigma sin a S,
  // and the in-plane direction toward the tip perpendicular to it, sin a T - sigma cos a S.
  auto barb_frame = [&](const Eigen::Matrix3f &vane_frame) {
    Eigen::Matrix3f m;
    m.col(0) = cos_a * vane_frame.col(2) + sigma * sin_a * vane_frame.col(0);
    m.col(1) = vane_frame.col(1);
    m.col(2) = sin_a * vane_frame.col(2) - sigma * cos_a * vane_frame.col(0);
    return m;
  };
  barb.attach = attachment.point;
  barb.frame = barb_frame(attachment.frame);
  barb.attach_flat = Eigen::Vector3f(0.0f, 0.0f, f.calamus_length + f.rachis_length * rp);
  barb.frame_flat = barb_frame(Eigen::Matrix3f::Identity());
  return barb;
}

}  // namespace plume::feathers
