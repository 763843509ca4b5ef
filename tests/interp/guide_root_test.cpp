// A strand rooted at a guide's root is that guide, also where another guide passes within a few
// hundredths of a segment of it: there the field turns sharply between the two, and a strand a
// rounding error off the first guide used to be carried along the second (as on Sintel, where one
// guide passes 0.006 from another and its strand ended 2.8% of its length away).
#include <catch2/catch.hpp>

#include <cmath>

#include "interp/hard_scenes.h"
#include "interp/interp_fixtures.h"
#include "interp/scene_measures.h"

using namespace plume;
using namespace plume::test;

namespace {

/// Two guides over a plane: A rises from (-2, 0, 0) and runs along +x; B rises from a root on the
/// y axis and runs across A at `angle` to it, passing `gap` above A where they cross. Both are 32
/// points, about 4 long (a segment about 0.13). A third guide farther off keeps the field from being
/// the two alone. Everything scaled by `scale`.
Scene near_passing_guides(double gap, double angle, double height, float scale) {
  Scene scene;
  scene.name = "near-passing guides";
  scene.mesh = make_plane(12.0f, 24);
  const auto rise = [](double t) { return 1.0 - std::pow(1.0 - t, 3.0); };
  StrandSet strands;
  strands.append(sample_curve([&](double t) { return Eigen::Vector3d(-2.0 + 4.0 * t, 0.0, height * rise(t)); }, 32), 0);
  // B crosses A at A's midpoint (x = 0, where A is height * rise(0.5) high), `gap` above it.
  const double crossing = height * rise(0.5) + gap;
  const Eigen::Vector3d along(std::cos(angle), std::sin(angle), 0.0);
  strands.append(sample_curve([&](double t) {
                   const Eigen::Vector3d flat = (4.0 * t - 2.0) * along;
                   return Eigen::Vector3d(flat.x(), flat.y(), crossing * rise(t) / rise(0.5));
                 }, 32), 1);
  strands.append(sample_curve([&](double t) { return Eigen::Vector3d(-2.0 + 3.0 * t, 3.0, height * rise(t)); }, 32), 2);
  for (size_t i = 0; i < strands.positions.size(); ++i) strands.positions[i] *= scale;
  for (Eigen::Vector3f &p : scene.mesh.positions) p *= scale;
  scene.mesh.compute_normals();
  scene.finish(strands);
  return scene;
}

}  // namespace

TEST_CASE("a strand at a guide's root follows its guide past another guide that nearly touches it", "[interp]") {
  for (const float scale : {1.0f, 0.01f, 100.0f})
    for (const double gap : {0.003, 0.001, 0.01})
      for (const double angle : {M_PI / 2.0, 0.35})
        for (const double height : {0.6, 0.2, 0.1}) {
        const Scene scene = near_passing_guides(gap, angle, height, scale);
        const Roots at_guides = roots_of(scene.guides);
        for (const int points : {32, 12}) {
          const StrandSet strands =
              grow_scene(scene, at_guides, settings_of(InterpolationSettings::Method::streamline), points);
          REQUIRE(strands.strand_count() == scene.guides.size());
          for (size_t g = 0; g < scene.guides.size(); ++g) {
            const double deviation = curve_deviation(scene.guides, g, strands.points(g));
            INFO("scale " << scale << ", gap " << gap << ", angle " << angle << ", height " << height << ", " << points
                          << " points, guide " << g << ": deviation " << 100.0 * deviation << "% of its length");
            CHECK(deviation < 1e-3);
          }
        }
      }
}
