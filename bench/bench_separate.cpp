// The separation pass on the real job: Sintel's head and 228 guides, strands scattered on her scalp
// as bench_sintel does, streamline growth at the demo's 12 points per strand, two threads; grown
// with and without the pass (interp/separate.h), the crossings of each as the checker counts them at
// its default tolerance, and the CPU seconds of each grow.
// Usage: bench_separate [STRANDS [POINTS]]   (default 30000 strands, 12 points)
#include <omp.h>

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

int main(int argc, char **argv) {
  const int64_t count = argc > 1 ? std::atoll(argv[1]) : 30000;
  const int points = argc > 2 ? std::atoi(argv[2]) : 12;
  if (count < 2 || count > 10000000 || points < 2 || points > 1000) {
    std::fprintf(stderr, "usage: bench_separate [STRANDS in 2..1e7 [POINTS in 2..1000]]\n");
    return 2;
  }
  omp_set_num_threads(2);
  const Mesh mesh = bench::sintel_mesh();
  const MeshQuery query(mesh);
  const Guides guides = bench::sintel_guides(query);
  const Roots roots = bench::sintel_scalp_roots(mesh, guides, count);
  InterpolationSettings settings;
  settings.method = InterpolationSettings::Method::streamline;
  const interp::Binding binding = interp::bind(mesh, guides, roots, settings);
  std::printf("The separation pass on Sintel: %zu guides, %zu strands x %d points, 2 threads (%d cores)\n\n",
              guides.size(), roots.size(), points, omp_get_num_procs());
  std::printf("%-9s %10s %10s %12s %11s %14s %11s\n", "pass", "wall s", "CPU s", "transversal", "touching",
              "largest angle", "inside");
  for (const bool separate : {false, true}) {
    interp::GrowOptions options;
    options.points_per_strand = points;
    options.separate = separate;
    interp::GrowStats stats;
    options.r_stats = &stats;
    StrandSet strands;
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    interp::grow(binding, mesh, query, roots, guides.strands, options, strands);
    const double cpu = double(std::clock() - cpu_start) / CLOCKS_PER_SEC;
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const check::CrossingCount crossings =
        check::count_crossings(strands, check::crossing_tolerance_for(strands, check::CheckOptions{}), 0);
    std::vector<uint64_t> examples;
    const size_t inside = check::count_points_inside(strands, query, 0.0f, 0, examples);
    std::printf("%-9s %10.2f %10.2f %12zu %11zu %14.1f %11zu\n", separate ? "with" : "without", wall, cpu,
                crossings.transversal_pairs, crossings.touching_pairs, crossings.largest_angle_degrees, inside);
    if (separate)
      std::printf("\n  the pass: %lld segment pairs found, %lld left within the tolerance, %lld points moved, %d sweeps, "
                  "largest move %.3g (%.3g of the median segment)\n",
                  static_cast<long long>(stats.separated_pairs), static_cast<long long>(stats.unseparated_pairs),
                  static_cast<long long>(stats.separation_points_moved), stats.separation_sweeps,
                  double(stats.separation_largest_move),
                  double(stats.separation_largest_move) / (1e3 * double(crossings.tolerance)));
  }
  return 0;
}
