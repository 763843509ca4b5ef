// The layering pass's warm start on the bird of grooms/bird/ with layers on (feathers.layers), the
// stems simulated as `plume regrow` simulates them and the skin pass warm in both runs: frames
// 1..last grown twice, each frame's layering pass stateless (the smallest turn that clears, from no
// turn) and from the frame before (the warm start). Per frame: the coat's time (grow, skin pass and
// layering), the feathers lifted, shrunk and left under, the vane pairs meeting (check/vanes.h, 0 is
// the promise); per frame step: the feathers whose layering turn changes by more than 0.05 radians,
// the largest jump of a vane vertex in its follicle's skin frame in rachis widths (as plume check
// --frames measures popping) and that of the other feathers. The first frame has no frame before,
// so both runs take the same time there: the summary gives it apart from the later frames' median.
// Usage: bench_layering_warm_start [last_frame, default 12] [follicles, default 1000] [folder]: with a
// folder, each frame's vanes are written there as stateless.####.obj and warm.####.obj, for
// `plume check --groom ... --frames` (the bird's groom with layers on, the proxy's follicle count).
#include <omp.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <cstdlib>
#include <unistd.h>
#include <vector>

#include "app/pipeline.h"
#include "bench_bird.h"
#include "check/vanes.h"
#include "feathers/coat.h"
#include "groom/mesh_query.h"
#include "io/feather_writers.h"
#include "io/groom_file.h"

using namespace plume;

namespace {

struct Frame {
  double seconds = 0.0;  // the coat's grow
  int64_t lifted = 0, shrunk = 0, under = 0;
  int64_t pairs = 0;  // vane pairs meeting
  // Against the frame before (frames after the first):
  int jumps = 0;               // feathers whose layering turn changed by more than 0.05 radians
  double largest = 0.0;        // the largest vertex jump, rachis widths
  double largest_other = 0.0;  // the same over the feathers that did not jump
  double load = 0.0;           // the 1-minute load average as the frame ended
};

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  const size_t m = values.size() / 2;
  return values.size() % 2 ? values[m] : 0.5 * (values[m - 1] + values[m]);
}

}  // namespace

int main(int argc, char **argv) {
  const int last = argc > 1 ? std::atoi(argv[1]) : 12;
  const int64_t follicles = argc > 2 ? std::atoll(argv[2]) : 1000;
  const std::string out = argc > 3 ? std::string(argv[3]) + "/" : std::string();
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  GroomDesc groom = io::read_groom_file(folder + "bird.groom.yaml");
  groom.feathers.layers = true;
  PipelineOptions options;
  options.strand_count = 0;
  options.simulation_start = 1;
  Pipeline pipeline(groom, options);
  const feathers::Coat coat(pipeline.rest_mesh(), pipeline.guides(), groom.feathers,
                            feathers::scatter_follicles(pipeline.rest_mesh(), groom.feathers.follicles, {}, follicles));
  const size_t n = coat.size();
  const feathers::FeatherRanges ranges = coat.ranges();
  io::FeatherWriteOptions write;
  for (const FeatherTemplate &t : groom.feathers.templates) write.template_names.push_back(t.name);

  std::array<std::vector<Frame>, 2> frames;
  bench::TwoRuns runs;
  runs.stateless_skin_warm = true;
  runs.warm_layers = true;
  bench::grow_twice(
      pipeline, coat, last, runs,
      [&](const bench::GrownFrame &g) {
        const feathers::CoatFrame &b = *g.now;
        Frame f;
        f.seconds = g.seconds;
        f.lifted = b.layering.lifted;
        f.shrunk = b.layering.unresolved;
        f.under = b.layering.left_under;
        f.pairs = check::check_vanes(b.vanes.positions, b.vanes.triangles, b.vanes.triangle_feathers).feather_pairs;
        if (g.before) {
          const feathers::CoatFrame &a = *g.before;
          for (size_t i = 0; i < n; ++i) {
            const bool jumped = std::abs(b.layer_state.turns[i] - a.layer_state.turns[i]) > 0.05f;
            f.jumps += jumped ? 1 : 0;
            const double jump = bench::skin_frame_jump(a, b, ranges, i, coat.shapes()[i].main.rachis_width);
            if (jump > 10.0 && std::getenv("PLUME_BENCH_TRACE"))
              std::printf("  %s frame %d feather %zu (id %llu): %.2f widths; skin lift %.4f -> %.4f, scale %.3f -> "
                          "%.3f; layering turn %.4f -> %.4f, scale %.3f -> %.3f, yaw %.4f -> %.4f\n",
                          g.run ? "warm" : "stateless", g.frame, i, (unsigned long long)coat.ids()[i], jump,
                          a.skin_pass.lifts[i], b.skin_pass.lifts[i], a.skin_pass.scales[i], b.skin_pass.scales[i],
                          a.layer_state.turns[i], b.layer_state.turns[i], a.layer_state.scales[i],
                          b.layer_state.scales[i], a.layer_state.yaws[i], b.layer_state.yaws[i]);
            f.largest = std::max(f.largest, jump);
            if (!jumped) f.largest_other = std::max(f.largest_other, jump);
          }
        }
        double load[3] = {0, 0, 0};
        getloadavg(load, 3);
        f.load = load[0];
        frames[size_t(g.run)].push_back(f);
        if (!out.empty()) {
          char name[64];
          std::snprintf(name, sizeof name, "%s.%04d.obj", g.run ? "warm" : "stateless", g.frame);
          io::write_vane_mesh(out + name, b.vanes, write);
        }
      },
      [](int frame) { std::fprintf(stderr, "frame %d done\n", frame); });
  std::printf("bench_layering_warm_start: the bird in layers, %zu feathers, frames 1-%d (stems simulated), %d threads, "
              "%ld cores\n",
              n, last, omp_get_max_threads(), sysconf(_SC_NPROCESSORS_ONLN));
  std::printf("frame | stateless: s lifted shrunk under pairs jumps largest other | warm start: s lifted shrunk under "
              "pairs jumps largest other | load\n");
  for (size_t k = 0; k < frames[0].size(); ++k) {
    std::printf("%5zu |", k + 1);
    for (int mode = 0; mode < 2; ++mode) {
      const Frame &f = frames[size_t(mode)][k];
      std::printf(" %6.2f %5lld %5lld %5lld %3lld %4d %6.2f %6.2f |", f.seconds, (long long)f.lifted,
                  (long long)f.shrunk, (long long)f.under, (long long)f.pairs, f.jumps, f.largest, f.largest_other);
    }
    std::printf(" %.1f\n", frames[1][k].load);
  }
  for (int mode = 0; mode < 2; ++mode) {
    const std::vector<Frame> &fs = frames[size_t(mode)];
    std::vector<double> later;
    int jumps = 0, most_jumps = 0, steps_over_10 = 0;
    double largest = 0.0, largest_other = 0.0;
    int64_t pairs = 0;
    for (size_t k = 0; k < fs.size(); ++k) {
      pairs = std::max(pairs, fs[k].pairs);
      if (k == 0) continue;
      later.push_back(fs[k].seconds);
      jumps += fs[k].jumps;
      most_jumps = std::max(most_jumps, fs[k].jumps);
      largest = std::max(largest, fs[k].largest);
      largest_other = std::max(largest_other, fs[k].largest_other);
      steps_over_10 += fs[k].largest > 10.0 ? 1 : 0;
    }
    std::printf("%s: first frame %.2f s, later frames %.2f s (median of %zu); turns jumping > 0.05 rad: %d in all, at "
                "most %d per step; largest jump %.2f rachis widths, others %.2f; steps above 10 widths: %d of %zu; "
                "vane pairs at most %lld\n",
                mode == 0 ? "stateless " : "warm start", fs.empty() ? 0.0 : fs[0].seconds, median(later), later.size(),
                jumps, most_jumps, largest, largest_other, steps_over_10, later.size(), (long long)pairs);
  }
  return 0;
}
