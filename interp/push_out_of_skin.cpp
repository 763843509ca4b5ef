#include "interp/interpolate.h"
#include "skin/skin_guard.h"

namespace plume::interp {

using namespace skin;

void push_out_of_skin(const MeshQuery &query, float margin, StrandSet &r_strands) {
  const float scale = mesh_scale(query.mesh());
  const SkinGrid grid(query.mesh(), query);
  const int64_t strand_count = int64_t(r_strands.strand_count());
#pragma omp parallel for schedule(static)
  for (int64_t s = 0; s < strand_count; ++s) {
    std::span<Eigen::Vector3f> points = r_strands.points_for_write(size_t(s));
    if (points.empty()) continue;
    SkinGuard guard(query, margin, scale, &grid);
    // The root is kept where it is; its own distance seeds the Lipschitz bound.
    guard.start_anywhere(points[0]);
    for (size_t i = 1; i < points.size(); ++i) guard.keep_out(points[i]);
  }
}

}  // namespace plume::interp
