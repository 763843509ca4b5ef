// Cost of the partings and of the checker on the Sintel head:
// - building a PartingField with 400 guides and two partial partings (the geodesic fields), and
//   binding 100k roots with it (the 2 s binding budget), against binding without partings;
// - checking 100k regrown strands x 32 points (skin, crossings, guide deviation).
// Figures are medians of 3 runs.
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <functional>
#include <string>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "check/check.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

using namespace plume;

namespace {

/// Median wall-clock seconds of 3 runs; r_cpu gets the median process CPU seconds (all threads),
/// the fairer figure on a machine shared with other jobs.
double median_seconds(const std::function<void()> &run, double *r_cpu = nullptr) {
  std::vector<double> times, cpu;
  for (int i = 0; i < 3; ++i) {
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    run();
    cpu.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  std::sort(times.begin(), times.end());
  std::sort(cpu.begin(), cpu.end());
  if (r_cpu) *r_cpu = cpu[1];
  return times[1];
}

PartingLine side_parting(float side) {
  PartingLine line;
  line.name = side > 0 ? "right" : "left";
  line.gamma = 2.0f;
  for (const Eigen::Vector3f &p : {Eigen::Vector3f(3.4f, 40.6f, 9.2f), Eigen::Vector3f(3.2f, 43.6f, 5.2f),
                                   Eigen::Vector3f(2.6f, 45.4f, 1.0f), Eigen::Vector3f(1.6f, 45.6f, -3.0f)})
    line.points.emplace_back(side * p.x(), p.y(), p.z());
  return line;
}

}  // namespace

int main(int argc, char **argv) {
  // --crossings: only the crossing count (the checker's costliest part).
  const bool crossings_only = argc > 1 && std::string(argv[1]) == "--crossings";
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/";
  const Mesh mesh = io::read_obj_mesh(folder + "sintel.obj");
  const MeshQuery query(mesh);
  const Guides sintel = bind_guides(query, io::read_strands(folder + "sintel_guides.hair"), "sintel_guides.hair");
  std::vector<Eigen::Vector3f> guide_roots;
  for (size_t g = 0; g < sintel.size(); ++g) guide_roots.push_back(sintel.strands.points(g)[0]);
  const std::vector<bool> scalp = triangles_near(mesh, guide_roots, 2.0);
  std::printf("Sintel head: %zu triangles; %d cores, %d threads\n", mesh.triangle_count(), omp_get_num_procs(),
              omp_get_max_threads());

  const Roots roots = scatter_roots(mesh, 100000, 7, scalp);
  InterpolationSettings interpolation;
  std::printf("%-58s %8s %8s\n", "", "wall s", "CPU s");
  if (!crossings_only) {
    // 400 guides standing on the scalp (only their roots matter to the partings).
    const Roots guide_points = scatter_roots(mesh, 400, 11, scalp);
    StrandSet standing;
    for (size_t g = 0; g < guide_points.size(); ++g) {
      const Eigen::Vector3f p = surface_position(mesh, guide_points.points[g]);
      const Eigen::Vector3f n = surface_normal(mesh, guide_points.points[g]);
      const Eigen::Vector3f strand[2] = {p, p + 10.0f * n};
      standing.append(strand, g);
    }
    const Guides guides400 = bind_guides(query, standing, "standing guides");
    PartingSettings settings;
    settings.lines = {side_parting(1.0f), side_parting(-1.0f)};
    double build_cpu = 0, plain_cpu = 0, parted_cpu = 0;
    const double build = median_seconds([&] { partings::PartingField field(mesh, guides400, settings); }, &build_cpu);
    const double plain_bind = median_seconds([&] { interp::bind(mesh, guides400, roots, interpolation); }, &plain_cpu);
    interp::Binding parted;
    const double parted_bind = median_seconds([&] {
      const partings::PartingField field(mesh, guides400, settings);
      parted = interp::bind(mesh, guides400, roots, interpolation, &field);
    }, &parted_cpu);
    const interp::Binding plain = interp::bind(mesh, guides400, roots, interpolation);
    size_t changed = 0;
    for (size_t i = 0; i < plain.weights.size(); ++i)
      changed += plain.guide_ids[i] != parted.guide_ids[i] || std::abs(plain.weights[i] - parted.weights[i]) > 1e-3f;
    std::printf("%-58s %8.3f %8.3f\n", "PartingField: 400 guides x 2 partial partings (build)", build, build_cpu);
    std::printf("%-58s %8.3f %8.3f\n", "bind: 100k roots, 400 guides, no parting", plain_bind, plain_cpu);
    std::printf("%-58s %8.3f %8.3f  (%.1f%% of slots changed)\n",
                "PartingField + bind: 100k roots, 400 guides, 2 partings", parted_bind, parted_cpu,
                100.0 * double(changed) / double(plain.weights.size()));
  }

  // 100k streamline strands x 32 points from Sintel's 228 guides.
  const interp::Binding binding = interp::bind(mesh, sintel, roots, interpolation);
  interp::GrowOptions options;
  options.points_per_strand = 32;
  StrandSet strands;
  interp::grow(binding, mesh, query, roots, sintel.strands, options, strands);

  double skin_cpu = 0, cross_cpu = 0, all_cpu = 0;
  check::CrossingCount crossings;
  const double cross = median_seconds([&] { crossings = check::count_crossings(strands, 0.001f, 8); }, &cross_cpu);
  std::printf("%-58s %8.3f %8.3f  (%zu pairs: %zu transversal, %zu touching; %.1f piece pairs examined per segment)\n",
              "check: crossings at tolerance 0.001, 100k x 32", cross, cross_cpu, crossings.pairs,
              crossings.transversal_pairs, crossings.touching_pairs,
              double(crossings.segment_pairs_examined) / double(strands.point_count() - strands.strand_count()));
  check::CrossingCount by_default;
  const float default_tolerance = check::crossing_tolerance_for(strands, check::CheckOptions{});
  double default_cpu = 0;
  const double default_wall =
      median_seconds([&] { by_default = check::count_crossings(strands, default_tolerance, 8); }, &default_cpu);
  std::printf("%-58s %8.3f %8.3f  (tolerance %.3g: %zu pairs, %zu transversal)\n",
              "check: crossings at the default tolerance, 100k x 32", default_wall, default_cpu, double(default_tolerance),
              by_default.pairs, by_default.transversal_pairs);
  if (crossings_only) return 0;

  std::vector<uint64_t> examples;
  size_t inside = 0;
  const double skin = median_seconds([&] { inside = check::count_points_inside(strands, query, 0.0f, 8, examples); }, &skin_cpu);
  check::CheckOptions check_options;
  check_options.crossing_tolerance = 0.001f;
  check::CheckReport report;
  check::CheckInputs inputs;
  inputs.guides = &sintel;
  const double all = median_seconds([&] { report = check::check_strands(strands, query, check_options, inputs); }, &all_cpu);
  std::printf("%-58s %8.3f %8.3f  (%zu points inside)\n", "check: points inside the skin, 100k x 32", skin, skin_cpu,
              inside);
  std::printf("%-58s %8.3f %8.3f  (%zu crossing pairs)\n", "check_strands: all checks with guides, 100k x 32", all,
              all_cpu, report.crossings.pairs);
  return 0;
}
