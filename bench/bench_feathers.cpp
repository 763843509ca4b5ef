// Feathers regrown per frame on the bird of grooms/bird/: 5,000 feathers x 150 barbs (75 per vane)
// x 8 points, curves and vane meshes, on posed frames of its sequence (the left wing open, the neck
// bent). Target: <= 0.5 s per frame on 2 cores. Also 300 barbs per feather, the skin pass's share
// (the same coat without it), the binding, writing the target's frame (binary curves, OBJ vanes),
// and the peak memory; and the target's coat grown into new arrays each frame (as `plume regrow`
// does) rather than into the same ones. The machine may be shared: the CPU seconds, the cores the
// frame got (CPU / wall) and the load average say how much of the wall time waited for a core.
#include <omp.h>
#include <sys/resource.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "bench_bird.h"
#include "feathers/coat.h"
#include "groom/guides.h"
#include "groom/mesh_query.h"
#include "io/feather_writers.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"
#include "skin/skin_grid.h"

using namespace plume;

namespace {

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

double peak_memory_mb() {
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // kB on Linux
}

/// The bird's feather types with `positions` barbs per vane each (spacing = rachis length / positions).
FeatherDesc with_barbs(FeatherDesc desc, int positions) {
  for (FeatherTemplate &t : desc.templates) t.spacing_base = t.spacing_tip = t.rachis_length / float(positions);
  desc.detail.barb_points = 8;
  return desc;
}

/// The 1-minute load average (/proc/loadavg), or -1.
double load_average() {
  std::ifstream file("/proc/loadavg");
  double load = -1.0;
  file >> load;
  return load;
}

struct Timing {
  double wall = 0.0, cpu = 0.0;
};

/// Median wall and CPU seconds of `runs` frames grown on `posed`, into the same arrays, or (`fresh`)
/// into new ones each frame as `plume regrow` does (their allocation and first touch timed too).
Timing time_frames(const feathers::Coat &coat, const Mesh &posed, const StrandSet &stems, int runs,
                   feathers::CoatFrame &r_frame, bool fresh = false) {
  std::vector<double> wall, cpu;
  for (int run = 0; run < runs; ++run) {
    if (fresh) r_frame = feathers::CoatFrame();
    const auto start = std::chrono::steady_clock::now();
    const std::clock_t cpu_start = std::clock();
    // A frame as `plume regrow` grows it: the skin's queries built for the pose, then the coat.
    const MeshQuery query(posed);
    const skin::SkinGrid grid(posed, query);
    coat.grow(posed, query, stems, r_frame, &grid);
    cpu.push_back(double(std::clock() - cpu_start) / CLOCKS_PER_SEC);
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  }
  return {median(wall), median(cpu)};
}

}  // namespace

int main() {
  const bench::Bird bird;
  const std::string &folder = bird.folder;
  const GroomDesc &groom = bird.groom;
  const Mesh &rest = bird.rest;
  const Guides &stems = bird.stems;
  const int hardware = int(std::thread::hardware_concurrency());
  std::printf("Feathers on the bird (grooms/bird): 5,000 feathers, curves (8 points per barb) and vane meshes\n");
  std::printf("hardware threads: %d; medians of 5 frames; posed frame 12 (wing open, neck bending)\n", hardware);
  std::printf("load average at the start: %.2f (cores: CPU s / frame s, the cores the frame got)\n\n", load_average());
  const Mesh posed = io::read_obj_pose(folder + "anim/bird.0012.obj", rest);
  const StrandSet posed_stems = carry_guides(rest, posed, stems);

  std::printf("%-32s %8s %8s %9s %8s %6s %10s %8s\n", "coat", "threads", "bind s", "frame s", "CPU s", "cores",
              "points", "target");
  double target_memory = 0.0;
  std::array<double, 4> written{};
  for (const int positions : {75, 150}) {
    for (const bool lift : {true, false}) {
      FeatherDesc desc = with_barbs(groom.feathers, positions);
      desc.lift = lift;
      FollicleSettings follicles = desc.follicles;
      follicles.count = 5000;
      const auto bind_start = std::chrono::steady_clock::now();
      const feathers::Coat coat(rest, stems, desc, feathers::scatter_follicles(rest, follicles, {}));
      const double bind = std::chrono::duration<double>(std::chrono::steady_clock::now() - bind_start).count();
      for (const int threads : {1, 2}) {
        if (threads > hardware) continue;
        omp_set_num_threads(threads);
        feathers::CoatFrame frame;
        const Timing t = time_frames(coat, posed, posed_stems, 5, frame);
        char label[64];
        std::snprintf(label, sizeof label, "%d barbs/feather%s", 2 * positions, lift ? "" : ", no skin pass");
        const bool target = positions == 75 && lift && threads == 2;
        std::printf("%-32s %8d %8.2f %9.3f %8.3f %6.2f %10zu %8s\n", label, threads, bind, t.wall, t.cpu,
                    t.cpu / t.wall, frame.curves.curves.point_count(),
                    target ? (t.wall <= 0.5 ? "met" : "NOT met") : "");
        if (target) {
          std::printf("%-32s %zu vane vertices, %zu triangles\n", "", frame.vanes.positions.size(),
                      frame.vanes.triangles.size());
          target_memory = peak_memory_mb();
          // Writing the frame as plume regrow does, to binary curves (.hair) and an OBJ of the vanes.
          const std::string folder_out = std::filesystem::temp_directory_path().string();
          const std::string curves_path = folder_out + "/bench_feathers.hair", vanes_path = folder_out + "/bench_vanes.obj";
          std::vector<double> curves_s, vanes_s;
          for (int run = 0; run < 3; ++run) {
            auto start = std::chrono::steady_clock::now();
            io::write_feather_curves(curves_path, frame.curves, {});
            curves_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
            start = std::chrono::steady_clock::now();
            io::write_vane_mesh(vanes_path, frame.vanes, {});
            vanes_s.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
          }
          written = {median(curves_s), median(vanes_s), double(std::filesystem::file_size(curves_path)) / 1e6,
                     double(std::filesystem::file_size(vanes_path)) / 1e6};
          std::filesystem::remove(curves_path);
          std::filesystem::remove(vanes_path);
        }
        if (positions == 75 && lift) {
          // Into the same frame object, emptied before each frame: one frame's arrays at a time.
          const Timing f = time_frames(coat, posed, posed_stems, 5, frame, true);
          std::printf("%-32s %8d %8s %9.3f %8.3f %6.2f %10zu\n", "150 barbs/feather, new arrays", threads, "", f.wall,
                      f.cpu, f.cpu / f.wall, frame.curves.curves.point_count());
        }
      }
    }
  }
  std::printf("\nwriting the target's frame (medians of 3): curves as .hair %.3f s (%.0f MB), vanes as .obj %.3f s (%.0f MB)\n",
              written[0], written[2], written[1], written[3]);
  std::printf("peak memory (resident set): %.0f MB after the target's coat (150 barbs per feather), %.0f MB in all\n",
              target_memory, peak_memory_mb());
  std::printf("load average at the end: %.2f\n", load_average());
  return 0;
}
