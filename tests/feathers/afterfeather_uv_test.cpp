// The afterfeather (a second feather with the main one's parameters at the top of the calamus) and
// the texture coordinates of sec. 4.3.3 (along the barb; across the vane, on the flat feather), on
// the feather as built, in feather space.
#include <catch2/catch.hpp>

#include <cmath>

#include "feather_fixtures.h"
#include "feathers/build.h"
#include "feathers/feather.h"

using namespace plume;
using namespace plume::feathers;

namespace {

/// The curves of `part` in `g`, by index.
std::vector<size_t> curves_of(const FeatherGeometry &g, FeatherPart part) {
  std::vector<size_t> found;
  for (size_t c = 0; c < g.parts.size(); ++c)
    if (g.parts[c] == part) found.push_back(c);
  return found;
}

}  // namespace

TEST_CASE("an afterfeather is a second feather with the main one's parameters, at the top of the calamus",
          "[feathers]") {
  FeatherTemplate t = test::contour_template();
  t.afterfeather = 0.4f;
  const FeatherShape shape = make_shape(t, 5);
  REQUIRE(shape.has_after);
  // The same parameters, lengths and widths scaled by its size; no calamus; angles and the barbs'
  // spacing kept (its barbs as dense as the main feather's).
  CHECK(shape.after.rachis_length == Approx(0.4f * t.rachis_length));
  CHECK(shape.after.rachis_width == Approx(0.4f * t.rachis_width));
  CHECK(shape.after.spacing_base == t.spacing_base);
  CHECK(shape.after.calamus_length == 0.0f);
  CHECK(shape.after.left.angle_base == t.left.angle_base);
  CHECK(shape.after.right.angle_tip == t.right.angle_tip);
  CHECK(shape.after.right.silhouette.at(0.3f) == Approx(0.4f * t.right.silhouette.at(0.3f)));
  // So it has about 0.4 times as many barbs.
  CHECK(double(shape.after_positions.size()) == Approx(0.4 * double(shape.main_positions.size())).margin(2.0));

  const FeatherGeometry g = build_feather(shape, FeatherDetail{});
  const std::vector<size_t> rachis = curves_of(g, FeatherPart::after_rachis);
  REQUIRE(rachis.size() == 1);
  CHECK(curves_of(g, FeatherPart::after_left_barb).size() == shape.after_positions.size());
  CHECK(curves_of(g, FeatherPart::after_right_barb).size() == shape.after_positions.size());
  // It starts at the top of the calamus, one rachis width on the ventral side (-y), and reaches its
  // length along the shaft.
  const auto points = g.curves.points(rachis.front());
  CHECK((points.front() - Eigen::Vector3f(0.0f, -t.rachis_width, t.calamus_length)).norm() < 1e-5f);
  CHECK(points.back().z() - points.front().z() == Approx(0.4f * t.rachis_length).epsilon(0.02));
  // Every afterfeather barb lies beside its own rachis, below the main feather's tip.
  for (const FeatherPart part : {FeatherPart::after_left_barb, FeatherPart::after_right_barb})
    for (const size_t c : curves_of(g, part))
      for (const Eigen::Vector3f &p : g.curves.points(c)) REQUIRE(p.z() < t.calamus_length + 0.6f * t.rachis_length);

  // Below the smallest size (and at 0) there is none.
  for (const float size : {0.0f, 0.5f * kSmallestAfterfeather}) {
    t.afterfeather = size;
    const FeatherShape none = make_shape(t, 5);
    CHECK_FALSE(none.has_after);
    CHECK(curves_of(build_feather(none, FeatherDetail{}), FeatherPart::after_rachis).empty());
  }
}

TEST_CASE("texture coordinates: along each barb, and across the vane on the flat feather whatever the rachis's curve",
          "[feathers]") {
  FeatherTemplate straight = test::contour_template();
  straight.curvature_side = straight.curvature_front = 0.0f;
  FeatherTemplate curved = straight;
  curved.curvature_side = 0.08f;
  curved.curvature_front = -0.1f;
  const float length = straight.calamus_length + straight.rachis_length;
  const FeatherGeometry flat = build_feather(make_shape(straight, 9), FeatherDetail{});
  const FeatherGeometry bent = build_feather(make_shape(curved, 9), FeatherDetail{});
  REQUIRE(flat.curves.positions.size() == bent.curves.positions.size());

  // Across the vane: on the straight feather, u = 0.5 + x / L and v = z / L of the point itself.
  for (size_t i = 0; i < flat.curves.positions.size(); ++i) {
    const Eigen::Vector3f &p = flat.curves.positions[i];
    INFO("point " << i);
    REQUIRE(flat.uv_vane[i].x() == Approx(0.5f + p.x() / length).margin(1e-5));
    REQUIRE(flat.uv_vane[i].y() == Approx(p.z() / length).margin(1e-5));
  }
  // The curved feather keeps the straight one's coordinates (the texture stays on the feather),
  // though its points moved.
  double moved = 0.0, uv_change = 0.0;
  for (size_t i = 0; i < flat.curves.positions.size(); ++i) {
    moved = std::max(moved, double((flat.curves.positions[i] - bent.curves.positions[i]).norm()));
    uv_change = std::max(uv_change, double((flat.uv_vane[i] - bent.uv_vane[i]).norm()));
    uv_change = std::max(uv_change, double((flat.uv_barb[i] - bent.uv_barb[i]).norm()));
  }
  CHECK(moved > 0.05 * length);
  CHECK(uv_change < 1e-6);

  // Along the barb: u from 0 at the rachis to 1 at the tip, increasing; v the barb's place on the
  // rachis, the same along the barb and increasing from barb to barb.
  for (const FeatherPart part : {FeatherPart::left_barb, FeatherPart::right_barb}) {
    float previous_v = -1.0f;
    for (const size_t c : curves_of(bent, part)) {
      const int64_t first = bent.curves.offsets[c], end = bent.curves.offsets[c + 1];
      const float v = bent.uv_barb[size_t(first)].y();
      CHECK(v > previous_v);
      CHECK(v >= 0.0f);
      CHECK(v <= 1.0f);
      previous_v = v;
      CHECK(bent.uv_barb[size_t(first)].x() == 0.0f);
      CHECK(bent.uv_barb[size_t(end - 1)].x() == 1.0f);
      for (int64_t k = first + 1; k < end; ++k) {
        REQUIRE(bent.uv_barb[size_t(k)].x() > bent.uv_barb[size_t(k - 1)].x());
        REQUIRE(bent.uv_barb[size_t(k)].y() == v);
      }
    }
  }
  // The vane meshes carry the same two kinds.
  REQUIRE(flat.vane_uv_vane.size() == flat.vane_positions.size());
  for (size_t i = 0; i < flat.vane_positions.size(); ++i) {
    REQUIRE(flat.vane_uv_vane[i].x() == Approx(0.5f + flat.vane_positions[i].x() / length).margin(1e-5));
    REQUIRE(flat.vane_uv_vane[i].y() == Approx(flat.vane_positions[i].z() / length).margin(1e-5));
  }
}
