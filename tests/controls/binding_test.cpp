// Which controls drive each guide: nearest or blended by falloff, restricted by face groups and
// vertex maps, mirrored pairs counted once; computed on the rest pose only.
#include <catch2/catch.hpp>

#include <cmath>

#include "controls/binding.h"
#include "controls_fixtures.h"

using namespace plume;
using namespace plume::test;

namespace {

std::vector<controls::RigControl> placed(const ControlSettings &settings, const Mesh &mesh) {
  const MeshQuery query(mesh);
  return controls::place_controls(settings, mesh, query);
}

// The falloff weight as the documentation states it, computed here independently.
double expected_falloff(ControlDesc::Falloff falloff, double d, double radius) {
  if (radius <= 0.0) return 1.0;
  const double x = d / radius;
  if (x >= 1.0) return 0.0;
  if (falloff == ControlDesc::Falloff::constant) return 1.0;
  if (falloff == ControlDesc::Falloff::linear) return 1.0 - x;
  return 1.0 - x * x * (3.0 - 2.0 * x);
}

}  // namespace

TEST_CASE("nearest binding: each guide follows the nearest control that reaches it, with its falloff", "[controls]") {
  const float size = 2.0f;
  const Mesh mesh = dome_patch(size);
  const Guides guides = patch_guides(mesh, size, 400, 7);
  std::vector<ControlDesc> list;
  const Eigen::Vector3f places[] = {{-1.0f, 0.3f, -1.0f}, {1.0f, 0.2f, 0.5f}, {0.0f, 0.6f, 0.0f}, {-0.5f, 0.2f, 1.2f}};
  for (int i = 0; i < 4; ++i) list.push_back(control_at(places[i], 1.4f, ControlDesc::Falloff(i % 3)));
  const ControlSettings settings = settings_of(list, ControlSettings::Binding::nearest);
  const auto controls = placed(settings, mesh);
  const controls::ControlBinding binding = controls::bind_controls(settings, controls, mesh, guides);
  REQUIRE(binding.guide_count() == guides.size());
  size_t driven = 0;
  for (size_t g = 0; g < guides.size(); ++g) {
    const Eigen::Vector3f root = surface_position(mesh, guides.roots[g]);
    int best = -1;
    double best_d = 1e30;
    for (int c = 0; c < 4; ++c) {
      const double d = (root - places[c]).norm();
      if (expected_falloff(list[size_t(c)].falloff, d, 1.4) > 0.0 && d < best_d) {
        best = c;
        best_d = d;
      }
    }
    const int64_t count = binding.offsets[g + 1] - binding.offsets[g];
    if (best < 0) {
      CHECK(count == 0);
      continue;
    }
    ++driven;
    REQUIRE(count == 1);
    CHECK(binding.controls[size_t(binding.offsets[g])] == best);
    CHECK(binding.weights[size_t(binding.offsets[g])] ==
          Approx(expected_falloff(list[size_t(best)].falloff, best_d, 1.4)).margin(1e-5));
  }
  CHECK(driven > 200);
}

TEST_CASE("blend binding: every control in reach by its falloff, weights scaled down to sum to 1 only past 1",
          "[controls]") {
  const float size = 1.0f;
  const Mesh mesh = dome_patch(size);
  const Guides guides = patch_guides(mesh, size, 300, 3);
  std::vector<ControlDesc> list = {control_at({-0.3f, 0.2f, 0.0f}, 0.9f),
                                   control_at({0.3f, 0.2f, 0.1f}, 0.7f, ControlDesc::Falloff::linear)};
  const ControlSettings settings = settings_of(list);
  const auto binding = controls::bind_controls(settings, placed(settings, mesh), mesh, guides);
  size_t both = 0;
  for (size_t g = 0; g < guides.size(); ++g) {
    const Eigen::Vector3f root = surface_position(mesh, guides.roots[g]);
    double w[2];
    for (int c = 0; c < 2; ++c)
      w[c] =
          expected_falloff(list[size_t(c)].falloff, (root - list[size_t(c)].position).norm(), list[size_t(c)].radius);
    const double total = w[0] + w[1];
    const double scale = total > 1.0 ? 1.0 / total : 1.0;
    double got[2] = {0.0, 0.0};
    for (int64_t e = binding.offsets[g]; e < binding.offsets[g + 1]; ++e)
      got[binding.controls[size_t(e)]] = binding.weights[size_t(e)];
    CHECK(got[0] == Approx(w[0] * scale).margin(1e-5));
    CHECK(got[1] == Approx(w[1] * scale).margin(1e-5));
    CHECK(binding.total_weight(g) <= 1.0f);
    both += w[0] > 0.0 && w[1] > 0.0;
  }
  CHECK(both > 20);
}

TEST_CASE("face groups and vertex maps restrict a control's guides", "[controls]") {
  const float size = 1.0f;
  const Mesh mesh = dome_patch(size);
  const Guides guides = patch_guides(mesh, size, 300, 5);
  ControlDesc c = control_at({0.0f, 0.3f, 0.0f}, 0.0f);
  c.groups = {"left"};
  c.vertex_map_path = "map";
  std::vector<float> map(mesh.vertex_count());
  for (size_t v = 0; v < map.size(); ++v) map[v] = mesh.positions[v].z() > 0.0f ? 1.0f : 0.0f;
  const ControlSettings settings = settings_of({c});
  const auto binding = controls::bind_controls(settings, placed(settings, mesh), mesh, guides, {map});
  size_t driven = 0;
  for (size_t g = 0; g < guides.size(); ++g) {
    const SurfacePoint &root = guides.roots[g];
    const bool left = mesh.triangle_groups[size_t(root.triangle)] == 1;
    const Eigen::Vector3i &t = mesh.triangles[size_t(root.triangle)];
    const float mapped =
        root.bary[0] * map[size_t(t[0])] + root.bary[1] * map[size_t(t[1])] + root.bary[2] * map[size_t(t[2])];
    const float expected = left ? mapped : 0.0f;
    CHECK(binding.total_weight(g) == Approx(expected).margin(1e-6));
    driven += expected > 0.0f;
  }
  CHECK(driven > 30);

  ControlDesc missing = c;
  missing.groups = {"tail"};
  missing.groups_key = "controls.list[0].groups";
  const ControlSettings bad = settings_of({missing});
  CHECK_THROWS_WITH(
      controls::bind_controls(bad, placed(bad, mesh), mesh, guides),
      Catch::Contains("controls.list[0].groups: no face group \"tail\"") && Catch::Contains("right, left"));
}

TEST_CASE("a mirrored control on its own plane drives each guide once, from the side the guide is on", "[controls]") {
  const float size = 1.0f;
  const Mesh mesh = dome_patch(size);
  const Guides guides = patch_guides(mesh, size, 400, 11);
  for (const ControlSettings::Binding mode : {ControlSettings::Binding::nearest, ControlSettings::Binding::blend}) {
    ControlDesc single = control_at({0.0f, 0.3f, 0.2f}, 1.2f);
    ControlDesc mirrored = single;
    mirrored.mirror = true;  // the plane x = 0 holds the control
    const ControlSettings one = settings_of({single}, mode), two = settings_of({mirrored}, mode);
    const auto placed_two = placed(two, mesh);
    REQUIRE(placed_two.size() == 2);
    CHECK(placed_two[1].twin);
    CHECK(placed_two[1].rest_position.isApprox(placed_two[0].rest_position));
    const auto a = controls::bind_controls(one, placed(one, mesh), mesh, guides);
    const auto b = controls::bind_controls(two, placed_two, mesh, guides);
    for (size_t g = 0; g < guides.size(); ++g) {
      CHECK(b.total_weight(g) == Approx(a.total_weight(g)).margin(1e-6));
      CHECK(b.offsets[g + 1] - b.offsets[g] <= 1);
      if (b.offsets[g + 1] == b.offsets[g]) continue;
      const bool positive_side = surface_position(mesh, guides.roots[g]).x() >= 0.0f;
      CHECK(b.controls[size_t(b.offsets[g])] == (positive_side ? 0 : 1));
    }
  }
}

TEST_CASE("a mirrored twin is reflected across any plane, offsets too", "[controls]") {
  const Mesh mesh = dome_patch(1.0f);
  ControlDesc c = control_at({0.4f, 0.5f, 0.1f}, 0.5f);
  c.place = ControlDesc::Place::space;
  c.mirror = true;
  c.mirror_point = Eigen::Vector3f(0.1f, 0.0f, 0.0f);
  c.mirror_normal = Eigen::Vector3f(1.0f, 0.0f, 1.0f).normalized();
  c.offset.frames = {1.0};
  c.offset.values = {Eigen::Vector3f(1.0f, 2.0f, 0.0f)};
  const auto controls = placed(settings_of({c}), mesh);
  REQUIRE(controls.size() == 2);
  const Eigen::Vector3f n = c.mirror_normal;
  const Eigen::Vector3f mid = 0.5f * (controls[0].rest_position + controls[1].rest_position);
  CHECK(std::abs((mid - c.mirror_point).dot(n)) < 1e-6f);
  CHECK((controls[0].rest_position - controls[1].rest_position).normalized().cross(n).norm() < 1e-6f);
  const Eigen::Vector3f reflected = controls[1].offset.values[0];
  const Eigen::Vector3f v(1.0f, 2.0f, 0.0f);
  // Across the plane the normal part flips and the rest stays.
  CHECK(std::abs((reflected + v).dot(n)) < 1e-5f);
  CHECK((reflected - v).cross(n).norm() < 1e-5f);
}

TEST_CASE("the binding is stable: a guide's controls and weights do not depend on the other guides", "[controls]") {
  const float size = 1.0f;
  const Mesh mesh = dome_patch(size);
  const Guides all = patch_guides(mesh, size, 300, 13);
  std::vector<ControlDesc> list = {control_at({-0.4f, 0.2f, 0.1f}, 0.8f), control_at({0.4f, 0.2f, -0.2f}, 0.9f)};
  list[1].mirror = true;
  for (const auto mode : {ControlSettings::Binding::nearest, ControlSettings::Binding::blend}) {
    const ControlSettings settings = settings_of(list, mode);
    const auto controls = placed(settings, mesh);
    const controls::ControlBinding whole = controls::bind_controls(settings, controls, mesh, all);
    // Every third guide alone.
    Guides some;
    for (size_t g = 0; g < all.size(); g += 3) {
      some.strands.append(all.strands.points(g), all.strands.ids[g]);
      some.roots.push_back(all.roots[g]);
    }
    const controls::ControlBinding part = controls::bind_controls(settings, controls, mesh, some);
    for (size_t i = 0; i < some.size(); ++i) {
      const size_t g = 3 * i;
      REQUIRE(part.offsets[i + 1] - part.offsets[i] == whole.offsets[g + 1] - whole.offsets[g]);
      for (int64_t k = 0; k < part.offsets[i + 1] - part.offsets[i]; ++k) {
        CHECK(part.controls[size_t(part.offsets[i] + k)] == whole.controls[size_t(whole.offsets[g] + k)]);
        CHECK(part.weights[size_t(part.offsets[i] + k)] == whole.weights[size_t(whole.offsets[g] + k)]);
      }
    }
  }
}
