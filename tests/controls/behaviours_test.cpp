// The behaviours' promises: amount 0 changes nothing, lift 1 stands the first segment on the
// normal, aim points the tips at the control, direction moves the tips with the control, random
// twist is seeded and order-free, and lengths are kept; at several scales, on a bending skin.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "controls/control_rig.h"
#include "controls_fixtures.h"

using namespace plume;
using namespace plume::test;

namespace {

const float kScales[] = {0.001f, 1.0f, 1000.0f};

// Largest relative change of a segment length between two strand sets.
double max_length_change(const StrandSet &a, const StrandSet &b) {
  double worst = 0.0;
  for (size_t g = 0; g < a.strand_count(); ++g) {
    const auto pa = a.points(g), pb = b.points(g);
    for (size_t j = 1; j < pa.size(); ++j) {
      const double la = (pa[j] - pa[j - 1]).cast<double>().norm(), lb = (pb[j] - pb[j - 1]).cast<double>().norm();
      worst = std::max(worst, std::abs(la - lb) / la);
    }
  }
  return worst;
}

// Every behaviour present, with amounts keyed to 0.
ControlDesc all_behaviours(const Eigen::Vector3f &position, float radius, float amount) {
  ControlDesc c = control_at(position, radius);
  c.lift = keys({{1, 0.0f}, {6, amount}});
  c.aim = keys({{1, 0.0f}, {6, 0.5f * amount}});
  c.direction = keys({{1, 0.0f}, {6, amount}});
  c.random_twist = keys({{1, 0.0f}, {6, 60.0f * amount}});
  c.twist_seed = 5;
  c.offset.frames = {1.0, 6.0};
  c.offset.values = {Eigen::Vector3f::Zero(), radius * Eigen::Vector3f(0.3f, 0.1f, -0.2f)};
  return c;
}

}  // namespace

TEST_CASE("every behaviour at amount 0 leaves the guides bit-identical", "[controls]") {
  for (const float size : kScales) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 300, 21);
    const Eigen::Vector3f centre(0.1f * size, 0.4f * size, 0.0f);
    std::vector<std::vector<ControlDesc>> cases;
    ControlDesc base = control_at(centre, 1.5f * size);
    base.offset.frames = {1.0, 9.0};
    base.offset.values = {Eigen::Vector3f::Zero(), size * Eigen::Vector3f(0.3f, 0.5f, -0.4f)};
    auto with = [&](auto set) {
      ControlDesc c = base;
      set(c);
      cases.push_back({c});
    };
    with([](ControlDesc &c) { c.lift = keys({{1, 0.0f}, {9, 0.0f}}, KeyInterpolation::smooth); });
    with([](ControlDesc &c) {
      c.lift_by = ControlDesc::LiftBy::angle;
      c.lift = keys({{3, 0.0f}});
    });
    with([](ControlDesc &c) { c.aim = keys({{1, 0.0f}, {9, 0.0f}}); });
    with([](ControlDesc &c) { c.direction = keys({{1, 0.0f}, {9, 0.0f}}); });
    with([](ControlDesc &c) {
      c.random_twist = keys({{1, 0.0f}});
      c.twist_seed = 99;
    });
    // Everything at once, several controls, a mirrored one and one in space, nearest and blended.
    ControlDesc a = all_behaviours(centre, 1.2f * size, 0.0f);
    ControlDesc b = all_behaviours(Eigen::Vector3f(-0.6f * size, 0.1f * size, 0.5f * size), 0.8f * size, 0.0f);
    b.mirror = true;
    ControlDesc s = all_behaviours(Eigen::Vector3f(0.0f, 2.0f * size, 0.0f), 0.0f, 0.0f);
    s.place = ControlDesc::Place::space;
    cases.push_back({a, b, s});
    for (size_t i = 0; i < cases.size(); ++i)
      for (const auto binding : {ControlSettings::Binding::nearest, ControlSettings::Binding::blend}) {
        const controls::ControlRig rig(rest, guides, settings_of(cases[i], binding));
        for (double frame : {0.0, 1.0, 4.0, 9.0, 15.0}) {
          const Mesh posed = bent_patch(rest, size, frame);
          const StrandSet carried = carry_guides(rest, posed, guides);
          StrandSet out = carried;
          rig.apply(frame, posed, out);
          INFO("scale " << size << ", case " << i << ", frame " << frame);
          CHECK(same_bits(out, carried));
        }
      }
  }
}

TEST_CASE("lift 1 makes each driven guide's first segment parallel to the skin normal (within 0.1 degree)",
          "[controls]") {
  for (const float size : kScales) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 600, 4);
    for (const auto binding : {ControlSettings::Binding::nearest, ControlSettings::Binding::blend}) {
      std::vector<ControlDesc> list;
      for (int i = 0; i < 4; ++i) {
        ControlDesc c = control_at(size * Eigen::Vector3f(i % 2 ? 0.5f : -0.5f, 0.2f, i / 2 ? 0.5f : -0.5f),
                                   0.9f * size, ControlDesc::Falloff::constant);
        c.lift = keys({{1, 0.0f}, {10, 1.0f}}, KeyInterpolation::smooth);
        list.push_back(c);
      }
      const controls::ControlRig rig(rest, guides, settings_of(list, binding));
      for (double frame : {10.0, 14.0, 30.0}) {
        const Mesh posed = bent_patch(rest, size, frame);
        const StrandSet out = controlled(rig, rest, posed, guides, frame);
        size_t driven = 0;
        double worst = 0.0;
        for (size_t g = 0; g < guides.size(); ++g) {
          if (rig.binding().total_weight(g) != 1.0f) continue;
          ++driven;
          const auto p = out.points(g);
          worst = std::max(worst, angle_degrees(p[1] - p[0], surface_normal(posed, guides.roots[g])));
        }
        INFO("scale " << size << ", frame " << frame << ", driven " << driven);
        CHECK(driven > 300);
        CHECK(worst < 0.1);
      }
    }
  }
}

TEST_CASE("lift by an angle raises the first segment by that angle, over the normal and no further than the skin",
          "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size);
  const Guides guides = patch_guides(rest, size, 300, 8);
  for (const float degrees : {-30.0f, 20.0f, 75.0f, 150.0f, 180.0f}) {
    ControlDesc c = control_at(Eigen::Vector3f::Zero(), 0.0f);
    c.lift_by = ControlDesc::LiftBy::angle;
    c.lift = keys({{1, degrees}});
    const controls::ControlRig rig(rest, guides, settings_of({c}));
    const Mesh posed = bent_patch(rest, size, 3.0);
    const StrandSet before = carry_guides(rest, posed, guides), after = controlled(rig, rest, posed, guides, 3.0);
    for (size_t g = 0; g < guides.size(); ++g) {
      const Eigen::Vector3f n = surface_normal(posed, guides.roots[g]);
      const auto p0 = before.points(g), p1 = after.points(g);
      const double e0 = 90.0 - angle_degrees(p0[1] - p0[0], n), e1 = 90.0 - angle_degrees(p1[1] - p1[0], n);
      // Elevation measured from the tangent plane, up to 90 at the normal; past it the segment
      // leans the other way: its elevation counted from that side is 180 - (e0 + angle).
      const double lifted = e0 + std::clamp(double(degrees), -std::max(e0, 0.0), 180.0 - e0);
      const double expected = lifted <= 90.0 ? lifted : 180.0 - lifted;
      INFO("guide " << g << ", lift " << degrees << ", rest elevation " << e0);
      CHECK(e1 == Approx(expected).margin(0.05));
    }
  }
}

TEST_CASE("aim points driven tips at the control within 1 degree", "[controls]") {
  for (const float size : kScales) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 500, 12);
    // A control in space high above, and one on the skin lifted by its offset (it moves with the skin).
    ControlDesc sky = control_at(size * Eigen::Vector3f(0.4f, 2.5f, -0.3f), 0.0f);
    sky.place = ControlDesc::Place::space;
    sky.aim = keys({{1, 0.0f}, {5, 1.0f}});
    ControlDesc skin =
        control_at(size * Eigen::Vector3f(-0.2f, 0.3f, 0.2f), 0.7f * size, ControlDesc::Falloff::constant);
    skin.aim = keys({{1, 1.0f}});
    skin.offset.frames = {1.0, 8.0};
    skin.offset.values = {size * Eigen::Vector3f(0.0f, 1.0f, 0.0f), size * Eigen::Vector3f(0.5f, 1.5f, 0.0f)};
    for (const auto &list : {std::vector<ControlDesc>{sky}, std::vector<ControlDesc>{skin}}) {
      const controls::ControlRig rig(rest, guides, settings_of(list));
      for (double frame : {5.0, 8.0, 12.0}) {
        const Mesh posed = bent_patch(rest, size, frame);
        controls::GuidePose pose;
        rig.pose(frame, posed, pose);
        StrandSet out = carry_guides(rest, posed, guides);
        rig.apply(pose, out);
        const Eigen::Vector3f target = pose.controls[0].position;
        size_t driven = 0;
        double worst = 0.0;
        for (size_t g = 0; g < guides.size(); ++g) {
          if (rig.binding().total_weight(g) != 1.0f) continue;
          ++driven;
          const Eigen::Vector3f o = surface_position(posed, guides.roots[g]);
          worst = std::max(worst, angle_degrees(out.points(g).back() - o, target - o));
        }
        INFO("scale " << size << ", frame " << frame);
        CHECK(driven > 100);
        CHECK(worst < 1.0);
      }
    }
  }
}

TEST_CASE("direction moves tips by the control's displacement times the weight", "[controls]") {
  for (const float size : kScales) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 500, 31);
    for (const float reach : {0.004f, 0.15f}) {  // of the size: small (first order) and large moves
      ControlDesc c = control_at(size * Eigen::Vector3f(0.1f, 0.3f, 0.0f), 1.3f * size, ControlDesc::Falloff::linear);
      c.direction = keys({{1, 1.0f}});
      c.offset.frames = {1.0, 10.0};
      c.offset.values = {Eigen::Vector3f::Zero(), reach * size * Eigen::Vector3f(0.6f, 0.0f, -0.8f)};
      const controls::ControlRig rig(rest, guides, settings_of({c}));
      const double frame = 10.0;
      const Mesh posed = bent_patch(rest, size, frame);
      controls::GuidePose pose;
      rig.pose(frame, posed, pose);
      const Eigen::Vector3f displacement = pose.controls[0].displacement;
      CHECK(displacement.norm() == Approx(reach * size).epsilon(1e-5));
      const StrandSet before = carry_guides(rest, posed, guides);
      StrandSet after = before;
      rig.apply(pose, after);
      size_t tested = 0;
      for (size_t g = 0; g < guides.size(); ++g) {
        const float w = rig.binding().total_weight(g);
        if (!(w > 0.0f)) continue;
        const Eigen::Vector3f o = surface_position(posed, guides.roots[g]);
        const Eigen::Vector3f n = surface_normal(posed, guides.roots[g]);
        const Eigen::Vector3f tip = before.points(g).back(), moved = after.points(g).back();
        const Eigen::Vector3f wanted = tip + w * displacement;
        // Targets below the skin's tangent plane (lower than the tip already is) are held there.
        if ((wanted - o).normalized().dot(n) < std::min(0.0f, (tip - o).normalized().dot(n))) continue;
        ++tested;
        // The tip keeps its distance from the root and lands on the ray toward tip + w d ...
        CHECK((moved - o).norm() == Approx((tip - o).norm()).epsilon(1e-4));
        CHECK(angle_degrees(moved - o, wanted - o) < 0.01);
        // ... which for a small move is the move itself across the root-to-tip line (a turn about
        // the root cannot move the tip along that line; the difference is second order).
        const Eigen::Vector3f chord = (tip - o).normalized();
        const Eigen::Vector3f across = w * (displacement - displacement.dot(chord) * chord);
        if (reach < 0.01f) CHECK((moved - tip - across).norm() <= 0.06f * w * displacement.norm() + 1e-6f * size);
      }
      INFO("scale " << size << ", reach " << reach);
      CHECK(tested > 250);
    }
  }
}

TEST_CASE("random twist is seeded and identical in any frame order, and turns guides about the skin normal",
          "[controls]") {
  const float size = 1.0f;
  const Mesh rest = dome_patch(size);
  const Guides guides = patch_guides(rest, size, 300, 2);
  ControlDesc c = control_at(Eigen::Vector3f(0.0f, 0.3f, 0.0f), 1.5f * size);
  c.random_twist = keys({{1, 0.0f}, {12, 90.0f}}, KeyInterpolation::smooth);
  c.twist_seed = 17;
  c.lift = keys({{1, 0.0f}, {12, 0.6f}});
  const controls::ControlRig rig(rest, guides, settings_of({c}));
  const int frames = 24;
  std::vector<StrandSet> forward;
  for (int f = 1; f <= frames; ++f) forward.push_back(controlled(rig, rest, bent_patch(rest, size, f), guides, f));
  std::vector<int> order(frames);
  std::iota(order.begin(), order.end(), 1);
  for (uint64_t shuffle = 0; shuffle < 3; ++shuffle) {
    if (shuffle == 1) std::reverse(order.begin(), order.end());
    if (shuffle == 2)
      std::sort(order.begin(), order.end(), [](int a, int b) { return hash64(uint64_t(a)) < hash64(uint64_t(b)); });
    const controls::ControlRig fresh(rest, guides, settings_of({c}));
    for (const int f : order)
      CHECK(same_bits(controlled(fresh, rest, bent_patch(rest, size, f), guides, f), forward[size_t(f - 1)]));
  }
  // Another seed gives other turns; the same seed, the same.
  ControlDesc other = c;
  other.twist_seed = 18;
  const controls::ControlRig reseeded(rest, guides, settings_of({other}));
  CHECK_FALSE(same_bits(controlled(reseeded, rest, bent_patch(rest, size, 12), guides, 12), forward[11]));

  // Twist alone turns about the normal: every point keeps its height over the root's tangent plane,
  // and the multipliers spread over [-1, 1].
  ControlDesc twist_only = control_at(Eigen::Vector3f::Zero(), 0.0f);
  twist_only.random_twist = keys({{1, 90.0f}});
  const controls::ControlRig twister(rest, guides, settings_of({twist_only}));
  const Mesh posed = bent_patch(rest, size, 5.0);
  const StrandSet before = carry_guides(rest, posed, guides), after = controlled(twister, rest, posed, guides, 5.0);
  double lo = 180.0, hi = -180.0;
  for (size_t g = 0; g < guides.size(); ++g) {
    const Eigen::Vector3f o = surface_position(posed, guides.roots[g]), n = surface_normal(posed, guides.roots[g]);
    for (size_t j = 0; j < before.points(g).size(); ++j)
      CHECK(std::abs((after.points(g)[j] - o).dot(n) - (before.points(g)[j] - o).dot(n)) < 1e-5f);
    const Eigen::Vector3f a = before.points(g).back() - o, b = after.points(g).back() - o;
    const Eigen::Vector3f pa = a - a.dot(n) * n, pb = b - b.dot(n) * n;
    if (pa.norm() < 0.01f) continue;
    const double turn = std::atan2(double(n.dot(pa.cross(pb))), double(pa.dot(pb))) * 180.0 / kPi;
    lo = std::min(lo, turn);
    hi = std::max(hi, turn);
    CHECK(std::abs(turn) <= 90.01);
  }
  CHECK(lo < -80.0);
  CHECK(hi > 80.0);
}

TEST_CASE("guides keep their segment lengths under every behaviour at once", "[controls]") {
  for (uint64_t seed = 0; seed < 24; ++seed) {
    const float size = kScales[seed % 3];
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 200, seed);
    auto unit = [&](uint64_t k) { return hash_to_unit(hash_combine(seed + 100, k)); };
    std::vector<ControlDesc> list;
    for (int i = 0; i < 3; ++i) {
      ControlDesc c = all_behaviours(size * Eigen::Vector3f(2.0f * unit(i) - 1.0f, 0.3f, 2.0f * unit(i + 9) - 1.0f),
                                     size * (0.5f + unit(i + 20)), 1.0f);
      c.lift_by = i == 1 ? ControlDesc::LiftBy::angle : ControlDesc::LiftBy::fraction;
      if (i == 1) c.lift = keys({{1, -40.0f}, {6, 170.0f}});
      c.mirror = i == 2;
      list.push_back(c);
    }
    const controls::ControlRig rig(
        rest, guides,
        settings_of(list, seed % 2 ? ControlSettings::Binding::nearest : ControlSettings::Binding::blend));
    for (double frame : {2.0, 4.5, 6.0, 11.0}) {
      const Mesh posed = bent_patch(rest, size, frame);
      const StrandSet before = carry_guides(rest, posed, guides), after = controlled(rig, rest, posed, guides, frame);
      for (const Eigen::Vector3f &p : after.positions) REQUIRE(p.allFinite());
      INFO("seed " << seed << ", frame " << frame);
      CHECK(max_length_change(before, after) < 1e-5);
    }
  }
}

TEST_CASE("a scaled groom gives the scaled guides", "[controls]") {
  auto run = [](float size) {
    const Mesh rest = dome_patch(size);
    const Guides guides = patch_guides(rest, size, 200, 9);
    std::vector<ControlDesc> list = {all_behaviours(size * Eigen::Vector3f(0.2f, 0.3f, -0.1f), 0.9f * size, 1.0f),
                                     all_behaviours(size * Eigen::Vector3f(-0.5f, 0.2f, 0.4f), 0.7f * size, 0.7f)};
    list[1].place = ControlDesc::Place::space;
    list[1].mirror = true;
    const controls::ControlRig rig(rest, guides, settings_of(list));
    return controlled(rig, rest, bent_patch(rest, size, 7.0), guides, 7.0);
  };
  const StrandSet unit = run(1.0f);
  for (const float size : {0.001f, 1000.0f}) {
    const StrandSet scaled = run(size);
    double worst = 0.0;
    for (size_t p = 0; p < unit.positions.size(); ++p)
      worst = std::max(worst, double((scaled.positions[p] / size - unit.positions[p]).norm()));
    INFO("scale " << size);
    CHECK(worst < 1e-4);
  }
}
