// Feathers kept apart in layers on the bird of grooms/bird/ (feathers.layers): the order's time at
// binding, then regrow plus layering per frame on posed frames of its sequence, 1 and 2 threads,
// for coats of 1,000 and 5,000 feathers; the feathers lifted and shrunk, and the vane checker's
// time and feather pairs on the layered frame (0 is the promise). Targets: under 1 s per frame at
// 5,000 feathers on 2 cores.
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

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

}  // namespace

int main() {
  const std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  const GroomDesc groom = io::read_groom_file(folder + "bird.groom.yaml");
  const Mesh rest = io::read_obj_mesh(folder + "bird.obj");
  const MeshQuery rest_query(rest);
  const Guides stems = bind_guides(rest_query, io::read_strands(folder + "stems.obj"), "stems.obj");
  const int hardware = int(std::thread::hardware_concurrency());
  std::printf("Feathers in layers on the bird (grooms/bird, feathers.layers on)\n");
  std::printf("hardware threads: %d; one run per row; posed frames of the sequence (stems carried by the skin)\n\n",
              hardware);
  std::printf("%-9s %6s %8s %8s %10s %10s %9s %9s %10s %10s %8s\n", "feathers", "frame", "threads", "bind s",
              "frame s", "layering s", "lifted", "shrunk", "check s", "pairs", "target");
  for (const int count : {1000, 5000}) {
    FeatherDesc desc = groom.feathers;
    desc.layers = true;
    desc.follicles.count = count;
    const auto bind_start = std::chrono::steady_clock::now();
    const feathers::Coat coat(rest, stems, desc, feathers::scatter_follicles(rest, desc.follicles, {}));
    const double bind = seconds_since(bind_start);
    FeatherDesc plain = desc;
    plain.layers = false;
    const feathers::Coat unlayered(rest, stems, plain, feathers::scatter_follicles(rest, plain.follicles, {}));
    for (const int frame : {1, 12, 24}) {
      char name[32];
      std::snprintf(name, sizeof name, "anim/bird.%04d.obj", frame);
      const Mesh posed = io::read_obj_pose(folder + name, rest);
      const StrandSet posed_stems = carry_guides(rest, posed, stems);
      for (const int threads : {1, 2}) {
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
        const bool target = count == 5000 && threads == 2;
        std::printf("%-9d %6d %8d %8.2f %10.2f %10.2f %9lld %9lld %10.2f %10lld %8s\n", count, frame, threads, bind,
                    time, time - plain_time, (long long)result.layering.lifted,
                    (long long)result.layering.unresolved, check_time, (long long)report.feather_pairs,
                    target ? (time <= 1.0 ? "met" : "NOT met") : "");
        std::fflush(stdout);
      }
    }
  }
  return 0;
}
