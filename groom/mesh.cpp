#include "groom/mesh.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <utility>

#include "groom/error.h"
#include "groom/limits.h"

namespace plume {

void Mesh::compute_normals() {
  vertex_normals.assign(positions.size(), Eigen::Vector3f::Zero());
  for (const Eigen::Vector3i &t : triangles) {
    // Cross product of two edges: area-weighted face normal.
    const Eigen::Vector3f n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
    for (int k = 0; k < 3; ++k) vertex_normals[t[k]] += n;
  }
  for (Eigen::Vector3f &n : vertex_normals) {
    const float len = n.norm();
    n = len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f(0.0f, 0.0f, 1.0f);
  }
}

double Mesh::triangle_area(size_t triangle) const {
  const Eigen::Vector3i &t = triangles[triangle];
  return 0.5 * double((positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]).norm());
}

Eigen::Vector3f Mesh::face_normal(size_t triangle) const {
  const Eigen::Vector3i &t = triangles[triangle];
  const Eigen::Vector3f n = (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
  const float len = n.norm();
  return len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::Zero();
}

int Mesh::group_index(const std::string &name) const {
  for (size_t g = 0; g < group_names.size(); ++g)
    if (group_names[g] == name) return int(g);
  return -1;
}

std::string Mesh::group_list() const {
  std::string list;
  for (const std::string &name : group_names) list += (list.empty() ? "" : ", ") + name;
  return list;
}

void Mesh::validate(const std::string &source) const {
  if (triangles.empty()) throw InputError(FileLoc{source}, "mesh: expected at least one triangle, got none");
  for (size_t v = 0; v < positions.size(); ++v) {
    if (!positions[v].allFinite())
      throw InputError(FileLoc{source}, "mesh: vertex " + std::to_string(v + 1) + " is not finite");
    if (!within_scene_bounds(positions[v]))
      throw InputError(FileLoc{source}, "mesh: vertex " + std::to_string(v + 1) + ": " +
                                            out_of_bounds_message(positions[v]));
  }
  const int vertex_num = int(positions.size());
  bool any_area = false;
  for (size_t f = 0; f < triangles.size(); ++f) {
    for (int k = 0; k < 3; ++k)
      if (triangles[f][k] < 0 || triangles[f][k] >= vertex_num)
        throw InputError(FileLoc{source}, "mesh: triangle " + std::to_string(f) + " refers to vertex " +
                                              std::to_string(triangles[f][k] + 1) + ", expected 1.." +
                                              std::to_string(vertex_num));
    if (triangle_area(f) > 0.0) any_area = true;
  }
  if (!any_area) throw InputError(FileLoc{source}, "mesh: every triangle is degenerate (zero area)");
  if (!triangle_uvs.empty()) {
    if (triangle_uvs.size() != triangles.size()) throw InputError(FileLoc{source}, "mesh: uv triangles do not match");
    for (const Eigen::Vector3i &t : triangle_uvs)
      for (int k = 0; k < 3; ++k)
        if (t[k] < 0 || t[k] >= int(uvs.size())) throw InputError(FileLoc{source}, "mesh: uv index out of range");
  }
  if (triangle_groups.size() != triangles.size()) throw InternalError("mesh: one group per triangle expected");
}

std::vector<uint32_t> welded_vertices(const Mesh &mesh, double weld) {
  weld = std::max(weld, 1e-30);
  std::vector<uint32_t> canonical(mesh.positions.size());
  std::iota(canonical.begin(), canonical.end(), 0u);
  auto root_of = [&](uint32_t v) {
    while (canonical[v] != v) v = canonical[v] = canonical[canonical[v]];
    return v;
  };
  std::vector<std::pair<uint64_t, uint32_t>> keyed(mesh.positions.size());
  for (const double shift : {0.0, 0.5}) {
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      uint64_t key = 0;
      for (int axis = 0; axis < 3; ++axis)
        key = key << 21 | (uint64_t(int64_t(std::floor(double(mesh.positions[v][axis]) / weld + shift))) & 0x1fffff);
      keyed[v] = {key, uint32_t(v)};
    }
    std::sort(keyed.begin(), keyed.end());
    for (size_t i = 1; i < keyed.size(); ++i)
      if (keyed[i].first == keyed[i - 1].first) {
        const uint32_t a = root_of(keyed[i].second), b = root_of(keyed[i - 1].second);
        canonical[std::max(a, b)] = std::min(a, b);
      }
  }
  for (uint32_t v = 0; v < canonical.size(); ++v) canonical[v] = root_of(v);
  return canonical;
}

double weld_distance(const Mesh &mesh) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
  for (const Eigen::Vector3f &p : mesh.positions) {
    lo = lo.cwiseMin(p.cast<double>());
    hi = hi.cwiseMax(p.cast<double>());
  }
  return mesh.positions.empty() ? 0.0 : 1e-6 * (hi - lo).norm();
}

Eigen::Vector3f surface_position(const Mesh &mesh, const SurfacePoint &sp) {
  const Eigen::Vector3i &t = mesh.triangles[sp.triangle];
  return sp.bary[0] * mesh.positions[t[0]] + sp.bary[1] * mesh.positions[t[1]] + sp.bary[2] * mesh.positions[t[2]];
}

Eigen::Vector3f surface_normal(const Mesh &mesh, const SurfacePoint &sp) {
  const Eigen::Vector3i &t = mesh.triangles[sp.triangle];
  Eigen::Vector3f n = sp.bary[0] * mesh.vertex_normals[t[0]] + sp.bary[1] * mesh.vertex_normals[t[1]] +
                      sp.bary[2] * mesh.vertex_normals[t[2]];
  const float len = n.norm();
  if (len > 1e-12f) return n / len;
  const Eigen::Vector3f face = mesh.face_normal(sp.triangle);
  return face.squaredNorm() > 0.0f ? face : Eigen::Vector3f(0.0f, 0.0f, 1.0f);
}

float surface_value(const Mesh &mesh, std::span<const float> per_vertex, const SurfacePoint &sp) {
  const Eigen::Vector3i &t = mesh.triangles[size_t(sp.triangle)];
  return sp.bary[0] * per_vertex[size_t(t[0])] + sp.bary[1] * per_vertex[size_t(t[1])] +
         sp.bary[2] * per_vertex[size_t(t[2])];
}

Eigen::Vector2f surface_uv(const Mesh &mesh, const SurfacePoint &sp) {
  if (!mesh.has_uvs()) return Eigen::Vector2f::Zero();
  const Eigen::Vector3i &t = mesh.triangle_uvs[sp.triangle];
  return sp.bary[0] * mesh.uvs[t[0]] + sp.bary[1] * mesh.uvs[t[1]] + sp.bary[2] * mesh.uvs[t[2]];
}

namespace {

// Direction of increasing u on the triangle (dP/du), or the first edge when there are no UVs
// or the UV triangle is degenerate.
Eigen::Vector3f triangle_tangent(const Mesh &mesh, int triangle) {
  const Eigen::Vector3i &t = mesh.triangles[triangle];
  const Eigen::Vector3f e1 = mesh.positions[t[1]] - mesh.positions[t[0]];
  const Eigen::Vector3f e2 = mesh.positions[t[2]] - mesh.positions[t[0]];
  if (mesh.has_uvs()) {
    const Eigen::Vector3i &tu = mesh.triangle_uvs[triangle];
    const Eigen::Vector2f d1 = mesh.uvs[tu[1]] - mesh.uvs[tu[0]];
    const Eigen::Vector2f d2 = mesh.uvs[tu[2]] - mesh.uvs[tu[0]];
    const float det = d1.x() * d2.y() - d2.x() * d1.y();
    if (std::abs(det) > 1e-12f) {
      const Eigen::Vector3f dpdu = (e1 * d2.y() - e2 * d1.y()) / det;
      if (dpdu.squaredNorm() > 0.0f) return dpdu;
    }
  }
  if (e1.squaredNorm() > 0.0f) return e1;
  return e2;
}

}  // namespace

SurfaceFrame surface_frame(const Mesh &mesh, const SurfacePoint &sp) {
  SurfaceFrame frame;
  frame.origin = surface_position(mesh, sp);
  const Eigen::Vector3f n = surface_normal(mesh, sp);
  const Eigen::Vector3f raw = triangle_tangent(mesh, sp.triangle);
  Eigen::Vector3f tangent = raw - n * n.dot(raw);  // Gram-Schmidt against the normal
  if (tangent.squaredNorm() <= 1e-6f * raw.squaredNorm() || tangent.squaredNorm() < 1e-30f) {
    // Tangent (nearly) parallel to the normal: a sliver or folded triangle. Fall back to the face
    // normal's plane, which such a triangle still carries rigidly.
    const Eigen::Vector3i &t = mesh.triangles[sp.triangle];
    const Eigen::Vector3f e2 = mesh.positions[t[2]] - mesh.positions[t[0]];
    tangent = e2 - n * n.dot(e2);
    if (tangent.squaredNorm() <= 1e-6f * e2.squaredNorm() || tangent.squaredNorm() < 1e-30f) tangent = n.unitOrthogonal();
  }
  tangent.normalize();
  frame.basis.col(0) = tangent;
  frame.basis.col(1) = n.cross(tangent);
  frame.basis.col(2) = n;
  return frame;
}

}  // namespace plume
