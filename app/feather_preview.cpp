#include "app/feather_preview.h"

namespace plume {

Image render_feather_preview(const PreviewCamera &camera, const Mesh &mesh, const feathers::CoatFrame &feathers,
                             const StrandSet *stems, PreviewStyle style) {
  // The vanes join the emitter as triangles painted in a dark tone of the hair colour: the barbs
  // drawn over them read as the feather's fibres.
  Mesh scene = mesh;
  const VaneMesh &vanes = feathers.vanes;
  const int first = int(scene.positions.size());
  scene.positions.insert(scene.positions.end(), vanes.positions.begin(), vanes.positions.end());
  for (const Eigen::Vector3i &t : vanes.triangles) scene.triangles.push_back(t + Eigen::Vector3i::Constant(first));
  scene.triangle_groups.resize(scene.triangles.size(), 0);
  scene.triangle_uvs.clear();
  scene.uvs.clear();
  scene.compute_normals();
  StrandPaint paint;
  paint.triangle_colors.assign(scene.triangles.size(), style.skin_color);
  std::fill(paint.triangle_colors.begin() + long(mesh.triangle_count()), paint.triangle_colors.end(),
            Eigen::Vector3f(0.45f * style.hair_color));
  return render_preview(camera, scene, feathers.curves.curves, stems, style, paint);
}

PreviewCamera feather_camera(const Mesh &rest_mesh, const StrandSet &curves, const CameraAngle &angle) {
  return fit_camera(scene_bounds(rest_mesh, curves), angle);
}

}  // namespace plume
