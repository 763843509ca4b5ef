#include "dynamics/emitter_query.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <vector>

#include "groom/error.h"

namespace plume::dynamics {

namespace {
using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using AabbTree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// Barycentric coordinates of p (on or near triangle abc), clamped into the triangle.
Eigen::Vector3f barycentric(const Eigen::Vector3d &p, const Eigen::Vector3d &a, const Eigen::Vector3d &b,
                            const Eigen::Vector3d &c) {
  const Eigen::Vector3d v0 = b - a, v1 = c - a, v2 = p - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1);
  const double d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double denom = d00 * d11 - d01 * d01;
  if (!(denom > 0.0)) return Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  double v = (d11 * d20 - d01 * d21) / denom;
  double w = (d00 * d21 - d01 * d20) / denom;
  v = std::clamp(v, 0.0, 1.0);
  w = std::clamp(w, 0.0, 1.0 - v);
  return Eigen::Vector3f(float(1.0 - v - w), float(v), float(w));
}
}  // namespace

struct EmitterQuery::Tree {
  std::vector<Triangle> triangles;
  std::vector<int> triangle_ids;  // mesh triangle of each stored triangle
  std::vector<int> stored;        // stored index of each mesh triangle, -1 for a degenerate one
  AabbTree tree;
};

EmitterQuery::EmitterQuery(const Mesh &mesh) : mesh_(mesh), tree_(std::make_unique<Tree>()) {
  tree_->triangles.reserve(mesh.triangle_count());
  tree_->stored.assign(mesh.triangle_count(), -1);
  for (size_t f = 0; f < mesh.triangle_count(); ++f) {
    if (!(mesh.triangle_area(f) > 0.0)) continue;
    const Eigen::Vector3i &t = mesh.triangles[f];
    auto point = [&](int v) {
      const Eigen::Vector3f &p = mesh.positions[v];
      return Point(p.x(), p.y(), p.z());
    };
    tree_->stored[f] = int(tree_->triangles.size());
    tree_->triangles.emplace_back(point(t[0]), point(t[1]), point(t[2]));
    tree_->triangle_ids.push_back(int(f));
  }
  if (tree_->triangles.empty()) throw InputError("mesh: every triangle is degenerate (zero area)");
  tree_->tree.insert(tree_->triangles.cbegin(), tree_->triangles.cend());
  tree_->tree.build();
}

EmitterQuery::~EmitterQuery() = default;

double EmitterQuery::signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint,
                                     SurfacePoint &r_closest) const {
  // The search starts from the hint's distance and prunes every box farther than the best point
  // so far; the hint must lie on its own primitive for the answer to be a surface point.
  const int hint_stored = hint.triangle >= 0 && size_t(hint.triangle) < tree_->stored.size()
                              ? tree_->stored[size_t(hint.triangle)]
                              : -1;
  const int start = hint_stored >= 0 ? hint_stored : 0;
  const Triangle &start_triangle = tree_->triangles[size_t(start)];
  const Eigen::Vector3f bary = hint_stored >= 0 ? hint.bary : Eigen::Vector3f(1.0f, 0.0f, 0.0f);
  const Point start_point = CGAL::barycenter(start_triangle[0], bary.x(), start_triangle[1], bary.y(),
                                             start_triangle[2], bary.z());
  const Point query(point.x(), point.y(), point.z());
  const auto [closest_point, primitive_id] = tree_->tree.closest_point_and_primitive(
      query, AabbTree::Point_and_primitive_id(start_point, tree_->triangles.cbegin() + start));
  const size_t stored = size_t(primitive_id - tree_->triangles.cbegin());
  r_closest.triangle = tree_->triangle_ids[stored];
  const Eigen::Vector3i &t = mesh_.triangles[size_t(r_closest.triangle)];
  const Eigen::Vector3d on_surface(closest_point.x(), closest_point.y(), closest_point.z());
  r_closest.bary = barycentric(on_surface, mesh_.positions[t[0]].cast<double>(), mesh_.positions[t[1]].cast<double>(),
                               mesh_.positions[t[2]].cast<double>());
  const Eigen::Vector3d offset = point - surface_position(mesh_, r_closest).cast<double>();
  const double distance = offset.norm();
  const double side = offset.dot(surface_normal(mesh_, r_closest).cast<double>());
  return side < 0.0 ? -distance : distance;
}

}  // namespace plume::dynamics
