// Feathers kept apart in layers on the bird of grooms/bird/ (feathers.layers): the order's time at
// binding, then regrow plus layering per frame on posed frames of its sequence, for coats of 1,000
// and 5,000 feathers (frames 1, 12 and 24, 1 and 2 threads) and 25,000 (frame 1, 2 threads); the
// feathers lifted, shrunk and left under a lower one (no turn takes them out), and the vane
// checker's time and feather pairs on the layered frame (0 is the promise), and the order check's
// time and layer-order violations there (check/feather_layers.h, against the frozen order); the
// machine's load (1-minute average) as each row ends. Targets: under 1 s per frame at 5,000
// feathers and under 5 s at 25,000, on 2 cores.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <string>
#include <thread>
#include <unordered_map>
#include <vector>

#include "bench_bird.h"
#include "check/feather_layers.h"
#include "check/vanes.h"
#include "feathers/coat.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"
#include "skin/skin_grid.h"

using namespace plume;

namespace {

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// The 1-minute load average (Linux), or -1.
double load_average() {
  std::ifstream file("/proc/loadavg");
  double load = -1.0;
  file >> load;
  return file ? load : -1.0;
}

}  // namespace

// Arguments (all optional), to time one part: feather counts, then "--frames" and frame numbers, then
// "--threads" and thread counts; e.g. `bench_layering 1000 --frames 1 --threads 2`. `--frames 0`
// times the binding alone (the order at rest), with the threads OpenMP is given.
int main(int argc, char **argv) {
  std::vector<int> counts, frames, thread_counts;
  std::vector<int> *into = &counts;
  for (int a = 1; a < argc; ++a) {
    const std::string arg = argv[a];
    if (arg == "--frames") into = &frames;
    else if (arg == "--threads") into = &thread_counts;
    else into->push_back(std::stoi(arg));
  }
  const bool chosen = !counts.empty();
  if (counts.empty()) counts = {1000, 5000, 25000};
  const bench::Bird bird;
  const std::string &folder = bird.folder;
  const GroomDesc &groom = bird.groom;
  const Mesh &rest = bird.rest;
  const Guides &stems = bird.stems;
  const int hardware = int(std::thread::hardware_concurrency());
  std::printf("Feathers in layers on the bird (grooms/bird, feathers.layers on)\n");
  std::printf("hardware threads: %d; one run per row; posed frames of the sequence (stems carried by the skin)\n\n",
              hardware);
  std::printf("%-9s %6s %8s %8s %10s %10s %9s %9s %9s %10s %10s %8s %10s %8s %6s\n", "feathers", "frame", "threads",
              "bind s", "frame s", "layering s", "lifted", "shrunk", "under", "check s", "pairs", "order s",
              "violations", "target", "load");
  for (const int count : counts) {
    FeatherDesc desc = groom.feathers;
    desc.layers = true;
    desc.follicles.count = count;
    const auto bind_start = std::chrono::steady_clock::now();
    const feathers::Coat coat(rest, stems, desc, feathers::scatter_follicles(rest, desc.follicles, {}));
    const double bind = seconds_since(bind_start);
    FeatherDesc plain = desc;
    plain.layers = false;
    const feathers::Coat unlayered(rest, stems, plain, feathers::scatter_follicles(rest, plain.follicles, {}));
    std::unordered_map<uint64_t, int64_t> rank;
    for (size_t i = 0; i < coat.size(); ++i) rank.emplace(coat.ids()[i], coat.layer_order().rank[i]);
    // The largest coat once only (frame 1, 2 threads) unless asked otherwise: it takes minutes.
    std::vector<int> count_frames = frames, count_threads = thread_counts;
    const bool every = chosen || count < 25000;
    if (count_frames.empty()) count_frames = every ? std::vector<int>{1, 12, 24} : std::vector<int>{1};
    if (count_threads.empty()) count_threads = every ? std::vector<int>{1, 2} : std::vector<int>{2};
    if (count_frames == std::vector<int>{0}) {
      std::printf("%-9d %6s %8d %8.2f %10s %10s %9s %9s %9s %10s %10s %8s %10s %8s %6.2f\n", count, "-",
                  omp_get_max_threads(), bind, "-", "-", "-", "-", "-", "-", "-", "-", "-", "", load_average());
      std::fflush(stdout);
      continue;
    }
    for (const int frame : count_frames) {
      char name[32];
      std::snprintf(name, sizeof name, "anim/bird.%04d.obj", frame);
      const Mesh posed = io::read_obj_pose(folder + name, rest);
      const StrandSet posed_stems = carry_guides(rest, posed, stems);
      for (const int threads : count_threads) {
        if (threads > hardware) continue;
        omp_set_num_threads(threads);
        feathers::CoatFrame result, plain_result;
        auto start = std::chrono::steady_clock::now();
        {
          const MeshQuery query(posed);
          const skin::SkinGrid grid(posed, query);
          unlayered.grow(posed, query, posed_stems, plain_result, &grid);
        }
        const double plain_time = seconds_since(start);
        start = std::chrono::steady_clock::now();
        {
          const MeshQuery query(posed);
          const skin::SkinGrid grid(posed, query);
          coat.grow(posed, query, posed_stems, result, &grid);
        }
        const double time = seconds_since(start);
        start = std::chrono::steady_clock::now();
        const check::VaneCheckReport report =
            check::check_vanes(result.vanes.positions, result.vanes.triangles, result.vanes.triangle_feathers);
        const double check_time = seconds_since(start);
        start = std::chrono::steady_clock::now();
        check::LayerOrderReport order;
        {
          const MeshQuery query(posed);
          order = check::layer_order_violations(
              check::vane_overlaps(result.vanes.positions, result.vanes.triangles, result.vanes.triangle_feathers,
                                   posed, query),
              rank);
        }
        const double order_time = seconds_since(start);
        const double limit = count == 5000 ? 1.0 : count == 25000 ? 5.0 : 0.0;
        const bool target = limit > 0.0 && threads == 2;
        std::printf("%-9d %6d %8d %8.2f %10.2f %10.2f %9lld %9lld %9lld %10.2f %10lld %8.2f %10lld %8s %6.2f\n",
                    count, frame, threads, bind, time, time - plain_time, (long long)result.layering.lifted,
                    (long long)result.layering.unresolved, (long long)result.layering.left_under, check_time,
                    (long long)report.feather_pairs, order_time, (long long)order.violations,
                    target ? (time <= limit ? "met" : "NOT met") : "", load_average());
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
