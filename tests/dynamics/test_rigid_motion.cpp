#include <catch2/catch.hpp>
#include <cmath>

#include "dynamics/dynamics_fixtures.h"
#include "dynamics/rigid_motion.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"

using namespace plume;

namespace {

// A point in [-20, 20]^3 from a hashed index (the tests' seeded randomness).
Eigen::Vector3d random_point(uint64_t seed, uint64_t i) {
  Eigen::Vector3d p;
  for (int k = 0; k < 3; ++k) p[k] = 40.0 * hash_to_unit(hash_combine(seed, 3 * i + uint64_t(k))) - 20.0;
  return p;
}

}  // namespace

TEST_CASE("rigid fit: an exact rigid motion is recovered with a tiny residual", "[dynamics]") {
  const Mesh head = test::sphere_mesh(10.0f);
  const Mesh moved = test::moved_mesh(head, 0.7f, Eigen::Vector3f(3.0f, -2.0f, 5.0f), Eigen::Vector3f(1.0f, 0.0f, 0.0f));
  const dynamics::RigidMotion motion = dynamics::fit_rigid_motion(head.positions, moved.positions);
  for (size_t p = 0; p < head.positions.size(); ++p)
    CHECK((motion.apply(head.positions[p].cast<double>()) - moved.positions[p].cast<double>()).norm() <= motion.residual);
  CHECK(motion.residual < 1e-3);
  CHECK(std::abs(Eigen::AngleAxisd(motion.rotation).angle() - 0.7) < 1e-5);
}

TEST_CASE("rigid fit: the residual bounds the change of distance to the skin at any point", "[dynamics]") {
  // The skin turned and shifted, then given a bulge: the emitter's distance at p must be within
  // `residual` of the rest distance at the point carried back by the fitted motion. The
  // simulator skips exact emitter queries on that bound.
  const Mesh head = test::sphere_mesh(10.0f, Eigen::Vector3f::Zero(), 24, 32);
  Mesh posed = test::moved_mesh(head, -0.4f, Eigen::Vector3f(0.0f, 1.0f, -2.0f));
  for (size_t v = 0; v < posed.positions.size(); ++v) {
    const float y = head.positions[v].y();
    const float bulge = y < -2.0f ? 2.0f * std::min(1.0f, (-2.0f - y) / 3.0f) : 0.0f;
    posed.positions[v] += bulge * head.vertex_normals[v];
  }
  posed.compute_normals();
  const dynamics::RigidMotion motion = dynamics::fit_rigid_motion(head.positions, posed.positions);
  CHECK(motion.residual > 0.5);  // really deformed: the bound is exercised, not trivial
  const MeshQuery rest_query(head), posed_query(posed);
  double tightest = 1e30;
  for (uint64_t i = 0; i < 2000; ++i) {
    const Eigen::Vector3d p = random_point(17, i);
    const Eigen::Vector3d back = motion.rotation.transpose() * (p - motion.translation);
    const double d_posed = (p.cast<float>() - surface_position(posed, posed_query.closest(p.cast<float>()))).norm();
    const double d_rest = (back.cast<float>() - surface_position(head, rest_query.closest(back.cast<float>()))).norm();
    tightest = std::min(tightest, motion.residual - std::abs(d_posed - d_rest));
  }
  INFO("smallest slack of the bound over the samples: " << tightest);
  CHECK(tightest >= 0.0);
}
