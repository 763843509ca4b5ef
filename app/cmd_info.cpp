// `plume info FILE [--json]`: what a strand file, an emitter mesh or a groom file holds, as text or
// as one JSON object.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/view_page.h"
#include "groom/error.h"
#include "io/feather_writers.h"
#include "io/file_scan.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume {

namespace {

std::string bounds_text(const Eigen::AlignedBox3f &box) {
  if (box.isEmpty()) return "empty";
  char text[160];
  std::snprintf(text, sizeof text, "(%g, %g, %g) .. (%g, %g, %g)", box.min().x(), box.min().y(), box.min().z(),
                box.max().x(), box.max().y(), box.max().z());
  return text;
}

/// "bounds": {"min": [x, y, z], "max": [x, y, z]}, or null when empty.
void json_bounds(JsonWriter &json, const Eigen::AlignedBox3f &box) {
  json.key("bounds");
  if (box.isEmpty()) {
    json.null();
    return;
  }
  json.begin_object().key("min").begin_array();
  for (int k = 0; k < 3; ++k) json.value(box.min()[k]);
  json.end_array().key("max").begin_array();
  for (int k = 0; k < 3; ++k) json.value(box.max()[k]);
  json.end_array().end_object();
}

void print_json(const JsonWriter &json) { std::printf("%s\n", json.text().c_str()); }

void print_mesh(const std::string &path, const Mesh &mesh, bool as_json, const char *kind = "mesh") {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : mesh.positions) box.extend(p);
  double area = 0.0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) area += mesh.triangle_area(f);
  if (as_json) {
    JsonWriter json;
    json.begin_object().key("file").value(path).key("kind").value(kind);
    json.key("vertices").value(mesh.vertex_count()).key("triangles").value(mesh.triangle_count());
    json.key("groups").begin_array();
    for (const std::string &name : mesh.group_names) json.value(name);
    json.end_array().key("uvs").value(mesh.has_uvs()).key("area").value(area);
    json_bounds(json, box);
    print_json(json.end_object());
    return;
  }
  std::printf("%s: mesh\n", path.c_str());
  std::printf("  vertices   %zu\n", mesh.vertex_count());
  std::printf("  triangles  %zu\n", mesh.triangle_count());
  std::printf("  groups     %zu:", mesh.group_names.size());
  for (const std::string &name : mesh.group_names) std::printf(" %s", name.c_str());
  std::printf("\n  uvs        %s\n", mesh.has_uvs() ? "yes" : "no");
  std::printf("  area       %g\n", area);
  std::printf("  bounds     %s\n", bounds_text(box).c_str());
}

void print_strands(const std::string &path, const StrandSet &strands, bool as_json) {
  const size_t n = strands.strand_count();
  int64_t min_points = std::numeric_limits<int64_t>::max(), max_points = 0;
  double min_length = std::numeric_limits<double>::infinity(), max_length = 0.0, sum_length = 0.0;
  Eigen::AlignedBox3f box;
  for (size_t s = 0; s < n; ++s) {
    min_points = std::min(min_points, strands.points_in(s));
    max_points = std::max(max_points, strands.points_in(s));
    const double length = strands.length(s);
    min_length = std::min(min_length, length);
    max_length = std::max(max_length, length);
    sum_length += length;
  }
  for (const Eigen::Vector3f &p : strands.positions) box.extend(p);
  if (as_json) {
    JsonWriter json;
    json.begin_object().key("file").value(path).key("kind").value("strands");
    json.key("strands").value(n).key("points").value(strands.point_count());
    json.key("points_per_strand");
    if (n > 0)
      json.begin_object().key("min").value(min_points).key("max").value(max_points).end_object();
    else
      json.null();
    json.key("length");
    if (n > 0)
      json.begin_object().key("min").value(min_length).key("mean").value(sum_length / double(n)).key("max")
          .value(max_length).end_object();
    else
      json.null();
    json.key("widths");
    if (!strands.widths.empty()) {
      const auto [lo, hi] = std::minmax_element(strands.widths.begin(), strands.widths.end());
      json.begin_object().key("min").value(*lo).key("max").value(*hi).end_object();
    } else {
      json.null();
    }
    json_bounds(json, box);
    print_json(json.end_object());
    return;
  }
  std::printf("%s: strands\n", path.c_str());
  std::printf("  strands    %zu\n", n);
  std::printf("  points     %zu\n", strands.point_count());
  if (n > 0) {
    std::printf("  points per strand  min %lld  max %lld\n", (long long)min_points, (long long)max_points);
    std::printf("  length     min %g  mean %g  max %g\n", min_length, sum_length / double(n), max_length);
  }
  if (!strands.widths.empty()) {
    const auto [lo, hi] = std::minmax_element(strands.widths.begin(), strands.widths.end());
    std::printf("  widths     min %g  max %g\n", *lo, *hi);
  } else {
    std::printf("  widths     none\n");
  }
  std::printf("  bounds     %s\n", bounds_text(box).c_str());
}

}  // namespace

/// The groom as JSON: its name, files, counts and outputs, and describe_groom()'s lines.
void print_groom_json(const std::string &path, const GroomDesc &groom) {
  JsonWriter json;
  json.begin_object().key("file").value(path).key("kind").value("groom").key("name").value(groom.name);
  json.key("emitter").value(groom.emitter_path).key("guides").value(groom.guides_path);
  json.key("feathers").value(groom.feathers.enabled).key("dynamics").value(groom.dynamics.enabled);
  // Hair groups, by name in groom_group_id order: empty for a groom without groups (its fields are
  // the groom's own); the fields above are then the first group's.
  json.key("groups").begin_array();
  for (const GroomDesc &group : groom.groups) json.value(group.group_name);
  json.end_array();
  json.key("output").begin_object();
  json.key("path").value(groom.output.path_pattern).key("preview").value(groom.output.preview_pattern);
  if (groom.feathers.enabled) json.key("vanes").value(groom.output.vanes_pattern);
  json.key("stage").value(groom.output.stage_path).key("meters_per_unit").value(groom.output.meters_per_unit);
  json.key("up_axis").value(groom.output.up_axis);
  json.key("frames").value(groom.output.frames.empty() ? std::string("1") : groom.output.frames).end_object();
  json.key("description").begin_array();
  const std::string text = io::describe_groom(groom);
  for (size_t begin = 0; begin < text.size();) {
    const size_t end = std::min(text.find('\n', begin), text.size());
    json.value(std::string_view(text).substr(begin, end - begin));
    begin = end + 1;
  }
  print_json(json.end_array().end_object());
}

void add_info_command(CLI::App &app, int &r_exit_code) {
  auto file = std::make_shared<std::string>();
  auto as_json = std::make_shared<bool>(false);
  CLI::App *cmd = app.add_subcommand(
      "info", "Describe a file: strands (.usda .hair .ply .obj), an emitter mesh (.obj) or a groom (.yaml).");
  cmd->add_option("file", *file, "The file to describe")->required();
  cmd->add_flag("--json", *as_json, "Print one JSON object (file, kind and the figures of the text form)");
  cmd->callback([file, as_json, &r_exit_code] {
    const std::string ext = io::detail::extension_of(*file);
    if (ext == ".yaml" || ext == ".yml") {
      const GroomDesc groom = io::read_groom_file(*file);
      if (*as_json)
        print_groom_json(*file, groom);
      else
        std::printf("%s", io::describe_groom(groom).c_str());
    } else if (ext == ".obj") {
      // An OBJ with faces is a mesh; one with only `l` lines holds strands.
      const io::ObjContents contents = io::read_obj_file(*file);
      if (contents.mesh)
        print_mesh(*file, *contents.mesh, *as_json);
      else
        print_strands(*file, contents.strands, *as_json);
    } else if (is_vane_mesh_file(*file)) {
      if (*as_json)
        print_mesh(*file, io::read_vane_mesh(*file), true, "vane mesh");
      else
        print_vane_mesh_info(*file);
    } else {
      print_strands(*file, io::read_strands(*file), *as_json);
    }
    r_exit_code = 0;
  });
}

}  // namespace plume
