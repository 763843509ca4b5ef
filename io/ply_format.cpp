// Strands as PLY polylines: a `vertex` element (x, y, z, optional width) and an `edge` element
// (vertex1, vertex2), one edge per segment; or, instead of edges, a per-vertex `strand`/`curve`
// id whose consecutive runs are strands. Reads ascii and binary_little_endian; writes binary.
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io::detail {
namespace {

enum class PlyType { Int8, UInt8, Int16, UInt16, Int32, UInt32, Float32, Float64 };

struct PlyProperty {
  std::string name;
  PlyType type = PlyType::Float32;
  bool is_list = false;
  PlyType count_type = PlyType::UInt8;
};

struct PlyElement {
  std::string name;
  uint64_t count = 0;
  std::vector<PlyProperty> properties;
  int line = 0;  // header line that declared it
};

int type_bytes(PlyType type) {
  switch (type) {
    case PlyType::Int8: case PlyType::UInt8: return 1;
    case PlyType::Int16: case PlyType::UInt16: return 2;
    case PlyType::Int32: case PlyType::UInt32: case PlyType::Float32: return 4;
    case PlyType::Float64: return 8;
  }
  return 0;
}

bool parse_type(std::string_view name, PlyType &r_type) {
  static const std::pair<std::string_view, PlyType> kNames[] = {
      {"char", PlyType::Int8},     {"int8", PlyType::Int8},     {"uchar", PlyType::UInt8},   {"uint8", PlyType::UInt8},
      {"short", PlyType::Int16},   {"int16", PlyType::Int16},   {"ushort", PlyType::UInt16}, {"uint16", PlyType::UInt16},
      {"int", PlyType::Int32},     {"int32", PlyType::Int32},   {"uint", PlyType::UInt32},   {"uint32", PlyType::UInt32},
      {"float", PlyType::Float32}, {"float32", PlyType::Float32}, {"double", PlyType::Float64}, {"float64", PlyType::Float64}};
  for (const auto &[key, type] : kNames)
    if (key == name) {
      r_type = type;
      return true;
    }
  return false;
}

double read_binary(const ByteCursor &in, size_t offset, PlyType type) {
  switch (type) {
    case PlyType::Int8: return in.get<int8_t>(offset);
    case PlyType::UInt8: return in.get<uint8_t>(offset);
    case PlyType::Int16: return in.get<int16_t>(offset);
    case PlyType::UInt16: return in.get<uint16_t>(offset);
    case PlyType::Int32: return in.get<int32_t>(offset);
    case PlyType::UInt32: return in.get<uint32_t>(offset);
    case PlyType::Float32: return in.get<float>(offset);
    case PlyType::Float64: return in.get<double>(offset);
  }
  return 0.0;
}

/// Where one value of an element item came from, for messages: a text line or a byte offset.
struct ValueLoc {
  int line = 0;
  long long byte = -1;
};

/// The vertex and edge data the strands are built from, whatever the encoding.
struct PlyData {
  std::vector<Eigen::Vector3f> positions;
  std::vector<float> widths;
  std::vector<int64_t> strand_ids;
  std::vector<std::array<int64_t, 2>> edges;
  std::vector<ValueLoc> edge_locs;
};

/// Which property of the vertex or edge element feeds which field (-1: absent).
struct Roles {
  int xyz[3] = {-1, -1, -1};
  int width = -1;
  int strand = -1;
  int vertex12[2] = {-1, -1};
};

class PlyReader {
 public:
  explicit PlyReader(const std::string &path) : path_(path), bytes_(read_file_bytes(path)) {}

  StrandSet read() {
    LineCursor header(bytes_, path_);
    parse_header(header);
    if (binary_)
      read_binary_body(header.end_offset());
    else
      read_ascii_body(header);
    return build_strands();
  }

 private:
  [[noreturn]] void fail_at(const ValueLoc &loc, const std::string &message) const {
    if (loc.line > 0) throw InputError(FileLoc{path_, loc.line}, message);
    throw InputError(FileLoc{path_, 0, 0, loc.byte}, message);
  }

  void parse_header(LineCursor &header) {
    if (!header.next() || header.line() != "ply")
      throw InputError(FileLoc{path_, 1}, "magic: expected \"ply\", got " + quoted(header.line()));
    bool format_seen = false;
    for (;;) {
      if (!header.next()) throw InputError(FileLoc{path_, header.line_number()}, "header: expected end_header, file ends");
      std::string_view rest = header.line();
      const std::string_view keyword = LineCursor::take_token(rest);
      if (keyword == "end_header") break;
      if (keyword == "comment" || keyword == "obj_info" || keyword.empty()) continue;
      if (keyword == "format") {
        const std::string_view format = LineCursor::take_token(rest);
        if (format == "binary_little_endian") binary_ = true;
        else if (format != "ascii")
          header.fail(format, "format: expected ascii or binary_little_endian, got " + quoted(format));
        format_seen = true;
      } else if (keyword == "element") {
        PlyElement element;
        element.name = std::string(LineCursor::take_token(rest));
        const std::string_view count = LineCursor::take_token(rest);
        const long long n = header.to_int(count, "element " + element.name + ": count");
        if (n < 0) header.fail(count, "element " + element.name + ": expected a count >= 0, got " + std::to_string(n));
        element.count = uint64_t(n);
        element.line = header.line_number();
        elements_.push_back(element);
      } else if (keyword == "property") {
        if (elements_.empty()) header.fail("property: expected an element line before it");
        PlyProperty property;
        std::string_view type = LineCursor::take_token(rest);
        if (type == "list") {
          property.is_list = true;
          const std::string_view count_type = LineCursor::take_token(rest);
          if (!parse_type(count_type, property.count_type) || property.count_type == PlyType::Float32 ||
              property.count_type == PlyType::Float64)
            header.fail(count_type, "property list: expected an integer count type (uchar, int, ...), got " + quoted(count_type));
          type = LineCursor::take_token(rest);
        }
        if (!parse_type(type, property.type))
          header.fail(type, "property: expected a type (char uchar short ushort int uint float double), got " + quoted(type));
        property.name = std::string(LineCursor::take_token(rest));
        if (property.name.empty()) header.fail("property: expected a name after the type");
        elements_.back().properties.push_back(property);
      } else {
        header.fail(keyword, "header: expected format, element, property, comment or end_header, got " + quoted(keyword));
      }
    }
    if (!format_seen) throw InputError(FileLoc{path_, 2}, "format: expected a format line in the header, found none");
    header_end_line_ = header.line_number();

    for (size_t e = 0; e < elements_.size(); ++e) {
      if (elements_[e].name == "vertex") vertex_element_ = int(e);
      if (elements_[e].name == "edge") edge_element_ = int(e);
    }
    if (vertex_element_ < 0) throw InputError(FileLoc{path_, header_end_line_}, "header: expected a vertex element, found none");
    const PlyElement &vertex = elements_[vertex_element_];
    for (size_t p = 0; p < vertex.properties.size(); ++p) {
      const PlyProperty &property = vertex.properties[p];
      const int role = property.name == "x" ? 0 : property.name == "y" ? 1 : property.name == "z" ? 2 : -1;
      if (role >= 0) roles_.xyz[role] = int(p);
      if (property.name == "width") roles_.width = int(p);
      if (property.name == "strand" || property.name == "curve") roles_.strand = int(p);
      if (property.is_list && (role >= 0 || property.name == "width" || property.name == "strand" || property.name == "curve"))
        throw InputError(FileLoc{path_, vertex.line}, "vertex: expected property " + property.name + " to be a scalar, got a list");
    }
    for (int axis = 0; axis < 3; ++axis)
      if (roles_.xyz[axis] < 0)
        throw InputError(FileLoc{path_, vertex.line}, std::string("vertex: expected properties x, y and z, missing ") + "xyz"[axis]);
    if (edge_element_ >= 0) {
      const PlyElement &edge = elements_[edge_element_];
      for (size_t p = 0; p < edge.properties.size(); ++p) {
        if (edge.properties[p].name == "vertex1") roles_.vertex12[0] = int(p);
        if (edge.properties[p].name == "vertex2") roles_.vertex12[1] = int(p);
      }
      if (roles_.vertex12[0] < 0 || roles_.vertex12[1] < 0 || edge.properties[roles_.vertex12[0]].is_list ||
          edge.properties[roles_.vertex12[1]].is_list)
        throw InputError(FileLoc{path_, edge.line}, "edge: expected scalar properties vertex1 and vertex2");
    } else if (roles_.strand < 0) {
      throw InputError(FileLoc{path_, header_end_line_},
                       "header: expected an edge element (vertex1, vertex2) or a per-vertex strand/curve property, found neither");
    }
  }

  /// Stores one scalar of the vertex or edge element.
  void take(int element, int property, double value, const ValueLoc &loc, uint64_t item) {
    if (element == vertex_element_) {
      for (int axis = 0; axis < 3; ++axis)
        if (property == roles_.xyz[axis]) {
          if (!fits_float(value))
            fail_at(loc, "vertex " + std::to_string(item) + ": " + "xyz"[axis] + ": " + float_range_message(value));
          data_.positions[item][axis] = to_float(value);
        }
      if (property == roles_.width) {
        if (!valid_width(value)) fail_at(loc, "vertex " + std::to_string(item) + ": width: " + width_message(value));
        data_.widths[item] = to_float(value);
      }
      if (property == roles_.strand) {
        // Any integer a double holds; 2^63 and beyond would not convert.
        if (!(std::abs(value) < 0x1p63) || value != std::floor(value))
          fail_at(loc, "vertex " + std::to_string(item) + ": " + elements_[vertex_element_].properties[size_t(property)].name +
                           ": expected an integer id, got " + number_text(value));
        data_.strand_ids[item] = int64_t(value);
      }
    } else if (element == edge_element_) {
      for (int end = 0; end < 2; ++end)
        if (property == roles_.vertex12[end]) {
          const uint64_t vertex_num = elements_[vertex_element_].count;
          if (!(value >= 0.0 && value < double(vertex_num)) || value != std::floor(value))
            fail_at(loc, "edge " + std::to_string(item) + ": vertex" + std::to_string(end + 1) + ": expected a vertex index 0.." +
                             std::to_string(int64_t(vertex_num) - 1) + ", got " + number_text(value));
          data_.edges[item][end] = int64_t(value);
          if (end == 0) data_.edge_locs[item] = loc;
        }
    }
  }

  /// Allocates the vertex and edge arrays once their counts have been checked against the file.
  void allocate(int element) {
    const uint64_t n = elements_[element].count;
    if (element == vertex_element_) {
      data_.positions.assign(n, Eigen::Vector3f::Zero());
      if (roles_.width >= 0) data_.widths.assign(n, 0.0f);
      if (roles_.strand >= 0) data_.strand_ids.assign(n, 0);
    } else if (element == edge_element_) {
      data_.edges.assign(n, {0, 0});
      data_.edge_locs.assign(n, ValueLoc{});
    }
  }

  void read_binary_body(size_t offset) {
    const ByteCursor in(bytes_, path_);
    for (size_t e = 0; e < elements_.size(); ++e) {
      const PlyElement &element = elements_[e];
      // Fixed-size items must all fit; list items need at least their count fields.
      uint64_t min_item_bytes = 0;
      for (const PlyProperty &property : element.properties)
        min_item_bytes += uint64_t(type_bytes(property.is_list ? property.count_type : property.type));
      in.require(offset, element.count, min_item_bytes, "element " + element.name);
      if (element.properties.empty()) continue;  // items of no bytes, however many
      const bool has_lists = std::any_of(element.properties.begin(), element.properties.end(),
                                         [](const PlyProperty &property) { return property.is_list; });
      allocate(int(e));
      const bool wanted = int(e) == vertex_element_ || int(e) == edge_element_;
      for (uint64_t item = 0; item < element.count; ++item) {
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty &property = element.properties[p];
          if (property.is_list) {
            in.require(offset, 1, type_bytes(property.count_type), "element " + element.name + " list count");
            const double count = read_binary(in, offset, property.count_type);  // an integer type: exact
            if (count < 0) in.fail(offset, "element " + element.name + ": list " + property.name + ": expected a count >= 0, got " + number_text(count));
            offset += type_bytes(property.count_type);
            in.require(offset, uint64_t(count), type_bytes(property.type), "element " + element.name + " list " + property.name);
            offset += size_t(count) * type_bytes(property.type);
            continue;
          }
          if (has_lists) in.require(offset, 1, type_bytes(property.type), "element " + element.name + " item " + std::to_string(item));
          if (wanted) take(int(e), int(p), read_binary(in, offset, property.type), ValueLoc{0, (long long)offset}, item);
          offset += type_bytes(property.type);
        }
      }
    }
    if (offset != bytes_.size())
      in.fail(offset, "expected the file to end after the last element, got " + std::to_string(bytes_.size() - offset) + " more bytes");
  }

  void read_ascii_body(LineCursor &lines) {
    uint64_t total_items = 0;  // saturating: no list of counts can wrap around into agreement
    for (const PlyElement &element : elements_)
      total_items = element.count > std::numeric_limits<uint64_t>::max() - total_items ? std::numeric_limits<uint64_t>::max()
                                                                                       : total_items + element.count;
    // One item per line: the header's counts cannot exceed the lines the file has.
    const size_t lines_left = lines.lines_left();
    if (total_items > lines_left)
      throw InputError(FileLoc{path_, header_end_line_}, "elements: expected " + std::to_string(total_items) +
                                                            " lines of data as the header says, the file has " +
                                                            std::to_string(lines_left));
    for (size_t e = 0; e < elements_.size(); ++e) {
      const PlyElement &element = elements_[e];
      allocate(int(e));
      const bool wanted = int(e) == vertex_element_ || int(e) == edge_element_;
      for (uint64_t item = 0; item < element.count; ++item) {
        if (!lines.next())
          throw InputError(FileLoc{path_, lines.line_number()}, "element " + element.name + ": expected " +
                                                                    std::to_string(element.count) + " lines, file ends");
        std::string_view rest = lines.line();
        for (size_t p = 0; p < element.properties.size(); ++p) {
          const PlyProperty &property = element.properties[p];
          const auto what = [&] { return element.name + " " + std::to_string(item) + ": " + property.name; };
          if (property.is_list) {
            const long long count = lines.to_int(LineCursor::take_token(rest), what() + " count");
            if (count < 0) lines.fail(what() + ": expected a list count >= 0, got " + std::to_string(count));
            for (long long k = 0; k < count; ++k) lines.to_float(LineCursor::take_token(rest), what());
            continue;
          }
          const std::string_view token = LineCursor::take_token(rest);
          double value = 0.0;
          if (property.type == PlyType::Float32 || property.type == PlyType::Float64) {
            float parsed = 0.0f;
            if (parse_float(token, parsed) != NumberStatus::Ok) lines.to_float(token, what());  // throws the message
            value = parsed;
          } else {
            long long parsed = 0;
            if (parse_int(token, parsed) != NumberStatus::Ok) lines.to_int(token, what());  // throws the message
            value = double(parsed);
          }
          if (wanted) take(int(e), int(p), value, ValueLoc{lines.line_number(), -1}, item);
        }
        if (const std::string_view extra = LineCursor::take_token(rest); !extra.empty())
          lines.fail(extra, element.name + " " + std::to_string(item) + ": expected " +
                                std::to_string(element.properties.size()) + " values, got more: " + quoted(extra));
      }
    }
  }

  StrandSet build_strands() const {
    const size_t vertex_num = data_.positions.size();
    std::vector<int64_t> order;  // vertex indices strand after strand
    std::vector<int64_t> offsets{0};
    if (edge_element_ >= 0) {
      chain_edges(vertex_num, order, offsets);
    } else {
      // Consecutive runs of the same strand id.
      for (size_t v = 0; v < vertex_num; ++v) {
        if (v > 0 && data_.strand_ids[v] != data_.strand_ids[v - 1]) offsets.push_back(int64_t(v));
        order.push_back(int64_t(v));
      }
      if (vertex_num > 0) offsets.push_back(int64_t(vertex_num));
      for (size_t s = 0; s + 1 < offsets.size(); ++s)
        if (offsets[s + 1] - offsets[s] < 2)
          throw InputError(FileLoc{path_, header_end_line_},
                           "vertex " + std::to_string(offsets[s]) + ": strand " + std::to_string(data_.strand_ids[offsets[s]]) +
                               " has 1 point, expected at least 2");
    }
    StrandSet strands;
    strands.offsets = std::move(offsets);
    strands.positions.resize(order.size());
    for (size_t p = 0; p < order.size(); ++p) strands.positions[p] = data_.positions[order[p]];
    if (!data_.widths.empty()) {
      strands.widths.resize(order.size());
      for (size_t p = 0; p < order.size(); ++p) strands.widths[p] = data_.widths[order[p]];
    }
    strands.ids.resize(strands.strand_count());
    for (size_t s = 0; s < strands.ids.size(); ++s) strands.ids[s] = s;
    return strands;
  }

  /// Turns edges into open chains. When every vertex has at most one outgoing and one incoming
  /// edge, the edges' direction gives the root; otherwise each chain starts at its lower-index end.
  /// Chains are ordered by their first vertex; isolated vertices belong to no strand.
  void chain_edges(size_t vertex_num, std::vector<int64_t> &r_order, std::vector<int64_t> &r_offsets) const {
    constexpr int64_t kNone = -1;
    std::vector<int64_t> neighbour(2 * vertex_num, kNone);
    std::vector<uint8_t> degree(vertex_num, 0);
    std::vector<int64_t> next(vertex_num, kNone);
    std::vector<uint8_t> in_degree(vertex_num, 0);
    bool directed = true;
    for (size_t e = 0; e < data_.edges.size(); ++e) {
      const auto [a, b] = data_.edges[e];
      if (a == b) fail_at(data_.edge_locs[e], "edge " + std::to_string(e) + ": expected two different vertices, got " + std::to_string(a) + " twice");
      for (const int64_t v : {a, b})
        if (degree[v] == 2)
          fail_at(data_.edge_locs[e], "edge " + std::to_string(e) + ": vertex " + std::to_string(v) +
                                          " gets a third edge; expected open chains (at most 2 edges per vertex)");
      neighbour[2 * a + degree[a]++] = b;
      neighbour[2 * b + degree[b]++] = a;
      if (next[a] != kNone || in_degree[b] != 0) directed = false;
      next[a] = b;
      in_degree[b] = 1;
    }
    std::vector<uint8_t> visited(vertex_num, 0);
    for (size_t start = 0; start < vertex_num; ++start) {
      const bool is_start = directed ? (in_degree[start] == 0 && next[start] != kNone) : degree[start] == 1;
      if (!is_start || visited[start]) continue;
      int64_t previous = kNone;
      for (int64_t v = int64_t(start); v != kNone;) {
        visited[v] = 1;
        r_order.push_back(v);
        int64_t following = kNone;
        if (directed) {
          following = next[v];
        } else {
          for (int k = 0; k < degree[v]; ++k)
            if (neighbour[2 * v + k] != previous) following = neighbour[2 * v + k];
        }
        previous = v;
        v = following;
      }
      r_offsets.push_back(int64_t(r_order.size()));
    }
    for (size_t v = 0; v < vertex_num; ++v)
      if (degree[v] > 0 && !visited[v])
        throw InputError(FileLoc{path_, header_end_line_},
                         "edges: vertex " + std::to_string(v) + " lies on a closed loop; expected open chains (strands)");
  }

  std::string path_;
  std::string bytes_;
  bool binary_ = false;
  std::vector<PlyElement> elements_;
  int vertex_element_ = -1;
  int edge_element_ = -1;
  int header_end_line_ = 0;
  Roles roles_;
  PlyData data_;
};

}  // namespace

StrandSet read_ply(const std::string &path) { return PlyReader(path).read(); }

void write_ply(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options) {
  constexpr size_t kMaxIndex = size_t(std::numeric_limits<int32_t>::max());
  if (strands.point_count() > kMaxIndex)
    throw InputError(FileLoc{file.path()}, ".ply edges hold 32-bit indices: at most 2^31-1 points, got " +
                                               std::to_string(strands.point_count()));
  const bool has_widths = !strands.widths.empty();
  const size_t edge_num = strands.point_count() - strands.strand_count();
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  std::string_view comment = options.comment;
  while (!comment.empty()) {
    const size_t newline = comment.find('\n');
    header += "comment ";
    header += comment.substr(0, newline);
    header += '\n';
    comment.remove_prefix(newline == std::string_view::npos ? comment.size() : newline + 1);
  }
  header += "element vertex " + std::to_string(strands.point_count()) + "\n";
  header += "property float x\nproperty float y\nproperty float z\n";
  if (has_widths) header += "property float width\n";
  header += "element edge " + std::to_string(edge_num) + "\n";
  header += "property int vertex1\nproperty int vertex2\nend_header\n";
  file.write(header);

  std::string block;
  block.reserve(kWriteBlockBytes + 32);
  auto put = [&](const void *data, size_t n) {
    block.append(static_cast<const char *>(data), n);
    flush_block_if_full(file, block);
  };
  for (size_t p = 0; p < strands.point_count(); ++p) {
    put(strands.positions[p].data(), 12);
    if (has_widths) put(&strands.widths[p], 4);
  }
  for (size_t s = 0; s < strands.strand_count(); ++s)
    for (int64_t p = strands.offsets[s]; p + 1 < strands.offsets[s + 1]; ++p) {
      const int32_t edge[2] = {int32_t(p), int32_t(p + 1)};
      put(edge, sizeof(edge));
    }
  file.write(block);
}

}  // namespace plume::io::detail
