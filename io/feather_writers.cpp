#include "io/feather_writers.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstring>
#include <limits>

#include "io/atomic_file.h"
#include "io/file_scan.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"
#include "io/strand_formats.h"

namespace plume::io {

namespace {

using detail::append_number;
using detail::append_obj_vertices;
using detail::append_string_literal;
using detail::append_tuple;
using detail::flush_block_if_full;


/// The layer header: doc, default prim, units, up axis and the frame's time code.
std::string layer_header(const FeatherWriteOptions &options) {
  std::string out;
  detail::append_layer_header(out, options.comment, options.meters_per_unit, options.up_axis, options.time_code,
                              options.fps);
  return out;
}

/// `name = [...]` or its time sample, for points and extents.
void begin_sampled(std::string &out, const char *declaration, const FeatherWriteOptions &options) {
  out += "        ";
  out += declaration;
  if (options.time_code) {
    out += ".timeSamples = {\n            ";
    append_number(out, *options.time_code);
    out += ": [";
  } else {
    out += " = [";
  }
}
void end_sampled(std::string &out, const FeatherWriteOptions &options) { out += options.time_code ? "],\n        }\n" : "]\n"; }

template <class Values, class Append>
void write_array(AtomicFile &file, std::string &out, const char *declaration, const Values &values, const Append &append,
                 const char *interpolation) {
  out += "        ";
  out += declaration;
  out += " = [";
  for (size_t i = 0; i < values.size(); ++i) {
    if (i > 0) out += ", ";
    append(out, values[i]);
    flush_block_if_full(file, out);
  }
  out += "]";
  if (interpolation) {
    out += " (\n            interpolation = \"";
    out += interpolation;
    out += "\"\n        )";
  }
  out += '\n';
}

void write_points(AtomicFile &file, std::string &out, const std::vector<Eigen::Vector3f> &points, const char *declaration,
                  const FeatherWriteOptions &options) {
  begin_sampled(out, declaration, options);
  for (size_t p = 0; p < points.size(); ++p) {
    if (p > 0) out += ", ";
    append_tuple(out, points[p].data(), 3);
    flush_block_if_full(file, out);
  }
  end_sampled(out, options);
}

void write_extent(std::string &out, const std::vector<Eigen::Vector3f> &points, float pad,
                  const FeatherWriteOptions &options) {
  Eigen::Vector3f lo = Eigen::Vector3f::Zero(), hi = Eigen::Vector3f::Zero();
  if (!points.empty()) {
    lo = hi = points[0];
    for (const Eigen::Vector3f &p : points) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  lo -= Eigen::Vector3f::Constant(pad);
  hi += Eigen::Vector3f::Constant(pad);
  begin_sampled(out, "float3[] extent", options);
  append_tuple(out, lo.data(), 3);
  out += ", ";
  append_tuple(out, hi.data(), 3);
  end_sampled(out, options);
}

void check_ids(const std::string &path, const std::vector<uint64_t> &ids) {
  if (!std::all_of(ids.begin(), ids.end(), [](uint64_t id) { return id <= uint64_t(std::numeric_limits<int64_t>::max()); }))
    throw InputError(FileLoc{path}, "primvars:feather_id: ids above 2^63-1 do not fit USD int64");
}

void write_template_names(std::string &out, const FeatherWriteOptions &options) {
  out += "        string[] primvars:feather_template_names = [";
  for (size_t i = 0; i < options.template_names.size(); ++i) {
    if (i > 0) out += ", ";
    append_string_literal(out, options.template_names[i]);
  }
  out += "] (\n            interpolation = \"constant\"\n        )\n";
}

const auto kAppendUv = [](std::string &out, const Eigen::Vector2f &uv) { append_tuple(out, uv.data(), 2); };
const auto kAppendInt = [](std::string &out, long long v) { append_number(out, v); };

void write_curves_usda(AtomicFile &file, const FeatherCurves &f, const FeatherWriteOptions &options) {
  const StrandSet &c = f.curves;
  check_ids(file.path(), c.ids);
  std::string out = layer_header(options);
  out.reserve(detail::kWriteBlockBytes + 256);
  out += "def Xform \"Groom\" (\n    kind = \"component\"\n    prepend apiSchemas = [\"GroomAPI\"]\n)\n{\n";
  out += "    def BasisCurves \"feathers\"\n    {\n";
  out += "        uniform token type = \"linear\"\n        uniform token wrap = \"nonperiodic\"\n";
  std::vector<long long> counts(c.strand_count());
  for (size_t s = 0; s < counts.size(); ++s) counts[s] = c.points_in(s);
  write_array(file, out, "int[] curveVertexCounts", counts, kAppendInt, nullptr);
  write_points(file, out, c.positions, "point3f[] points", options);
  write_array(file, out, "float[] widths", c.widths, [](std::string &o, float w) { append_number(o, w); }, "vertex");
  const float max_width = c.widths.empty() ? 0.0f : *std::max_element(c.widths.begin(), c.widths.end());
  write_extent(out, c.positions, 0.5f * max_width, options);
  std::vector<long long> templates(f.templates.begin(), f.templates.end());
  std::vector<long long> ids(c.ids.begin(), c.ids.end());
  std::vector<long long> parts(f.parts.size());
  for (size_t i = 0; i < parts.size(); ++i) parts[i] = (long long)f.parts[i];
  write_array(file, out, "int[] primvars:groom_group_id", templates, kAppendInt, "uniform");
  write_array(file, out, "int64[] primvars:plume_id", ids, kAppendInt, "uniform");
  write_array(file, out, "int64[] primvars:feather_id", ids, kAppendInt, "uniform");
  write_array(file, out, "int[] primvars:feather_part", parts, kAppendInt, "uniform");
  write_array(file, out, "int[] primvars:feather_template", templates, kAppendInt, "uniform");
  write_template_names(out, options);
  write_array(file, out, "texCoord2f[] primvars:st", f.uv_barb, kAppendUv, "vertex");
  write_array(file, out, "texCoord2f[] primvars:st_vane", f.uv_vane, kAppendUv, "vertex");
  out += "    }\n}\n";
  file.write(out);
}

void write_curves_ply(AtomicFile &file, const FeatherCurves &f, const FeatherWriteOptions &options) {
  const StrandSet &c = f.curves;
  const size_t edges = c.point_count() - c.strand_count();
  std::string header = "ply\nformat binary_little_endian 1.0\n";
  if (!options.comment.empty()) header += "comment " + options.comment.substr(0, options.comment.find('\n')) + "\n";
  header += "element vertex " + std::to_string(c.point_count()) +
            "\nproperty float x\nproperty float y\nproperty float z\nproperty float width\nproperty uint feather\n"
            "property uchar part\nelement edge " +
            std::to_string(edges) + "\nproperty int vertex1\nproperty int vertex2\nend_header\n";
  if (c.point_count() > size_t(std::numeric_limits<int32_t>::max()))
    throw InputError(FileLoc{file.path()}, "PLY edges index vertices as 32-bit ints: at most 2^31-1 points");
  std::string out = header;
  char record[21];
  for (size_t s = 0; s < c.strand_count(); ++s) {
    const uint32_t feather = f.feathers.empty() ? 0u : f.feathers[s];
    const uint8_t part = f.parts.empty() ? 0 : uint8_t(f.parts[s]);
    for (int64_t p = c.offsets[s]; p < c.offsets[s + 1]; ++p) {
      std::memcpy(record, c.positions[size_t(p)].data(), 12);
      const float width = c.widths.empty() ? 0.0f : c.widths[size_t(p)];
      std::memcpy(record + 12, &width, 4);
      std::memcpy(record + 16, &feather, 4);
      std::memcpy(record + 20, &part, 1);
      out.append(record, 21);
      flush_block_if_full(file, out);
    }
  }
  for (size_t s = 0; s < c.strand_count(); ++s)
    for (int64_t p = c.offsets[s]; p + 1 < c.offsets[s + 1]; ++p) {
      const int32_t pair[2] = {int32_t(p), int32_t(p + 1)};
      out.append(reinterpret_cast<const char *>(pair), 8);
      flush_block_if_full(file, out);
    }
  file.write(out);
}

void write_vanes_usda(AtomicFile &file, const VaneMesh &v, const FeatherWriteOptions &options) {
  check_ids(file.path(), v.triangle_feathers);
  std::string out = layer_header(options);
  out.reserve(detail::kWriteBlockBytes + 256);
  out += "def Xform \"Groom\" (\n    kind = \"component\"\n)\n{\n";
  out += "    def Mesh \"vanes\"\n    {\n";
  out += "        uniform token subdivisionScheme = \"none\"\n        uniform token orientation = \"rightHanded\"\n";
  out += "        uniform bool doubleSided = 1\n";
  const std::vector<long long> counts(v.triangles.size(), 3);
  write_array(file, out, "int[] faceVertexCounts", counts, kAppendInt, nullptr);
  out += "        int[] faceVertexIndices = [";
  for (size_t t = 0; t < v.triangles.size(); ++t) {
    for (int k = 0; k < 3; ++k) {
      if (t > 0 || k > 0) out += ", ";
      append_number(out, (long long)v.triangles[t][k]);
    }
    flush_block_if_full(file, out);
  }
  out += "]\n";
  write_points(file, out, v.positions, "point3f[] points", options);
  write_extent(out, v.positions, 0.0f, options);
  write_array(file, out, "texCoord2f[] primvars:st", v.uv_vane, kAppendUv, "vertex");
  write_array(file, out, "texCoord2f[] primvars:st_barb", v.uv_barb, kAppendUv, "vertex");
  std::vector<long long> ids(v.triangle_feathers.begin(), v.triangle_feathers.end());
  std::vector<long long> templates(v.triangle_templates.begin(), v.triangle_templates.end());
  write_array(file, out, "int64[] primvars:feather_id", ids, kAppendInt, "uniform");
  write_array(file, out, "int[] primvars:feather_template", templates, kAppendInt, "uniform");
  write_template_names(out, options);
  out += "    }\n}\n";
  file.write(out);
}

void write_vanes_obj(AtomicFile &file, const VaneMesh &v, const FeatherWriteOptions &options) {
  std::string out;
  out.reserve(detail::kWriteBlockBytes + 256);
  if (!options.comment.empty()) out += "# " + options.comment.substr(0, options.comment.find('\n')) + "\n";
  out += "# " + std::to_string(v.positions.size()) + " vertices, " + std::to_string(v.triangles.size()) +
         " triangles; texture coordinates " + (options.obj_uv_along_barbs ? "along the barbs" : "across the vane") +
         "; one group per feather\n";
  append_obj_vertices(file, out, v.positions);
  const std::vector<Eigen::Vector2f> &uvs = options.obj_uv_along_barbs ? v.uv_barb : v.uv_vane;
  for (const Eigen::Vector2f &uv : uvs) {
    out += "vt ";
    append_number(out, uv.x());
    out += ' ';
    append_number(out, uv.y());
    out += '\n';
    flush_block_if_full(file, out);
  }
  for (size_t t = 0; t < v.triangles.size(); ++t) {
    if (t == 0 || v.triangle_feathers[t] != v.triangle_feathers[t - 1]) {
      out += "g feather_";
      append_number(out, (unsigned long long)v.triangle_feathers[t]);
      out += '\n';
    }
    out += 'f';
    for (int k = 0; k < 3; ++k) {
      const long long index = (long long)v.triangles[t][k] + 1;
      out += ' ';
      append_number(out, index);
      out += '/';
      append_number(out, index);
    }
    out += '\n';
    flush_block_if_full(file, out);
  }
  file.write(out);
}

// ---------------------------------------------------------------------------------------------
// Reading the vane meshes back.

/// Finds `name` followed by `=` (or `.timeSamples = {time:`) at the start of a declaration and
/// returns the offset of the '[' that opens its array; npos when absent.
size_t array_start(const std::string &text, const std::string &name) {
  for (size_t at = text.find(name); at != std::string::npos; at = text.find(name, at + 1)) {
    size_t p = at + name.size();
    if (text.compare(p, 12, ".timeSamples") == 0) {
      p = text.find('{', p);
      if (p == std::string::npos) return p;
      p = text.find(':', p);
      if (p == std::string::npos) return p;
      return text.find('[', p);
    }
    while (p < text.size() && (text[p] == ' ' || text[p] == '\t')) ++p;
    if (p < text.size() && text[p] == '=') return text.find('[', p);
  }
  return std::string::npos;
}

int line_of(const std::string &text, size_t offset) {
  return 1 + int(std::count(text.begin(), text.begin() + long(std::min(offset, text.size())), '\n'));
}

/// The numbers of the array opening at `open` (tuples' parentheses and commas skipped).
std::vector<double> numbers_of(const std::string &path, const std::string &text, size_t open, const std::string &what) {
  std::vector<double> values;
  size_t p = open + 1;
  while (p < text.size() && text[p] != ']') {
    const char c = text[p];
    if (c == ' ' || c == ',' || c == '(' || c == ')' || c == '\n' || c == '\r' || c == '\t') {
      ++p;
      continue;
    }
    double value = 0.0;
    const auto result = std::from_chars(text.data() + p, text.data() + text.size(), value);
    if (result.ec != std::errc() || !std::isfinite(value))
      throw InputError(FileLoc{path, line_of(text, p)}, what + ": expected a finite number, got " +
                                                            detail::quoted(std::string_view(text).substr(p, 20)));
    values.push_back(value);
    p = size_t(result.ptr - text.data());
  }
  if (p >= text.size()) throw InputError(FileLoc{path, line_of(text, open)}, what + ": expected ']', the file ends");
  return values;
}

Mesh read_vanes_usda(const std::string &path) {
  const std::string text = detail::read_file_bytes(path);
  if (text.rfind("#usda 1.0", 0) != 0) throw InputError(FileLoc{path, 1, 1}, "first line: expected \"#usda 1.0\"");
  const size_t mesh_at = text.find("def Mesh");
  if (mesh_at == std::string::npos) throw InputError(FileLoc{path}, "expected a Mesh prim, found none");
  const std::string body = text.substr(mesh_at);
  const int line0 = line_of(text, mesh_at) - 1;
  auto array = [&](const std::string &name) {
    const size_t open = array_start(body, name);
    if (open == std::string::npos)
      throw InputError(FileLoc{path, line0 + 1}, "Mesh: expected " + name + ", found none");
    try {
      return numbers_of(path, body, open, name);
    } catch (const InputError &e) {
      throw InputError(FileLoc{path, line0 + line_of(body, open)}, e.what());
    }
  };
  const std::vector<double> points = array("point3f[] points");
  const std::vector<double> counts = array("int[] faceVertexCounts");
  const std::vector<double> indices = array("int[] faceVertexIndices");
  if (points.size() % 3 != 0) throw InputError(FileLoc{path}, "points: expected triples");
  Mesh mesh;
  for (size_t i = 0; i < points.size(); i += 3)
    mesh.positions.emplace_back(float(points[i]), float(points[i + 1]), float(points[i + 2]));
  size_t at = 0;
  for (size_t f = 0; f < counts.size(); ++f) {
    if (counts[f] != 3.0) throw InputError(FileLoc{path}, "faceVertexCounts[" + std::to_string(f) + "]: expected 3 (triangles)");
    if (at + 3 > indices.size()) throw InputError(FileLoc{path}, "faceVertexIndices: expected 3 per face, the list ends");
    Eigen::Vector3i t;
    for (int k = 0; k < 3; ++k) {
      const double index = indices[at + size_t(k)];
      if (!(index >= 0.0 && index < double(mesh.positions.size()) && index == std::floor(index)))
        throw InputError(FileLoc{path}, "faceVertexIndices[" + std::to_string(at + size_t(k)) + "]: expected a vertex index in [0, " +
                                            std::to_string(mesh.positions.size()) + ")");
      t[k] = int(index);
    }
    mesh.triangles.push_back(t);
    at += 3;
  }
  if (at != indices.size()) throw InputError(FileLoc{path}, "faceVertexIndices: expected 3 per face, got more");
  // Each feather's triangles as a group named feather_<id> (as the OBJ writer names them).
  mesh.group_names = {"default"};
  mesh.triangle_groups.assign(mesh.triangles.size(), 0);
  if (array_start(body, "int64[] primvars:feather_id") != std::string::npos) {
    const std::vector<double> ids = array("int64[] primvars:feather_id");
    if (ids.size() != mesh.triangles.size())
      throw InputError(FileLoc{path}, "primvars:feather_id: expected one id per face (" +
                                          std::to_string(mesh.triangles.size()) + "), got " + std::to_string(ids.size()));
    mesh.group_names.clear();
    for (size_t f = 0; f < ids.size(); ++f) {
      if (f == 0 || ids[f] != ids[f - 1]) mesh.group_names.push_back("feather_" + std::to_string((long long)ids[f]));
      mesh.triangle_groups[f] = int(mesh.group_names.size()) - 1;
    }
  }
  mesh.validate(path);
  mesh.compute_normals();
  return mesh;
}

}  // namespace

void write_feather_curves(const std::string &path, const FeatherCurves &curves, const FeatherWriteOptions &options) {
  curves.curves.check_invariants();
  const std::string ext = detail::extension_of(path);
  if (ext == ".hair" || ext == ".obj") {
    StrandWriteOptions strand_options;
    strand_options.time_code = options.time_code;
    strand_options.fps = options.fps;
    strand_options.comment = options.comment;
    write_strands(path, curves.curves, strand_options);
    return;
  }
  if (ext != ".usda" && ext != ".ply")
    throw InputError(FileLoc{path}, "feather curves: expected a file ending in .usda, .hair, .ply or .obj");
  AtomicFile file(path);
  if (ext == ".usda")
    write_curves_usda(file, curves, options);
  else
    write_curves_ply(file, curves, options);
  file.commit();
}

void write_vane_mesh(const std::string &path, const VaneMesh &vanes, const FeatherWriteOptions &options) {
  const std::string ext = detail::extension_of(path);
  if (ext != ".usda" && ext != ".obj") throw InputError(FileLoc{path}, "vane meshes: expected a file ending in .usda or .obj");
  AtomicFile file(path);
  if (ext == ".usda")
    write_vanes_usda(file, vanes, options);
  else
    write_vanes_obj(file, vanes, options);
  file.commit();
}

Mesh read_vane_mesh(const std::string &path) {
  const std::string ext = detail::extension_of(path);
  if (ext == ".obj") return read_obj_mesh(path);
  if (ext == ".usda") return read_vanes_usda(path);
  throw InputError(FileLoc{path}, "vane meshes: expected a file ending in .usda or .obj");
}

}  // namespace plume::io
