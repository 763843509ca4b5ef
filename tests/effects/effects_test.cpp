// The effects stack: amount 0 is a no-op, results are deterministic and rigid, each effect does
// what its keys say, and nothing ends inside the skin.
#include <omp.h>

#include <catch2/catch.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <thread>

#include "effects/effects_fixtures.h"
#include "groom/groom_scene.h"
#include "groom/error.h"
#include "effects/effects.h"
#include "interp/interpolate.h"
#include "effects/noise.h"
#include "skin/skin_grid.h"

using namespace plume;
using plume::effects::EffectStack;

namespace {

EffectDesc effect(EffectType type, float amount, uint64_t seed = 7) {
  EffectDesc d;
  d.type = type;
  d.amount = amount;
  d.seed = seed;
  return d;
}

/// Every effect type, each with strong non-default settings, scaled by `amount`.
std::vector<EffectDesc> full_stack(float amount) {
  EffectDesc large = effect(EffectType::clump, amount, 1);
  large.clump_radius = 0.35f;
  large.ramp = Ramp::linear(0.0f, 1.0f);
  large.clump_twist = 0.3f;
  large.stray_fraction = 0.1f;
  EffectDesc small = effect(EffectType::clump, amount * 0.5f, 2);
  small.clump_radius = 0.12f;
  small.ramp = Ramp::linear(0.0f, 1.0f);
  EffectDesc tension = effect(EffectType::tension, amount * 0.3f, 3);
  tension.ramp = Ramp::linear(0.0f, 1.0f);
  EffectDesc length = effect(EffectType::length, amount, 4);
  length.length_variation = 0.2f;
  length.max_length = 0.55f;
  EffectDesc wave = effect(EffectType::wave, amount, 5);
  wave.frequency = 3.0f;
  wave.amplitude = 0.04f;
  wave.ramp = Ramp::linear(0.0f, 1.0f);
  EffectDesc frizz = effect(EffectType::frizz, amount, 6);
  frizz.frequency = 25.0f;
  frizz.amplitude = 0.01f;
  frizz.fraction = 0.3f;
  EffectDesc curl = effect(EffectType::curl, amount, 8);
  curl.curl_radius = 0.02f;
  curl.turns_per_unit = 6.0f;
  curl.ramp = Ramp::linear(0.2f, 1.0f);
  return {large, small, tension, length, wave, frizz, curl};
}

/// A sphere emitter (radius 1) with roots, guides and radial, slightly bent strands.
struct SphereScene {
  Mesh mesh = test::make_sphere(1.0f, 24, 48);
  MeshQuery query{mesh};
  Roots roots = scatter_roots(mesh, 800, 3);
  Guides guides = test::make_guides(mesh, query, 40, 0.5f, 0.3f);
  std::vector<int32_t> nearest = test::nearest_guides(mesh, roots, guides);
  StrandSet strands = test::grow_straight(mesh, roots, 0.5f, 16, 0.3f);
};

/// A plane emitter (side 2, groups "left" / "right") with straight strands along +y.
struct PlaneScene {
  Mesh mesh = test::make_plane(2.0f, 20);
  MeshQuery query{mesh};
  Roots roots = scatter_roots(mesh, 2000, 5);
  Guides guides = test::make_guides(mesh, query, 30, 0.5f, 0.0f);
  std::vector<int32_t> nearest = test::nearest_guides(mesh, roots, guides);
  StrandSet strands = test::grow_straight(mesh, roots, 0.5f, 12);
};

StrandSet run(const std::vector<EffectDesc> &effects, const Mesh &mesh, const MeshQuery &query, const Roots &roots,
              const Guides &guides, const std::vector<int32_t> &nearest, const StrandSet &guides_now,
              StrandSet strands, float margin = 0.005f) {
  const EffectStack stack(effects, mesh, roots, guides, nearest);
  stack.apply(mesh, query, guides_now, margin, strands);
  return strands;
}

StrandSet run(const std::vector<EffectDesc> &effects, const SphereScene &s) {
  return run(effects, s.mesh, s.query, s.roots, s.guides, s.nearest, s.guides.strands, s.strands);
}
StrandSet run(const std::vector<EffectDesc> &effects, const PlaneScene &s) {
  return run(effects, s.mesh, s.query, s.roots, s.guides, s.nearest, s.guides.strands, s.strands);
}

bool bit_identical(const StrandSet &a, const StrandSet &b) {
  return a.offsets == b.offsets && a.ids == b.ids &&
         std::equal(a.positions.begin(), a.positions.end(), b.positions.begin(), b.positions.end(),
                    [](const Eigen::Vector3f &p, const Eigen::Vector3f &q) {
                      return p.x() == q.x() && p.y() == q.y() && p.z() == q.z();
                    });
}

size_t changed_strands(const StrandSet &a, const StrandSet &b) {
  size_t changed = 0;
  for (size_t i = 0; i < a.strand_count(); ++i) {
    const auto pa = a.points(i), pb = b.points(i);
    if (!std::equal(pa.begin(), pa.end(), pb.begin())) ++changed;
  }
  return changed;
}

std::filesystem::path temp_file(const std::string &name, const std::string &text) {
  const std::filesystem::path path = std::filesystem::temp_directory_path() / ("plume_effects_" + name);
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("every effect at amount 0 leaves strands bit-identical, and at amount > 0 changes them", "[effects]") {
  const SphereScene s;
  const std::vector<EffectDesc> zero = full_stack(0.0f), strong = full_stack(1.0f);
  for (size_t e = 0; e < zero.size(); ++e) {
    INFO("effect " << e);
    CHECK(bit_identical(run({zero[e]}, s), s.strands));
    CHECK(changed_strands(run({strong[e]}, s), s.strands) > s.strands.strand_count() / 5);
  }
  CHECK(bit_identical(run(zero, s), s.strands));
}

TEST_CASE("the same groom gives identical strands in two runs, for 1 and 2 threads, and per frame alone",
          "[effects]") {
  const SphereScene s;
  const std::vector<EffectDesc> effects = full_stack(1.0f);
  const int threads = omp_get_max_threads();
  omp_set_num_threads(1);
  const StrandSet one = run(effects, s);
  omp_set_num_threads(2);
  const StrandSet two = run(effects, s);
  const StrandSet again = run(effects, s);
  omp_set_num_threads(threads);
  CHECK(bit_identical(one, two));
  CHECK(bit_identical(two, again));

  // One stack, frames A, B, A: frame A regrown after B is the same as A regrown first.
  const EffectStack stack(effects, s.mesh, s.roots, s.guides, s.nearest);
  const Eigen::Matrix3f rotation = Eigen::AngleAxisf(0.4f, Eigen::Vector3f(1, 2, 3).normalized()).toRotationMatrix();
  const Mesh mesh_b = test::moved(s.mesh, rotation, Eigen::Vector3f(0.2f, 0.1f, 0.0f));
  const MeshQuery query_b(mesh_b);
  const StrandSet guides_b = test::moved(s.guides.strands, rotation, Eigen::Vector3f(0.2f, 0.1f, 0.0f));
  const StrandSet strands_b = test::moved(s.strands, rotation, Eigen::Vector3f(0.2f, 0.1f, 0.0f));
  StrandSet a1 = s.strands, b = strands_b, a2 = s.strands;
  stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, a1);
  stack.apply(mesh_b, query_b, guides_b, 0.005f, b);
  stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, a2);
  CHECK(bit_identical(a1, a2));
  CHECK(bit_identical(a1, one));

  // Frames A and B applied at the same time on the one stack (which keeps a buffer from frame to
  // frame) give what they give one after the other.
  for (int attempt = 0; attempt < 4; ++attempt) {
    StrandSet a3 = s.strands, b2 = strands_b;
    std::thread other([&] { stack.apply(mesh_b, query_b, guides_b, 0.005f, b2); });
    stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, a3);
    other.join();
    CHECK(bit_identical(a3, a1));
    CHECK(bit_identical(b2, b));
  }
}

TEST_CASE("a rigid motion of the emitter moves the effected strands rigidly (within 1e-5 of length)", "[effects]") {
  const SphereScene s;
  const std::vector<EffectDesc> effects = full_stack(1.0f);
  const EffectStack stack(effects, s.mesh, s.roots, s.guides, s.nearest);
  StrandSet rest = s.strands;
  stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, rest);

  const Eigen::Matrix3f rotation =
      Eigen::AngleAxisf(1.1f, Eigen::Vector3f(0.3f, -1.0f, 0.5f).normalized()).toRotationMatrix();
  const Eigen::Vector3f translation(0.7f, -1.3f, 2.1f);
  const Mesh posed = test::moved(s.mesh, rotation, translation);
  const MeshQuery posed_query(posed);
  StrandSet moved = test::moved(s.strands, rotation, translation);
  stack.apply(posed, posed_query, test::moved(s.guides.strands, rotation, translation), 0.005f, moved);

  const StrandSet expected = test::moved(rest, rotation, translation);
  double worst = 0.0;
  for (size_t i = 0; i < expected.strand_count(); ++i) {
    const double length = s.strands.length(i);
    for (int64_t j = expected.offsets[i]; j < expected.offsets[i + 1]; ++j)
      worst = std::max(worst, double((expected.positions[j] - moved.positions[j]).norm()) / length);
  }
  CHECK(worst < 1e-5);
  CHECK(changed_strands(rest, s.strands) > s.strands.strand_count() / 2);
}

TEST_CASE("clumped strands end closer to their clump centre by the requested amount", "[effects]") {
  const PlaneScene s;
  for (const auto centres : {EffectDesc::ClumpCenters::poisson, EffectDesc::ClumpCenters::per_guide}) {
    EffectDesc clump = effect(EffectType::clump, 0.5f);
    clump.clump_centers = centres;
    clump.clump_radius = 0.2f;
    clump.ramp = Ramp::linear(0.0f, 1.0f);  // 0.5 at the tip, 0.25 half way
    const EffectStack stack({clump}, s.mesh, s.roots, s.guides, s.nearest);
    StrandSet out = s.strands;
    stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, out);
    const std::vector<int32_t> &centre = stack.clump_centres(0);
    size_t members = 0;
    for (size_t i = 0; i < out.strand_count(); ++i) {
      const int32_t c = centre[i];
      REQUIRE(c >= 0);
      const int64_t n = out.points_in(i);
      if (c == int32_t(i)) {
        CHECK(std::equal(out.points(i).begin(), out.points(i).end(), s.strands.points(i).begin()));
        continue;
      }
      ++members;
      const float before_tip = (s.strands.points(i)[n - 1] - s.strands.points(c)[n - 1]).norm();
      const float after_tip = (out.points(i)[n - 1] - out.points(c)[n - 1]).norm();
      CHECK(after_tip == Approx(0.5f * before_tip).margin(1e-5));
      const int64_t mid = (n - 1) / 2;
      const float w_mid = 0.5f * float(mid) / float(n - 1);
      const float before_mid = (s.strands.points(i)[mid] - s.strands.points(c)[mid]).norm();
      const float after_mid = (out.points(i)[mid] - out.points(c)[mid]).norm();
      CHECK(after_mid == Approx((1.0f - w_mid) * before_mid).margin(1e-5));
      if (centres == EffectDesc::ClumpCenters::poisson) CHECK(before_tip <= 0.2f + 1e-5f);
    }
    CHECK(members > out.strand_count() / 2);
  }
}

TEST_CASE("two clump levels compose: small clumps pull toward their centre as the large clumps left it",
          "[effects]") {
  const PlaneScene s;
  EffectDesc large = effect(EffectType::clump, 0.6f, 1);
  large.clump_radius = 0.4f;
  large.ramp = Ramp::linear(0.0f, 1.0f);
  EffectDesc small = effect(EffectType::clump, 0.8f, 2);
  small.clump_radius = 0.1f;
  const StrandSet after_large = run({large}, s);
  const EffectStack stack({large, small}, s.mesh, s.roots, s.guides, s.nearest);
  StrandSet both = s.strands;
  stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, both);
  const std::vector<int32_t> &small_centre = stack.clump_centres(1);
  size_t checked = 0;
  for (size_t i = 0; i < both.strand_count(); ++i) {
    const int32_t c = small_centre[i];
    if (c == int32_t(i)) continue;
    const int64_t tip = both.points_in(i) - 1;
    const float before = (after_large.points(i)[tip] - after_large.points(c)[tip]).norm();
    const float after = (both.points(i)[tip] - both.points(c)[tip]).norm();
    CHECK(after == Approx(0.2f * before).margin(1e-5));
    ++checked;
  }
  CHECK(checked > both.strand_count() / 2);
  // More than one small clump per large clump: the levels are really different.
  const auto count_centres = [](const std::vector<int32_t> &c) {
    size_t k = 0;
    for (size_t i = 0; i < c.size(); ++i) k += c[i] == int32_t(i);
    return k;
  };
  CHECK(count_centres(small_centre) > 4 * count_centres(stack.clump_centres(0)));
}

TEST_CASE("clump twist turns members about the centre by the requested angle; strays are left out", "[effects]") {
  const PlaneScene s;
  EffectDesc clump = effect(EffectType::clump, 1.0f);
  clump.clump_radius = 0.2f;
  clump.ramp = Ramp::linear(0.0f, 0.0f);  // no pull: only the twist
  clump.clump_twist = 0.25f;              // a quarter turn at the tip
  clump.stray_fraction = 0.3f;
  const EffectStack stack({clump}, s.mesh, s.roots, s.guides, s.nearest);
  StrandSet out = s.strands;
  stack.apply(s.mesh, s.query, s.guides.strands, 0.005f, out);
  size_t members = 0, strays = 0;
  for (size_t i = 0; i < out.strand_count(); ++i) {
    const int32_t c = stack.clump_centres(0)[i];
    if (c == int32_t(i)) continue;
    ++members;
    const int64_t tip = out.points_in(i) - 1;
    const Eigen::Vector3f before = s.strands.points(i)[tip] - s.strands.points(c)[tip];
    const Eigen::Vector3f after = out.points(i)[tip] - out.points(c)[tip];
    if (before == after) {
      ++strays;
      continue;
    }
    // Straight strands along +y: the offset turns a quarter turn counter-clockwise about +y.
    CHECK(after.norm() == Approx(before.norm()).margin(1e-5));
    CHECK(after.dot(before) == Approx(0.0f).margin(1e-5));
    CHECK(Eigen::Vector3f::UnitY().dot(before.cross(after)) > 0.0f);
  }
  CHECK(double(strays) / double(members) == Approx(0.3).margin(0.04));
}

TEST_CASE("tension at full strength turns a strand into its guide carried to its root", "[effects]") {
  PlaneScene s;
  // Bent guides of length 0.5; strands straight, length 0.5.
  s.guides = test::make_guides(s.mesh, s.query, 30, 0.5f, 0.6f);
  s.nearest = test::nearest_guides(s.mesh, s.roots, s.guides);
  EffectDesc tension = effect(EffectType::tension, 1.0f);
  const StrandSet out = run({tension}, s);
  double worst = 0.0;
  for (size_t i = 0; i < out.strand_count(); ++i) {
    const auto guide = s.guides.strands.points(size_t(s.nearest[i]));
    const double scale = s.strands.length(i) / s.guides.strands.length(size_t(s.nearest[i]));
    const auto pts = out.points(i);
    // Guides have 9 points and strands 12: the tips coincide exactly.
    worst = std::max(worst, double((pts.back() - (pts[0] + (guide.back() - guide[0]) * float(scale))).norm()));
  }
  CHECK(worst < 1e-5);
  // Half strength: the tip moves half way.
  const StrandSet half = run({effect(EffectType::tension, 0.5f)}, s);
  for (size_t i = 0; i < half.strand_count(); i += 37) {
    const Eigen::Vector3f expected = 0.5f * (s.strands.points(i).back() + out.points(i).back());
    CHECK((half.points(i).back() - expected).norm() < 1e-5);
  }
}

TEST_CASE("strands with another point count than the first get the same effects as when all share it",
          "[effects]") {
  // The stack tabulates ramps and guide shapes for the first strand's point count; the others
  // take the direct path, which must give the same bits.
  PlaneScene s;
  s.guides = test::make_guides(s.mesh, s.query, 30, 0.5f, 0.6f);
  s.nearest = test::nearest_guides(s.mesh, s.roots, s.guides);
  EffectDesc tension = effect(EffectType::tension, 0.7f), wave = effect(EffectType::wave, 1.0f);
  EffectDesc curl = effect(EffectType::curl, 1.0f), length = effect(EffectType::length, 1.0f);
  for (EffectDesc *d : {&tension, &wave, &curl, &length}) d->ramp = Ramp{{0.0f, 0.3f, 1.0f}, {0.0f, 0.8f, 0.5f}};
  const std::vector<EffectDesc> stack = {tension, wave, curl, length};
  StrandSet mixed;
  for (size_t i = 0; i < s.strands.strand_count(); ++i) {
    const auto pts = s.strands.points(i);
    std::vector<Eigen::Vector3f> points(pts.begin(), pts.end());
    if (i == 0) {
      points.resize(20);
      for (int j = 0; j < 20; ++j) points[size_t(j)] = pts[0] + (pts.back() - pts[0]) * (float(j) / 19.0f);
    }
    mixed.append(points, s.strands.ids[i]);
  }
  const StrandSet all_same = run(stack, s);
  const StrandSet with_other =
      run(stack, s.mesh, s.query, s.roots, s.guides, s.nearest, s.guides.strands, mixed);
  int differing = 0;
  for (size_t i = 1; i < all_same.strand_count(); ++i)
    for (int64_t j = 0; j < all_same.points_in(i); ++j)
      differing += all_same.points(i)[size_t(j)] != with_other.points(i)[size_t(j)];
  CHECK(differing == 0);
  CHECK(!bit_identical(all_same, s.strands));
}

TEST_CASE("the measured length distribution matches the requested one (uniform and normal)", "[effects]") {
  const PlaneScene s;  // straight strands of length 0.5: lengths are exact after resampling
  const double base = 0.5;
  for (const auto dist : {EffectDesc::LengthDistribution::uniform, EffectDesc::LengthDistribution::normal}) {
    EffectDesc length = effect(EffectType::length, 1.0f);
    length.length_distribution = dist;
    length.length_variation = 0.2f;
    const StrandSet out = run({length}, s);
    std::vector<double> ratio(out.strand_count());
    for (size_t i = 0; i < out.strand_count(); ++i) {
      ratio[i] = out.length(i) / base;
      CHECK(out.points_in(i) == s.strands.points_in(i));
    }
    std::sort(ratio.begin(), ratio.end());
    const double n = double(ratio.size());
    double mean = 0.0, var = 0.0;
    for (double r : ratio) mean += r / n;
    for (double r : ratio) var += (r - mean) * (r - mean) / n;
    // Kolmogorov-Smirnov statistic against the requested law; 1.63 / sqrt(n) is its 1% critical value.
    double ks = 0.0;
    for (size_t k = 0; k < ratio.size(); ++k) {
      const double x = ratio[k];
      const double cdf = dist == EffectDesc::LengthDistribution::uniform
                             ? std::clamp((x - 0.8) / 0.4, 0.0, 1.0)
                             : 0.5 * std::erfc(-(x - 1.0) / (0.2 * std::sqrt(2.0)));
      ks = std::max({ks, std::abs(cdf - double(k) / n), std::abs(cdf - double(k + 1) / n)});
    }
    INFO((dist == EffectDesc::LengthDistribution::uniform ? "uniform" : "normal"));
    CHECK(mean == Approx(1.0).margin(0.01));
    const double expected_sd = dist == EffectDesc::LengthDistribution::uniform ? 0.4 / std::sqrt(12.0) : 0.2;
    CHECK(std::sqrt(var) == Approx(expected_sd).epsilon(0.05));
    CHECK(ks < 1.63 / std::sqrt(n));
  }
}

TEST_CASE("length: max_length and a cut plane bound every strand, keeping the point count", "[effects]") {
  const PlaneScene s;
  EffectDesc cap = effect(EffectType::length, 1.0f);
  cap.max_length = 0.3f;
  const StrandSet capped = run({cap}, s);
  for (size_t i = 0; i < capped.strand_count(); ++i) CHECK(capped.length(i) == Approx(0.3).margin(1e-5));

  EffectDesc plane = effect(EffectType::length, 1.0f);
  plane.cut_plane = true;
  plane.cut_point = Eigen::Vector3f(0.0f, 0.35f, 0.0f);
  plane.cut_normal = Eigen::Vector3f(1.0f, 4.0f, 0.0f).normalized();  // slanted: y = 0.35 - x / 4
  const StrandSet cut = run({plane}, s);
  size_t shortened = 0;
  for (size_t i = 0; i < cut.strand_count(); ++i) {
    for (const Eigen::Vector3f &p : cut.points(i)) CHECK((p - plane.cut_point).dot(plane.cut_normal) < 1e-5f);
    shortened += cut.length(i) < 0.499;
  }
  CHECK(shortened > cut.strand_count() / 2);
}

TEST_CASE("waves and frizz displace perpendicular to the strand, bounded by amplitude x ramp", "[effects]") {
  const PlaneScene s;  // strands along +y
  EffectDesc wave = effect(EffectType::wave, 1.0f);
  wave.frequency = 4.0f;
  wave.amplitude = 0.05f;
  wave.ramp = Ramp::linear(0.0f, 1.0f);
  EffectDesc frizz = wave;
  frizz.type = EffectType::frizz;
  frizz.frequency = 30.0f;
  frizz.fraction = 0.25f;
  for (const EffectDesc &d : {wave, frizz}) {
    const StrandSet out = run({d}, s);
    float largest = 0.0f;
    for (size_t i = 0; i < out.strand_count(); ++i) {
      const int64_t n = out.points_in(i);
      for (int64_t j = 0; j < n; ++j) {
        const Eigen::Vector3f disp = out.points(i)[j] - s.strands.points(i)[j];
        CHECK(std::abs(disp.y()) < 1e-6f);
        CHECK(disp.norm() <= d.amplitude * float(j) / float(n - 1) * std::sqrt(3.0f) + 1e-6f);
        largest = std::max(largest, disp.norm());
      }
    }
    CHECK(largest > 0.3f * d.amplitude);
    const double share = double(changed_strands(out, s.strands)) / double(out.strand_count());
    CHECK(share == Approx(d.fraction).margin(0.04));
  }
}

TEST_CASE("waves follow the rest space: neighbouring strands wave together, frizz does not", "[effects]") {
  const PlaneScene s;
  EffectDesc wave = effect(EffectType::wave, 1.0f);
  wave.frequency = 1.0f;
  wave.amplitude = 0.05f;
  EffectDesc frizz = wave;
  frizz.type = EffectType::frizz;
  // Correlation of tip displacements between each strand and the strand whose root is nearest.
  auto neighbour_correlation = [&](const StrandSet &out) {
    double dot = 0.0, norm = 0.0;
    for (size_t i = 0; i < out.strand_count(); i += 7) {
      size_t best = i;
      float best_d = INFINITY;
      for (size_t k = 0; k < out.strand_count(); ++k) {
        const float d = (s.strands.points(k)[0] - s.strands.points(i)[0]).norm();
        if (k != i && d < best_d) best_d = d, best = k;
      }
      const Eigen::Vector3f a = out.points(i).back() - s.strands.points(i).back();
      const Eigen::Vector3f b = out.points(best).back() - s.strands.points(best).back();
      dot += a.dot(b);
      norm += 0.5 * (a.squaredNorm() + b.squaredNorm());
    }
    return dot / norm;
  };
  CHECK(neighbour_correlation(run({wave}, s)) > 0.9);
  CHECK(std::abs(neighbour_correlation(run({frizz}, s))) < 0.3);
}

TEST_CASE("curl turns a straight strand into a helix of the requested radius and pitch", "[effects]") {
  const PlaneScene s;
  EffectDesc curl = effect(EffectType::curl, 1.0f);
  curl.curl_radius = 0.03f;
  curl.turns_per_unit = 2.0f;  // one turn per 0.5: a full turn along the strand
  const StrandSet out = run({curl}, s);
  for (size_t i = 0; i < out.strand_count(); i += 13) {
    const int64_t n = out.points_in(i);
    for (int64_t j = 1; j < n; ++j) {
      const Eigen::Vector3f disp = out.points(i)[j] - s.strands.points(i)[j];
      CHECK(disp.norm() == Approx(0.03f).margin(1e-5));
      CHECK(std::abs(disp.y()) < 1e-6f);
    }
    // Consecutive points turn by 2 pi * turns * segment length about +y.
    const Eigen::Vector3f d1 = out.points(i)[1] - s.strands.points(i)[1];
    const Eigen::Vector3f d2 = out.points(i)[2] - s.strands.points(i)[2];
    const float angle = std::atan2(Eigen::Vector3f::UnitY().dot(d1.cross(d2)), d1.dot(d2));
    CHECK(std::abs(angle) == Approx(2.0 * M_PI * 2.0 * 0.5 / 11.0).margin(1e-3));
  }
}

TEST_CASE("face groups and vertex maps limit and scale an effect", "[effects]") {
  const PlaneScene s;
  EffectDesc wave = effect(EffectType::wave, 1.0f);
  wave.amplitude = 0.05f;
  wave.frequency = 2.0f;
  wave.groups = {"right"};
  const StrandSet out = run({wave}, s);
  size_t right_changed = 0, right = 0;
  for (size_t i = 0; i < out.strand_count(); ++i) {
    const bool in_right = s.mesh.triangle_groups[s.roots.points[i].triangle] == 1;
    const bool changed = !std::equal(out.points(i).begin(), out.points(i).end(), s.strands.points(i).begin());
    if (!in_right) CHECK_FALSE(changed);
    right += in_right;
    right_changed += in_right && changed;
  }
  CHECK(right_changed == right);

  // A map of 0 on the left edge rising to 1 on the right edge, on a curl (displacement = radius x map).
  std::string text = "# x-ramp\n";
  for (const Eigen::Vector3f &p : s.mesh.positions) text += std::to_string((p.x() + 1.0f) * 0.5f) + "\n";
  EffectDesc curl = effect(EffectType::curl, 1.0f);
  curl.curl_radius = 0.04f;
  curl.turns_per_unit = 3.0f;
  curl.vertex_map_path = temp_file("ramp.txt", text).string();
  const StrandSet scaled = run({curl}, s);
  for (size_t i = 0; i < scaled.strand_count(); i += 11) {
    const float x = s.strands.points(i)[0].x();
    const float disp = (scaled.points(i).back() - s.strands.points(i).back()).norm();
    CHECK(disp == Approx(0.04f * (x + 1.0f) * 0.5f).margin(2e-4));
  }

  wave.groups = {"nose"};
  wave.groups_loc = FileLoc{"head.groom.yaml", 9, 13};
  wave.groups_key = "effects[1].groups";
  CHECK_THROWS_WITH(EffectStack({wave}, s.mesh, s.roots, s.guides, s.nearest),
                    "head.groom.yaml:9:13: effects[1].groups: no face group \"nose\" in the emitter (groups: left, right)");
}

TEST_CASE("a bad vertex map is an input error naming the file and line", "[effects]") {
  const PlaneScene s;
  EffectDesc curl = effect(EffectType::curl, 1.0f);
  curl.curl_radius = 0.01f;
  std::string text;
  for (size_t v = 0; v < s.mesh.vertex_count(); ++v) text += v == 5 ? "0.5x\n" : "1\n";
  curl.vertex_map_path = temp_file("bad.txt", text).string();
  CHECK_THROWS_WITH(EffectStack({curl}, s.mesh, s.roots, s.guides, s.nearest),
                    Catch::Contains(curl.vertex_map_path + ":6:1") && Catch::Contains("0.5x"));
  curl.vertex_map_path = temp_file("short.txt", "1\n1\n1\n").string();
  CHECK_THROWS_WITH(EffectStack({curl}, s.mesh, s.roots, s.guides, s.nearest),
                    Catch::Contains(curl.vertex_map_path) &&
                        Catch::Contains("expected " + std::to_string(s.mesh.vertex_count()) + " values") &&
                        Catch::Contains("got 3"));
  curl.vertex_map_path = (std::filesystem::temp_directory_path() / "plume_effects_missing.txt").string();
  CHECK_THROWS_AS(EffectStack({curl}, s.mesh, s.roots, s.guides, s.nearest), InputError);
}

TEST_CASE("a vertex map value outside [0, 1] is an input error naming the file and line", "[effects]") {
  // A value of 1e30 scaled a clump's twist and a curl's radius into non-finite points.
  const PlaneScene s;
  EffectDesc curl = effect(EffectType::curl, 1.0f);
  curl.curl_radius = 0.01f;
  for (const std::string value : {"1e30", "-0.5", "1.01"}) {
    std::string text;
    for (size_t v = 0; v < s.mesh.vertex_count(); ++v) text += v == 2 ? value + "\n" : "1\n";
    curl.vertex_map_path = temp_file("range.txt", text).string();
    CHECK_THROWS_WITH(EffectStack({curl}, s.mesh, s.roots, s.guides, s.nearest),
                      Catch::Contains(curl.vertex_map_path + ":3:1") &&
                          Catch::Contains("expected a number in [0, 1], got \"" + value + "\""));
  }
}

TEST_CASE("a curl of 1000 turns per unit on long strands gives finite points", "[effects]") {
  // Beyond about 1600 turns the helix angle left sin_cos4's accurate range, and far beyond it the
  // quadrant integer overflowed: the turn count is taken modulo one there.
  PlaneScene s;
  for (Eigen::Vector3f &p : s.strands.positions) p.y() *= 2e6f;  // strands ~1e6 units long: 1e9 turns
  EffectDesc curl = effect(EffectType::curl, 1.0f);
  curl.curl_radius = 0.1f;
  curl.turns_per_unit = 1000.0f;
  const StrandSet out = run({curl}, s);
  for (const Eigen::Vector3f &p : out.positions) REQUIRE(p.allFinite());
}

TEST_CASE("after the stack no strand point is inside the skin", "[effects]") {
  SphereScene s;
  // Strands lying close to the scalp (strong bend), then effects that throw them into it.
  s.strands = test::grow_straight(s.mesh, s.roots, 0.5f, 16, 1.5f);
  std::vector<EffectDesc> effects = full_stack(1.0f);
  effects[4].amplitude = 0.2f;  // wave
  effects[6].curl_radius = 0.1f;
  const float margin = 0.01f;
  const StrandSet out = run(effects, s.mesh, s.query, s.roots, s.guides, s.nearest, s.guides.strands, s.strands, margin);
  size_t inside_before_pushout = 0;
  for (size_t i = 0; i < out.strand_count(); ++i)
    for (int64_t j = 1; j < out.points_in(i); ++j) {
      const float d = s.query.signed_distance(out.points(i)[j]);
      CHECK(d >= 0.0f);
      // Points sitting on the margin band were pushed there (strands do not land on it by chance).
      inside_before_pushout += d < 1.5f * margin;
    }
  CHECK(inside_before_pushout > 100);
}

namespace {

/// What the stack's skin pass does with growth's clearances against checking every point.
struct SkinPassComparison {
  StrandSet with_bounds;     // the stack applied with the clearances
  size_t near_skin = 0;      // its points (roots aside) closer to the skin than `near` x the margin
  float largest_difference = 0.0f;  // the largest distance between a point with and without them
};

/// Applies `stack` to `grown` with and without `clearance` and compares; every point with them is
/// checked to be outside by the margin (to rounding).
SkinPassComparison compare_skin_pass(const EffectStack &stack, const MeshQuery &query, const StrandSet &guides,
                                     float margin, const StrandSet &grown, std::span<const float> clearance,
                                     float near) {
  SkinPassComparison r;
  r.with_bounds = grown;
  StrandSet without_bounds = grown;
  stack.apply(query.mesh(), query, guides, margin, r.with_bounds, clearance);
  stack.apply(query.mesh(), query, guides, margin, without_bounds);
  for (size_t i = 0; i < r.with_bounds.strand_count(); ++i)
    for (int64_t j = 1; j < r.with_bounds.points_in(i); ++j) {
      const float d = query.signed_distance(r.with_bounds.points(i)[j]);
      CHECK(d >= margin * (1.0f - 1e-3f));
      r.near_skin += d < near * margin;
      r.largest_difference =
          std::max(r.largest_difference, (r.with_bounds.points(i)[j] - without_bounds.points(i)[j]).norm());
    }
  return r;
}

}  // namespace

TEST_CASE("with growth's clearance the stack skips proven points and still ends out of the skin", "[effects]") {
  SphereScene s;
  InterpolationSettings settings;
  settings.skin_margin = 0.01f;
  const interp::Binding binding = interp::bind(s.mesh, s.guides, s.roots, settings);
  interp::GrowOptions options;
  options.points_per_strand = 16;
  StrandSet grown;
  std::vector<float> clearance;
  interp::grow(binding, s.mesh, s.query, s.roots, s.guides.strands, options, grown, &clearance);
  std::vector<EffectDesc> effects = full_stack(1.0f);
  effects[4].amplitude = 0.2f;  // wave
  effects[6].curl_radius = 0.1f;
  const EffectStack stack(effects, s.mesh, s.roots, s.guides, s.nearest);
  SkinPassComparison pass =
      compare_skin_pass(stack, s.query, s.guides.strands, settings.skin_margin, grown, clearance, 1.5f);
  StrandSet &with_bounds = pass.with_bounds;
  CHECK(pass.near_skin > 100);
  // The bounds only spare queries: the same points are pushed, to the same places.
  CHECK(pass.largest_difference <= 1e-5f);

  // One skin grid shared by growth and the stack, as the pipeline does, gives the same bits as each
  // building its own.
  const skin::SkinGrid grid(s.mesh, s.query);
  StrandSet shared;
  std::vector<float> shared_clearance;
  interp::grow(binding, s.mesh, s.query, s.roots, s.guides.strands, options, shared, &shared_clearance, &grid);
  CHECK(bit_identical(shared, grown));
  CHECK(shared_clearance == clearance);
  stack.apply(s.mesh, s.query, s.guides.strands, settings.skin_margin, shared, shared_clearance, &grid);
  CHECK(bit_identical(shared, with_bounds));
  CHECK_THROWS_AS(stack.apply(s.mesh, s.query, s.guides.strands, settings.skin_margin, with_bounds,
                              std::span<const float>(clearance.data(), 5)),
                  InternalError);
}

TEST_CASE("on strands combed down along the skin, the skin pass's proofs change nothing", "[effects]") {
  // Grown strands that hug the skin at the margin, which the stack moves a little: most points need
  // the skin pass, and its bounds (growth's clearances, the grown places it hands the guard, the
  // empty ball at the first point) must give exactly what checking every point gives.
  const Mesh mesh = test::make_sphere(1.0f, 32, 64);
  const MeshQuery query(mesh);
  const Guides guides = bind_guides(query, test::combed_guides(mesh, scatter_roots(mesh, 120, 11)), "combed");
  const Roots roots = scatter_roots(mesh, 3000, 3);
  InterpolationSettings settings;
  settings.skin_margin = 0.02f;  // a band the combed strands lie in
  const interp::Binding binding = interp::bind(mesh, guides, roots, settings);
  std::vector<int32_t> nearest(roots.size());
  for (size_t i = 0; i < roots.size(); ++i) nearest[i] = binding.guide_ids[i * size_t(binding.k)];
  interp::GrowOptions options;
  StrandSet grown;
  std::vector<float> clearance;
  interp::grow(binding, mesh, query, roots, guides.strands, options, grown, &clearance);
  const EffectStack stack(full_stack(1.0f), mesh, roots, guides, nearest);
  const SkinPassComparison pass =
      compare_skin_pass(stack, query, guides.strands, binding.skin_margin, grown, clearance, 2.0f);
  INFO("points within twice the margin: " << pass.near_skin);
  CHECK(pass.near_skin > 500);  // 725 of 93000 points (the margin a tenth of the guides' segment)
  CHECK(pass.largest_difference <= 1e-5f);
}

TEST_CASE("simplex noise is smooth, bounded and seeded", "[effects]") {
  const effects::SimplexNoise3 a(1), b(2);
  double differ = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const Eigen::Vector3f p(0.37f * float(k % 97) - 13.0f, 0.11f * float(k % 89), 0.53f * float(k % 83) - 20.0f);
    const Eigen::Vector3f v = a.vector_at(p);
    CHECK(v.cwiseAbs().maxCoeff() <= 1.0f);
    CHECK(v.x() == a.at(p));
    // Lipschitz: a step of 1e-3 changes the value by at most a few 1e-3 (the field is C1).
    CHECK(std::abs(a.at(p + Eigen::Vector3f(1e-3f, 0, 0)) - a.at(p)) < 1e-2f);
    differ += std::abs(a.at(p) - b.at(p));
  }
  CHECK(differ / 20000.0 > 0.1);
  // Four points at once (SIMD lanes) give the bits of one at a time, negative coordinates included.
  int mismatches = 0;
  for (int k = 0; k < 5000; k += 4) {
    skin::Float4 at[3], channels[3];
    for (int l = 0; l < 4; ++l) {
      at[0][l] = 0.731f * float(k + l) - 1500.0f;
      at[1][l] = -0.113f * float((k + l) % 71) + 3.0f;
      at[2][l] = 0.0371f * float((k + l) % 193) - 2.5f;
    }
    a.vector_at4(at, channels);
    for (int l = 0; l < 4; ++l) {
      const Eigen::Vector3f v = a.vector_at(Eigen::Vector3f(at[0][l], at[1][l], at[2][l]));
      for (int c = 0; c < 3; ++c) {
        const float lane = channels[c][l];
        mismatches += std::memcmp(&lane, &v[c], sizeof(float)) != 0;
      }
    }
  }
  CHECK(mismatches == 0);
}

TEST_CASE("on Sintel's open head, grooms/effects leaves no point behind the skin", "[effects]") {
  // The shipped effects groom at rest, every point but the roots measured with the signed distance
  // itself (no "reached through the skin" allowance): the head is open at the neck and around the
  // eyes, where the side of a point changes round an open edge with nothing crossed.
  const test::GroomScene scene(std::string(PLUME_SOURCE_DIR) + "/grooms/effects/effects.groom.yaml");
  const interp::Binding binding = interp::bind(scene.mesh, scene.guides, scene.roots, scene.groom.interpolation);
  std::vector<int32_t> nearest(scene.roots.size());
  for (size_t i = 0; i < scene.roots.size(); ++i) nearest[i] = binding.guide_ids[i * size_t(binding.k)];
  interp::GrowOptions options;
  options.points_per_strand = scene.groom.points_per_strand;
  StrandSet strands;
  std::vector<float> clearance;
  interp::grow(binding, scene.mesh, *scene.query, scene.roots, scene.guides.strands, options, strands, &clearance);
  const EffectStack stack(scene.groom.effects, scene.mesh, scene.roots, scene.guides, nearest);
  stack.apply(scene.mesh, *scene.query, scene.guides.strands, binding.skin_margin, strands, clearance);
  Eigen::Vector3f lo = scene.mesh.positions[0], hi = lo;
  for (const Eigen::Vector3f &p : scene.mesh.positions) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const float eps = 1e-5f * (hi - lo).norm();  // the checker's allowance for rounding
  const int64_t count = int64_t(strands.strand_count());
  int64_t behind = 0;
#pragma omp parallel for reduction(+ : behind) schedule(dynamic, 64)
  for (int64_t i = 0; i < count; ++i) {
    const auto pts = strands.points(size_t(i));
    for (size_t j = 1; j < pts.size(); ++j) behind += scene.query->signed_distance(pts[j]) < -eps;
  }
  CHECK(count == 20000);
  CHECK(behind == 0);
}
