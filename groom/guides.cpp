#include "groom/guides.h"

#include "groom/error.h"
#include "groom/limits.h"

namespace plume {

void check_guide_points(const StrandSet &strands, const std::string &source) {
  for (size_t g = 0; g < strands.strand_count(); ++g) {
    const std::span<const Eigen::Vector3f> points = strands.points(g);
    for (size_t j = 0; j < points.size(); ++j)
      if (!within_scene_bounds(points[j]))
        throw InputError(FileLoc{source}, "guide " + std::to_string(g) + ", point " + std::to_string(j) + ": " +
                                              out_of_bounds_message(points[j]));
  }
}

Guides bind_guides(const MeshQuery &rest_query, StrandSet rest_strands, const std::string &source) {
  Guides guides;
  for (size_t g = 0; g < rest_strands.strand_count(); ++g)
    if (rest_strands.points_in(g) < 2)
      throw InputError(FileLoc{source}, "guide " + std::to_string(g) + ": expected at least 2 points, got " +
                                            std::to_string(rest_strands.points_in(g)));
  check_guide_points(rest_strands, source);
  guides.roots.resize(rest_strands.strand_count());
  for (size_t g = 0; g < rest_strands.strand_count(); ++g)
    guides.roots[g] = surface_point_below(rest_query, rest_strands.points(g)[0]);
  guides.strands = std::move(rest_strands);
  return guides;
}

StrandSet carry_guides(const Mesh &rest_mesh, const Mesh &posed_mesh, const Guides &guides) {
  StrandSet posed = guides.strands;
  for (size_t g = 0; g < guides.size(); ++g) {
    const SurfaceFrame rest_frame = surface_frame(rest_mesh, guides.roots[g]);
    const SurfaceFrame posed_frame = surface_frame(posed_mesh, guides.roots[g]);
    for (Eigen::Vector3f &p : posed.points_for_write(g)) p = posed_frame.to_world(rest_frame.to_local(p));
  }
  return posed;
}

}  // namespace plume
