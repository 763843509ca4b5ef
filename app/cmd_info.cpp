// `plume info FILE`: what a strand file, an emitter mesh or a groom file holds.
#include <algorithm>
#include <cstdio>
#include <limits>
#include <memory>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "groom/error.h"
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

void print_mesh(const std::string &path, const Mesh &mesh) {
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : mesh.positions) box.extend(p);
  double area = 0.0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) area += mesh.triangle_area(f);
  std::printf("%s: mesh\n", path.c_str());
  std::printf("  vertices   %zu\n", mesh.vertex_count());
  std::printf("  triangles  %zu\n", mesh.triangle_count());
  std::printf("  groups     %zu:", mesh.group_names.size());
  for (const std::string &name : mesh.group_names) std::printf(" %s", name.c_str());
  std::printf("\n  uvs        %s\n", mesh.has_uvs() ? "yes" : "no");
  std::printf("  area       %g\n", area);
  std::printf("  bounds     %s\n", bounds_text(box).c_str());
}

void print_strands(const std::string &path, const StrandSet &strands) {
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

void add_info_command(CLI::App &app, int &r_exit_code) {
  auto file = std::make_shared<std::string>();
  CLI::App *cmd = app.add_subcommand(
      "info", "Describe a file: strands (.usda .hair .ply .obj), an emitter mesh (.obj) or a groom (.yaml).");
  cmd->add_option("file", *file, "The file to describe")->required();
  cmd->callback([file, &r_exit_code] {
    const std::string ext = io::detail::extension_of(*file);
    if (ext == ".yaml" || ext == ".yml") {
      std::printf("%s", io::describe_groom(io::read_groom_file(*file)).c_str());
    } else if (ext == ".obj") {
      // An OBJ with faces is a mesh; one with only `l` lines holds strands.
      const io::ObjContents contents = io::read_obj_file(*file);
      if (contents.mesh)
        print_mesh(*file, *contents.mesh);
      else
        print_strands(*file, contents.strands);
    } else if (is_vane_mesh_file(*file)) {
      print_vane_mesh_info(*file);
    } else {
      print_strands(*file, io::read_strands(*file));
    }
    r_exit_code = 0;
  });
}

}  // namespace plume
