#include "io/point_list.h"

#include "groom/limits.h"
#include "io/file_scan.h"
#include "io/strand_file.h"

namespace plume::io {

std::vector<Eigen::Vector3f> read_points(const std::string &path) {
  const std::string ext = detail::extension_of(path);
  if (ext != ".txt" && ext != ".hair" && ext != ".ply" && ext != ".usda" && ext != ".obj")
    throw InputError(FileLoc{path}, "point list: expected extension .txt, .hair, .ply, .usda or .obj, got " +
                                        detail::quoted(ext));
  if (ext != ".txt") {
    const StrandSet strands = read_strands(path);
    std::vector<Eigen::Vector3f> roots(strands.strand_count());
    for (size_t s = 0; s < roots.size(); ++s) {
      roots[s] = strands.positions[strands.offsets[s]];
      if (!within_scene_bounds(roots[s]))
        throw InputError(FileLoc{path}, "strand " + std::to_string(s) + ", point 0: " + out_of_bounds_message(roots[s]));
    }
    return roots;
  }
  const std::string text = detail::read_file_bytes(path);
  detail::LineCursor cursor(text, path);
  std::vector<Eigen::Vector3f> points;
  while (cursor.next()) {
    std::string_view rest = cursor.line();
    if (const size_t hash = rest.find('#'); hash != std::string_view::npos) rest = rest.substr(0, hash);
    std::string_view token = detail::LineCursor::take_token(rest);
    if (token.empty()) continue;
    const std::string_view body = cursor.line();
    Eigen::Vector3f p;
    p.x() = cursor.to_float(token, "x");
    p.y() = cursor.to_float(detail::LineCursor::take_token(rest), "y");
    p.z() = cursor.to_float(detail::LineCursor::take_token(rest), "z");
    if (const std::string_view extra = detail::LineCursor::take_token(rest); !extra.empty())
      cursor.fail(extra, "expected 3 numbers (x y z) on the line, got more: " + detail::quoted(extra));
    if (!within_scene_bounds(p)) cursor.fail(body, "point " + std::to_string(points.size()) + ": " + out_of_bounds_message(p));
    points.push_back(p);
  }
  return points;
}

}  // namespace plume::io
