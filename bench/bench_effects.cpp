// Regrowth time of 100k strands x 32 points with and without the full effects stack (every effect type,
// two clump levels), on a sphere with 400 guides. The budget: the stack adds at most 50%.
#include <omp.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/groom_scene.h"
#include "groom/test_fixtures.h"
#include "groom/roots.h"
#include "effects/effects.h"
#include "interp/interpolate.h"
#include "skin/skin_grid.h"

using namespace plume;

namespace {

std::vector<EffectDesc> full_stack() {
  auto make = [](EffectType type, float amount, uint64_t seed) {
    EffectDesc d;
    d.type = type;
    d.amount = amount;
    d.seed = seed;
    d.ramp = Ramp::linear(0.0f, 1.0f);
    return d;
  };
  EffectDesc large = make(EffectType::clump, 0.6f, 1);
  large.clump_radius = 0.12f;
  large.clump_twist = 0.2f;
  large.stray_fraction = 0.05f;
  EffectDesc small = make(EffectType::clump, 0.5f, 2);
  small.clump_radius = 0.03f;
  EffectDesc tension = make(EffectType::tension, 0.2f, 3);
  EffectDesc length = make(EffectType::length, 1.0f, 4);
  length.length_distribution = EffectDesc::LengthDistribution::normal;
  length.length_variation = 0.1f;
  EffectDesc wave = make(EffectType::wave, 1.0f, 5);
  wave.frequency = 3.0f;
  wave.amplitude = 0.05f;
  EffectDesc frizz = make(EffectType::frizz, 1.0f, 6);
  frizz.frequency = 30.0f;
  frizz.amplitude = 0.01f;
  frizz.fraction = 0.2f;
  EffectDesc curl = make(EffectType::curl, 1.0f, 7);
  curl.curl_radius = 0.01f;
  curl.turns_per_unit = 8.0f;
  return {large, small, tension, length, wave, frizz, curl};
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// CPU time of the whole process (all threads), seconds: less sensitive than wall time to other
/// processes sharing the cores.
double cpu_seconds() {
  timespec ts;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

}  // namespace

/// Optional arguments: strand count (default 100000), repeats (default 7), and "stack-only" to run
/// nothing but the stack (for a profiler).
int main(int argc, char **argv) {
  const int strand_count = argc > 1 ? std::atoi(argv[1]) : 100000, points = 32;
  const int repeats = argc > 2 ? std::max(std::atoi(argv[2]), 1) : 7;
  const Mesh rest = test::make_sphere(1.0f, 64, 128);
  const MeshQuery rest_query(rest);
  const Roots guide_roots = scatter_roots(rest, 400, 11);
  const Guides guides = bind_guides(rest_query, test::combed_guides(rest, guide_roots), "bench guides");
  const Roots roots = scatter_roots(rest, strand_count, 3);
  InterpolationSettings settings;
  const interp::Binding binding = interp::bind(rest, guides, roots, settings);
  std::vector<int32_t> nearest(roots.size());
  for (size_t i = 0; i < roots.size(); ++i) nearest[i] = binding.guide_ids[i * size_t(binding.k)];

  // The frame: the head turned and moved (rigidly), guides carried by the skin.
  Mesh posed = rest;
  const Eigen::Matrix3f rotation = Eigen::AngleAxisf(0.5f, Eigen::Vector3f(0.2f, 1.0f, 0.1f).normalized()).toRotationMatrix();
  for (Eigen::Vector3f &p : posed.positions) p = rotation * p + Eigen::Vector3f(0.1f, 0.2f, -0.3f);
  posed.compute_normals();
  const MeshQuery posed_query(posed);
  const StrandSet posed_guides = carry_guides(rest, posed, guides);
  interp::GrowOptions options;
  options.points_per_strand = points;

  const auto t_prepare = std::chrono::steady_clock::now();
  const effects::EffectStack stack(full_stack(), rest, roots, guides, nearest);
  const double prepare = seconds_since(t_prepare);

  StrandSet strands;
  std::vector<float> clearance;
  if (argc > 3 && std::string(argv[3]) == "stack-only") {
    // Profiling aid: the stack alone, applied `repeats` times to one grown frame.
    interp::grow(binding, posed, posed_query, roots, posed_guides, options, strands, &clearance);
    const StrandSet grown = strands;
    std::vector<double> wall, cpu;
    for (int r = 0; r < repeats; ++r) {
      strands = grown;
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = cpu_seconds();
      stack.apply(posed, posed_query, posed_guides, binding.skin_margin, strands, clearance);
      cpu.push_back(cpu_seconds() - c0);
      wall.push_back(seconds_since(t0));
    }
    std::printf("stack alone, median of %d: %.3f s wall, %.3f s CPU\n", repeats, median(wall), median(cpu));
    // A digest of the output's bits, to tell whether two builds give the same strands.
    uint64_t digest = 0;
    for (const Eigen::Vector3f &p : strands.positions)
      for (int axis = 0; axis < 3; ++axis) {
        uint32_t bits = 0;
        std::memcpy(&bits, &p[axis], sizeof bits);
        digest = hash_combine(digest, bits);
      }
    std::printf("stack output digest: %016llx\n", static_cast<unsigned long long>(digest));
    return 0;
  }  // growth's skin bounds, handed to the stack as the pipeline does
  std::vector<double> grow_only, grow_and_stack, stack_only, cpu_grow, cpu_stack;
  for (int r = 0; r < repeats; ++r) {
    auto t0 = std::chrono::steady_clock::now();
    double c0 = cpu_seconds();
    interp::grow(binding, posed, posed_query, roots, posed_guides, options, strands);
    grow_only.push_back(seconds_since(t0));
    cpu_grow.push_back(cpu_seconds() - c0);

    // As the pipeline does it: one skin grid for the frame, shared by growth and the stack.
    t0 = std::chrono::steady_clock::now();
    const skin::SkinGrid grid(posed, posed_query);
    interp::grow(binding, posed, posed_query, roots, posed_guides, options, strands, &clearance, &grid);
    const auto t1 = std::chrono::steady_clock::now();
    c0 = cpu_seconds();
    stack.apply(posed, posed_query, posed_guides, binding.skin_margin, strands, clearance, &grid);
    grow_and_stack.push_back(seconds_since(t0));
    stack_only.push_back(seconds_since(t1));
    cpu_stack.push_back(cpu_seconds() - c0);
  }

  const double base = median(grow_only), full = median(grow_and_stack);
  std::printf("bench_effects: %d strands x %d points, 400 guides, streamline k=%d, %d cores (%d OpenMP threads), "
              "median of %d\n",
              strand_count, points, settings.k, omp_get_num_procs(), omp_get_max_threads(), repeats);
  std::printf("%-34s %10s\n", "figure", "seconds");
  std::printf("%-34s %10.3f\n", "stack preparation (once)", prepare);
  std::printf("%-34s %10.3f\n", "regrowth, no effects (baseline)", base);
  std::printf("%-34s %10.3f\n", "effects stack alone (7 effects)", median(stack_only));
  std::printf("%-34s %10.3f\n", "regrowth + effects stack", full);
  std::printf("ratio with / without stack: %.2f (budget 1.50) %s\n", full / base, full / base <= 1.5 ? "ok" : "OVER");
  const double cpu_base = median(cpu_grow), cpu_fx = median(cpu_stack);
  std::printf("CPU time (all threads): regrowth %.3f s, stack %.3f s, ratio (regrowth + stack) / regrowth %.2f\n",
              cpu_base, cpu_fx, (cpu_base + cpu_fx) / cpu_base);

  // Each effect alone (with the closing skin pass), CPU time: where the stack's time goes.
  const char *names[] = {"clump (large)", "clump (small)", "tension", "length", "wave", "frizz", "curl"};
  const std::vector<EffectDesc> all = full_stack();
  std::printf("%-34s %10s\n", "one effect alone (+ skin pass)", "CPU s");
  for (size_t e = 0; e < all.size(); ++e) {
    const effects::EffectStack single({all[e]}, rest, roots, guides, nearest);
    std::vector<double> cpu;
    for (int r = 0; r < std::min(repeats, 3); ++r) {
      interp::grow(binding, posed, posed_query, roots, posed_guides, options, strands, &clearance);
      const double c0 = cpu_seconds();
      single.apply(posed, posed_query, posed_guides, binding.skin_margin, strands, clearance);
      cpu.push_back(cpu_seconds() - c0);
    }
    std::printf("  %-32s %10.3f\n", names[e], median(cpu));
  }
  return 0;
}
