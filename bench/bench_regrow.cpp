// Regrowth throughput (strand points per second) on the Sintel groom: 10k and 100k strands x 32
// points from her 228 guides, fur and streamline (the strands as integral curves of the guides'
// field); median of repeated runs (argument 1: how many, default 3).
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <thread>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "interp/interpolate.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume;

namespace {

std::string data_path(const std::string &name) {
  const std::string groom = std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/" + name;
  return std::filesystem::exists(groom) ? groom : std::string(PLUME_SOURCE_DIR) + "/../shared/data/sintel/" + name;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

}  // namespace

int main(int argc, char **argv) {
  const int runs = argc > 1 ? std::max(std::atoi(argv[1]), 1) : 3;
  const Mesh mesh = io::read_obj_mesh(data_path("sintel.obj"));
  const MeshQuery query(mesh);
  const Guides guides = bind_guides(query, io::read_strands(data_path("sintel_guides.hair")), "sintel_guides.hair");
  std::vector<Eigen::Vector3f> guide_roots;
  for (const SurfacePoint &sp : guides.roots) guide_roots.push_back(surface_position(mesh, sp));
  const std::vector<bool> scalp = triangles_near(mesh, guide_roots, 2.0);

  std::printf("Regrowth from the Sintel guides (%zu guides), 32 points per strand\n", guides.size());
  std::printf("cores (OpenMP threads): %d, hardware threads: %u, median of %d runs\n\n", omp_get_max_threads(),
              std::thread::hardware_concurrency(), runs);
  std::printf("%-10s %-11s %12s %16s %10s %18s\n", "strands", "method", "median ms", "points/s", "vs fur",
              "points/CPU-s x cores");
  for (const int64_t count : {int64_t(10000), int64_t(100000)}) {
    const Roots roots = scatter_roots(mesh, count, 1, scalp);
    double fur_rate = 0.0;
    for (const auto method : {InterpolationSettings::Method::fur, InterpolationSettings::Method::streamline}) {
      InterpolationSettings settings;
      settings.method = method;
      const interp::Binding binding = interp::bind(mesh, guides, roots, settings);
      interp::GrowOptions options;
      StrandSet strands;
      std::vector<double> times, cpu_times;
      for (int run = 0; run < runs; ++run) {
        const auto start = std::chrono::steady_clock::now();
        const std::clock_t cpu_start = std::clock();
        interp::grow(binding, mesh, query, roots, guides.strands, options, strands);
        cpu_times.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
        times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
      }
      const double seconds = median(times);
      const double rate = double(strands.point_count()) / seconds;
      // CPU time summed over threads: points per CPU-second times the thread count is what the cores
      // would give unshared (wall-clock figures drop when other processes share the machine).
      const double cpu_rate = double(strands.point_count()) / median(cpu_times) * omp_get_max_threads();
      if (method == InterpolationSettings::Method::fur) fur_rate = rate;
      std::printf("%-10lld %-11s %12.1f %16.3e %9.2fx %18.3e\n", (long long)roots.size(),
                  method == InterpolationSettings::Method::fur ? "fur" : "streamline", seconds * 1e3, rate,
                  rate / fur_rate, cpu_rate);
      if (method == InterpolationSettings::Method::streamline) {
        interp::GrowStats stats;
        options.r_stats = &stats;
        interp::grow(binding, mesh, query, roots, guides.strands, options, strands);
        std::printf("%-22s %s\n", "", stats.summary().c_str());
      }
    }
  }
  return 0;
}
