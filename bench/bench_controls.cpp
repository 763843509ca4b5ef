// Animator controls: posing 10,000 guides x 32 points every frame (the turns at a frame, then the
// guides turned; the carry before it is not timed), with six controls (one mirrored) and lift, random twist, direction
// and aim all at once, blended and nearest; the dynamic blend's mix; the binding, once. In-run baseline: the per-frame
// work without controls, carrying the guides with the skin (carry_guides), which every frame does anyway. Prints
// medians of repeated runs, the core count, wall and CPU times.

#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <ctime>
#include <functional>
#include <vector>

#include "controls/control_rig.h"
#include "bench_sphere.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"

using namespace plume;

namespace {

constexpr int kGuides = 10000;
constexpr int kPoints = 32;
constexpr int kFrames = 24;
constexpr int kRuns = 5;
constexpr float kRadius = 10.0f;
constexpr double kPi = 3.14159265358979;

// The head nodding and turning, and squashed a little (not rigid): skin frames turn differently.
Mesh posed_head(const Mesh &rest, int frame) {
  Mesh posed = rest;
  const float phase = 2.0f * float(kPi) * float(frame) / 24.0f;
  const Eigen::Matrix3f turn = (Eigen::AngleAxisf(0.4f * std::sin(phase), Eigen::Vector3f::UnitY()) *
                                Eigen::AngleAxisf(0.2f * std::cos(phase), Eigen::Vector3f::UnitX()))
                                   .toRotationMatrix();
  for (Eigen::Vector3f &p : posed.positions) {
    p.y() *= 1.0f + 0.05f * std::sin(phase);
    p = turn * p;
  }
  posed.compute_normals();
  return posed;
}

// Guides over the upper head (a Fibonacci spiral), 12 units long, leaving the skin at 20 degrees
// and bending down along it.
Guides make_guides(const Mesh &head) {
  StrandSet strands;
  std::vector<Eigen::Vector3f> points(kPoints);
  for (int g = 0; g < kGuides; ++g) {
    const double y = 1.0 - 1.3 * (g + 0.5) / kGuides, r = std::sqrt(std::max(0.0, 1.0 - y * y)), a = 2.39996 * g;
    const Eigen::Vector3f normal(float(r * std::cos(a)), float(y), float(r * std::sin(a)));
    Eigen::Vector3f side = normal.cross(Eigen::Vector3f::UnitY());
    side = side.squaredNorm() > 1e-6f ? side.normalized() : Eigen::Vector3f::UnitX();
    const Eigen::Vector3f lean = side.cross(normal);
    points[0] = kRadius * normal;
    for (int j = 1; j < kPoints; ++j) {
      const float elevation = 0.35f * (1.0f - float(j - 1) / float(kPoints - 2)) + 0.05f;
      points[j] = points[j - 1] + (12.0f / (kPoints - 1)) * (std::cos(elevation) * lean + std::sin(elevation) * normal);
    }
    strands.append(points, uint64_t(g));
  }
  const MeshQuery query(head);
  return bind_guides(query, std::move(strands), "bench");
}

Keyed<float> ramp_keys(float to) {
  Keyed<float> k;
  k.interpolation = KeyInterpolation::smooth;
  k.frames = {1.0, 12.0};
  k.values = {0.0f, to};
  return k;
}

// Six controls over the head, every behaviour, one mirrored, one in space (an aim target).
ControlSettings head_controls(ControlSettings::Binding binding) {
  ControlSettings settings;
  settings.binding = binding;
  const Eigen::Vector3f places[] = {{0, 10, 0}, {6, 8, 0}, {-6, 8, 0}, {0, 8, 6}, {0, 8, -6}};
  for (int i = 0; i < 5; ++i) {
    ControlDesc c;
    c.name = std::to_string(i);
    c.position = places[i];
    c.radius = 9.0f;
    c.lift = ramp_keys(0.8f);
    c.random_twist = ramp_keys(40.0f);
    c.twist_seed = 7;
    c.direction = ramp_keys(1.0f);
    c.offset.frames = {1.0, 24.0};
    c.offset.values = {Eigen::Vector3f::Zero(), Eigen::Vector3f(2.0f, 0.5f, -1.0f)};
    c.mirror = i == 1;
    settings.controls.push_back(c);
  }
  ControlDesc sky;
  sky.name = "sky";
  sky.place = ControlDesc::Place::space;
  sky.position = Eigen::Vector3f(0.0f, 40.0f, 20.0f);
  sky.aim = ramp_keys(0.5f);
  settings.controls.push_back(sky);
  return settings;
}

double cpu_seconds() {
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

struct Timing {
  double wall_ms = 0.0;  // per frame, median of the runs
  double cpu_ms = 0.0;   // per frame, the same run's process CPU time (all threads)
};

// Median over kRuns of the per-frame time of `work(f)` over every frame; `prepare(f)` runs before
// each frame, outside the timing.
Timing time_frames(
    const std::function<void(int)> &work, const std::function<void(int)> &prepare = [](int) {}) {
  std::vector<Timing> runs;
  for (int run = 0; run < kRuns; ++run) {
    double wall = 0.0, cpu = 0.0;
    for (int f = 1; f <= kFrames; ++f) {
      prepare(f);
      const auto start = std::chrono::steady_clock::now();
      const double cpu_start = cpu_seconds();
      work(f);
      cpu += cpu_seconds() - cpu_start;
      wall += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    runs.push_back({1e3 * wall / kFrames, 1e3 * cpu / kFrames});
  }
  std::sort(runs.begin(), runs.end(), [](const Timing &a, const Timing &b) { return a.wall_ms < b.wall_ms; });
  return runs[runs.size() / 2];
}

}  // namespace

int main() {
  const Mesh head = bench::closed_sphere(kRadius, 64, 128);
  const Guides guides = make_guides(head);
  std::vector<Mesh> poses;
  for (int f = 1; f <= kFrames; ++f) poses.push_back(posed_head(head, f));
  const double points = double(guides.strands.point_count());
  const int cores = omp_get_num_procs();

  std::printf("bench_controls: %d guides x %d points, %d frames, %d runs (medians), %d cores\n", kGuides, kPoints,
              kFrames, kRuns, cores);
  std::printf("%-58s %8s %10s %12s %9s\n", "figure", "threads", "ms/frame", "points/s", "CPU ms");

  // Binding, once per groom.
  for (const auto binding : {ControlSettings::Binding::blend, ControlSettings::Binding::nearest}) {
    const auto start = std::chrono::steady_clock::now();
    const controls::ControlRig rig(head, guides, head_controls(binding));
    const double ms = 1e3 * std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    size_t entries = rig.binding().controls.size();
    std::printf("%-58s %8s %10.2f %12s %9s  (%zu guide-control pairs)\n",
                binding == ControlSettings::Binding::blend ? "bind, blend (once)" : "bind, nearest (once)", "1", ms, "",
                "", entries);
  }

  const controls::ControlRig blended(head, guides, head_controls(ControlSettings::Binding::blend));
  const controls::ControlRig nearest(head, guides, head_controls(ControlSettings::Binding::nearest));
  StrandSet carried, simulated;
  controls::GuidePose pose;
  for (const int threads : {1, 2}) {
    if (threads > cores) continue;
    omp_set_num_threads(threads);
    const Timing baseline = time_frames([&](int f) { carried = carry_guides(head, poses[size_t(f - 1)], guides); });
    // Ratios are to the baseline: what posing the guides adds to what every frame does anyway.
    auto row = [&](const char *name, const Timing &t) {
      std::printf("%-58s %8d %10.3f %12.3g %9.3f  %.2fx baseline\n", name, threads, t.wall_ms,
                  points / (1e-3 * t.wall_ms), t.cpu_ms, t.wall_ms / baseline.wall_ms);
    };
    std::printf("%-58s %8d %10.3f %12.3g %9.3f\n", "baseline: carry the guides with the skin", threads,
                baseline.wall_ms, points / (1e-3 * baseline.wall_ms), baseline.cpu_ms);
    for (const auto *rig : {&blended, &nearest}) {
      const bool is_blend = rig == &blended;
      auto carry = [&](int f) { carried = carry_guides(head, poses[size_t(f - 1)], guides); };
      const Timing posing = time_frames([&](int f) { rig->pose(f, poses[size_t(f - 1)], pose); });
      const Timing turning = time_frames([&](int f) { rig->apply(f, poses[size_t(f - 1)], carried); }, carry);
      row(is_blend ? "controls, blend: the turns at a frame (pose)" : "controls, nearest: the turns at a frame (pose)",
          posing);
      row(is_blend ? "controls, blend: pose + turn the guides (apply)"
                   : "controls, nearest: pose + turn the guides (apply)",
          turning);
    }
    // The dynamic blend's mix against a stand-in simulation (the carried guides), every guide mixed.
    ControlSettings with_blend = head_controls(ControlSettings::Binding::blend);
    for (ControlDesc &c : with_blend.controls) {
      c.dynamic_blend = Keyed<float>::constant(1.0f);
      c.blend_ramp = Ramp{{0.0f, 0.3f, 1.0f}, {0.0f, 0.1f, 0.85f}};
    }
    const controls::ControlRig blend_rig(head, guides, with_blend);
    blend_rig.pose(12, poses[11], pose);
    simulated = carry_guides(head, poses[11], guides);
    StrandSet rig_guides = simulated;
    blend_rig.apply(pose, rig_guides);
    const StrandSet rig_start = rig_guides;
    const Timing mixing = time_frames([&](int) { blend_rig.blend_dynamics(pose, simulated, rig_guides); },
                                      [&](int) { rig_guides.positions = rig_start.positions; });
    row("dynamic blend: mix rig and simulation", mixing);
  }
  std::printf("(one run on a shared machine: figures are noisy; CPU ms is the process's CPU time per frame)\n");
  return 0;
}
