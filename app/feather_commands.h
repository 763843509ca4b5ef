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

/// What `plume check` was asked of a feather frame.
struct FeatherCheckArgs {
  std::string path;   // feather curves or vane meshes
  std::string mesh;   // the emitter at their pose (or give groom)
  std::string groom;  // the feather groom (its emitter posed at frame, its coat's order and templates)
  std::optional<int> frame;  // with groom; default its first
  float margin = 0.0f;
  bool strict = false;
  bool json = false;
  /// With groom and vane meshes: the previous frame's vane meshes, at previous_frame (default frame - 1).
  std::string previous;
  std::optional<int> previous_frame;
  /// With previous: the largest popping (rachis widths) --strict accepts; none: popping is reported only.
  std::optional<double> max_pop;
};

/// `plume check` of feather curves or vane meshes against the emitter at their pose (`mesh`, or the
/// emitter of `groom` posed at `frame`): every point or vertex below the skin (signed distance below
/// margin - eps, eps = 1e-5 x the emitter's bounding-box diagonal, as for strands; a curve's first
/// point below -eps). Feather against feather is judged on vane meshes only: every pair of feathers
/// whose vanes intersect or touch (check/vanes.h); with a groom, layer-order violations against the
/// order its coat freezes at rest (check/feather_layers.h) and the shape drift from the rest shape
/// (check/feather_motion.h); with `previous`, order flips and popping between the two frames. With
/// `json`, one JSON object (docs/check.md lists its fields). Returns the exit code (kExitViolations
/// under `strict` when a promise is broken or popping exceeds max_pop).
int run_feather_check(const FeatherCheckArgs &args);

}  // namespace plume
