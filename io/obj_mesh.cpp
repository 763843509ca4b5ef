#include "io/obj_mesh.h"

#include <array>
#include <unordered_map>

#include "groom/limits.h"
#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io {
namespace {

using detail::LineCursor;

/// Names seen by one kind of grouping statement (usemtl, g or o), and each face's name.
struct GroupTable {
  std::vector<std::string> names;
  std::unordered_map<std::string, int> index_of;
  std::vector<int> face_group;  // one per triangle; -1 before the first statement of this kind
  int current = -1;
  bool seen = false;

  void set(std::string_view name) {
    seen = true;
    const std::string key(name.empty() ? std::string_view("default") : name);
    const auto [it, inserted] = index_of.emplace(key, int(names.size()));
    if (inserted) names.push_back(key);
    current = it->second;
  }
};

Mesh parse_obj(const std::string &path, const std::string &text) {
  LineCursor cursor(text, path);
  Mesh mesh;
  size_t normal_count = 0;
  bool every_face_has_uvs = true;
  std::array<GroupTable, 3> groups;  // usemtl, g, o: the first kind the file uses names the face groups
  std::vector<std::array<int, 2>> corners;  // (vertex, uv or -1) of the current face

  while (cursor.next()) {
    std::string_view rest = cursor.line();
    if (const size_t hash = rest.find('#'); hash != std::string_view::npos) rest = rest.substr(0, hash);
    const std::string_view keyword = LineCursor::take_token(rest);
    if (keyword == "v") {
      const std::string_view body = rest;
      const Eigen::Vector3f p = cursor.take_vec3(rest, "v");
      if (!within_scene_bounds(p))
        cursor.fail(body, "v: vertex " + std::to_string(mesh.positions.size() + 1) + ": " + out_of_bounds_message(p));
      mesh.positions.push_back(p);
    } else if (keyword == "vt") {
      Eigen::Vector2f uv(cursor.to_float(LineCursor::take_token(rest), "vt: u"), 0.0f);
      if (const std::string_view v = LineCursor::take_token(rest); !v.empty()) uv.y() = cursor.to_float(v, "vt: v");
      mesh.uvs.push_back(uv);
    } else if (keyword == "vn") {
      for (const char *axis : {"vn: x", "vn: y", "vn: z"}) cursor.to_float(LineCursor::take_token(rest), axis);
      ++normal_count;
    } else if (keyword == "f") {
      corners.clear();
      bool face_has_uvs = true;
      for (std::string_view token = LineCursor::take_token(rest); !token.empty();
           token = LineCursor::take_token(rest)) {
        // v, v/vt, v/vt/vn or v//vn
        const size_t slash1 = token.find('/');
        const std::string_view v_part = token.substr(0, slash1);
        std::string_view vt_part, vn_part;
        if (slash1 != std::string_view::npos) {
          const size_t slash2 = token.find('/', slash1 + 1);
          vt_part = token.substr(slash1 + 1, slash2 == std::string_view::npos ? std::string_view::npos : slash2 - slash1 - 1);
          if (slash2 != std::string_view::npos) vn_part = token.substr(slash2 + 1);
        }
        const int v = cursor.to_obj_index(token, v_part, mesh.positions.size(), "f: vertex", "vertices");
        int vt = -1;
        if (!vt_part.empty())
          vt = cursor.to_obj_index(token, vt_part, mesh.uvs.size(), "f: uv", "uvs");
        else
          face_has_uvs = false;
        if (!vn_part.empty()) cursor.to_obj_index(token, vn_part, normal_count, "f: normal", "normals");
        corners.push_back({v, vt});
      }
      if (corners.size() < 3)
        cursor.fail("f: expected at least 3 corners, got " + std::to_string(corners.size()));
      every_face_has_uvs = every_face_has_uvs && face_has_uvs;
      // Fan triangulation around the first corner.
      for (size_t k = 1; k + 1 < corners.size(); ++k) {
        mesh.triangles.emplace_back(corners[0][0], corners[k][0], corners[k + 1][0]);
        mesh.triangle_uvs.emplace_back(corners[0][1], corners[k][1], corners[k + 1][1]);
        for (GroupTable &table : groups) table.face_group.push_back(table.current);
      }
    } else if (keyword == "usemtl") {
      groups[0].set(LineCursor::take_token(rest));
    } else if (keyword == "g") {
      groups[1].set(LineCursor::take_token(rest));
    } else if (keyword == "o") {
      groups[2].set(LineCursor::take_token(rest));
    }
    // Other statements (s, mtllib, l, p, curves) do not shape the emitter.
  }

  if (!every_face_has_uvs) {
    mesh.triangle_uvs.clear();
    mesh.uvs.clear();
  }
  const GroupTable *chosen = nullptr;
  for (const GroupTable &table : groups)
    if (table.seen) {
      chosen = &table;
      break;
    }
  if (chosen == nullptr) {
    mesh.group_names = {"default"};
    mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  } else {
    // Faces before the first grouping statement go to "default", added only when used.
    mesh.group_names = chosen->names;
    int default_group = -1;
    mesh.triangle_groups.resize(mesh.triangles.size());
    for (size_t f = 0; f < mesh.triangles.size(); ++f) {
      int group = chosen->face_group[f];
      if (group < 0) {
        if (default_group < 0) {
          const auto it = chosen->index_of.find("default");
          default_group = it != chosen->index_of.end() ? it->second : int(mesh.group_names.size());
          if (it == chosen->index_of.end()) mesh.group_names.push_back("default");
        }
        group = default_group;
      }
      mesh.triangle_groups[f] = group;
    }
  }
  return mesh;
}

std::string vertex_triple(const Eigen::Vector3i &t) {
  return std::to_string(t[0] + 1) + " " + std::to_string(t[1] + 1) + " " + std::to_string(t[2] + 1);
}

/// Whether some line of an OBJ text is a face (`f`), after leading blanks.
bool obj_text_has_faces(std::string_view text) {
  for (size_t start = 0; start < text.size();) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    const std::string_view line = text.substr(start, end - start);
    const size_t first = line.find_first_not_of(" \t");
    if (first != std::string_view::npos && line.size() > first + 1 && line[first] == 'f' &&
        (line[first + 1] == ' ' || line[first + 1] == '\t'))
      return true;
    start = end + 1;
  }
  return false;
}

/// read_obj_mesh() of `text`, the contents of `path`.
Mesh read_obj_mesh_text(const std::string &path, const std::string &text) {
  Mesh mesh = parse_obj(path, text);
  mesh.validate(path);
  mesh.compute_normals();
  return mesh;
}

}  // namespace

Mesh read_obj_mesh(const std::string &path) { return read_obj_mesh_text(path, detail::read_file_bytes(path)); }

ObjContents read_obj_file(const std::string &path) {
  const std::string text = detail::read_file_bytes(path);
  ObjContents contents;
  if (obj_text_has_faces(text))
    contents.mesh = read_obj_mesh_text(path, text);
  else
    contents.strands = detail::read_obj_strands_text(path, text);
  return contents;
}

Mesh read_obj_pose(const std::string &path, const Mesh &rest) {
  Mesh frame = parse_obj(path, detail::read_file_bytes(path));
  if (frame.vertex_count() != rest.vertex_count())
    throw InputError(FileLoc{path}, "vertex count: expected " + std::to_string(rest.vertex_count()) +
                                        " as in the rest mesh, got " + std::to_string(frame.vertex_count()));
  if (frame.triangle_count() != rest.triangle_count())
    throw InputError(FileLoc{path}, "triangle count: expected " + std::to_string(rest.triangle_count()) +
                                        " as in the rest mesh, got " + std::to_string(frame.triangle_count()));
  for (size_t f = 0; f < rest.triangle_count(); ++f)
    if (frame.triangles[f] != rest.triangles[f])
      throw InputError(FileLoc{path}, "triangle " + std::to_string(f + 1) + ": expected vertices " +
                                          vertex_triple(rest.triangles[f]) + " as in the rest mesh, got " +
                                          vertex_triple(frame.triangles[f]));
  Mesh posed = rest;
  posed.positions = std::move(frame.positions);
  posed.validate(path);
  posed.compute_normals();
  return posed;
}

}  // namespace plume::io
