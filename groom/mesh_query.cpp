#include "groom/mesh_query.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>
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

// The closest point of mesh triangle `triangle` to p, as weights that name its feature
// (closest_on_triangle, in double).
Eigen::Vector3f weights_on(const Mesh &mesh, int triangle, const Eigen::Vector3d &p) {
  const Eigen::Vector3i &t = mesh.triangles[size_t(triangle)];
  return closest_on_triangle<double>(p, mesh.positions[size_t(t[0])].cast<double>(), mesh.positions[size_t(t[1])].cast<double>(),
                                     mesh.positions[size_t(t[2])].cast<double>())
      .cast<float>();
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
  compute_side_normals();
}

void MeshQuery::compute_side_normals() {
  const Mesh &mesh = mesh_;
  const size_t triangle_count = mesh.triangle_count();
  const std::vector<uint32_t> canonical = welded_vertices(mesh, weld_distance(mesh));
  face_normals_.resize(triangle_count);
  corner_normals_.assign(mesh.positions.size(), Eigen::Vector3f::Zero());
  for (size_t f = 0; f < triangle_count; ++f) {
    const Eigen::Vector3i &t = mesh.triangles[f];
    face_normals_[f] = tree_->stored[f] >= 0 ? mesh.face_normal(f) : Eigen::Vector3f::Zero();
    if (face_normals_[f].squaredNorm() == 0.0f) continue;
    // The triangle's angles (the third from the other two: they sum to pi).
    float angles[3];
    for (int k = 0; k < 2; ++k) {
      const Eigen::Vector3f &corner = mesh.positions[size_t(t[k])];
      const Eigen::Vector3f to_next = mesh.positions[size_t(t[(k + 1) % 3])] - corner;
      const Eigen::Vector3f to_previous = mesh.positions[size_t(t[(k + 2) % 3])] - corner;
      angles[k] = std::atan2(to_next.cross(to_previous).norm(), to_next.dot(to_previous));
    }
    angles[2] = std::max(float(M_PI) - angles[0] - angles[1], 0.0f);
    for (int k = 0; k < 3; ++k) corner_normals_[canonical[size_t(t[k])]] += angles[k] * face_normals_[f];
  }
  for (size_t v = 0; v < corner_normals_.size(); ++v) corner_normals_[v] = corner_normals_[canonical[v]];
  for (Eigen::Vector3f &n : corner_normals_) n = n.normalized();  // zero stays zero

  // Edges under their lower welded vertex (a counting sort, linear in the edges); an edge's faces are
  // those listed under the same two ends. Edge k of triangle f is the one opposite corner k.
  auto ends = [&](size_t f, int k) {
    const Eigen::Vector3i &t = mesh.triangles[f];
    const uint32_t a = canonical[size_t(t[(k + 1) % 3])], b = canonical[size_t(t[(k + 2) % 3])];
    return std::pair<uint32_t, uint32_t>(std::min(a, b), std::max(a, b));
  };
  std::vector<uint32_t> offsets(mesh.positions.size() + 1, 0);
  for (size_t f = 0; f < triangle_count; ++f)
    for (int k = 0; k < 3; ++k) ++offsets[ends(f, k).first + 1];
  std::partial_sum(offsets.begin(), offsets.end(), offsets.begin());
  // Per listed edge: which triangle edge (3 f + k) it is, and its higher end.
  std::vector<uint32_t> listed(offsets.back()), listed_high(offsets.back()), fill(offsets.begin(), offsets.end() - 1);
  for (size_t f = 0; f < triangle_count; ++f)
    for (int k = 0; k < 3; ++k) {
      const auto [low, high] = ends(f, k);
      listed_high[fill[low]] = high;
      listed[fill[low]++] = uint32_t(3 * f + size_t(k));
    }
  edge_normals_.resize(3 * triangle_count);
  open_edges_.clear();
  for (size_t low = 0; low + 1 < offsets.size(); ++low)
    for (uint32_t e = offsets[low]; e < offsets[low + 1]; ++e) {
      Eigen::Vector3f sum = Eigen::Vector3f::Zero();
      int faces = 0;
      for (uint32_t other = offsets[low]; other < offsets[low + 1]; ++other)
        if (listed_high[other] == listed_high[e]) {
          sum += face_normals_[listed[other] / 3];
          ++faces;
        }
      edge_normals_[listed[e]] = sum.normalized();
      // An edge whose ends weld into one (of a degenerate triangle) is no edge.
      if (faces == 1 && listed_high[e] != low) open_edges_.emplace_back(uint32_t(low), listed_high[e]);
    }
}

const Eigen::Vector3f &MeshQuery::side_normal(const SurfacePoint &closest) const {
  const size_t f = size_t(closest.triangle);
  const Eigen::Vector3f &w = closest.bary;
  const int zeros = int(w[0] == 0.0f) + int(w[1] == 0.0f) + int(w[2] == 0.0f);
  if (zeros == 0) return face_normals_[f];
  if (zeros == 1) return edge_normals_[3 * f + size_t(w[0] == 0.0f ? 0 : w[1] == 0.0f ? 1 : 2)];
  return corner_normals_[size_t(mesh_.triangles[f][w[0] != 0.0f ? 0 : w[1] != 0.0f ? 1 : 2])];
}

MeshQuery::~MeshQuery() = default;

SurfacePoint MeshQuery::closest(const Eigen::Vector3f &point) const {
  // The tree's point is not kept: weights_on finds it again on the primitive, with its feature.
  const auto primitive_id = tree_->tree.closest_point_and_primitive(Point(point.x(), point.y(), point.z())).second;
  const size_t stored = size_t(primitive_id - tree_->triangles.cbegin());
  SurfacePoint sp;
  sp.triangle = tree_->triangle_ids[stored];
  sp.bary = weights_on(mesh_, sp.triangle, point.cast<double>());
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
  const ::plume::Tree::Point_and_primitive_id start_hint(start_point, tree_->triangles.cbegin() + start);
  const auto primitive_id = tree_->tree.closest_point_and_primitive(Point(point.x(), point.y(), point.z()), start_hint).second;
  SurfacePoint sp;
  sp.triangle = tree_->triangle_ids[size_t(primitive_id - tree_->triangles.cbegin())];
  sp.bary = weights_on(mesh_, sp.triangle, point);
  return sp;
}

double MeshQuery::signed_distance(const Eigen::Vector3d &point, const SurfacePoint &hint,
                                  SurfacePoint &r_closest) const {
  r_closest = closest(point, hint);
  const Eigen::Vector3d offset = point - surface_position(mesh_, r_closest).cast<double>();
  const double distance = offset.norm();
  const double side = offset.dot(side_normal(r_closest).cast<double>());
  return side < 0.0 ? -distance : distance;
}

float MeshQuery::signed_distance(const Eigen::Vector3f &point, SurfacePoint *r_closest) const {
  const SurfacePoint sp = closest(point);
  if (r_closest) *r_closest = sp;
  const Eigen::Vector3f offset = point - surface_position(mesh_, sp);
  const float distance = offset.norm();
  const float side = offset.dot(side_normal(sp));
  return side < 0.0f ? -distance : distance;
}

SurfacePoint surface_point_below(const MeshQuery &query, const Eigen::Vector3f &point) {
  const Mesh &mesh = query.mesh();
  SurfacePoint foot = query.closest(point);
  const Eigen::Vector3f start = surface_position(mesh, foot);
  const auto across = [&](const SurfacePoint &sp, float &r_height) {
    const Eigen::Vector3f n = surface_normal(mesh, sp), d = point - surface_position(mesh, sp);
    r_height = d.dot(n);
    return Eigen::Vector3f(d - r_height * n);
  };
  float height = 0.0f;
  Eigen::Vector3f miss = across(foot, height);
  const float first_miss = miss.norm();
  // Moving the foot by its miss overshoots where the normals turn fast under a high point (by the
  // factor 1 + height x the normals' rate of turn): a step that does not shrink the miss is halved,
  // up to 6 times.
  for (int i = 0; i < 32 && height > 0.0f && miss.norm() > 1e-6f * height; ++i) {
    bool moved = false;
    for (float fraction = 1.0f; fraction > 0.01f && !moved; fraction *= 0.5f) {
      const SurfacePoint next = query.closest(Eigen::Vector3f(surface_position(mesh, foot) + fraction * miss));
      float next_height = 0.0f;
      const Eigen::Vector3f next_miss = across(next, next_height);
      if (next_miss.norm() < miss.norm() && next_height > 0.0f &&
          (surface_position(mesh, next) - start).norm() <= 4.0f * first_miss) {
        foot = next;
        miss = next_miss;
        height = next_height;
        moved = true;
      }
    }
    if (!moved) break;
  }
  return foot;
}

}  // namespace plume
