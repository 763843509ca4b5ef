// Guides: the groomer's control strands, bound to the emitter at their roots.
#pragma once

#include <vector>

#include "groom/mesh.h"
#include "groom/mesh_query.h"
#include "groom/strand_set.h"

namespace plume {

struct Guides {
  /// Rest-pose strands, emitter object space; each has at least 2 points.
  StrandSet strands;
  /// One per guide, on the rest mesh: the surface point below the guide's first point along the
  /// normal (surface_point_below()).
  std::vector<SurfacePoint> roots;
  size_t size() const { return roots.size(); }
};

/// Throws InputError naming `source`, the guide and the point for a point beyond max_coordinate
/// (groom/limits.h): rest guides, and simulated guides read back from a cache.
void check_guide_points(const StrandSet &strands, const std::string &source);

/// Binds each strand's first point to the rest mesh's surface point below it along the normal
/// (surface_point_below()).
/// Throws InputError (naming `source`, the guide and the point) if a strand has fewer than 2
/// points or a point beyond max_coordinate (groom/limits.h).
Guides bind_guides(const MeshQuery &rest_query, StrandSet rest_strands, const std::string &source);

/// The guides as the skin carries them to a deformed pose, without dynamics: each guide keeps
/// its shape in its root's surface frame (rest frame -> posed frame), and its root point keeps
/// its offset from the surface in that frame.
StrandSet carry_guides(const Mesh &rest_mesh, const Mesh &posed_mesh, const Guides &guides);

}  // namespace plume
