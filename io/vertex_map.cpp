#include "io/vertex_map.h"

#include <cmath>
#include <string_view>

#include "io/file_scan.h"

namespace plume::io {

std::vector<float> read_vertex_map(const std::string &path, size_t vertex_count, const std::string &what) {
  std::string text;
  try {
    text = detail::read_file_bytes(path);
  } catch (const InputError &e) {
    throw InputError(what + ": " + e.what());
  }
  // Every message names the file (and line) first, then what the map is for.
  try {
    detail::LineCursor cursor(text, path);
    std::vector<float> values;
    values.reserve(vertex_count);
    while (cursor.next()) {
      std::string_view rest = cursor.line();
      if (const size_t hash = rest.find('#'); hash != std::string_view::npos) rest = rest.substr(0, hash);
      const std::string_view token = detail::LineCursor::take_token(rest);
      if (token.empty()) continue;
      if (!detail::LineCursor::take_token(rest).empty()) cursor.fail(rest, "expected one number per line");
      const float v = cursor.to_float(token, "vertex map value");
      if (!(v >= 0.0f && v <= 1.0f))
        cursor.fail(token, "vertex map value: expected a number in [0, 1], got " + detail::quoted(token));
      if (values.size() == vertex_count)
        cursor.fail(token, "expected " + std::to_string(vertex_count) + " values (one per emitter vertex), got more");
      values.push_back(v);
    }
    if (values.size() != vertex_count)
      throw InputError(FileLoc{path}, "expected " + std::to_string(vertex_count) +
                                          " values (one per emitter vertex), got " + std::to_string(values.size()));
    return values;
  } catch (const InputError &e) {
    throw InputError(std::string(e.what()) + " (" + what + ")");
  }
}

}  // namespace plume::io
