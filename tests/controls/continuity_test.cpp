// No flip: controls swept through 180 degrees over 48 frames move every guide point, frame by
// frame, by no more than the turn the sweep asks of it; and the hard places (a target on the
// normal, opposite the guide, at the root; overlapping controls) give finite, continuous guides.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <functional>

#include "controls/control_rig.h"
#include "controls_fixtures.h"

using namespace plume;
using namespace plume::test;

namespace {

constexpr int kFrames = 48;

// Runs frames 1..kFrames on the still rest skin (only the controls move) and checks, frame by frame,
// that no point moved more than `factor` times the angle `turn(g, f)` (radians: how far the sweep
// turned guide g's target from frame f to f + 1) times its distance from the root, plus rounding.
void check_sweep(
    const Mesh &rest, const Guides &guides, const controls::ControlRig &rig, float size,
    const std::function<double(size_t, int, const controls::GuidePose &, const controls::GuidePose &)> &turn,
    double factor) {
  controls::GuidePose before_pose, after_pose;
  rig.pose(1.0, rest, before_pose);
  StrandSet before = carry_guides(rest, rest, guides);
  rig.apply(before_pose, before);
  double worst_ratio = 0.0, largest_move = 0.0;
  for (int f = 1; f < kFrames; ++f) {
    rig.pose(f + 1, rest, after_pose);
    StrandSet after = carry_guides(rest, rest, guides);
    rig.apply(after_pose, after);
    for (size_t g = 0; g < guides.size(); ++g) {
      const Eigen::Vector3f o = surface_position(rest, guides.roots[g]);
      const double angle = turn(g, f, before_pose, after_pose);
      for (size_t j = 0; j < after.points(g).size(); ++j) {
        const double move = (after.points(g)[j] - before.points(g)[j]).norm();
        const double allowed = factor * angle * (before.points(g)[j] - o).norm() + 1e-5 * size;
        largest_move = std::max(largest_move, move / size);
        worst_ratio = std::max(worst_ratio, move / allowed);
        if (move > allowed) {
          INFO("frame " << f << " -> " << f + 1 << ", guide " << g << ", point " << j << ": moved " << move
                        << ", allowed " << allowed);
          CHECK(move <= allowed);
          return;
        }
      }
    }
    before = std::move(after);
    std::swap(before_pose, after_pose);
  }
  INFO("largest move per frame " << largest_move << " x size, worst move / allowed " << worst_ratio);
  CHECK(worst_ratio <= 1.0);
  CHECK(largest_move > 0.0);
}

// Angle between the directions from guide g's root to the control in two poses.
double target_turn(const Mesh &rest, const Guides &guides, size_t g, const controls::GuidePose &a,
                   const controls::GuidePose &b) {
  const Eigen::Vector3f o = surface_position(rest, guides.roots[g]);
  return angle_degrees(a.controls[0].position - o, b.controls[0].position - o) * kPi / 180.0;
}

}  // namespace

TEST_CASE(
    "no flip: an aim control swept through 180 degrees over the guides moves every point by a bounded amount per "
    "frame",
    "[controls]") {
  for (const float size : {0.01f, 1.0f, 100.0f}) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 300, 40);
    // Over the top: from one side, through the normal of the middle guides, down to the other side.
    ControlDesc over = control_at(Eigen::Vector3f::Zero(), 0.0f);
    over.place = ControlDesc::Place::space;
    over.aim = keys({{1, 1.0f}});
    over.offset.interpolation = KeyInterpolation::linear;
    for (int f = 1; f <= kFrames; ++f) {
      const float a = kPi * float(f - 1) / float(kFrames - 1);
      over.offset.frames.push_back(f);
      over.offset.values.push_back(size * Eigen::Vector3f(2.0f * std::cos(a), 0.3f + 2.0f * std::sin(a), 0.3f));
    }
    // Around, low: half a turn about the patch at skin height, so that the target passes opposite
    // every guide's lean.
    ControlDesc around = over;
    for (int f = 1; f <= kFrames; ++f) {
      const float a = kPi * float(f - 1) / float(kFrames - 1);
      around.offset.values[size_t(f - 1)] = size * Eigen::Vector3f(1.6f * std::cos(a), 0.3f, 1.6f * std::sin(a));
    }
    for (const ControlDesc &c : {over, around}) {
      const controls::ControlRig rig(rest, guides, settings_of({c}));
      INFO("scale " << size);
      check_sweep(
          rest, guides, rig, size,
          [&](size_t g, int, const controls::GuidePose &a, const controls::GuidePose &b) {
            return target_turn(rest, guides, g, a, b);
          },
          2.5);
    }
  }
}

TEST_CASE(
    "no flip: hooked guides lying on a flat skin aimed at a control that circles them at skin height, passing "
    "behind each",
    "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size, 8, 0.0f);
  const MeshQuery query(rest);
  // Guides hooked sideways, nearly lying on the skin (rising 3 degrees), in every azimuth: a target
  // passing just beside the opposite of their lean is where a shortest-arc turn would roll them over.
  StrandSet strands;
  for (int g = 0; g < 120; ++g) {
    const float x = 0.8f * size * (2.0f * hash_to_unit(hash64(uint64_t(g))) - 1.0f);
    const float z = 0.8f * size * (2.0f * hash_to_unit(hash64(uint64_t(g) + 500)) - 1.0f);
    const float azimuth = 2.0f * kPi * float(g) / 120.0f;
    std::vector<Eigen::Vector3f> points{Eigen::Vector3f(x, 0.0f, z)};
    for (int j = 1; j < 8; ++j) {
      const float heading = azimuth + 0.25f * kPi * float(j - 1) / 6.0f, rise = 3.0f * kPi / 180.0f;
      points.push_back(points.back() + 0.03f * size *
                                           Eigen::Vector3f(std::cos(rise) * std::cos(heading), std::sin(rise),
                                                           std::cos(rise) * std::sin(heading)));
    }
    strands.append(points, uint64_t(g));
  }
  const Guides guides = bind_guides(query, std::move(strands), "test");
  ControlDesc c = control_at(Eigen::Vector3f::Zero(), 0.0f);
  c.place = ControlDesc::Place::space;
  c.aim = keys({{1, 1.0f}});
  for (int f = 1; f <= kFrames; ++f) {
    const float a = kPi * float(f - 1) / float(kFrames - 1);
    c.offset.frames.push_back(f);
    c.offset.values.push_back(size * Eigen::Vector3f(1.5f * std::cos(a), 0.0f, 1.5f * std::sin(a)));
  }
  const controls::ControlRig rig(rest, guides, settings_of({c}));
  check_sweep(
      rest, guides, rig, size,
      [&](size_t g, int, const controls::GuidePose &a, const controls::GuidePose &b) {
        return target_turn(rest, guides, g, a, b);
      },
      2.5);
}

TEST_CASE(
    "no flip: a direction control whose displacement turns through 180 degrees moves every point by a bounded "
    "amount per frame",
    "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size);
  const Guides guides = patch_guides(rest, size, 300, 41);
  ControlDesc c = control_at(Eigen::Vector3f(0.0f, 0.3f, 0.0f), 0.0f);
  c.direction = keys({{1, 1.0f}});
  for (int f = 1; f <= kFrames; ++f) {
    const float a = kPi * float(f - 1) / float(kFrames - 1);
    c.offset.frames.push_back(f);
    c.offset.values.push_back(size * Eigen::Vector3f(0.35f * std::cos(a), 0.05f, 0.35f * std::sin(a)));
  }
  const controls::ControlRig rig(rest, guides, settings_of({c}));
  const StrandSet carried = carry_guides(rest, rest, guides);
  check_sweep(
      rest, guides, rig, size,
      [&](size_t g, int, const controls::GuidePose &a, const controls::GuidePose &b) {
        // The tip's target turns from tip + d(f) to tip + d(f + 1), seen from the root.
        const Eigen::Vector3f o = surface_position(rest, guides.roots[g]);
        const Eigen::Vector3f tip = carried.points(g).back() - o;
        return angle_degrees(tip + a.controls[0].displacement, tip + b.controls[0].displacement) * kPi / 180.0;
      },
      2.5);
}

TEST_CASE("no flip: lift by an angle from -90 to 180 degrees sweeps past the normal smoothly", "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size);
  const Guides guides = patch_guides(rest, size, 300, 42);
  ControlDesc c = control_at(Eigen::Vector3f::Zero(), 0.0f);
  c.lift_by = ControlDesc::LiftBy::angle;
  c.lift = keys({{1, -90.0f}, {double(kFrames), 180.0f}});
  const controls::ControlRig rig(rest, guides, settings_of({c}));
  const double step = 270.0 / (kFrames - 1) * kPi / 180.0;
  check_sweep(
      rest, guides, rig, size,
      [&](size_t, int, const controls::GuidePose &, const controls::GuidePose &) { return step; }, 1.01);
}

TEST_CASE(
    "hard places: a target on the normal, opposite the guide, at the root, and overlapping controls that pull "
    "apart stay finite and keep lengths",
    "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size);
  const Guides guides = patch_guides(rest, size, 200, 43);
  const StrandSet carried = carry_guides(rest, rest, guides);
  for (size_t g = 0; g < guides.size(); g += 7) {
    const Eigen::Vector3f o = surface_position(rest, guides.roots[g]);
    const Eigen::Vector3f n = surface_normal(rest, guides.roots[g]);
    const Eigen::Vector3f tip = carried.points(g).back() - o;
    const Eigen::Vector3f across = tip - tip.dot(n) * n;
    const Eigen::Vector3f lean = across.norm() > 1e-3f * tip.norm() ? Eigen::Vector3f(across.normalized())
                                                                    : surface_frame(rest, guides.roots[g]).basis.col(0);
    const Eigen::Vector3f targets[] = {o + 0.5f * n,                 // straight up the normal
                                       o - 0.5f * lean + 0.01f * n,  // opposite the guide, at skin level
                                       guides.strands.points(g)[0],  // at the root itself
                                       o - 0.5f * n};                // straight into the skin
    for (int t = 0; t < 4; ++t) {
      ControlDesc c = control_at(targets[t], 0.0f);
      c.place = ControlDesc::Place::space;
      c.aim = keys({{1, 1.0f}});
      const controls::ControlRig rig(rest, guides, settings_of({c}));
      const StrandSet out = controlled(rig, rest, rest, guides, 1.0);
      const auto p = out.points(g);
      for (const Eigen::Vector3f &q : p) REQUIRE(q.allFinite());
      for (size_t j = 1; j < p.size(); ++j)
        CHECK((p[j] - p[j - 1]).norm() ==
              Approx((carried.points(g)[j] - carried.points(g)[j - 1]).norm()).epsilon(1e-5));
      const Eigen::Vector3f aimed = p.back() - o;
      INFO("guide " << g << ", target " << t);
      if (t == 0) CHECK(angle_degrees(aimed, n) < 1.0);
      if (t == 1) CHECK(angle_degrees(aimed, targets[1] - o) < 1.0);
      if (t == 2)  // a target at the root fades out: nothing to aim at
        CHECK(std::equal(p.begin(), p.end(), carried.points(g).begin()));
      if (t == 3) CHECK(aimed.dot(n) >= std::min(0.0f, tip.dot(n)) - 1e-5f);  // held at the tangent plane
    }
  }
  // Two overlapping controls aiming at opposite points: the mean of their swings, never zero.
  ControlDesc left = control_at(Eigen::Vector3f(-3.0f, 0.3f, 0.0f), 0.0f), right = left;
  left.place = right.place = ControlDesc::Place::space;
  right.position = Eigen::Vector3f(3.0f, 0.3f, 0.0f);
  left.aim = right.aim = keys({{1, 1.0f}});
  const controls::ControlRig rig(rest, guides, settings_of({left, right}));
  const StrandSet out = controlled(rig, rest, rest, guides, 1.0);
  for (const Eigen::Vector3f &q : out.positions) REQUIRE(q.allFinite());
}

// A smoke test over rigs nobody tuned (three controls, random places, reaches, mirrors, keyed offsets
// and amounts up to every range's end, displacements past the guides' lengths): finite, and no large
// move in a thousandth of a frame. The sweeps above are the test of continuity frame by frame.
TEST_CASE(
    "no jump anywhere: random rigs move no guide point by more than 2% of its reach between frames f and "
    "f + 0.001",
    "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size, 16);
  size_t steps = 0;
  double worst = 0.0;
  for (uint64_t seed = 0; seed < 60; ++seed) {
    const Guides guides = patch_guides(rest, size, 80, seed + 300);
    auto unit = [&](uint64_t k) { return hash_to_unit(hash_combine(seed * 977 + 5, k)); };
    std::vector<ControlDesc> list;
    for (int i = 0; i < 3; ++i) {
      const uint64_t b = uint64_t(i) * 64;
      ControlDesc c =
          control_at(size * Eigen::Vector3f(2.0f * unit(b) - 1.0f, 0.2f + unit(b + 1), 2.0f * unit(b + 2) - 1.0f),
                     unit(b + 3) < 0.3f ? 0.0f : size * (0.4f + 1.2f * unit(b + 3)), ControlDesc::Falloff(i % 3));
      c.place = unit(b + 4) < 0.5f ? ControlDesc::Place::skin : ControlDesc::Place::space;
      c.mirror = unit(b + 5) < 0.3f;
      c.offset.interpolation = KeyInterpolation::smooth;
      for (int k = 0; k < 4; ++k) {
        c.offset.frames.push_back(10.0 * k);
        c.offset.values.push_back(size * Eigen::Vector3f(2.0f * unit(b + 10 + uint64_t(k)) - 1.0f,
                                                         2.0f * unit(b + 20 + uint64_t(k)) - 0.8f,
                                                         2.0f * unit(b + 30 + uint64_t(k)) - 1.0f));
      }
      if (unit(b + 6) < 0.6f) {
        c.lift_by = unit(b + 7) < 0.5f ? ControlDesc::LiftBy::angle : ControlDesc::LiftBy::fraction;
        const float hi = c.lift_by == ControlDesc::LiftBy::angle ? 180.0f : 1.0f;
        c.lift = keys({{0, hi * (2.0f * unit(b + 40) - 1.0f)}, {30, hi * (2.0f * unit(b + 41) - 1.0f)}},
                      KeyInterpolation::smooth);
      }
      if (unit(b + 8) < 0.6f) c.aim = keys({{0, unit(b + 42)}, {30, unit(b + 43)}});
      if (unit(b + 9) < 0.6f) c.direction = keys({{0, 2.0f * unit(b + 44)}, {30, 2.0f * unit(b + 45) - 1.0f}});
      if (unit(b + 50) < 0.6f) c.random_twist = keys({{0, 180.0f * unit(b + 46)}, {30, 180.0f * unit(b + 47)}});
      c.twist_seed = seed;
      list.push_back(c);
    }
    const controls::ControlRig rig(
        rest, guides,
        settings_of(list, seed % 2 ? ControlSettings::Binding::nearest : ControlSettings::Binding::blend));
    const StrandSet carried = carry_guides(rest, rest, guides);
    for (int s = 0; s < 40; ++s) {
      const double f = 30.0 * unit(1000 + uint64_t(s));
      const StrandSet a = controlled(rig, rest, rest, guides, f), b = controlled(rig, rest, rest, guides, f + 0.001);
      for (const Eigen::Vector3f &p : a.positions) REQUIRE(p.allFinite());
      for (size_t g = 0; g < guides.size(); ++g) {
        const double reach = (carried.points(g).back() - surface_position(rest, guides.roots[g])).norm();
        for (size_t j = 0; j < a.points(g).size(); ++j) {
          const double move = (a.points(g)[j] - b.points(g)[j]).norm() / reach;
          worst = std::max(worst, move);
          if (move > 0.02) {
            INFO("seed " << seed << ", frame " << f << ", guide " << g << ", point " << j << ": moved " << move
                         << " x reach");
            CHECK(move <= 0.02);
          }
        }
      }
      ++steps;
    }
  }
  INFO("largest move " << worst << " x reach over " << steps << " steps of 0.001 frame");
  CHECK(worst < 0.02);
}
