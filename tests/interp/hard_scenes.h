// Hard interpolation scenes built in code (seeded): guides of unequal lengths that arch and curl,
// S-curves, layered combed guides, ringlets, long guides over a closed sphere, parted spheres,
// random non-crossing guide sets; and the measures the promises are checked with (an exact 2-D
// intersection test, the closest approach of neighbouring strands against their roots' spacing).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/parting.h"
#include "groom/roots.h"
#include "groom/strand_set.h"
#include "groom/test_fixtures.h"
#include "interp/interp_fixtures.h"

namespace plume::test {

/// `count` points evenly spaced in arc length along the curve c(t), t in [0, 1] (sampled densely).
inline std::vector<Eigen::Vector3f> sample_curve(const std::function<Eigen::Vector3d(double)> &c, int count) {
  const int dense = 4000;
  std::vector<Eigen::Vector3d> p(dense + 1);
  std::vector<double> arc(dense + 1, 0.0);
  for (int i = 0; i <= dense; ++i) {
    p[size_t(i)] = c(double(i) / dense);
    if (i > 0) arc[size_t(i)] = arc[size_t(i - 1)] + (p[size_t(i)] - p[size_t(i - 1)]).norm();
  }
  std::vector<Eigen::Vector3f> out;
  size_t j = 0;
  for (int i = 0; i < count; ++i) {
    const double s = arc.back() * double(i) / double(count - 1);
    while (j + 2 < p.size() && arc[j + 1] < s) ++j;
    const double span = arc[j + 1] - arc[j];
    const double t = span > 0.0 ? std::clamp((s - arc[j]) / span, 0.0, 1.0) : 0.0;
    out.push_back((p[j] + t * (p[j + 1] - p[j])).cast<float>());
  }
  return out;
}

/// A scene: a skin, guides bound to it, roots; `planar` scenes lie in the plane y = 0.
struct Scene {
  std::string name;
  Mesh mesh;
  std::unique_ptr<MeshQuery> query;
  Guides guides;
  Roots roots;
  bool planar = false;

  Scene() = default;
  /// The query refers to the mesh: a moved scene builds its own on its own mesh.
  Scene(Scene &&other) noexcept
      : name(std::move(other.name)), mesh(std::move(other.mesh)), guides(std::move(other.guides)),
        roots(std::move(other.roots)), planar(other.planar) {
    query = std::make_unique<MeshQuery>(mesh);
  }
  Scene &operator=(Scene &&) = delete;

  void finish(const StrandSet &strands) {
    query = std::make_unique<MeshQuery>(mesh);
    guides = bind_guides(*query, strands, name);
  }
  void roots_at_points(const std::vector<Eigen::Vector3f> &points) {
    roots = roots_at(*query, points);
  }
};

/// Planar: guide A (about 1.5 long) leans a little; guide B (about 3.6 long, 2.4x A) rises beside it,
/// arches over A's tip and curls back down on A's far side. Roots between them and outside both.
inline Scene planar_arch(int points = 32, int root_count = 40) {
  Scene s;
  s.name = "planar arch";
  s.planar = true;
  s.mesh = make_plane(6.0f, 12);
  StrandSet strands;
  strands.append(sample_curve([](double t) { return Eigen::Vector3d(0.3 + 0.15 * t, 0.0, 1.5 * t); }, points), 0);
  strands.append(sample_curve(
                     [](double t) {
                       const double rise = 1.2, r = 0.6, turn = 225.0 * M_PI / 180.0;
                       const double l1 = rise, l2 = r * turn, s = t * (l1 + l2);
                       if (s <= l1) return Eigen::Vector3d(-0.3, 0.0, s);
                       const double a = M_PI - (s - l1) / r;  // clockwise from 180 degrees
                       return Eigen::Vector3d(0.3 + r * std::cos(a), 0.0, rise + r * std::sin(a));
                     },
                     points),
                 1);
  s.finish(strands);
  std::vector<Eigen::Vector3f> roots;
  for (int i = 0; i < root_count; ++i) roots.emplace_back(-0.9f + 1.8f * (float(i) + 0.5f) / float(root_count), 0.0f, 0.0f);
  s.roots_at_points(roots);
  return s;
}

/// Planar: three S-curves of different amplitudes, phases and lengths side by side (none crossing).
inline Scene planar_s_curves(int points = 32, int root_count = 50) {
  Scene s;
  s.name = "planar S-curves";
  s.planar = true;
  s.mesh = make_plane(6.0f, 12);
  StrandSet strands;
  const double xs[3] = {-0.5, 0.0, 0.5}, lengths[3] = {1.2, 2.0, 1.5}, amplitude[3] = {0.12, 0.2, 0.1},
               phase[3] = {0.0, 0.8, 1.6};
  for (int g = 0; g < 3; ++g)
    strands.append(sample_curve(
                       [&, g](double t) {
                         const double z = lengths[g] * t;
                         return Eigen::Vector3d(xs[g] + amplitude[g] * std::sin(3.0 * z + phase[g]) -
                                                    amplitude[g] * std::sin(phase[g]),
                                                0.0, z);
                       },
                       points),
                   uint64_t(g));
  s.finish(strands);
  std::vector<Eigen::Vector3f> roots;
  for (int i = 0; i < root_count; ++i) roots.emplace_back(-0.8f + 1.6f * (float(i) + 0.5f) / float(root_count), 0.0f, 0.0f);
  s.roots_at_points(roots);
  return s;
}

/// A point on the unit sphere from polar angle theta (from +z) and azimuth phi.
inline Eigen::Vector3d on_sphere(double theta, double phi) {
  return {std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta)};
}

/// Layered combed guides over the unit sphere's cap: each guide rises from its root, bends over and
/// lies along the sphere at a height of 0.04 to 0.1, combed towards +x along great circles, so the
/// guides of one row pass over the roots of the guides behind them (layers).
inline Scene combed_layers(int points = 32, int root_count = 400, uint64_t seed = 3) {
  Scene s;
  s.name = "combed layers";
  s.mesh = make_sphere(1.0f, 48, 96, PoleAxis::z, false);
  const MeshQuery query(s.mesh);
  StrandSet strands;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  int id = 0;
  for (int row = 0; row < 5; ++row)
    for (int col = 0; col < 5; ++col) {
      // Root at angle a along the comb (x-z great circle, tilted by b sideways).
      const double a = -0.5 + 0.2 * row + jitter(random), b = -0.4 + 0.2 * col + jitter(random);
      // Rows farther along the comb lie beneath the rows before them, which pass over their roots.
      const double height = 0.1 - 0.015 * row, length = 0.7 + 0.1 * ((row + col) % 3);
      strands.append(sample_curve(
                         [=](double t) {
                           // Along the comb the angle grows; the height rises over the first 0.15
                           // of arc, then holds.
                           const double s = t * length;
                           const double h = height * std::sin(0.5 * M_PI * std::min(s / 0.15, 1.0));
                           // (C1: the comb's progress eases in over the first 0.1 of arc.)
                           const double along = s < 0.1 ? s * s / 0.2 : s - 0.05;
                           const double angle = a + along / (1.0 + height);
                           const Eigen::Vector3d p = on_sphere(std::abs(angle), angle >= 0.0 ? 0.0 : M_PI);
                           const Eigen::Vector3d q = Eigen::AngleAxisd(b, Eigen::Vector3d::UnitX()) * p;
                           return Eigen::Vector3d((1.0 + h) * q);
                         },
                         points),
                     uint64_t(id++));
    }
  s.finish(strands);
  std::vector<bool> cap(s.mesh.triangle_count());
  for (size_t f = 0; f < s.mesh.triangle_count(); ++f) {
    const Eigen::Vector3f c = s.mesh.positions[size_t(s.mesh.triangles[f][0])];
    cap[f] = c.z() > 0.85f && std::abs(c.y()) < 0.35f && std::abs(c.x()) < 0.45f;
  }
  s.roots = scatter_roots(s.mesh, root_count, seed + 11, cap);
  return s;
}

/// Helical ringlets of several turns on a plane, each with its own phase and radius.
inline Scene ringlets(int points = 64, int root_count = 300, uint64_t seed = 5) {
  Scene s;
  s.name = "ringlets";
  s.mesh = make_plane(4.0f, 16);
  StrandSet strands;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int id = 0;
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) {
      const double x = -0.45 + 0.3 * i, y = -0.45 + 0.3 * j;
      const double radius = 0.05 + 0.02 * unit(random), rise = 0.02 + 0.005 * unit(random),
                   phase = 2.0 * M_PI * unit(random), turns = 3.0 + unit(random);
      const double total = 2.0 * M_PI * turns;
      strands.append(sample_curve(
                         [=](double t) {
                           const double a = t * total;
                           // A straight rise of 0.1, then the helix about the vertical through the root.
                           const double lead = 0.1;
                           return Eigen::Vector3d(x + radius * (std::cos(a + phase) - std::cos(phase)),
                                                  y + radius * (std::sin(a + phase) - std::sin(phase)),
                                                  lead * std::min(1.0, t * 20.0) + rise * a);
                         },
                         points),
                     uint64_t(id++));
    }
  s.finish(strands);
  std::vector<bool> patch(s.mesh.triangle_count());
  for (size_t f = 0; f < s.mesh.triangle_count(); ++f) {
    const Eigen::Vector3f c = s.mesh.positions[size_t(s.mesh.triangles[f][0])];
    patch[f] = std::abs(c.x()) < 0.5f && std::abs(c.y()) < 0.5f;
  }
  s.roots = scatter_roots(s.mesh, root_count, seed + 7, patch);
  return s;
}

/// Long guides of 1x to 4x lengths draping over a closed unit sphere: each rises from the upper
/// hemisphere, then follows its meridian down past the equator at a height of 0.05 to 0.08.
inline Scene draped_sphere(int points = 48, int root_count = 600, uint64_t seed = 9) {
  Scene s;
  s.name = "draped sphere";
  s.mesh = make_sphere(1.0f, 48, 96, PoleAxis::z, false);
  StrandSet strands;
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int id = 0;
  for (int ring = 0; ring < 3; ++ring)
    for (int k = 0; k < 10; ++k) {
      const double theta = 0.25 + 0.25 * ring, phi = 2.0 * M_PI * (k + ring / 3.0) / 10.0;
      const double height = 0.05 + 0.03 * unit(random);
      // 1x to 4x, ending above the south pole, where the meridians meet.
      const double length = std::min(0.5 * (1.0 + 3.0 * unit(random)), (2.7 - theta) * (1.0 + height));
      strands.append(sample_curve(
                         [=](double t) {
                           const double arc = t * length;
                           const double h = height * std::sin(0.5 * M_PI * std::min(arc / 0.12, 1.0));
                           const double along = arc < 0.08 ? arc * arc / 0.16 : arc - 0.04;  // eased in: C1
                           const double th = theta + along / (1.0 + height);
                           return Eigen::Vector3d((1.0 + h) * on_sphere(th, phi));
                         },
                         points),
                     uint64_t(id++));
    }
  s.finish(strands);
  std::vector<bool> upper(s.mesh.triangle_count());
  for (size_t f = 0; f < s.mesh.triangle_count(); ++f)
    upper[f] = s.mesh.positions[size_t(s.mesh.triangles[f][0])].z() > std::cos(0.85);
  s.roots = scatter_roots(s.mesh, root_count, seed + 3, upper);
  return s;
}

/// Random non-crossing guides on a square patch: each guide is an integral curve (fine RK4) of one
/// smooth random field that always rises (z component >= 0.5), so no two guides meet; lengths vary
/// by up to 3x.
inline Scene random_flow(uint64_t seed, int points = 32, int guide_count = 20, int root_count = 200) {
  Scene s;
  s.name = "random flow " + std::to_string(seed);
  s.mesh = make_plane(4.0f, 16);
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  struct Wave {
    Eigen::Vector3d k;
    double phase;
    Eigen::Vector2d amplitude;
  };
  std::vector<Wave> waves;
  for (int w = 0; w < 4; ++w)
    waves.push_back({Eigen::Vector3d(6.0 * (unit(random) - 0.5), 6.0 * (unit(random) - 0.5), 4.0 * unit(random)),
                     2.0 * M_PI * unit(random), Eigen::Vector2d(unit(random) - 0.5, unit(random) - 0.5)});
  auto field = [&](const Eigen::Vector3d &p) {
    Eigen::Vector3d v(0.0, 0.0, 0.7);
    for (const Wave &w : waves) {
      const double c = std::cos(w.k.dot(p) + w.phase);
      v.x() += 1.6 * w.amplitude.x() * c;
      v.y() += 1.6 * w.amplitude.y() * c;
    }
    return v.normalized();
  };
  StrandSet strands;
  for (int g = 0; g < guide_count; ++g) {
    const Eigen::Vector3d root(unit(random) - 0.5, unit(random) - 0.5, 0.0);
    const double length = 0.5 + 1.0 * unit(random);
    std::vector<Eigen::Vector3d> dense{root};
    const int steps = 2000;
    const double h = length / steps;
    Eigen::Vector3d p = root;
    for (int i = 0; i < steps; ++i) {
      const Eigen::Vector3d k1 = field(p), k2 = field(p + 0.5 * h * k1), k3 = field(p + 0.5 * h * k2),
                            k4 = field(p + h * k3);
      p += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      dense.push_back(p);
    }
    strands.append(sample_curve(
                       [&](double t) {
                         const double at = t * steps;
                         const size_t i = std::min(size_t(at), size_t(steps - 1));
                         return Eigen::Vector3d(dense[i] + (at - double(i)) * (dense[i + 1] - dense[i]));
                       },
                       points),
                   uint64_t(g));
  }
  s.finish(strands);
  std::vector<bool> patch(s.mesh.triangle_count());
  for (size_t f = 0; f < s.mesh.triangle_count(); ++f) {
    const Eigen::Vector3f c = s.mesh.positions[size_t(s.mesh.triangles[f][0])];
    patch[f] = std::abs(c.x()) < 0.5f && std::abs(c.y()) < 0.5f;
  }
  s.roots = scatter_roots(s.mesh, root_count, seed + 1, patch);
  return s;
}

/// A sphere with a parting along the meridian y = 0 over its top: guides on either side comb away
/// from it (towards +y or -y), the rows nearest the parting lying on top of the rows behind them.
/// `hard`: the parting is a hard cut all round the sphere (two zones); otherwise a partial line over
/// the top from x = -0.35 to 0.35, past whose ends the two sides blend. `r_settings` gets the
/// partings to build.
inline Scene parted_sphere(bool hard, PartingSettings &r_settings, int points = 32, int root_count = 500,
                           uint64_t seed = 13) {
  Scene s;
  s.name = hard ? "hard parting" : "partial parting";
  s.mesh = make_sphere(1.0f, 48, 96, PoleAxis::z, false);
  StrandSet strands;
  int id = 0;
  for (int i = 0; i < 7; ++i)
    for (const double y : {-0.5, -0.3, -0.1, 0.1, 0.3, 0.5}) {
      const double x = -0.6 + 0.2 * i;
      const Eigen::Vector3d r0 = Eigen::Vector3d(x, y, std::sqrt(1.0 - x * x - y * y));
      const double side = y > 0.0 ? 1.0 : -1.0;
      const double height = 0.1 - 0.1 * std::abs(y), length = 0.6 + 0.1 * (i % 4);
      strands.append(sample_curve(
                         [=](double t) {
                           const double arc = t * length;
                           const double h = height * std::sin(0.5 * M_PI * std::min(arc / 0.12, 1.0));
                           const double along = arc < 0.08 ? arc * arc / 0.16 : arc - 0.04;
                           const double angle = side * along / (1.0 + height);
                           return Eigen::Vector3d((1.0 + h) * (Eigen::AngleAxisd(-angle, Eigen::Vector3d::UnitX()) * r0));
                         },
                         points),
                     uint64_t(id++));
    }
  s.finish(strands);
  r_settings = PartingSettings{};
  PartingLine line;
  line.name = hard ? "all round" : "over the top";
  line.gamma = 2.0f;
  line.hard = hard;
  line.closed = hard;
  if (hard) {
    r_settings.zone_source = PartingSettings::ZoneSource::lines;
    for (int k = 0; k < 48; ++k) {
      const double a = 2.0 * M_PI * k / 48.0;
      line.points.emplace_back(float(std::sin(a)), 0.0f, float(std::cos(a)));
    }
  } else {
    for (int k = 0; k <= 8; ++k) {
      const double a = -0.35 + 0.7 * k / 8.0;
      line.points.emplace_back(float(std::sin(a)), 0.0f, float(std::cos(a)));
    }
  }
  r_settings.lines.push_back(line);
  std::vector<bool> cap(s.mesh.triangle_count());
  for (size_t f = 0; f < s.mesh.triangle_count(); ++f) {
    const Eigen::Vector3f c = s.mesh.positions[size_t(s.mesh.triangles[f][0])];
    cap[f] = c.z() > 0.7f && std::abs(c.x()) < 0.6f && std::abs(c.y()) < 0.55f;
  }
  s.roots = scatter_roots(s.mesh, root_count, seed, cap);
  return s;
}

/// The same scene with every length (mesh, guides) scaled by `factor` about the origin.
inline Scene scaled(const Scene &original, float factor) {
  Scene s;
  s.name = original.name + " scaled";
  s.planar = original.planar;
  s.mesh = original.mesh;
  for (Eigen::Vector3f &p : s.mesh.positions) p *= factor;
  s.mesh.compute_normals();
  StrandSet strands = original.guides.strands;
  for (Eigen::Vector3f &p : strands.positions) p *= factor;
  s.finish(strands);
  s.roots = original.roots;  // surface points: the same triangles and weights
  return s;
}

// ---- measures ----

/// Orientation of c relative to the directed line a -> b in the XZ plane, in double: > 0 left.
inline double orient_xz(const Eigen::Vector3f &a, const Eigen::Vector3f &b, const Eigen::Vector3f &c) {
  return (double(b.x()) - a.x()) * (double(c.z()) - a.z()) - (double(b.z()) - a.z()) * (double(c.x()) - a.x());
}

/// Pairs of strands (in the XZ plane) whose segments properly intersect or touch, excluding the
/// shared root point of strands rooted at the same place.
inline size_t planar_intersections(const StrandSet &strands) {
  size_t pairs = 0;
  for (size_t i = 0; i < strands.strand_count(); ++i)
    for (size_t j = i + 1; j < strands.strand_count(); ++j) {
      const auto a = strands.points(i), b = strands.points(j);
      bool met = false;
      for (size_t u = 0; u + 1 < a.size() && !met; ++u)
        for (size_t v = 0; v + 1 < b.size() && !met; ++v) {
          if (u == 0 && v == 0 && a[0] == b[0]) continue;
          const double d1 = orient_xz(a[u], a[u + 1], b[v]), d2 = orient_xz(a[u], a[u + 1], b[v + 1]);
          const double d3 = orient_xz(b[v], b[v + 1], a[u]), d4 = orient_xz(b[v], b[v + 1], a[u + 1]);
          met = ((d1 > 0) != (d2 > 0) || d1 == 0 || d2 == 0) && ((d3 > 0) != (d4 > 0) || d3 == 0 || d4 == 0);
          if (met && d1 == 0 && d2 == 0) {  // collinear: overlap of the projections on the line
            const Eigen::Vector3f dir = a[u + 1] - a[u];
            const float s0 = dir.dot(b[v] - a[u]), s1 = dir.dot(b[v + 1] - a[u]), len = dir.squaredNorm();
            met = std::max(s0, s1) >= 0.0f && std::min(s0, s1) <= len;
          }
        }
      pairs += met;
    }
  return pairs;
}

/// The smallest ratio, over pairs of strands whose roots are within `near` of each other, of the
/// strands' closest approach (segment to segment, root segments left out) to their roots' distance.
/// Below 1 neighbours come closer than their roots; far below it they bunch.
inline float closest_approach_ratio(const StrandSet &strands, float near) {
  float worst = INFINITY;
  for (size_t i = 0; i < strands.strand_count(); ++i)
    for (size_t j = i + 1; j < strands.strand_count(); ++j) {
      const auto a = strands.points(i), b = strands.points(j);
      const float roots = (a[0] - b[0]).norm();
      if (!(roots < near) || roots <= 0.0f) continue;
      float closest = INFINITY;
      for (size_t u = 1; u + 1 < a.size(); ++u)
        for (size_t v = 1; v + 1 < b.size(); ++v)
          closest = std::min(closest, segment_distance(a[u], a[u + 1], b[v], b[v + 1]));
      worst = std::min(worst, closest / roots);
    }
  return worst;
}

}  // namespace plume::test
