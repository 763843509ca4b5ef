// The emitter: a triangle mesh with optional UVs and face groups, and the surface points and
// frames that roots and guides are bound to.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace plume {

struct Mesh {
  /// #V by 3, scene units.
  std::vector<Eigen::Vector3f> positions;
  /// #F vertex index triples (polygons are fan-triangulated by the reader).
  std::vector<Eigen::Vector3i> triangles;
  /// #UV texture coordinates; empty when the mesh has none.
  std::vector<Eigen::Vector2f> uvs;
  /// #F uv index triples; empty when the mesh has no UVs.
  std::vector<Eigen::Vector3i> triangle_uvs;
  /// #F indices into group_names (OBJ `g` / `usemtl`); every face has one, "default" if unnamed.
  std::vector<int> triangle_groups;
  std::vector<std::string> group_names;
  /// #V area-weighted vertex normals; fill with compute_normals() after changing positions.
  std::vector<Eigen::Vector3f> vertex_normals;

  size_t vertex_count() const { return positions.size(); }
  size_t triangle_count() const { return triangles.size(); }
  bool has_uvs() const { return !triangle_uvs.empty(); }

  void compute_normals();
  double triangle_area(size_t triangle) const;
  Eigen::Vector3f face_normal(size_t triangle) const;  // unit; zero for a degenerate face
  /// Index of a group by name, or -1.
  int group_index(const std::string &name) const;
  /// The group names joined by ", ", for a message about an unknown group.
  std::string group_list() const;
  /// Throws InputError naming `source` when an index is out of range, a value is not finite or
  /// beyond max_coordinate (groom/limits.h), or every triangle is degenerate. Degenerate triangles alone are allowed (they get no roots).
  void validate(const std::string &source) const;
};

/// A point on the surface: a triangle and barycentric weights (w0 + w1 + w2 == 1).
struct SurfacePoint {
  int32_t triangle = -1;
  Eigen::Vector3f bary = Eigen::Vector3f(1.0f, 0.0f, 0.0f);
};

Eigen::Vector3f surface_position(const Mesh &mesh, const SurfacePoint &sp);
/// Interpolated vertex normal, normalised.
Eigen::Vector3f surface_normal(const Mesh &mesh, const SurfacePoint &sp);
/// (0,0) when the mesh has no UVs.
Eigen::Vector2f surface_uv(const Mesh &mesh, const SurfacePoint &sp);
/// A value per vertex (`per_vertex`, one per mesh vertex: a vertex map) interpolated at `sp`.
float surface_value(const Mesh &mesh, std::span<const float> per_vertex, const SurfacePoint &sp);

/// An orthonormal frame at a surface point: columns of `basis` are (tangent, bitangent, normal).
/// The tangent follows the UV u direction when the mesh has UVs, else the triangle's first edge,
/// projected onto the plane of the interpolated normal. Both are carried by the triangle as it
/// deforms, so the frame turns with the skin and never spins (feather thesis, sec. 3.2.1).
struct SurfaceFrame {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Matrix3f basis = Eigen::Matrix3f::Identity();

  Eigen::Vector3f normal() const { return basis.col(2); }
  Eigen::Vector3f to_local(const Eigen::Vector3f &world) const { return basis.transpose() * (world - origin); }
  Eigen::Vector3f to_world(const Eigen::Vector3f &local) const { return origin + basis * local; }
  Eigen::Vector3f dir_to_local(const Eigen::Vector3f &d) const { return basis.transpose() * d; }
  Eigen::Vector3f dir_to_world(const Eigen::Vector3f &d) const { return basis * d; }
};

SurfaceFrame surface_frame(const Mesh &mesh, const SurfacePoint &sp);

/// Closest point of triangle abc to p, as barycentric weights (Ericson, Real-Time Collision
/// Detection, 5.1.5). The weights name the feature that holds the point: on an edge the opposite
/// corner's weight is exactly 0, at a corner the other two are; inside the face none is.
template <class Scalar>
Eigen::Matrix<Scalar, 3, 1> closest_on_triangle(const Eigen::Matrix<Scalar, 3, 1> &p, const Eigen::Matrix<Scalar, 3, 1> &a,
                                                const Eigen::Matrix<Scalar, 3, 1> &b, const Eigen::Matrix<Scalar, 3, 1> &c) {
  using Vector = Eigen::Matrix<Scalar, 3, 1>;
  const Scalar zero = 0, one = 1;
  const Vector ab = b - a, ac = c - a, ap = p - a;
  const Scalar d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= zero && d2 <= zero) return {one, zero, zero};
  const Vector bp = p - b;
  const Scalar d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= zero && d4 <= d3) return {zero, one, zero};
  const Scalar vc = d1 * d4 - d3 * d2;
  if (vc <= zero && d1 >= zero && d3 <= zero) {
    const Scalar v = d1 / (d1 - d3);
    return {one - v, v, zero};
  }
  const Vector cp = p - c;
  const Scalar d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= zero && d5 <= d6) return {zero, zero, one};
  const Scalar vb = d5 * d2 - d1 * d6;
  if (vb <= zero && d2 >= zero && d6 <= zero) {
    const Scalar w = d2 / (d2 - d6);
    return {one - w, zero, w};
  }
  const Scalar va = d3 * d6 - d5 * d4;
  if (va <= zero && (d4 - d3) >= zero && (d5 - d6) >= zero) {
    const Scalar w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {zero, one - w, w};
  }
  const Scalar denom = one / (va + vb + vc);
  const Scalar v = vb * denom, w = vc * denom;
  return {one - v - w, v, w};
}

/// For each vertex, the lowest-numbered vertex it is welded to: vertices much closer than `weld`
/// count as one (a mesh split along its UV seams is whole again). They share a cube of side `weld`
/// in one of two grids of cubes offset by half a cube; a pair that straddles a face in both grids
/// stays apart (rare).
std::vector<uint32_t> welded_vertices(const Mesh &mesh, double weld);
/// The weld distance Plume uses for a mesh: a millionth of its bounding box's diagonal.
double weld_distance(const Mesh &mesh);

}  // namespace plume
