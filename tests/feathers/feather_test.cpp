// One feather (seed 001 sec. 4.1-4.3): the paper's formulas as properties over many random
// templates.
#include <catch2/catch.hpp>

#include <cmath>

#include "feather_fixtures.h"
#include "feathers/bezier.h"
#include "feathers/blend.h"
#include "feathers/build.h"
#include "feathers/feather.h"
#include "feathers/growth.h"

using namespace plume;
using namespace plume::feathers;
using plume::test::Draw;

namespace {

ControlPolygon random_polygon(Draw &d, int count) {
  ControlPolygon polygon;
  polygon.count = count;
  for (int i = 0; i < count; ++i) polygon.points[size_t(i)] = Eigen::Vector3f(d.in(-1, 1), d.in(-1, 1), d.in(-1, 1));
  return polygon;
}

float feather_length(const FeatherTemplate &t) { return t.calamus_length + t.rachis_length; }

}  // namespace

TEST_CASE("an elevated Bezier curve is the original curve, sampled, to 1e-6", "[feathers]") {
  Draw d(11);
  for (int trial = 0; trial < 300; ++trial) {
    const int count = d.integer(1, max_barb_control_points - 1);
    const ControlPolygon original = random_polygon(d, count);
    ControlPolygon once = original;
    elevate_degree(once);
    REQUIRE(once.count == count + 1);
    ControlPolygon full = original;
    elevate_to(full, max_barb_control_points);
    // End vertices are kept exactly.
    CHECK(once.points[0] == original.points[0]);
    CHECK(full.points[size_t(full.count - 1)] == original.points[size_t(count - 1)]);
    float worst = 0.0f;
    for (int s = 0; s <= 200; ++s) {
      const float u = float(s) / 200.0f;
      const Eigen::Vector3f p = bezier_point(original.view(), u);
      worst = std::max(worst, (bezier_point(once.view(), u) - p).norm());
      worst = std::max(worst, (bezier_point(full.view(), u) - p).norm());
    }
    INFO("trial " << trial << ", " << count << " vertices");
    CHECK(worst <= 1e-6f);
  }
}

TEST_CASE("Bernstein weights give de Casteljau's point and sum to 1", "[feathers]") {
  Draw d(12);
  for (int trial = 0; trial < 100; ++trial) {
    const ControlPolygon polygon = random_polygon(d, d.integer(1, max_barb_control_points));
    const float u = d.unit();
    float w[max_barb_control_points];
    bernstein_weights(polygon.degree(), u, w);
    Eigen::Vector3f p = Eigen::Vector3f::Zero();
    float sum = 0.0f;
    for (int i = 0; i < polygon.count; ++i) {
      p += w[i] * polygon.points[size_t(i)];
      sum += w[i];
    }
    CHECK(std::abs(sum - 1.0f) <= 1e-6f);
    CHECK((p - bezier_point(polygon.view(), u)).norm() <= 1e-6f);
  }
}

TEST_CASE("a barb at a key barb's position is that key barb", "[feathers]") {
  int checked = 0;
  for (uint64_t seed = 1; seed <= 200; ++seed) {
    const FeatherTemplate t = test::random_template(seed);
    for (const VaneDesc *vane : {&t.left, &t.right}) {
      const std::vector<KeyBarb> keys = complete_key_barbs(vane->key_barbs);
      for (size_t k = 0; k < keys.size(); ++k) {
        // The upper key barb of a step is the one a barb at that position takes.
        if (k + 1 < keys.size() && keys[k + 1].position == keys[k].position) continue;
        const KeyBarbBlend blend = interpolate_key_barbs(keys, keys[k].position);
        REQUIRE(blend.polygon.count == int(keys[k].points.size()));
        for (int i = 0; i < blend.polygon.count; ++i) CHECK(blend.polygon.points[size_t(i)] == keys[k].points[size_t(i)]);
        CHECK(blend.plumulaceous == keys[k].plumulaceous);
        CHECK(blend.open == keys[k].open);
        ++checked;
      }
    }
  }
  CHECK(checked > 400);
}

TEST_CASE("barbs between two key barbs are linear in t", "[feathers]") {
  Draw d(13);
  for (int trial = 0; trial < 200; ++trial) {
    KeyBarb a, b;
    a.position = d.in(0.0f, 0.5f);
    b.position = a.position + d.in(0.01f, 0.5f);
    const ControlPolygon pa = random_polygon(d, d.integer(2, 8)), pb = random_polygon(d, d.integer(2, 8));
    a.points.assign(pa.points.begin(), pa.points.begin() + pa.count);
    b.points.assign(pb.points.begin(), pb.points.begin() + pb.count);
    a.plumulaceous = d.unit();
    b.plumulaceous = d.unit();
    const std::vector<KeyBarb> keys{a, b};
    // The two key barbs at the common degree.
    ControlPolygon ea = pa, eb = pb;
    elevate_to(ea, std::max(pa.count, pb.count));
    elevate_to(eb, std::max(pa.count, pb.count));
    for (int s = 1; s < 20; ++s) {
      const float t = float(s) / 20.0f;
      const float rp = a.position + t * (b.position - a.position);
      const KeyBarbBlend blend = interpolate_key_barbs(keys, rp);
      const float t_exact = (rp - a.position) / (b.position - a.position);
      REQUIRE(blend.polygon.count == ea.count);
      for (int i = 0; i < ea.count; ++i) {
        const Eigen::Vector3f expected = (1.0f - t_exact) * ea.points[size_t(i)] + t_exact * eb.points[size_t(i)];
        CHECK((blend.polygon.points[size_t(i)] - expected).norm() <= 1e-5f);
      }
      CHECK(std::abs(blend.plumulaceous - ((1 - t_exact) * a.plumulaceous + t_exact * b.plumulaceous)) <= 1e-6f);
    }
  }
}

TEST_CASE("the rachis tip is a point and the calamus width continuous with the rachis", "[feathers]") {
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    const FeatherTemplate t = test::random_template(seed, seed % 3 == 0 ? 1000.0f : seed % 3 == 1 ? 0.001f : 1.0f);
    const float top = t.calamus_length + t.rachis_length;
    CHECK(shaft_width(t, top) == 0.0f);
    CHECK(rachis_point(t, 1.0f) == Eigen::Vector3f(0.0f, 0.0f, top));
    CHECK(rachis_point(t, 0.0f) == Eigen::Vector3f(0.0f, 0.0f, t.calamus_length));
    // At the calamus's top both sides give the rachis base width, and approach it as the slopes say.
    const float w = t.rachis_width;
    CHECK(shaft_width(t, t.calamus_length) == Approx(w).margin(1e-6 * w));
    for (const float eps : {1e-2f, 1e-4f}) {
      const float dz = eps * feather_length(t);
      const float slope_below = t.calamus_length > 0.0f ? w * std::abs(1.0f - t.calamus_width_ratio) / t.calamus_length : 0.0f;
      const float slope_above = w / t.rachis_length;
      CHECK(std::abs(shaft_width(t, t.calamus_length - dz) - w) <= 1.01f * slope_below * dz + 1e-5f * w);
      CHECK(std::abs(shaft_width(t, t.calamus_length + dz) - w) <= 1.01f * slope_above * dz + 1e-5f * w);
    }
    // The built rachis curve ends in a point of width 0 at the tip.
    const FeatherGeometry g = build_feather(make_shape(t, seed), FeatherDetail{});
    REQUIRE(g.parts[0] == FeatherPart::rachis);
    const auto rachis = g.curves.points(0);
    CHECK((rachis.back() - Eigen::Vector3f(0.0f, 0.0f, top)).norm() <= 1e-6f * top);
    CHECK(g.curves.widths[size_t(g.curves.offsets[1] - 1)] == 0.0f);
  }
}

TEST_CASE("every barb leaves the rachis in the plane of the vane, at its barb angle", "[feathers]") {
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    const FeatherTemplate t = test::random_template(seed);
    const FeatherShape shape = make_shape(t, seed);
    for (const Vane vane : {Vane::left, Vane::right}) {
      for (size_t j = 0; j < shape.main_positions.size(); ++j) {
        // The mean shape (index -1): a plumulaceous barb's fuzz is added after the tilt.
        const Barb barb = build_barb(shape.main, shape.main_keys[size_t(vane)], vane, shape.main_positions[j], -1, seed);
        const ControlPolygon &p = barb.polygon;
        CHECK(p.points[0] == Eigen::Vector3f::Zero());
        const Eigen::Vector3f half = bezier_point(p.view(), 0.5f);
        CHECK(std::abs(half.y()) <= 1e-5f * std::max(1.0f, half.norm()));
        // Never longer end to end than the barb length.
        const VaneDesc &desc = vane == Vane::left ? t.left : t.right;
        CHECK(p.points[size_t(p.count - 1)].norm() <= barb_length(desc, shape.main_positions[j]) * (1.0f + 1e-5f) + 1e-6f);
        // Barb x is the direction at the barb angle from the rachis tangent, in the vane's plane.
        const Eigen::Matrix3f vane_frame = rachis_frame(shape.main, shape.main_positions[j]);
        CHECK(std::abs(barb.frame.col(0).dot(vane_frame.col(2)) - std::cos(barb.angle)) <= 1e-5f);
        CHECK(std::abs(barb.frame.col(0).dot(vane_frame.col(1))) <= 1e-5f);
        const float side = barb.frame.col(0).dot(vane_frame.col(0));
        CHECK((vane == Vane::right ? side : -side) >= -1e-6f);
      }
    }
  }
}

TEST_CASE("key barbs shorter than 1 end to end make shorter barbs: a discontinuity in the vane", "[feathers]") {
  FeatherTemplate t = test::contour_template();
  KeyBarb shortened = t.right.key_barbs[0];
  for (Eigen::Vector3f &p : shortened.points) p *= 0.4f;
  shortened.position = 0.6f;
  KeyBarb full = t.right.key_barbs[0];
  full.position = 0.6f;
  t.right.key_barbs = {t.right.key_barbs[0], shortened, full};  // a step at 0.6: short below, full above
  const FeatherShape shape = make_shape(t, 1);
  const std::vector<KeyBarb> &keys = shape.main_keys[size_t(Vane::right)];
  const Barb below = build_barb(shape.main, keys, Vane::right, 0.5999f, 0, 1);
  const Barb at = build_barb(shape.main, keys, Vane::right, 0.6f, 0, 1);
  const float reach_below = below.polygon.points[3].norm(), reach_at = at.polygon.points[3].norm();
  CHECK(reach_below < 0.5f * reach_at);
}

TEST_CASE("a vane without key barbs is plumulaceous, from a table stable across calls", "[feathers]") {
  FeatherTemplate t = test::contour_template();
  t.left.key_barbs.clear();
  t.right.key_barbs.clear();
  const FeatherShape shape = make_shape(t, 77);
  for (const KeyBarb &key : shape.main_keys[0]) CHECK(key.plumulaceous == 1.0f);
  const ControlPolygon a = plumulaceous_jitter(77, Vane::left, 5), b = plumulaceous_jitter(77, Vane::left, 5);
  const ControlPolygon c = plumulaceous_jitter(77, Vane::left, 6), e = plumulaceous_jitter(78, Vane::left, 5);
  for (int i = 0; i < 4; ++i) CHECK(a.points[size_t(i)] == b.points[size_t(i)]);
  CHECK((a.points[2] - c.points[2]).norm() > 1e-4f);
  CHECK((a.points[2] - e.points[2]).norm() > 1e-4f);
  // Fuzz only ever moves a barb dorsally: every fuzzy barb lies on or above its mean shape.
  for (int index = 0; index < 200; ++index) {
    const Barb fuzzy = build_barb(shape.main, shape.main_keys[0], Vane::left, 0.3f, index, 77);
    const Barb mean = build_barb(shape.main, shape.main_keys[0], Vane::left, 0.3f, -1, 77);
    for (int u = 0; u <= 10; ++u) {
      const float at = float(u) / 10.0f;
      CHECK(bezier_point(fuzzy.polygon.view(), at).y() >= bezier_point(mean.polygon.view(), at).y() - 1e-6f);
    }
  }
  // A down feather built twice is the same to the bit.
  const FeatherGeometry g1 = build_feather(shape, FeatherDetail{}), g2 = build_feather(make_shape(t, 77), FeatherDetail{});
  CHECK(g1.curves.positions == g2.curves.positions);
}

TEST_CASE("the growth schedule ends at the adult feather", "[feathers]") {
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    const FeatherTemplate t = seed == 1 ? test::contour_template() : test::random_template(seed);
    const FeatherGeometry adult = build_feather(make_shape(t, seed), FeatherDetail{});
    const FeatherGeometry grown = build_feather(make_shape(t, seed, 1.0f), FeatherDetail{});
    CHECK(test::max_point_difference(adult, grown) == 0.0f);
    // Continuous as it reaches the end: the feather a moment before adulthood is nearly the adult.
    const FeatherGeometry almost = build_feather(make_shape(t, seed, 0.9999f), FeatherDetail{});
    const float scale = feather_length(t) + 2.0f * std::max(t.left.barb_length, t.right.barb_length) + 4.0f;
    CHECK(test::max_point_difference(adult, almost) <= 2e-3f * scale);
    // The same barbs at every stage (topology constant as it grows), and a shaft that lengthens first.
    float previous_top = -1.0f;
    for (const float stage : {0.0f, 0.1f, 0.25f, 0.3f, 0.5f, 0.75f, 0.8f, 0.9f, 1.0f}) {
      const FeatherShape shape = make_shape(t, seed, stage);
      CHECK(shape.main_positions == make_shape(t, seed).main_positions);
      const float top = shape.main.calamus_length + shape.main.rachis_length;
      CHECK(top >= previous_top);
      previous_top = top;
      const FeatherGeometry g = build_feather(shape, FeatherDetail{});
      for (const Eigen::Vector3f &p : g.curves.positions) REQUIRE(p.allFinite());
      if (stage <= growth_shaft_end) {
        // No barb has length yet.
        CHECK(shape.main.left.barb_length == 0.0f);
      }
    }
  }
}

TEST_CASE("growth follows the schedule: shaft, then barbs in the sheath, the sheath's front from tip to base",
          "[feathers]") {
  const FeatherTemplate t = test::contour_template();
  const FeatherTemplate early = grown_template(t, 0.15f);
  CHECK(early.rachis_length == Approx(0.5f * t.rachis_length));
  CHECK(early.right.silhouette.value[1] == 0.0f);
  // At 60%: barbs full length, key barbs the three straight ones, the front at 1 - 0.3 / 0.5 = 0.4.
  const FeatherTemplate mid = grown_template(t, 0.6f);
  CHECK(mid.rachis_length == t.rachis_length);
  CHECK(mid.right.silhouette.value[1] == t.right.silhouette.value[1]);
  REQUIRE(mid.right.key_barbs.size() == 3);
  CHECK(mid.right.key_barbs[1].position == Approx(0.4f));
  CHECK(mid.right.key_barbs[0].open == 0.0f);
  CHECK(mid.curvature_front == 0.0f);
  const FeatherShape shape = make_shape(t, 1, 0.6f);
  const Barb low = build_barb(shape.main, shape.main_keys[1], Vane::right, 0.1f, 0, 1);
  const Barb high = build_barb(shape.main, shape.main_keys[1], Vane::right, 0.7f, 0, 1);
  CHECK(low.angle < 0.5f * high.angle);  // below the front: still closing along the rachis
  CHECK(high.angle == Approx((55.0f + (30.0f - 55.0f) * 0.7f) * 3.14159265f / 180.0f).epsilon(1e-5));
  // Late: curvature grows back.
  CHECK(grown_template(t, 0.9f).curvature_front == Approx(0.5f * t.curvature_front));
}

TEST_CASE("blending a template with itself gives it back", "[feathers]") {
  for (uint64_t seed = 1; seed <= 150; ++seed) {
    const FeatherTemplate t = test::random_template(seed, seed % 2 ? 1.0f : 100.0f);
    const FeatherTemplate *copies[3] = {&t, &t, &t};
    const float weights[3] = {0.2f, 0.5f, 0.3f};
    const FeatherTemplate blended = blend_templates(copies, weights);
    const FeatherGeometry a = build_feather(make_shape(t, seed), FeatherDetail{});
    const FeatherGeometry b = build_feather(make_shape(blended, seed), FeatherDetail{});
    INFO("seed " << seed);
    CHECK(test::max_point_difference(a, b) <= 1e-6f * (feather_length(t) + 1.0f));
    CHECK(blended.rachis_length == t.rachis_length);
    CHECK(blended.right.angle_tip == t.right.angle_tip);
  }
}

TEST_CASE("blending two types: the ends are the types, and the feather changes continuously between", "[feathers]") {
  for (uint64_t seed = 1; seed <= 60; ++seed) {
    const FeatherTemplate a = test::random_template(2 * seed), b = test::random_template(2 * seed + 1);
    const FeatherTemplate *pair[2] = {&a, &b};
    // Same barb positions whatever the weight, so geometries compare point by point.
    auto geometry_at = [&](float w) {
      const float weights[2] = {1.0f - w, w};
      FeatherTemplate blended = blend_templates(pair, weights);
      blended.spacing_base = a.spacing_base;
      blended.spacing_tip = a.spacing_tip;
      blended.rachis_length = a.rachis_length;
      blended.afterfeather = a.afterfeather;
      return build_feather(make_shape(blended, seed), FeatherDetail{});
    };
    FeatherTemplate a_fixed = a;
    const FeatherGeometry at_a = build_feather(make_shape(a_fixed, seed), FeatherDetail{});
    CHECK(test::max_point_difference(at_a, geometry_at(0.0f)) <= 1e-5f * (feather_length(a) + 1.0f));
    const float scale = std::max(feather_length(a), feather_length(b)) + 4.0f;
    for (int s = 0; s < 10; ++s) {
      const float w = float(s) / 10.0f;
      CHECK(test::max_point_difference(geometry_at(w), geometry_at(w + 1e-4f)) <= 2e-2f * scale);
    }
  }
}

TEST_CASE("inflating key barbs keeps each feather's barbs", "[feathers]") {
  for (uint64_t seed = 1; seed <= 100; ++seed) {
    const FeatherTemplate a = test::random_template(seed), b = test::random_template(seed + 1000);
    const std::vector<KeyBarb> lists[2] = {complete_key_barbs(a.right.key_barbs), complete_key_barbs(b.right.key_barbs)};
    const std::vector<std::vector<KeyBarb>> inflated = inflate_key_barbs(lists);
    REQUIRE(inflated[0].size() == inflated[1].size());
    for (size_t k = 0; k < inflated[0].size(); ++k) CHECK(inflated[0][k].position == inflated[1][k].position);
    for (int s = 0; s <= 50; ++s) {
      const float rp = float(s) / 50.0f;
      const KeyBarbBlend before = interpolate_key_barbs(lists[0], rp), after = interpolate_key_barbs(inflated[0], rp);
      ControlPolygon x = before.polygon, y = after.polygon;
      elevate_to(x, std::max(x.count, y.count));
      elevate_to(y, std::max(x.count, y.count));
      for (int u = 0; u <= 10; ++u)
        CHECK((bezier_point(x.view(), float(u) / 10.0f) - bezier_point(y.view(), float(u) / 10.0f)).norm() <= 1e-5f);
    }
  }
}

TEST_CASE("random templates give finite feathers with the announced counts", "[feathers]") {
  for (uint64_t seed = 1; seed <= 300; ++seed) {
    const float scale = seed % 5 == 0 ? 1e-3f : seed % 5 == 1 ? 1e3f : 1.0f;
    const FeatherTemplate t = test::random_template(seed, scale);
    FeatherDetail detail;
    detail.rachis_points = int(2 + seed % 20);
    detail.barb_points = int(2 + seed % 11);
    detail.vane_rows = int(2 + seed % 7);
    detail.vane_columns = int(1 + seed % 5);
    const FeatherShape shape = make_shape(t, seed, seed % 4 == 0 ? float(seed % 100) / 100.0f : 1.0f);
    const FeatherCounts counts = feather_counts(shape, detail);
    const FeatherGeometry g = build_feather(shape, detail);
    CHECK(int64_t(g.curves.strand_count()) == counts.curves);
    CHECK(int64_t(g.curves.point_count()) == counts.points);
    CHECK(g.curves.offsets.back() == counts.points);
    for (const Eigen::Vector3f &p : g.curves.positions) REQUIRE(p.allFinite());
    for (const Eigen::Vector3f &p : g.vane_positions) REQUIRE(p.allFinite());
    for (const Eigen::Vector3i &tri : g.vane_triangles)
      for (int k = 0; k < 3; ++k) REQUIRE((tri[k] >= 0 && tri[k] < int(g.vane_positions.size())));
    // Barb texture coordinates run from 0 at the rachis to 1 at the tip.
    for (size_t c = 0; c < g.parts.size(); ++c)
      if (g.parts[c] == FeatherPart::right_barb) {
        CHECK(g.uv_barb[size_t(g.curves.offsets[c])].x() == 0.0f);
        CHECK(g.uv_barb[size_t(g.curves.offsets[c + 1] - 1)].x() == 1.0f);
      }
  }
}

TEST_CASE("vane meshes face dorsally and meet the barbs at the rachis", "[feathers]") {
  const FeatherTemplate t = test::contour_template();
  const FeatherGeometry g = build_feather(make_shape(t, 3), FeatherDetail{});
  int dorsal = 0;
  for (const Eigen::Vector3i &tri : g.vane_triangles) {
    const Eigen::Vector3f n = (g.vane_positions[size_t(tri[1])] - g.vane_positions[size_t(tri[0])])
                                  .cross(g.vane_positions[size_t(tri[2])] - g.vane_positions[size_t(tri[0])]);
    if (n.y() > 0.0f) ++dorsal;
  }
  CHECK(dorsal >= int(0.9 * double(g.vane_triangles.size())));
  // Column 0 of every row lies on the rachis.
  const FeatherDetail detail;
  for (int r = 0; r < detail.vane_rows; ++r) {
    const float rp = float(r) / float(detail.vane_rows - 1);
    CHECK((g.vane_positions[size_t(r * (detail.vane_columns + 1))] - rachis_point(t, rp)).norm() <= 1e-5f);
  }
}

TEST_CASE("bad templates are refused naming the field", "[feathers]") {
  FeatherTemplate t = test::contour_template();
  t.rachis_length = -1.0f;
  CHECK_THROWS_WITH(validate_template(t), Catch::Contains("rachis.length: expected a finite number > 0, got -1"));
  t = test::contour_template();
  t.calamus_length = -0.5f;
  CHECK_THROWS_WITH(validate_template(t), Catch::Contains("calamus.length"));
  t = test::contour_template();
  KeyBarb early = t.right.key_barbs[0];
  early.position = 0.1f;
  t.right.key_barbs.push_back(early);  // 0.35 then 0.1: unsorted
  CHECK_THROWS_WITH(validate_template(t), Catch::Contains("barbs.right.key_barbs[1].position"));
  t = test::contour_template();
  t.spacing_base = t.spacing_tip = t.rachis_length * 1e-6f;
  CHECK_THROWS_WITH(validate_template(t), Catch::Contains("barbs per vane"));
}
