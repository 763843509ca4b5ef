// Streamline-ratio throughput at 100k strands x 32 points from 400 synthetic guides (k = 4, one
// partial parting), its ratio to the fur scheme in the same run, and the binding time of 100k roots
// with 400 guides and two partial partings. Medians of repeated runs.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <thread>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/test_fixtures.h"
#include "groom/roots.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"

using namespace plume;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

/// Median wall-clock seconds, and median CPU seconds summed over threads (r_cpu).
template <class F>
double time_median(int runs, F &&f, double *r_cpu = nullptr) {
  std::vector<double> times, cpu_times;
  for (int run = 0; run < runs; ++run) {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    f();
    cpu_times.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  if (r_cpu) *r_cpu = median(cpu_times);
  return median(times);
}

/// A partial parting: a meridian arc on the northern cap from polar angle 0.15 to `end` at longitude `phi`.
PartingLine meridian(const std::string &name, float phi, float end) {
  PartingLine line;
  line.name = name;
  for (int i = 0; i <= 20; ++i) {
    const float theta = 0.15f + (end - 0.15f) * float(i) / 20.0f;
    line.points.emplace_back(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi), std::cos(theta));
  }
  line.gamma = 2.0f;
  return line;
}

}  // namespace

int main() {
  const Mesh mesh = test::make_sphere(1.0f, 96, 192, test::PoleAxis::z, false);
  const MeshQuery query(mesh);
  std::vector<bool> cap(mesh.triangle_count());
  for (size_t f = 0; f < mesh.triangle_count(); ++f)
    cap[f] = mesh.positions[size_t(mesh.triangles[f][0])].z() > 0.0f;

  // 400 guides over the northern hemisphere: 32-point arcs leaving along the normal and bending
  // towards the surface tangent, lengths 0.8 to 1.2.
  const Roots guide_roots = scatter_roots(mesh, 400, 99, cap);
  StrandSet strands;
  for (size_t g = 0; g < guide_roots.size(); ++g) {
    const SurfaceFrame frame = surface_frame(mesh, guide_roots.points[g]);
    const float length = 0.8f + 0.4f * hash_to_unit(hash64(g)), kappa = 1.0f;
    std::vector<Eigen::Vector3f> points;
    for (int i = 0; i < 32; ++i) {
      const float s = length * float(i) / 31.0f;
      points.push_back(frame.to_world(Eigen::Vector3f((1.0f - std::cos(kappa * s)) / kappa, 0.0f, std::sin(kappa * s) / kappa)));
    }
    strands.append(points, g);
  }
  const Guides guides = bind_guides(query, strands, "synthetic");
  const Roots roots = scatter_roots(mesh, 100000, 1, cap);

  PartingSettings one_line;
  one_line.lines = {meridian("part", 0.0f, 0.9f)};
  PartingSettings two_lines;
  two_lines.lines = {meridian("left", 0.0f, 0.9f), meridian("right", 2.5f, 0.7f)};

  std::printf("Synthetic groom: %zu guides x 32 points on a sphere of %zu triangles, %zu roots, k = 4\n",
              guides.size(), mesh.triangle_count(), roots.size());
  std::printf("cores (OpenMP threads): %d, hardware threads: %u\n\n", omp_get_max_threads(),
              std::thread::hardware_concurrency());

  double field_seconds = 0.0;
  {
    const auto start = std::chrono::steady_clock::now();
    const partings::PartingField field(mesh, guides, one_line);
    field_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf("%-44s %10.1f ms (once)\n", "parting field, 1 partial line", field_seconds * 1e3);
    double fur_rate = 0.0;
    std::printf("%-44s %10s %14s %8s %22s\n", "growth, 100k x 32 points (median of 3)", "ms", "points/s", "vs fur",
                "points/CPU-s x cores");
    for (const auto method : {InterpolationSettings::Method::fur, InterpolationSettings::Method::streamline}) {
      InterpolationSettings settings;
      settings.method = method;
      const interp::Binding binding = interp::bind(mesh, guides, roots, settings, &field);
      interp::GrowOptions options;
      StrandSet grown;
      double cpu = 0.0;
      const double seconds =
          time_median(3, [&] { interp::grow(binding, mesh, query, roots, guides.strands, options, grown); }, &cpu);
      const double rate = double(grown.point_count()) / seconds;
      if (method == InterpolationSettings::Method::fur) fur_rate = rate;
      std::printf("  %-42s %10.1f %14.3e %7.2fx %22.3e\n",
                  method == InterpolationSettings::Method::fur ? "fur" : "streamline", seconds * 1e3, rate,
                  rate / fur_rate, double(grown.point_count()) / cpu * omp_get_max_threads());
      if (method == InterpolationSettings::Method::streamline) {
        interp::GrowStats stats;
        options.r_stats = &stats;
        interp::grow(binding, mesh, query, roots, guides.strands, options, grown);
        std::printf("    %s\n", stats.summary().c_str());
      }
    }
  }
  {
    const auto start = std::chrono::steady_clock::now();
    const partings::PartingField field(mesh, guides, two_lines);
    const double build = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    InterpolationSettings settings;
    double bind_cpu = 0.0;
    const double bind_seconds = time_median(3, [&] { interp::bind(mesh, guides, roots, settings, &field); }, &bind_cpu);
    std::printf("\n%-44s %10.1f ms (once)\n", "parting field, 2 partial lines", build * 1e3);
    std::printf("%-44s %10.1f ms (median of 3; %.1f CPU-ms)\n", "bind 100k roots, 400 guides, 2 partial lines",
                bind_seconds * 1e3, bind_cpu * 1e3);
    std::printf("%-44s %10.1f ms\n", "field + bind", (build + bind_seconds) * 1e3);
  }
  return 0;
}
