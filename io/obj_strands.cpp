// Strands as Wavefront OBJ polylines: `v` lines and `l` lines. Viewers keep only the first segment
// of a longer `l`, so the writer puts one two-index `l` per segment and the reader chains
// consecutive `l` lines that continue where the previous one ended.
#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io::detail {

StrandSet read_obj_strands(const std::string &path) { return read_obj_strands_text(path, read_file_bytes(path)); }

StrandSet read_obj_strands_text(const std::string &path, const std::string &text) {
  LineCursor cursor(text, path);
  std::vector<Eigen::Vector3f> vertices;
  std::vector<int64_t> chain_offsets{0};  // strands as runs of `chain`
  std::vector<int> chain;                 // vertex indices
  while (cursor.next()) {
    std::string_view rest = cursor.line();
    if (const size_t hash = rest.find('#'); hash != std::string_view::npos) rest = rest.substr(0, hash);
    const std::string_view keyword = LineCursor::take_token(rest);
    if (keyword == "v") {
      vertices.push_back(cursor.take_vec3(rest, "v"));
    } else if (keyword == "l") {
      const size_t line_start = chain.size();
      for (std::string_view token = LineCursor::take_token(rest); !token.empty(); token = LineCursor::take_token(rest)) {
        chain.push_back(cursor.to_obj_index(token, token.substr(0, token.find('/')), vertices.size(), "l: vertex", "vertices"));
      }
      const size_t index_num = chain.size() - line_start;
      if (index_num < 2) cursor.fail("l: expected at least 2 vertex indices, got " + std::to_string(index_num));
      // Continue the previous strand when this line starts where it ended.
      const bool continues = chain_offsets.size() > 1 && chain[line_start - 1] == chain[line_start];
      if (continues) {
        chain.erase(chain.begin() + int64_t(line_start));
        chain_offsets.back() = int64_t(chain.size());
      } else {
        chain_offsets.push_back(int64_t(chain.size()));
      }
    }
  }
  StrandSet strands;
  strands.offsets = std::move(chain_offsets);
  strands.positions.resize(chain.size());
  for (size_t p = 0; p < chain.size(); ++p) strands.positions[p] = vertices[chain[p]];
  strands.ids.resize(strands.strand_count());
  for (size_t s = 0; s < strands.ids.size(); ++s) strands.ids[s] = s;
  return strands;
}

void write_obj_strands(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options) {
  std::string out;
  out.reserve(kWriteBlockBytes + 256);
  if (!options.comment.empty()) {
    std::string_view rest = options.comment;
    while (!rest.empty()) {
      const size_t newline = rest.find('\n');
      out += "# ";
      out += rest.substr(0, newline);
      out += '\n';
      rest.remove_prefix(newline == std::string_view::npos ? rest.size() : newline + 1);
    }
  }
  out += "# " + std::to_string(strands.strand_count()) + " strands, " + std::to_string(strands.point_count()) +
         " points, one l per segment\n";
  append_obj_vertices(file, out, strands.positions);
  for (size_t s = 0; s < strands.strand_count(); ++s)
    for (int64_t p = strands.offsets[s] + 1; p < strands.offsets[s + 1]; ++p) {
      out += "l ";
      append_number(out, (long long)p);  // 1-based index of point p - 1
      out += ' ';
      append_number(out, (long long)p + 1);
      out += '\n';
      flush_block_if_full(file, out);
    }
  file.write(out);
}

}  // namespace plume::io::detail
