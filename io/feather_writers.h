// Writes a frame of feathers: curves (rachis and barbs) as USD BasisCurves with feather primvars,
// `.hair`, PLY or OBJ; vanes as USD Mesh or OBJ with texture coordinates. Reads back the vane meshes
// Plume writes (for `plume info` and `plume check`).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "groom/feather_frame.h"
#include "groom/mesh.h"

namespace plume::io {

struct FeatherWriteOptions {
  /// The templates' names, by index (USD: `primvars:feather_template_names`).
  std::vector<std::string> template_names;
  /// When set, the USD layer's start and end time codes and the points' time sample.
  std::optional<double> time_code;
  double fps = 24.0;
  double meters_per_unit = 0.01;
  /// USD layer metadata `upAxis`: "Y" or "Z".
  std::string up_axis = "Y";
  /// OBJ vane meshes carry one set of texture coordinates: across the vane, or along the barbs.
  bool obj_uv_along_barbs = false;
  std::string comment;
};

/// Writes feather curves, the format from the extension:
/// - `.usda`: linear BasisCurves "feathers" with vertex widths, `int64[] primvars:feather_id` and
///   `primvars:plume_id` (the feathers' stable ids), `int[] primvars:feather_part` (0 rachis, 1 left
///   barb, 2 right barb, 3..5 the afterfeather's), `int[] primvars:feather_template` and
///   `primvars:groom_group_id` (the template index: one Unreal hair group per template),
///   `string[] primvars:feather_template_names`, and vertex texture coordinates `primvars:st` (along
///   the barb) and `primvars:st_vane` (across the vane);
/// - `.ply`: binary vertices x, y, z, width, `uint feather` (the feather's index in the coat) and
///   `uchar part`, and one edge per segment;
/// - `.hair`, `.obj`: the curves alone (as write_strands writes strands).
/// The file appears whole or not at all. Throws InputError on an unknown extension.
void write_feather_curves(const std::string &path, const FeatherCurves &curves, const FeatherWriteOptions &options);

/// Writes vane meshes: `.usda` (a Mesh "vanes": triangles, `primvars:st` across the vane and
/// `primvars:st_barb` along the barbs, per-face `int64[] primvars:feather_id` and
/// `int[] primvars:feather_template`, double sided) or `.obj` (v, vt, f v/vt, one `g feather_ID`
/// group per feather). Throws InputError on an unknown extension.
void write_vane_mesh(const std::string &path, const VaneMesh &vanes, const FeatherWriteOptions &options);

/// Reads the points and triangles of a vane mesh as write_vane_mesh writes it (`.usda`: the first
/// Mesh prim's points, or their first time sample, faceVertexCounts of 3 and faceVertexIndices;
/// `.obj`: as read_obj_mesh). Each feather's triangles form a group named feather_<id> (the OBJ's
/// groups; the `.usda`'s primvars:feather_id, when present). Throws InputError "file:line: ..." for
/// anything else.
Mesh read_vane_mesh(const std::string &path);

}  // namespace plume::io
