// Guide dynamics throughput: joint-steps per second for 10,000 guides x 25 joints on a shaken
// sphere head, without and with body collisions (skin spheres and capsule + the emitter mesh),
// against an in-run baseline: a position-based chain (Verlet + 4 Gauss-Seidel distance passes).
// Prints medians of repeated runs, the core count and the length error of each method.

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string_view>
#include <ctime>
#include <vector>

#include "dynamics/guide_simulator.h"
#include "bench_sphere.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"

using namespace plume;

namespace {

constexpr int kGuides = 10000;
constexpr int kJoints = 25;
constexpr int kFrames = 12;
constexpr int kRuns = 3;
constexpr float kRadius = 10.0f;
constexpr double kPi = 3.14159265358979;

Mesh shaken(const Mesh &rest, int frame) {
  Mesh posed = rest;
  const double phase = 2.0 * kPi * 2.0 * frame / 24.0;
  const Eigen::Matrix3f turn = Eigen::AngleAxisf(float(0.5 * std::sin(phase)), Eigen::Vector3f::UnitY()).toRotationMatrix();
  for (Eigen::Vector3f &p : posed.positions) p = turn * p + Eigen::Vector3f(float(2.0 * std::sin(phase)), 0.0f, 0.0f);
  posed.compute_normals();
  return posed;
}

// Guides on the upper part of the head (a Fibonacci spiral), 15 units long, curving down.
Guides make_guides(const Mesh &head) {
  StrandSet strands;
  std::vector<Eigen::Vector3f> points(kJoints);
  for (int g = 0; g < kGuides; ++g) {
    const double y = 1.0 - 1.2 * (g + 0.5) / kGuides, r = std::sqrt(std::max(0.0, 1.0 - y * y)), a = 2.39996 * g;
    const Eigen::Vector3f normal(float(r * std::cos(a)), float(y), float(r * std::sin(a)));
    Eigen::Vector3f side = normal.cross(Eigen::Vector3f::UnitY());
    side = side.squaredNorm() > 1e-6f ? side.normalized() : Eigen::Vector3f::UnitX();
    points[0] = kRadius * normal;
    for (int j = 1; j < kJoints; ++j)
      points[j] = points[j - 1] + (15.0f / (kJoints - 1)) * (Eigen::AngleAxisf(-1.2f * (j - 1) / (kJoints - 2), side) * normal);
    strands.append(points, uint64_t(g));
  }
  const MeshQuery query(head);
  return bind_guides(query, std::move(strands), "bench");
}

double max_length_error(const std::vector<Eigen::Vector3d> &x, const StrandSet &rest) {
  double worst = 0.0;
  for (size_t g = 0; g < rest.strand_count(); ++g)
    for (int64_t p = rest.offsets[g] + 1; p < rest.offsets[g + 1]; ++p) {
      const double l0 = (rest.positions[p] - rest.positions[p - 1]).cast<double>().norm();
      worst = std::max(worst, std::abs((x[p] - x[p - 1]).norm() - l0) / l0);
    }
  return worst;
}

struct Figure {
  double joint_steps_per_second;      // wall clock
  double joint_steps_per_cpu_second;  // process CPU time (all threads): robust on a loaded machine
  double length_error;
  double solves_per_guide_step = 0.0;  // tridiagonal solves per guide and substep (simulator only)
  double queries_per_joint_step = 0.0;  // exact emitter closest-point queries per joint and substep
};

double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

Figure run_simulator(const Mesh &head, const std::vector<Mesh> &poses, const Guides &guides, bool collisions) {
  DynamicsSettings settings;
  settings.substeps = 1;
  settings.collide_with_emitter = collisions;
  settings.wind = Eigen::Vector3f(60.0f, 0.0f, 20.0f);
  settings.wind_gust = 0.5f;
  if (collisions) {
    settings.shapes.push_back({CollisionShape::Kind::sphere, Eigen::Vector3f(11.0f, -8.0f, 0.0f), {}, 4.0f, 0.4f, {}});
    settings.shapes.push_back({CollisionShape::Kind::sphere, Eigen::Vector3f(-11.0f, -8.0f, 0.0f), {}, 4.0f, 0.4f, {}});
    settings.shapes.push_back({CollisionShape::Kind::capsule, Eigen::Vector3f(-12.0f, -14.0f, -3.0f),
                               Eigen::Vector3f(12.0f, -14.0f, -3.0f), 5.0f, 0.4f, {}});
  }
  dynamics::GuideSimulator sim(head, guides, settings);
  sim.reset(head);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_seconds();
  for (const Mesh &pose : poses) sim.step_frame(pose);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = cpu_seconds() - cpu_start;
  const std::vector<Eigen::Vector3d> x(sim.positions().begin(), sim.positions().end());
  const double work = double(guides.strands.point_count()) * double(poses.size());
  const double guide_steps = double(sim.work().substeps) * double(guides.size());
  return {work / seconds, work / cpu, max_length_error(x, guides.strands),
          double(sim.work().tridiagonal_solves) / guide_steps, double(sim.work().emitter_queries) / work};
}

// Baseline: a position-based chain. Verlet step under gravity, root and first joint carried
// rigidly by the root frame, then 4 Gauss-Seidel passes of mass-weighted distance projection.
Figure run_position_based_chain(const Mesh &head, const std::vector<Mesh> &poses, const Guides &guides) {
  const StrandSet &rest = guides.strands;
  const size_t point_num = rest.point_count();
  std::vector<Eigen::Vector3d> x(point_num), previous(point_num), local(point_num);
  std::vector<double> length(point_num, 0.0);
  for (size_t g = 0; g < guides.size(); ++g) {
    const SurfaceFrame frame = surface_frame(head, guides.roots[g]);
    for (int64_t p = rest.offsets[g]; p < rest.offsets[g + 1]; ++p) {
      x[p] = previous[p] = rest.positions[p].cast<double>();
      local[p] = frame.to_local(rest.positions[p]).cast<double>();
      if (p > rest.offsets[g]) length[p] = (rest.positions[p] - rest.positions[p - 1]).cast<double>().norm();
    }
  }
  const double h = 1.0 / 24.0;
  const Eigen::Vector3d gravity(0.0, -981.0, 0.0);
  const auto start = std::chrono::steady_clock::now();
  const double cpu_start = cpu_seconds();
  for (const Mesh &pose : poses) {
#pragma omp parallel for schedule(dynamic, 64)
    for (int64_t g = 0; g < int64_t(guides.size()); ++g) {
      const SurfaceFrame frame = surface_frame(pose, guides.roots[g]);
      const int64_t begin = rest.offsets[g], end = rest.offsets[g + 1];
      for (int64_t p = begin; p < begin + 2; ++p) previous[p] = x[p] = frame.to_world(local[p].cast<float>()).cast<double>();
      for (int64_t p = begin + 2; p < end; ++p) {
        const Eigen::Vector3d next = x[p] + 0.98 * (x[p] - previous[p]) + h * h * gravity;
        previous[p] = x[p];
        x[p] = next;
      }
      for (int pass = 0; pass < 4; ++pass)
        for (int64_t p = begin + 2; p < end; ++p) {
          const Eigen::Vector3d d = x[p] - x[p - 1];
          const double len = d.norm();
          const Eigen::Vector3d correction = (len - length[p]) / len * d;
          if (p == begin + 2) {
            x[p] -= correction;
          } else {
            x[p - 1] += 0.5 * correction;
            x[p] -= 0.5 * correction;
          }
        }
    }
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double cpu = cpu_seconds() - cpu_start;
  const double work = double(point_num) * double(poses.size());
  return {work / seconds, work / cpu, max_length_error(x, rest)};
}

Figure median(std::vector<Figure> runs) {
  std::sort(runs.begin(), runs.end(),
            [](const Figure &a, const Figure &b) { return a.joint_steps_per_second < b.joint_steps_per_second; });
  return runs[runs.size() / 2];
}

}  // namespace

// With --profile-plain, only the chain without collisions is run (a few times, nothing printed):
// a clean run to record with a profiler.
int main(int argc, char **argv) {
  const bool profile_plain = argc > 1 && std::string_view(argv[1]) == "--profile-plain";
  const Mesh head = bench::closed_sphere(kRadius, 48, 96);
  const Guides guides = make_guides(head);
  std::vector<Mesh> poses;
  for (int f = 1; f <= kFrames; ++f) poses.push_back(shaken(head, f));
  if (profile_plain) {
    for (int run = 0; run < 3 * kRuns; ++run) run_simulator(head, poses, guides, false);
    return 0;
  }
  std::vector<Figure> plain, collide, baseline;
  for (int run = 0; run < kRuns; ++run) {
    plain.push_back(run_simulator(head, poses, guides, false));
    collide.push_back(run_simulator(head, poses, guides, true));
    baseline.push_back(run_position_based_chain(head, poses, guides));
  }
  const Figure p = median(plain), c = median(collide), b = median(baseline);
  std::printf("guide dynamics: %d guides x %d joints, %d frames at 1 step/frame (dt = 1/24 s), shaken head "
              "(%zu triangles), median of %d runs, %d threads on %d cores\n",
              kGuides, kJoints, kFrames, head.triangle_count(), kRuns, omp_get_max_threads(), omp_get_num_procs());
  // Wall-clock figures depend on what else runs on the machine; the CPU-time figure times the
  // core count is what the same run would give with the cores to itself.
  const int cores = omp_get_num_procs();
  std::printf("%-58s %14s %18s %12s %12s %18s %18s\n", "method", "joint-steps/s", "cpu-based x cores",
              "vs baseline", "length err", "solves/guide/step", "queries/joint-step");
  auto row = [&](const char *name, const Figure &f) {
    std::printf("%-58s %14.3e %18.3e %12.2f %12.2e %18.2f %18.4f\n", name, f.joint_steps_per_second,
                f.joint_steps_per_cpu_second * cores, f.joint_steps_per_second / b.joint_steps_per_second,
                f.length_error, f.solves_per_guide_step, f.queries_per_joint_step);
  };
  row("tridiagonal chain, no collisions (target >= 1e7)", p);
  row("tridiagonal chain, shapes + emitter (target >= 2.5e6)", c);
  row("BASELINE position-based chain (Verlet, 4 GS passes), no coll.", b);
  return 0;
}
