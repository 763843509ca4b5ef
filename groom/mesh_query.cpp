#include "groom/mesh_query.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <vector>

#include "groom/error.h"

namespace plume {

namespace {
using Kernel = CGAL::Simple_cartesian<double>;
using Point = Kernel::Point_3;
using Triangle = Kernel::Triangle_3;
using TriangleIterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<Kernel, TriangleIterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, Primitive>>;

// Barycentric coordinates of p (on or near triangle abc), computed in double.
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

struct MeshQuery::Tree {
  std::vector<Triangle> triangles;
  std::vector<int> triangle_ids;  // index into mesh.triangles for each stored triangle
  std::vector<int> stored;        // stored index of each mesh triangle, -1 for a degenerate one
  ::plume::Tree tree;
};

MeshQuery::MeshQuery(const Mesh &mesh, Start start) : mesh_(mesh), tree_(std::make_unique<Tree>()) {
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
  if (start == Start::kd_tree) tree_->tree.accelerate_distance_queries();
}

MeshQuery::~MeshQuery() = default;

SurfacePoint MeshQuery::closest(const Eigen::Vector3f &point) const {
  const auto [closest_point, primitive_id] = tree_->tree.closest_point_and_primitive(Point(point.x(), point.y(), point.z()));
  const size_t stored = size_t(primitive_id - tree_->triangles.cbegin());
  SurfacePoint sp;
  sp.triangle = tree_->triangle_ids[stored];
  const Eigen::Vector3i &t = mesh_.triangles[sp.triangle];
  sp.bary = barycentric(Eigen::Vector3d(closest_point.x(), closest_point.y(), closest_point.z()),
                        mesh_.positions[t[0]].cast<double>(), mesh_.positions[t[1]].cast<double>(),
                        mesh_.positions[t[2]].cast<double>());
  return sp;
}

SurfacePoint MeshQuery::closest(const Eigen::Vector3d &point, const SurfacePoint &hint) const {
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
  const auto [closest_point, primitive_id] = tree_->tree.closest_point_and_primitive(
      Point(point.x(), point.y(), point.z()),
      ::plume::Tree::Point_and_primitive_id(start_point, tree_->triangles.cbegin() + start));
  SurfacePoint sp;
  sp.triangle = tree_->triangle_ids[size_t(primitive_id - tree_->triangles.cbegin())];
  const Eigen::Vector3i &t = mesh_.triangles[sp.triangle];
  sp.bary = barycentric(Eigen::Vector3d(closest_point.x(), closest_point.y(), closest_point.z()),
                        mesh_.positions[t[0]].cast<double>(), mesh_.positions[t[1]].cast<double>(),
                        mesh_.positions[t[2]].cast<double>());
  return sp;
}

double MeshQuery::signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint,
                                  SurfacePoint &r_closest) const {
  r_closest = closest(point, hint);
  const Eigen::Vector3d offset = point - surface_position(mesh_, r_closest).cast<double>();
  const double distance = offset.norm();
  const double side = offset.dot(surface_normal(mesh_, r_closest).cast<double>());
  return side < 0.0 ? -distance : distance;
}

float MeshQuery::signed_distance(const Eigen::Vector3f &point, SurfacePoint *r_closest) const {
  const SurfacePoint sp = closest(point);
  if (r_closest) *r_closest = sp;
  const Eigen::Vector3f offset = point - surface_position(mesh_, sp);
  const float distance = offset.norm();
  const Eigen::Vector3f n = surface_normal(mesh_, sp);
  const float side = offset.dot(n);
  return side < 0.0f ? -distance : distance;
}

}  // namespace plume
