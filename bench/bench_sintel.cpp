// Growth on the real job: Sintel's head and 228 guides, 100,000 strands x 32 points on her scalp
// (roots within 2 of a guide root, as her grooms scatter them), every interpolation method as a
// groom runs it by default (streamline with its separation pass), two threads; the median of
// repeated runs of grow() alone (binding is done once, as a groom does), in points per second.
// bench/vs_blender.sh runs it beside Blender's interpolated children (bench/blender_children.py) in
// one go and prints the ratio.
// Usage: bench_sintel [STRANDS [RUNS [METHOD]]]   (default 100000 strands, 7 runs, every method)
// The last lines are machine-readable, one per method:
//   PLUME_GROWTH method=streamline strands=100000 points=32 threads=2 median_s=... points_per_s=...
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <string>
#include <vector>

#include "check/check.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "interp/interpolate.h"
#include "bench_sintel_scene.h"

using namespace plume;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char **argv) {
  const int64_t count = argc > 1 ? std::atoll(argv[1]) : 100000;
  const int runs = argc > 2 ? std::atoi(argv[2]) : 7;
  const std::string only = argc > 3 ? argv[3] : "";
  if (count < 1 || count > 10000000 || runs < 1 || runs > 1000) {
    std::fprintf(stderr, "usage: bench_sintel [STRANDS in 1..1e7 [RUNS in 1..1000 [streamline|fur|linear]]]\n");
    return 2;
  }
  constexpr int kThreads = 2, kPoints = 32;
  omp_set_num_threads(kThreads);
  const Mesh mesh = bench::sintel_mesh();
  const MeshQuery query(mesh);
  const Guides guides = bench::sintel_guides(query);
  const Roots roots = bench::sintel_scalp_roots(mesh, guides, count);

  std::printf("Growth on Sintel: %zu guides, %zu strands x %d points on the scalp, %d threads (%d cores), median of "
              "%d runs\n\n",
              guides.size(), roots.size(), kPoints, kThreads, omp_get_num_procs(), runs);
  std::printf("%-11s %11s %11s %11s %14s %18s %14s\n", "method", "median ms", "min ms", "max ms", "points/s",
              "points/CPU-s x 2", "inside skin");
  using Method = InterpolationSettings::Method;
  std::vector<std::string> lines;
  for (const auto &[method, name] : {std::pair{Method::streamline, "streamline"}, std::pair{Method::fur, "fur"},
                                     std::pair{Method::linear, "linear"}}) {
    if (!only.empty() && only != name) continue;
    InterpolationSettings settings;
    settings.method = method;
    const interp::Binding binding = interp::bind(mesh, guides, roots, settings);
    interp::GrowOptions options;
    options.points_per_strand = kPoints;
    // As a groom grows them: streamline with the separation pass unless the groom turns it off.
    options.separate = method == Method::streamline && settings.separate;
    StrandSet strands;
    interp::grow(binding, mesh, query, roots, guides.strands, options, strands);  // warm-up: allocations
    std::vector<double> times, cpu_times;
    interp::GrowStats stats;
    options.r_stats = &stats;
    for (int run = 0; run < runs; ++run) {
      const auto start = std::chrono::steady_clock::now();
      const std::clock_t cpu_start = std::clock();
      interp::grow(binding, mesh, query, roots, guides.strands, options, strands);
      cpu_times.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    }
    std::vector<uint64_t> examples;
    const size_t inside = check::count_points_inside(strands, query, 0.0f, 1, examples);
    const double seconds = median(times), rate = double(strands.point_count()) / seconds;
    std::printf("%-11s %11.1f %11.1f %11.1f %14.3e %18.3e %14zu\n", name, seconds * 1e3,
                *std::min_element(times.begin(), times.end()) * 1e3, *std::max_element(times.begin(), times.end()) * 1e3,
                rate, double(strands.point_count()) / median(cpu_times) * kThreads, inside);
    char line[256];
    std::snprintf(line, sizeof line, "PLUME_GROWTH method=%s strands=%zu points=%d threads=%d median_s=%.6f points_per_s=%.4e",
                  name, strands.strand_count(), kPoints, kThreads, seconds, rate);
    lines.push_back(line);
    lines.push_back(std::string("  ") + name + ": " + std::to_string(double(stats.steps) / double(strands.strand_count())) +
                    " steps per strand, " + stats.summary() +
                    (options.separate ? "; the separation pass: " + std::to_string(stats.separated_pairs) +
                                            " segment pairs found, " + std::to_string(stats.unseparated_pairs) + " left after " +
                                            std::to_string(stats.separation_sweeps) + " sweeps"
                                      : std::string()));
  }
  std::printf("\n");
  for (const std::string &line : lines) std::printf("%s\n", line.c_str());
  return 0;
}
