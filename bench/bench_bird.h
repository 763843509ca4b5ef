// The bird of grooms/bird as the feather benchmarks load it: its groom, its rest mesh (with a query)
// and its guide stems bound to that mesh. Posed frames are read from `folder` + "anim/...". And the
// measurement the popping benchmarks share: the bird's frames grown twice, stateless and from the
// frame before, with each feather's largest jump in its follicle's skin frame.
#pragma once

#include <algorithm>
#include <array>
#include <chrono>
#include <string>

#include "app/pipeline.h"
#include "feathers/coat.h"
#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"
#include "skin/skin_grid.h"

namespace plume::bench {

struct Bird {
  std::string folder = std::string(PLUME_SOURCE_DIR) + "/grooms/bird/";
  GroomDesc groom = io::read_groom_file(folder + "bird.groom.yaml");
  Mesh rest = io::read_obj_mesh(folder + "bird.obj");
  MeshQuery rest_query{rest};  // not copyable: a Bird stays where it is made
  Guides stems = bind_guides(rest_query, io::read_strands(folder + "stems.obj"), "stems.obj");
};

/// The largest jump of feather `i`'s vane vertices from frame `a` to frame `b`, each vertex in its
/// follicle's skin frame (as plume check --frames measures popping), divided by `width`.
inline double skin_frame_jump(const feathers::CoatFrame &a, const feathers::CoatFrame &b,
                              const feathers::FeatherRanges &ranges, size_t i, float width) {
  const Eigen::Matrix3f ta = a.root_frames[i].basis.transpose(), tb = b.root_frames[i].basis.transpose();
  double jump = 0.0;
  for (int64_t v = ranges.first_vertex[i]; v < ranges.first_vertex[i + 1]; ++v) {
    const Eigen::Vector3f pa = ta * (a.vanes.positions[size_t(v)] - a.root_frames[i].origin);
    const Eigen::Vector3f pb = tb * (b.vanes.positions[size_t(v)] - b.root_frames[i].origin);
    jump = std::max(jump, double((pb - pa).norm()) / double(width));
  }
  return jump;
}

/// Which state each of the two runs of grow_twice() starts from at a frame after the first.
struct TwoRuns {
  bool stateless_skin_warm = false;  // the stateless run's skin pass starts from the frame before
  bool warm_layers = false;          // the warm run's layering pass starts from the frame before
};

/// What grow_twice() hands its measure at each frame and run.
struct GrownFrame {
  int frame = 0;
  int run = 0;  // 0: stateless, 1: warm start
  const Mesh *posed = nullptr;
  const skin::SkinGrid *grid = nullptr;
  const feathers::CoatFrame *before = nullptr;  // null at the first frame
  const feathers::CoatFrame *now = nullptr;
  double seconds = 0.0;  // the coat's grow
};

/// Frames 1..`last` of `pipeline`'s sequence (its stems simulated as plume regrow simulates them),
/// the coat grown twice at each: stateless (the skin pass warm with `runs.stateless_skin_warm`) and
/// from the frame before (the skin pass warm, the layering pass too with `runs.warm_layers`). Calls
/// `measure(const GrownFrame &)` after each grow, then `done(frame)` after both runs of a frame.
template <class Measure, class Done>
void grow_twice(Pipeline &pipeline, const feathers::Coat &coat, int last, TwoRuns runs, Measure measure,
                Done done) {
  std::array<feathers::CoatFrame, 2> before, now;  // [stateless, warm]
  for (int frame = 1; frame <= last; ++frame) {
    const Mesh posed = pipeline.posed_mesh(frame);
    const StrandSet stems = pipeline.guides_at(frame, posed);
    const MeshQuery query(posed);
    const skin::SkinGrid grid(posed, query);
    for (int run = 0; run < 2; ++run) {
      feathers::CoatFrame &a = before[size_t(run)], &b = now[size_t(run)];
      const bool has_before = frame > 1;
      const bool skin_warm = has_before && (run == 1 || runs.stateless_skin_warm);
      const bool layers_warm = has_before && run == 1 && runs.warm_layers;
      const auto t0 = std::chrono::steady_clock::now();
      coat.grow(posed, query, stems, b, &grid, skin_warm ? &a.skin_pass : nullptr, layers_warm ? &a.layer_state : nullptr);
      GrownFrame grown;
      grown.frame = frame;
      grown.run = run;
      grown.posed = &posed;
      grown.grid = &grid;
      grown.before = has_before ? &a : nullptr;
      grown.now = &b;
      grown.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      measure(grown);
      std::swap(a, b);
    }
    done(frame);
  }
}

}  // namespace plume::bench
