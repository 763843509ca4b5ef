// The `plume` subcommands on feather grooms and feather files: regrow and preview grow the coat
// every frame (app/feather_pipeline.h); info and check read vane meshes as well as curves.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "app/preview.h"
#include "groom/groom_desc.h"

namespace plume {

/// What `plume regrow` was asked for, its outputs chosen already (the command line's, else the
/// groom's, renamed for a proxy run: app/run_outputs.h).
struct FeatherRegrowArgs {
  std::string frames;
  std::string out;  // feather curves (.usda .hair .ply .obj); empty: none
  std::string out_what;  // where `out` came from (the option or the groom key), for messages
  std::string vanes;  // vane meshes (.usda .obj); empty: none
  std::string vanes_what;
  std::string preview;  // empty: none
  std::string preview_what;
  int preview_every = -1;
  int preview_size = 0;
  bool preview_guides = false;
  int threads = 0;
  int64_t strands = -1;  // follicles
  std::string guides_cache;
  bool skip_existing = false;  // regrow only the frames whose files are missing
};

/// `plume regrow` of a feather groom: for every frame of the range, the curves and/or the vane
/// meshes, and the previews due. Every output location is checked before the first frame is grown.
/// Throws InputError (exit 2) for bad input, including a groom with neither a curves nor a vanes
/// output.
void run_feather_regrow(const GroomDesc &groom, const FeatherRegrowArgs &args);

/// How `plume preview` looks at a feather groom: from `angle`, or with `turntable` > 0 that many
/// views round it from one distance, tiled `columns` to a row.
struct FeatherPreviewViews {
  CameraAngle angle;
  int turntable = 0;
  int columns = 1;
};

/// `plume preview` of a feather groom at `frame`, written to `path` (the frame field already replaced).
void run_feather_preview(const GroomDesc &groom, int frame, const std::string &path, int size, bool stems, int threads,
                         int64_t strands, const std::string &guides_cache, const FeatherPreviewViews &views);

/// True when `path` holds vane meshes (a `.usda` with a Mesh prim and no BasisCurves), which the
/// strand readers do not read.
bool is_vane_mesh_file(const std::string &path);

/// True when `plume check` should judge `path` as feathers: vane meshes (.usda or an OBJ with faces),
/// feather curves Plume wrote (.usda with feather ids, .ply with a feather property), or any file
/// checked against a feather groom (`groom_path`, may be empty).
bool is_feather_check(const std::string &path, const std::string &groom_path);

/// `plume info` of a vane mesh file.
void print_vane_mesh_info(const std::string &path);

/// `plume check` of feather curves or vane meshes against the emitter at their pose (`mesh_path`, or
/// the emitter of `groom_path` posed at `frame`, default the groom's first): every point or vertex
/// below the skin (signed distance below margin - eps, eps = 1e-5 x the emitter's bounding-box
/// diagonal, as for strands; a curve's first point below -eps). Feather against feather is not
/// judged on curves; on vane meshes, every pair of feathers whose vanes intersect or touch
/// (check/vanes.h) is a violation. With `json`, the report is one JSON object: file, kind ("feather curves" or "vane
/// mesh"), mesh, curves, points, inside_skin {points, margin, deepest}, violations, clean, strict,
/// exit_code. Returns the exit code (kExitViolations under `strict` when any point is below).
int run_feather_check(const std::string &path, const std::string &mesh_path, const std::string &groom_path,
                      std::optional<int> frame, float margin, bool strict, bool json);

}  // namespace plume
