// The side of a point (the sign of MeshQuery::signed_distance) is the true side of the skin, so
// that the distance is 1-Lipschitz: growth clears points with bounds taken from earlier distances,
// and the checker must agree with them.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "io/obj_mesh.h"

using namespace plume;

namespace {

/// A flat closed tetrahedron over the triangle (0,0,0), (1,0,0), (0,1,0), apex (0.3, 0.3, height),
/// outward-facing. Each base corner's area-weighted normal points down, against the faces above
/// it: the interpolated normal then calls points just above those faces inside (as at an ear's rim).
/// With `split_seam` the face over the first edge gets its own copies of its corners, as a mesh cut
/// along a UV seam.
Mesh flat_tetrahedron(float height, bool split_seam = false) {
  Mesh mesh;
  mesh.positions = {{0.0f, 0.0f, 0.0f}, {1.0f, 0.0f, 0.0f}, {0.0f, 1.0f, 0.0f}, {0.3f, 0.3f, height}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {2, 0, 3}};
  if (split_seam) {
    for (int k = 0; k < 3; ++k) mesh.positions.push_back(mesh.positions[size_t(mesh.triangles[1][k])]);
    mesh.triangles[1] = {4, 5, 6};
  }
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  mesh.group_names = {"default"};
  mesh.compute_normals();
  return mesh;
}

/// Inside the tetrahedron: behind the planes of all its faces.
bool inside_tetrahedron(const Mesh &mesh, const Eigen::Vector3f &p, float &r_depth) {
  r_depth = INFINITY;
  for (size_t f = 0; f < mesh.triangle_count(); ++f)
    r_depth = std::min(r_depth, -(p - mesh.positions[size_t(mesh.triangles[f][0])]).dot(mesh.face_normal(f)));
  return r_depth > 0.0f;
}

/// A value in [-1, 1) from a counter.
float unit(uint64_t counter) { return 2.0f * hash_to_unit(hash64(counter)) - 1.0f; }

}  // namespace

TEST_CASE("the side of a point is the true side of a flat closed tetrahedron, at its rim too", "[groom]") {
  for (const bool split_seam : {false, true}) {
    const Mesh tetrahedron = flat_tetrahedron(0.05f, split_seam);
    const MeshQuery query(tetrahedron);
    int wrong = 0, interpolated_wrong = 0, inside = 0, counted = 0;
    for (uint64_t k = 0; k < 20000; ++k) {
      const Eigen::Vector3f p(0.6f + 0.7f * unit(3 * k), 0.6f + 0.7f * unit(3 * k + 1), 0.025f + 0.075f * unit(3 * k + 2));
      float depth = 0.0f;
      const bool truly_inside = inside_tetrahedron(tetrahedron, p, depth);
      SurfacePoint closest;
      const float distance = query.signed_distance(p, &closest);
      if (std::abs(distance) < 1e-4f) continue;  // on the skin, up to rounding
      ++counted;
      inside += truly_inside;
      wrong += (distance < 0.0f) != truly_inside;
      const float interpolated_side = (p - surface_position(tetrahedron, closest)).dot(surface_normal(tetrahedron, closest));
      interpolated_wrong += (interpolated_side < 0.0f) != truly_inside;
      // The double-precision query agrees.
      SurfacePoint found;
      wrong += (query.signed_distance(p.cast<double>(), closest, found) < 0.0) != truly_inside;
    }
    INFO("split along a seam: " << split_seam);
    CHECK(counted > 15000);
    CHECK(inside > 300);
    CHECK(wrong == 0);
    CHECK(interpolated_wrong > 100);  // the case is exercised: the interpolated normal's side fails here
  }
}

// Sintel's ears are thin flaps whose vertex normals average their two sides. There the side by
// the interpolated normal flipped between points 0.1 apart, 0.16 and 0.21 from the skin (no skin
// between them), and growth, trusting the 1-Lipschitz bound, left strand points inside.
TEST_CASE("on Sintel's head, folded ears included, the signed distance is 1-Lipschitz", "[groom]") {
  const Mesh mesh = io::read_obj_mesh(std::string(PLUME_SOURCE_DIR) + "/grooms/sintel/sintel.obj");
  const MeshQuery query(mesh);
  // The pair found beside the left ear.
  const Eigen::Vector3f outside_before(-6.666146f, 29.284716f, -0.153803f), inside_before(-6.586254f, 29.222084f, -0.169431f);
  CHECK(std::abs(query.signed_distance(outside_before) - query.signed_distance(inside_before)) <=
        (outside_before - inside_before).norm());

  // Pairs of points 0.1 apart within 0.4 of the ears' triangles whose face normal turns against
  // one of their corners' normals (the folds). Elsewhere on this head the lips cross each other and
  // the eyes and the neck are open: there no side is well defined, by any rule.
  int pairs = 0, violations = 0, interpolated_violations = 0;
  uint64_t counter = 0;
  auto interpolated_distance = [&](const Eigen::Vector3f &p) {
    SurfacePoint closest;
    const float distance = std::abs(query.signed_distance(p, &closest));
    return (p - surface_position(mesh, closest)).dot(surface_normal(mesh, closest)) < 0.0f ? -distance : distance;
  };
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    const Eigen::Vector3f face = mesh.face_normal(f);
    bool folded = false;
    for (int c = 0; c < 3; ++c) folded = folded || mesh.vertex_normals[size_t(mesh.triangles[f][c])].dot(face) < 0.0f;
    const Eigen::Vector3f centre = surface_position(mesh, SurfacePoint{int32_t(f), Eigen::Vector3f::Constant(1.0f / 3.0f)});
    const bool ear = std::abs(centre.x()) > 6.3f && centre.z() < 1.0f;
    if (!folded || !ear) continue;
    for (int k = 0; k < 500; ++k, counter += 6) {
      const Eigen::Vector3f p = centre + 0.4f * Eigen::Vector3f(unit(counter), unit(counter + 1), unit(counter + 2));
      const Eigen::Vector3f step = Eigen::Vector3f(unit(counter + 3), unit(counter + 4), unit(counter + 5)).normalized();
      const Eigen::Vector3f q = p + 0.1f * step;
      ++pairs;
      violations += std::abs(query.signed_distance(p) - query.signed_distance(q)) > (p - q).norm() + 1e-5f;
      interpolated_violations += std::abs(interpolated_distance(p) - interpolated_distance(q)) > (p - q).norm() + 1e-5f;
    }
  }
  CHECK(pairs > 10000);
  CHECK(violations == 0);
  CHECK(interpolated_violations > 0);  // the case is exercised: the interpolated normal's side breaks it
}
