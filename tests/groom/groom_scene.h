// A groom file's rest scene loaded as `plume regrow` sets it up (mesh, guides, scattered roots), and
// synthetic guide shapes shared by tests and benchmarks. Needs plume_io.
#pragma once

#include <Eigen/Core>
#include <memory>
#include <string>
#include <vector>

#include "groom/groom_desc.h"
#include "groom/guides.h"
#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume::test {

/// The rest pose of a groom whose roots are scattered by count on the triangles near its guide roots
/// (roots.count and roots.near_guides, as the Sintel grooms give them).
struct GroomScene {
  GroomDesc groom;
  Mesh mesh;
  std::unique_ptr<MeshQuery> query;  // on `mesh`
  Guides guides;
  Roots roots;

  explicit GroomScene(const std::string &groom_path) : groom(io::read_groom_file(groom_path)) {
    mesh = io::read_obj_mesh(groom.emitter_path);
    query = std::make_unique<MeshQuery>(mesh);
    guides = bind_guides(*query, io::read_strands(groom.guides_path), groom.guides_path);
    std::vector<Eigen::Vector3f> guide_roots(guides.size());
    for (size_t g = 0; g < guides.size(); ++g) guide_roots[g] = surface_position(mesh, guides.roots[g]);
    roots = scatter_roots(mesh, groom.roots.count, groom.roots.seed,
                          triangles_near(mesh, guide_roots, groom.roots.near_guides));
  }
  GroomScene(const GroomScene &) = delete;
  GroomScene &operator=(const GroomScene &) = delete;
};

/// One 12-point guide per root: out along the normal, then combed down (-y) toward the tip, so that
/// strands grown from them lie close to the skin.
inline StrandSet combed_guides(const Mesh &mesh, const Roots &roots) {
  StrandSet guides;
  std::vector<Eigen::Vector3f> pts(12);
  for (size_t g = 0; g < roots.size(); ++g) {
    const SurfaceFrame f = surface_frame(mesh, roots.points[g]);
    Eigen::Vector3f p = f.origin;
    for (int j = 0; j < 12; ++j) {
      pts[size_t(j)] = p;
      const float t = float(j) / 11.0f;
      p += 0.06f * (f.normal() * (1.0f - t) - Eigen::Vector3f::UnitY() * t + 0.3f * f.basis.col(0)).normalized();
    }
    guides.append(pts, roots.ids[g]);
  }
  return guides;
}

}  // namespace plume::test
