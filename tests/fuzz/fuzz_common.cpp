#include "fuzz_common.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "groom/limits.h"

namespace plume::fuzz {

namespace fs = std::filesystem;

const std::string &work_folder(const std::vector<std::string> &seed_files) {
  // Never destroyed: the exit handler that removes the folder runs after static destructors.
  static const std::string *folder = [&] {
    std::error_code error;
    const fs::path base = fs::is_directory("/dev/shm", error) ? fs::path("/dev/shm") : fs::temp_directory_path();
    const fs::path path = base / ("plume_fuzz_" + std::to_string(long(::getpid())));
    fs::remove_all(path, error);
    fs::create_directories(path);
    for (const std::string &file : seed_files) fs::copy_file(file, path / fs::path(file).filename());
    std::atexit([] {
      std::error_code ignored;
      fs::remove_all(work_folder(), ignored);
    });
    return new std::string(path.string());
  }();
  return *folder;
}

std::string write_input(const uint8_t *data, size_t size, const std::string &name) {
  const std::string path = work_folder() + "/" + name;
  std::FILE *file = std::fopen(path.c_str(), "wb");
  if (!file || std::fwrite(data, 1, size, file) != size || std::fclose(file) != 0) {
    std::perror(path.c_str());
    std::abort();  // the harness, not the reader: stop rather than test nothing
  }
  return path;
}

void finding(const std::string &what) {
  std::fprintf(stderr, "plume fuzz finding: %s\n", what.c_str());
  std::abort();
}

namespace {

void require(bool holds, const std::string &what) {
  if (!holds) finding(what);
}

bool finite(double value) { return std::isfinite(value); }
bool finite(const Eigen::Vector3f &v) { return v.allFinite(); }

void check_ramp(const Ramp &ramp, const std::string &what) {
  require(ramp.t.size() == ramp.value.size(), what + ": ramp sizes");  // empty: a constant 1
  for (size_t i = 0; i < ramp.t.size(); ++i) {
    require(ramp.t[i] >= 0.0f && ramp.t[i] <= 1.0f && (i == 0 || ramp.t[i] >= ramp.t[i - 1]), what + ": ramp t");
    require(finite(ramp.value[i]), what + ": ramp value");
  }
}

}  // namespace

void check_strands(const StrandSet &strands) {
  try {
    strands.check_invariants();
  } catch (const InternalError &error) {
    finding(std::string("strands break their invariants: ") + error.what());
  }
  // Finite points (check_invariants); strand files round-trip any float, so the scene bound is the
  // stages' to check, not the readers'.
  for (size_t s = 0; s < strands.strand_count(); ++s)
    require(strands.points_in(s) >= 2, "strand " + std::to_string(s) + " has fewer than 2 points");
  for (const float width : strands.widths) require(std::isfinite(width) && width >= 0.0f, "a width not finite and >= 0");
}

void check_mesh(const Mesh &mesh) {
  const size_t vertex_count = mesh.positions.size();
  for (const Eigen::Vector3f &p : mesh.positions) require(within_scene_bounds(p), "a vertex beyond the scene bound");
  require(mesh.vertex_normals.size() == vertex_count, "one normal per vertex");
  for (const Eigen::Vector3f &n : mesh.vertex_normals) require(finite(n), "a non-finite normal");
  require(mesh.triangle_groups.size() == mesh.triangles.size(), "one group per triangle");
  for (size_t f = 0; f < mesh.triangles.size(); ++f) {
    for (int k = 0; k < 3; ++k)
      require(mesh.triangles[f][k] >= 0 && size_t(mesh.triangles[f][k]) < vertex_count, "a vertex index out of range");
    require(mesh.triangle_groups[f] >= 0 && size_t(mesh.triangle_groups[f]) < mesh.group_names.size(),
            "a group index out of range");
  }
  require(mesh.triangle_uvs.empty() || mesh.triangle_uvs.size() == mesh.triangles.size(), "uv triangles");
  for (const Eigen::Vector3i &t : mesh.triangle_uvs)
    for (int k = 0; k < 3; ++k) require(t[k] >= 0 && size_t(t[k]) < mesh.uvs.size(), "a uv index out of range");
  for (const Eigen::Vector2f &uv : mesh.uvs) require(uv.allFinite(), "a non-finite uv");
  bool any_area = false;
  for (size_t f = 0; f < mesh.triangles.size(); ++f) any_area = any_area || mesh.triangle_area(f) > 0.0;
  require(mesh.triangles.empty() || any_area, "every triangle degenerate");
}

void check_points(const std::vector<Eigen::Vector3f> &points) {
  for (const Eigen::Vector3f &p : points) require(within_scene_bounds(p), "a point beyond the scene bound");
}

void check_groom(const GroomDesc &groom) {
  require(fs::path(groom.emitter_path).is_absolute() && fs::is_regular_file(groom.emitter_path), "emitter.mesh");
  require(fs::path(groom.guides_path).is_absolute() && fs::is_regular_file(groom.guides_path), "guides.file");
  require(groom.points_per_strand >= 2 && groom.points_per_strand <= 65536, "strands.points");
  require(finite(groom.width_root) && (groom.width_root >= 0.0f || groom.width_root == -1.0f) &&
              finite(groom.width_tip) && (groom.width_tip >= 0.0f || groom.width_tip == -1.0f),
          "strands.width");
  const RootSettings &roots = groom.roots;
  require(roots.count >= 0 && roots.count <= max_root_count && finite(roots.density) && roots.density >= 0.0 &&
              finite(roots.near_guides) && roots.near_guides >= 0.0,
          "roots");
  const InterpolationSettings &interp = groom.interpolation;
  require(interp.k >= 1 && interp.k <= max_guides_per_root && finite(interp.radius) && finite(interp.falloff) &&
              finite(interp.skin_margin) && (interp.skin_margin >= 0.0f || interp.skin_margin == -1.0f),
          "interpolation");
  const EmitterAnimation &animation = groom.animation;
  require(within_scene_bounds(animation.pivot), "animation.pivot");
  for (size_t i = 0; i < animation.keys.size(); ++i) {
    const RigidKey &key = animation.keys[i];
    require(finite(key.frame) && (i == 0 || key.frame > animation.keys[i - 1].frame), "animation keys sorted");
    require(finite(key.translate) && finite(key.rotate_degrees) && finite(key.scale) && key.scale > 0.0f,
            "animation key values");
  }
  for (const PartingLine &line : groom.partings.lines) {
    require(finite(line.gamma) && line.gamma >= 1.0f, "parting gamma");
    for (const Eigen::Vector3f &p : line.points) require(within_scene_bounds(p), "parting point");
  }
  for (const EffectDesc &effect : groom.effects) {
    require(effect.amount >= 0.0f && effect.amount <= 1.0f, "effect amount");
    check_ramp(effect.ramp, "effect");
    for (const float value : {effect.clump_radius, effect.clump_twist, effect.stray_fraction, effect.length_variation,
                              effect.max_length, effect.frequency, effect.amplitude, effect.fraction, effect.curl_radius,
                              effect.turns_per_unit})
      require(finite(value) && std::abs(value) <= max_coordinate, "an effect value");
    require(within_scene_bounds(effect.cut_point) && finite(effect.cut_normal), "effect cut");
  }
  const DynamicsSettings &dynamics = groom.dynamics;
  require(dynamics.substeps >= 1 && finite(dynamics.fps) && dynamics.fps > 0.0f && dynamics.preroll_frames >= 0,
          "dynamics steps");
  check_ramp(dynamics.stiffness, "dynamics.stiffness");
  for (const float value : {dynamics.stiffness_scale, dynamics.damping, dynamics.drag, dynamics.mass_per_unit,
                            dynamics.wind_gust, dynamics.wind_gust_frequency, dynamics.emitter_friction,
                            dynamics.collision_margin})
    require(finite(value) && value >= 0.0f, "a dynamics value");
  require(finite(dynamics.gravity) && finite(dynamics.wind), "dynamics vectors");
  for (const CollisionShape &shape : dynamics.shapes)
    require(within_scene_bounds(shape.a) && within_scene_bounds(shape.b) && finite(shape.radius) && shape.radius > 0.0f &&
                finite(shape.friction),
            "a collision shape");
  const OutputSettings &output = groom.output;
  require(output.preview_every >= 0 && output.preview_size >= 16 && output.preview_size <= max_preview_size, "output");
}

}  // namespace plume::fuzz
