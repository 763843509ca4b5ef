#include "groom/roots.h"

#include <algorithm>
#include <cmath>

#include "groom/error.h"

namespace plume {

namespace {

// Root j of triangle f arrives at "time" (j + u_fj) / area_f, u_fj in [0, 1) from a hash: each
// triangle is a jittered arrival process whose rate is its area. The N roots with the earliest
// arrivals are area-weighted, and the set for N is contained in the set for any larger N, so
// raising the count never moves an existing root.
double arrival(uint64_t seed, size_t triangle, int64_t j, double area) {
  const float u = hash_to_unit(hash_combine(hash_combine(seed, triangle), uint64_t(j)));
  return (double(j) + double(u)) / area;
}

// Number of arrivals of a triangle at or before time t (arrival is increasing in j).
int64_t arrivals_before(uint64_t seed, size_t triangle, double area, double t) {
  const int64_t upper = int64_t(std::floor(t * area)) + 1;  // j + u <= t*area  =>  j <= t*area
  int64_t n = std::max<int64_t>(upper - 1, 0);
  // The last candidate j = floor(t*area) arrives before t only if its jitter is small enough.
  if (upper - 1 >= 0 && arrival(seed, triangle, upper - 1, area) <= t) n = upper;
  return n;
}

}  // namespace

double masked_area(const Mesh &mesh, const std::vector<bool> &triangle_mask) {
  double total = 0.0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f)
    if (triangle_mask.empty() || triangle_mask[f]) total += mesh.triangle_area(f);
  return total;
}

Roots scatter_roots(const Mesh &mesh, int64_t count, uint64_t seed, const std::vector<bool> &triangle_mask,
                    const FileLoc &where) {
  Roots roots;
  if (count <= 0) return roots;
  const double total_area = masked_area(mesh, triangle_mask);
  // The message names the groom's roots settings when the caller gives them.
  auto fail = [&](const std::string &what) { throw InputError(where, "roots: " + what); };
  if (!(total_area > 0.0)) fail("the selected faces (roots.groups, roots.near_guides) have no area to scatter roots on");
  // A triangle too large for float arithmetic has an infinite area (the reader's coordinate bound
  // keeps a loaded mesh clear of this); its normalised area would be NaN and no arrival time
  // would ever be found.
  if (!std::isfinite(total_area)) fail("the selected faces have an infinite total area (coordinates too large)");

  std::vector<size_t> faces;
  std::vector<double> areas;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const double a = mesh.triangle_area(f);
    if ((triangle_mask.empty() || triangle_mask[f]) && a > 0.0) {
      faces.push_back(f);
      areas.push_back(a / total_area);  // normalised: the expected count by time t is ~t
    }
  }
  auto count_at = [&](double t) {
    int64_t n = 0;
    for (size_t i = 0; i < faces.size(); ++i) n += arrivals_before(seed, faces[i], areas[i], t);
    return n;
  };
  // Smallest time t with at least `count` arrivals, by bisection (count_at is monotonic in t).
  // The normalised areas sum to 1 and each triangle loses less than one arrival to rounding down,
  // so count_at(t) > t - #faces and t = count + #faces always suffices: the doubling stops below
  // twice that. Past it something is wrong with the areas; an error, never an endless loop.
  double lo = 0.0, hi = double(count) + 2.0;
  const double hi_limit = 2.0 * (double(count) + double(faces.size()) + 2.0);
  while (count_at(hi) < count) {
    if (!(hi <= hi_limit))
      fail("cannot place " + std::to_string(count) + " roots on the selected faces (their areas do not add up)");
    hi *= 2.0;
  }
  for (int iter = 0; iter < 100 && hi - lo > 1e-12 * hi; ++iter) {
    const double mid = 0.5 * (lo + hi);
    (count_at(mid) >= count ? hi : lo) = mid;
  }

  struct Candidate {
    double time;
    size_t face;
    int64_t j;
  };
  std::vector<Candidate> candidates;
  candidates.reserve(size_t(count) + 16);
  for (size_t i = 0; i < faces.size(); ++i) {
    const int64_t n = arrivals_before(seed, faces[i], areas[i], hi);
    for (int64_t j = 0; j < n; ++j) candidates.push_back({arrival(seed, faces[i], j, areas[i]), faces[i], j});
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate &a, const Candidate &b) {
    return a.time != b.time ? a.time < b.time : (a.face != b.face ? a.face < b.face : a.j < b.j);
  });
  candidates.resize(std::min<size_t>(candidates.size(), size_t(count)));
  // Keep a spatially coherent order (by triangle, then index) rather than arrival order.
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate &a, const Candidate &b) { return a.face != b.face ? a.face < b.face : a.j < b.j; });

  roots.points.reserve(candidates.size());
  roots.ids.reserve(candidates.size());
  roots.arrival.reserve(candidates.size());
  for (const Candidate &c : candidates) {
    const uint64_t h = hash_combine(hash_combine(seed ^ 0x5EEDull, c.face), uint64_t(c.j));
    // Uniform point in the triangle from two hashed numbers (square-root warp).
    const float r1 = std::sqrt(hash_to_unit(h));
    const float r2 = hash_to_unit(hash64(h));
    SurfacePoint sp;
    sp.triangle = int32_t(c.face);
    sp.bary = Eigen::Vector3f(1.0f - r1, r1 * (1.0f - r2), r1 * r2);
    roots.points.push_back(sp);
    roots.ids.push_back((uint64_t(c.face) << 24) | uint64_t(c.j));
    roots.arrival.push_back(c.time);
  }
  return roots;
}

std::vector<bool> triangles_near(const Mesh &mesh, const std::vector<Eigen::Vector3f> &points, double radius) {
  std::vector<bool> mask(mesh.triangle_count(), false);
  const double r2 = radius * radius;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::Vector3i &t = mesh.triangles[f];
    const Eigen::Vector3f &a = mesh.positions[t[0]], &b = mesh.positions[t[1]], &c = mesh.positions[t[2]];
    for (const Eigen::Vector3f &p : points) {
      // Distance to the triangle approximated by the nearest of its vertices and centroid; exact
      // enough for a selection radius that is larger than the triangles.
      const Eigen::Vector3f centroid = (a + b + c) / 3.0f;
      const double d2 = std::min({(p - a).squaredNorm(), (p - b).squaredNorm(), (p - c).squaredNorm(),
                                  (p - centroid).squaredNorm()});
      if (d2 <= r2) {
        mask[f] = true;
        break;
      }
    }
  }
  return mask;
}

}  // namespace plume
