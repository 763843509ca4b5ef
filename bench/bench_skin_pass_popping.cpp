// The skin pass's popping on the shipped bird (grooms/bird, its groom as shipped, the stems
// simulated as `plume regrow` simulates them): frames 1-48 grown twice, each feather's turn the
// smallest that clears the skin (stateless), and from the frame before (the warm start). Per frame
// step: the feathers whose skin-pass lift changes by more than 0.05 radians, the largest jump of a
// vane vertex in its follicle's skin frame in rachis widths (as plume check --previous measures
// popping), the largest jump of the other feathers, the vane vertices below the skin, and the
// coat's time. Usage: bench_skin_pass_popping [last_frame, default 48] [follicles, default the groom's].
#include <omp.h>

#include <cstdio>
#include <cstdlib>
#include <unistd.h>

#include "app/pipeline.h"
#include "bench_bird.h"
#include "feathers/coat.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"

using namespace plume;

namespace {

struct Step {
  int jumps = 0;             // feathers whose skin-pass lift changed by more than 0.05 radians
  double largest = 0.0;      // the largest vertex jump, rachis widths
  double largest_other = 0.0;  // the same over the feathers that did not jump
  int64_t below = 0;         // vane vertices below the skin (signed distance < 0)
  double seconds = 0.0;      // the coat's grow at this frame
};

}  // namespace

int main(int argc, char **argv) {
  const int last = argc > 1 ? std::atoi(argv[1]) : 48;
  const int64_t follicles = argc > 2 ? std::atoll(argv[2]) : -1;
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  const GroomDesc groom = io::read_groom_file(folder + "bird.groom.yaml");
  PipelineOptions options;
  options.strand_count = 0;
  options.simulation_start = 1;
  Pipeline pipeline(groom, options);
  feathers::Coat coat(pipeline.rest_mesh(), pipeline.guides(), groom.feathers,
                      feathers::scatter_follicles(pipeline.rest_mesh(), groom.feathers.follicles, {}, follicles));
  const size_t n = coat.size();
  const feathers::FeatherRanges ranges = coat.ranges();
  std::vector<float> widths(n);
  for (size_t i = 0; i < n; ++i) widths[i] = coat.shapes()[i].main.rachis_width;

  std::array<std::vector<Step>, 2> steps;
  bench::grow_twice(
      pipeline, coat, last, bench::TwoRuns{},
      [&](const bench::GrownFrame &g) {
        if (!g.before) return;
        const feathers::CoatFrame &a = *g.before, &b = *g.now;
        Step step;
        step.seconds = g.seconds;
        for (size_t i = 0; i < n; ++i) {
          const bool jumped = std::abs(b.skin_pass.lifts[i] - a.skin_pass.lifts[i]) > 0.05f;
          step.jumps += jumped ? 1 : 0;
          const double jump = bench::skin_frame_jump(a, b, ranges, i, widths[i]);
          if (jumped && std::getenv("PLUME_BENCH_TRACE"))
            std::printf("  %s frame %d feather %zu (id %llu): lift %.4f -> %.4f, scale %.3f -> %.3f, %.2f widths\n",
                        g.run ? "warm" : "stateless", g.frame, i, (unsigned long long)coat.ids()[i], a.skin_pass.lifts[i],
                        b.skin_pass.lifts[i], a.skin_pass.scales[i], b.skin_pass.scales[i], jump);
          step.largest = std::max(step.largest, jump);
          if (!jumped) step.largest_other = std::max(step.largest_other, jump);
        }
        // As plume check counts them: below -eps, eps = 1e-5 x the skin's bounding-box diagonal.
        Eigen::AlignedBox3f box;
        for (const Eigen::Vector3f &p : g.posed->positions) box.extend(p);
        const float eps = 1e-5f * box.diagonal().norm();
        int64_t below = 0;
#pragma omp parallel for reduction(+ : below) schedule(dynamic, 16)
        for (int64_t f = 0; f < int64_t(n); ++f) {
          int hint = coat.follicles()[size_t(f)].triangle;
          for (int64_t v = ranges.first_vertex[size_t(f)]; v < ranges.first_vertex[size_t(f) + 1]; ++v) {
            SurfacePoint closest;
            below += g.grid->signed_distance(b.vanes.positions[size_t(v)], hint, closest) < -eps ? 1 : 0;
            hint = closest.triangle;
          }
        }
        step.below = below;
        steps[size_t(g.run)].push_back(step);
      },
      [](int) {});
  double load[3] = {0, 0, 0};
  getloadavg(load, 3);
  std::printf("bench_skin_pass_popping: the bird, %zu feathers, frames 1-%d, %d threads, %ld cores, load %.1f\n", n,
              last, omp_get_max_threads(), sysconf(_SC_NPROCESSORS_ONLN), load[0]);
  std::printf("step   | stateless: jumps largest other below s | warm start: jumps largest other below s\n");
  std::array<Step, 2> worst;
  std::array<double, 2> total_seconds = {0, 0};
  std::array<int, 2> total_jumps = {0, 0};
  for (size_t k = 0; k < steps[0].size(); ++k) {
    std::printf("%2zu-%2zu  |", k + 1, k + 2);
    for (int mode = 0; mode < 2; ++mode) {
      const Step &s = steps[size_t(mode)][k];
      std::printf(" %3d %6.2f %5.2f %5lld %5.2f |", s.jumps, s.largest, s.largest_other, (long long)s.below, s.seconds);
      worst[size_t(mode)].jumps = std::max(worst[size_t(mode)].jumps, s.jumps);
      worst[size_t(mode)].largest = std::max(worst[size_t(mode)].largest, s.largest);
      worst[size_t(mode)].largest_other = std::max(worst[size_t(mode)].largest_other, s.largest_other);
      worst[size_t(mode)].below = std::max(worst[size_t(mode)].below, s.below);
      total_seconds[size_t(mode)] += s.seconds;
      total_jumps[size_t(mode)] += s.jumps;
    }
    std::printf("\n");
  }
  for (int mode = 0; mode < 2; ++mode)
    std::printf("%s: at most %d feathers jump per step (%d in all), largest jump %.2f rachis widths, others %.2f, at "
                "most %lld vertices below the skin, coat %.3f s per frame (mean)\n",
                mode == 0 ? "stateless " : "warm start", worst[size_t(mode)].jumps, total_jumps[size_t(mode)],
                worst[size_t(mode)].largest, worst[size_t(mode)].largest_other, (long long)worst[size_t(mode)].below,
                total_seconds[size_t(mode)] / double(steps[size_t(mode)].size()));
  return 0;
}
