// Reads the emitter mesh from Wavefront OBJ, and the frames of an OBJ sequence that deform it.
#pragma once

#include <optional>
#include <string>

#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume::io {

/// Reads `v`, `vt` and `f` (v, v/vt, v/vt/vn, v//vn; negative indices count back from the last
/// vertex read so far). Polygons are fan-triangulated around their first corner. `vn` lines are
/// parsed and checked but the normals are recomputed from the triangles (area-weighted).
/// Face groups: a face belongs to the last `usemtl` name seen if the file has any `usemtl`,
/// else to the last `g` name (the first name on the line); faces before any name go to "default".
/// UVs are kept only when every face has them. Calls mesh.validate(path).
/// Throws InputError "file:line: ..." on malformed lines, out-of-range indices, NaN/Inf values and
/// coordinates beyond max_coordinate (groom/limits.h).
Mesh read_obj_mesh(const std::string &path);

/// What an OBJ file holds: a mesh when it has faces (`f` lines), else strands (`l` lines).
struct ObjContents {
  std::optional<Mesh> mesh;  // as read_obj_mesh() gives it
  StrandSet strands;         // as read_strands() gives an .obj, when there is no mesh
};

/// Reads an OBJ once and returns the mesh or the strands it holds (`plume info`). Throws
/// InputError as read_obj_mesh() or read_strands() do, naming the file.
ObjContents read_obj_file(const std::string &path);

/// Reads one frame of an OBJ sequence of `rest`'s topology: same vertex count and same triangles
/// (after triangulation). Returns rest's topology (triangles, UVs, groups) with the frame's
/// positions and recomputed normals. Throws InputError naming the file and what differs.
Mesh read_obj_pose(const std::string &path, const Mesh &rest);

}  // namespace plume::io
