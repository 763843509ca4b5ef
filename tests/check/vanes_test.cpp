// The vane checker against brute force: on random clusters of triangles from several feathers, with
// planted pairs just inside and just outside the thickness (parallel, tilted, coplanar, slivers), the
// grid and the plane filter find exactly the intersecting and touching pairs that testing every pair
// of triangles with CGAL finds.
#include <catch2/catch.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/intersections.h>
#include <CGAL/squared_distance_3.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <vector>

#include "check/vanes.h"

using namespace plume;

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;

struct Coat {
  std::vector<Eigen::Vector3f> positions;
  std::vector<Eigen::Vector3i> triangles;
  std::vector<uint64_t> feathers;
  void add(const Eigen::Vector3f &a, const Eigen::Vector3f &b, const Eigen::Vector3f &c, uint64_t feather) {
    const int i = int(positions.size());
    positions.insert(positions.end(), {a, b, c});
    triangles.emplace_back(i, i + 1, i + 2);
    feathers.push_back(feather);
  }
};

Kernel::Triangle_3 cgal(const Coat &coat, size_t t) {
  const auto p = [&](int k) {
    const Eigen::Vector3f &v = coat.positions[size_t(coat.triangles[t][k])];
    return Kernel::Point_3(v.x(), v.y(), v.z());
  };
  return {p(0), p(1), p(2)};
}

/// A random coat: feathers whose bases lie far out (so their clusters are outside the root discs),
/// each with triangles in one unit box, and pairs planted at `eps` times 1 +- 2% (parallel, tilted,
/// coplanar, slivers).
Coat random_coat(uint32_t seed, float eps) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  const auto point = [&] { return Eigen::Vector3f(unit(rng), unit(rng), unit(rng)); };
  Coat coat;
  const int feathers = 4 + int(rng() % 6);
  for (int f = 0; f < feathers; ++f) {
    // The base: the first triangle's first vertex, 20 units out.
    const Eigen::Vector3f out = 20.0f * Eigen::Vector3f(std::cos(float(f)), std::sin(float(f)), 0.3f);
    coat.add(out, out + Eigen::Vector3f(0.01f, 0, 0), out + Eigen::Vector3f(0, 0.01f, 0), uint64_t(f));
    const int count = 3 + int(rng() % 6);
    for (int t = 0; t < count; ++t) {
      const Eigen::Vector3f a = point(), b = a + 0.3f * (point() - Eigen::Vector3f::Constant(0.5f)),
                            c = a + 0.3f * (point() - Eigen::Vector3f::Constant(0.5f));
      coat.add(a, b, c, uint64_t(f));
      if (f == 0) continue;
      // Planted against the previous feather: a copy of this triangle moved off its plane by eps
      // times 1 +- 2%, turned a little, or a sliver, or coplanar and shifted.
      const Eigen::Vector3f n = (b - a).cross(c - a).normalized();
      const float scale = eps * (unit(rng) < 0.5f ? 0.98f : 1.02f);
      switch (rng() % 4) {
        case 0:
          coat.add(a + scale * n, b + scale * n, c + scale * n, uint64_t(f - 1));
          break;
        case 1: {
          const Eigen::Vector3f lift = scale * n;
          coat.add(a + lift, b + lift + 0.5f * eps * n, c + lift + 2.0f * eps * n, uint64_t(f - 1));
          break;
        }
        case 2: {
          // A sliver: its third corner almost on the line of the first two.
          const Eigen::Vector3f m = 0.5f * (a + b) + 1e-5f * (c - a) + scale * n;
          coat.add(a + scale * n, b + scale * n, m, uint64_t(f - 1));
          break;
        }
        default: {
          const Eigen::Vector3f shift = 0.1f * (b - a);
          coat.add(a + shift, b + shift, c + shift, uint64_t(f - 1));
        }
      }
    }
  }
  // Feathers' triangles must be consecutive: sort by feather, stably (the base stays first).
  std::vector<size_t> order(coat.triangles.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](size_t x, size_t y) { return coat.feathers[x] < coat.feathers[y]; });
  Coat sorted;
  for (const size_t t : order)
    sorted.add(coat.positions[size_t(coat.triangles[t][0])], coat.positions[size_t(coat.triangles[t][1])],
               coat.positions[size_t(coat.triangles[t][2])], coat.feathers[t]);
  return sorted;
}

}  // namespace

TEST_CASE("the vane checker finds what testing every pair finds, on random coats with planted near-touches",
          "[check]") {
  int64_t intersecting = 0, touching = 0;
  for (uint32_t seed = 1; seed <= 60; ++seed) {
    INFO("seed " << seed);
    const float eps = seed % 3 == 0 ? 1e-4f : 1e-2f;
    const Coat coat = random_coat(seed, eps);
    // The thickness option is relative to the median extent: chosen so that it comes to eps.
    check::VaneCheckOptions options;
    options.thickness = 1.0;
    const double median = check::check_vanes(coat.positions, coat.triangles, coat.feathers, options).median_extent;
    options.thickness = double(eps) / median;
    const check::VaneCheckReport report = check::check_vanes(coat.positions, coat.triangles, coat.feathers, options);
    REQUIRE(report.thickness == Approx(eps));
    // Brute force: every pair of triangles of two feathers, both outside the root discs.
    std::vector<Eigen::Vector3f> bases;
    std::vector<double> extents;
    std::vector<size_t> feather_index(coat.triangles.size());
    for (size_t t = 0; t < coat.triangles.size(); ++t) {
      if (t == 0 || coat.feathers[t] != coat.feathers[t - 1]) {
        bases.push_back(coat.positions[size_t(coat.triangles[t][0])]);
        extents.push_back(0.0);
      }
      feather_index[t] = bases.size() - 1;
      for (int k = 0; k < 3; ++k)
        extents.back() = std::max(extents.back(), double((coat.positions[size_t(coat.triangles[t][k])] - bases.back()).norm()));
    }
    const auto in_disc = [&](size_t t) {
      for (int k = 0; k < 3; ++k)
        if ((coat.positions[size_t(coat.triangles[t][k])] - bases[feather_index[t]]).norm() >
            options.root_disc * extents[feather_index[t]])
          return false;
      return true;
    };
    int64_t meet = 0, near = 0;
    std::set<std::pair<uint64_t, uint64_t>> pairs;
    for (size_t i = 0; i < coat.triangles.size(); ++i)
      for (size_t j = i + 1; j < coat.triangles.size(); ++j) {
        if (coat.feathers[i] == coat.feathers[j] || in_disc(i) || in_disc(j)) continue;
        const Kernel::Triangle_3 a = cgal(coat, i), b = cgal(coat, j);
        const bool hit = CGAL::do_intersect(a, b);
        const bool close = !hit && CGAL::to_double(CGAL::squared_distance(a, b)) <= double(report.thickness) * report.thickness;
        meet += hit ? 1 : 0;
        near += close ? 1 : 0;
        if (hit || close) pairs.emplace(std::min(coat.feathers[i], coat.feathers[j]), std::max(coat.feathers[i], coat.feathers[j]));
      }
    CHECK(report.intersecting_triangle_pairs == meet);
    CHECK(report.touching_triangle_pairs == near);
    CHECK(report.feather_pairs == int64_t(pairs.size()));
    intersecting += meet;
    touching += near;
  }
  // The planted pairs make both kinds common.
  CHECK(intersecting > 100);
  CHECK(touching > 100);
}
