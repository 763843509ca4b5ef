// Sintel's head and her 228 guides as the growth benchmarks load them, and roots scattered on her
// scalp (the triangles within 2 units of a guide root).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume::bench {

inline std::string sintel_folder() { return std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/"; }

inline Mesh sintel_mesh() { return io::read_obj_mesh(sintel_folder() + "sintel.obj"); }

inline Guides sintel_guides(const MeshQuery &query) {
  return bind_guides(query, io::read_strands(sintel_folder() + "sintel_guides.hair"), "sintel_guides.hair");
}

/// `count` roots (seed 1) on the triangles within 2 units of a guide root.
inline Roots sintel_scalp_roots(const Mesh &mesh, const Guides &guides, int64_t count) {
  std::vector<Eigen::Vector3f> guide_roots;
  for (const SurfacePoint &sp : guides.roots) guide_roots.push_back(surface_position(mesh, sp));
  return scatter_roots(mesh, count, 1, triangles_near(mesh, guide_roots, 2.0));
}

}  // namespace plume::bench
