#include "app/pipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>

#include <unistd.h>

#include "app/frame_range.h"
#include "controls/control_rig.h"
#include "dynamics/guide_simulator.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "effects/effects.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"
#include "skin/skin_grid.h"
#include "skin/skin_guard.h"
#include "io/control_section.h"
#include "io/obj_mesh.h"
#include "io/point_list.h"
#include "io/strand_file.h"

namespace plume {

namespace {

constexpr float kDegrees = 3.14159265358979f / 180.0f;

Eigen::Quaternionf euler_xyz(const Eigen::Vector3f &degrees) {
  // Applied X first, then Y, then Z: R = Rz * Ry * Rx.
  return Eigen::AngleAxisf(degrees.z() * kDegrees, Eigen::Vector3f::UnitZ()) *
         Eigen::AngleAxisf(degrees.y() * kDegrees, Eigen::Vector3f::UnitY()) *
         Eigen::AngleAxisf(degrees.x() * kDegrees, Eigen::Vector3f::UnitX());
}

}  // namespace

double usable_memory_bytes() {
  const long pages = sysconf(_SC_PHYS_PAGES), page_size = sysconf(_SC_PAGESIZE);
  double usable = pages > 0 && page_size > 0 ? double(pages) * double(page_size) : 0.0;
  // "0::/path" names this process's cgroup; each level up to the root may set memory.max.
  std::ifstream membership("/proc/self/cgroup");
  std::string line;
  while (std::getline(membership, line)) {
    if (line.rfind("0::", 0) != 0) continue;
    for (std::filesystem::path group = line.substr(3);; group = group.parent_path()) {
      std::ifstream limit_file("/sys/fs/cgroup" + group.string() + "/memory.max");
      double limit = 0.0;
      if (limit_file >> limit && limit > 0.0) usable = usable > 0.0 ? std::min(usable, limit) : limit;
      if (group == group.parent_path()) break;
    }
  }
  return usable;
}

namespace {

/// Throws InputError (at `loc`, naming `what`) when regrowing `count` strands of `points` points
/// would need more memory than this process may use: one frame holds the strands' points, widths and
/// skin clearances, the binding and the stack's and writer's working copies, about 300 bytes per
/// strand and 32 per point (measured peak, 8 to 64 points per strand). The run would otherwise end
/// in an allocation failure or swapping, after minutes of work.
void check_memory_for(int64_t count, int points, const FileLoc &loc, const std::string &what) {
  const double needed = double(count) * (300.0 + 32.0 * double(points));
  const double usable = usable_memory_bytes();
  if (usable <= 0.0 || needed <= usable) return;
  char figures[160];
  std::snprintf(figures, sizeof figures, "need about %.1f GB to regrow a frame, more than the %.1f GB of memory",
                needed / 1e9, usable / 1e9);
  const std::string message = what + ": " + std::to_string(count) + " strands of " + std::to_string(points) +
                              " points " + figures + " this run may use (regrow fewer strands, or fewer points per strand)";
  throw InputError(loc, message);
}

Roots make_roots(const GroomDesc &groom, const Mesh &rest_mesh, const MeshQuery &rest_query, const Guides &guides,
                 int64_t count_override) {
  const RootSettings &settings = groom.roots;
  if (settings.source == RootSettings::Source::file) {
    const std::vector<Eigen::Vector3f> points = io::read_points(settings.file);
    const size_t count = count_override >= 0 ? std::min(points.size(), size_t(count_override)) : points.size();
    check_memory_for(int64_t(count), groom.points_per_strand, settings.loc, "roots.file");
    Roots roots;
    roots.points.resize(count);
    roots.ids.resize(count);
    roots.arrival.resize(count);
    for (size_t i = 0; i < count; ++i) {
      roots.points[i] = surface_point_below(rest_query, points[i]);
      roots.ids[i] = i;  // the point's index in the file: stable as long as the file is
      roots.arrival[i] = double(i);  // --strands N keeps the first N points
    }
    return roots;
  }

  std::vector<bool> mask;
  if (!settings.groups.empty()) {
    std::vector<bool> wanted(rest_mesh.group_names.size(), false);
    for (const std::string &name : settings.groups) {
      const int g = rest_mesh.group_index(name);
      if (g < 0)
        throw InputError(settings.loc, "roots.groups: no face group \"" + name + "\" in " + groom.emitter_path +
                                           " (groups: " + rest_mesh.group_list() + ")");
      wanted[size_t(g)] = true;
    }
    mask.resize(rest_mesh.triangle_count());
    for (size_t f = 0; f < rest_mesh.triangle_count(); ++f) mask[f] = wanted[size_t(rest_mesh.triangle_groups[f])];
  }
  if (settings.near_guides > 0.0) {
    std::vector<Eigen::Vector3f> guide_roots(guides.size());
    for (size_t g = 0; g < guides.size(); ++g) guide_roots[g] = surface_position(rest_mesh, guides.roots[g]);
    const std::vector<bool> near = triangles_near(rest_mesh, guide_roots, settings.near_guides);
    if (mask.empty()) {
      mask = near;
    } else {
      for (size_t f = 0; f < mask.size(); ++f) mask[f] = mask[f] && near[f];
    }
  }
  int64_t count = settings.count;
  if (count_override >= 0) {
    count = count_override;
  } else if (count <= 0) {
    const double wanted = settings.density * masked_area(rest_mesh, mask);
    // Checked as a double: a product beyond int64 would not round to a count at all.
    if (!(wanted <= double(max_root_count)))
      throw InputError(settings.loc, "roots.density: density x area gives " + std::to_string(wanted) +
                                         " roots, more than " + std::to_string(max_root_count));
    count = int64_t(std::llround(wanted));
  }
  if (count <= 0 && count_override < 0)
    throw InputError(settings.loc, "roots.density: density x area gives no root (less than 1)");
  if (count_override >= 0)
    check_memory_for(count, groom.points_per_strand, FileLoc{}, "--strands");
  else
    check_memory_for(count, groom.points_per_strand, settings.loc, settings.count > 0 ? "roots.count" : "roots.density");
  return scatter_roots(rest_mesh, count, settings.seed, mask, settings.loc);
}

}  // namespace

Roots groom_roots(const GroomDesc &groom, const Mesh &rest_mesh, const Guides &guides, int64_t count_override) {
  const MeshQuery rest_query(rest_mesh);
  return make_roots(groom, rest_mesh, rest_query, guides, count_override);
}

Eigen::Affine3f rigid_pose_at(const EmitterAnimation &animation, double frame) {
  Eigen::Affine3f pose = Eigen::Affine3f::Identity();
  if (animation.kind != EmitterAnimation::Kind::rigid || animation.keys.empty()) return pose;
  const std::vector<RigidKey> &keys = animation.keys;
  Eigen::Vector3f translate;
  Eigen::Quaternionf rotate;
  float scale;
  if (frame <= keys.front().frame) {
    translate = keys.front().translate;
    rotate = euler_xyz(keys.front().rotate_degrees);
    scale = keys.front().scale;
  } else if (frame >= keys.back().frame) {
    translate = keys.back().translate;
    rotate = euler_xyz(keys.back().rotate_degrees);
    scale = keys.back().scale;
  } else {
    size_t i = 1;
    while (keys[i].frame <= frame) ++i;
    const RigidKey &a = keys[i - 1], &b = keys[i];
    const float t = float((frame - a.frame) / (b.frame - a.frame));
    translate = (1.0f - t) * a.translate + t * b.translate;
    rotate = euler_xyz(a.rotate_degrees).slerp(t, euler_xyz(b.rotate_degrees));
    scale = (1.0f - t) * a.scale + t * b.scale;
  }
  const Eigen::Vector3f &pivot = animation.pivot;
  pose.translate(pivot + translate);
  pose.rotate(rotate);
  pose.scale(scale);
  pose.translate(-pivot);
  return pose;
}

Pipeline::Pipeline(const GroomDesc &groom, const PipelineOptions &options) : groom_(groom), options_(options) {
  rest_mesh_ = io::read_obj_mesh(groom_.emitter_path);
  // Automatic widths: scaled to the emitter.
  const float auto_root_width = default_width_root_fraction * skin::mesh_scale(rest_mesh_);
  if (groom_.width_root < 0.0f) groom_.width_root = auto_root_width;
  if (groom_.width_tip < 0.0f) groom_.width_tip = 0.25f * auto_root_width;
  const MeshQuery rest_query(rest_mesh_);
  guides_ = bind_guides(rest_query, io::read_strands(groom_.guides_path), groom_.guides_path);
  if (guides_.size() == 0) throw InputError(groom_.guides_loc, "guides: " + groom_.guides_path + " holds no strands");
  roots_ = options_.roots ? *options_.roots : make_roots(groom_, rest_mesh_, rest_query, guides_, options_.strand_count);
  if (roots_.size() == 0 && options_.strand_count != 0 && !options_.roots)
    throw InputError(groom_.roots.loc, "roots: no roots to grow (the roots file holds no points)");
  if (rest_mesh_.has_uvs()) {
    root_uvs_.resize(roots_.size());
    for (size_t r = 0; r < roots_.size(); ++r) root_uvs_[r] = surface_uv(rest_mesh_, roots_.points[r]);
  }

  partings_ = std::make_unique<partings::PartingField>(rest_mesh_, guides_, groom_.partings);
  binding_ = std::make_unique<interp::Binding>(
      interp::bind(rest_mesh_, guides_, roots_, groom_.interpolation, partings_->empty() ? nullptr : partings_.get()));
  // The strongest guide of each root (slots are ordered by decreasing weight).
  std::vector<int32_t> nearest_guide(roots_.size(), -1);
  for (size_t r = 0; r < roots_.size(); ++r) nearest_guide[r] = binding_->guide_ids[r * size_t(binding_->k)];
  effects_ = std::make_unique<effects::EffectStack>(groom_.effects, rest_mesh_, roots_, guides_, nearest_guide);

  if (groom_.dynamics.enabled && options_.guides_cache.empty())
    simulator_ = std::make_unique<dynamics::GuideSimulator>(rest_mesh_, guides_, groom_.dynamics);
  if (!groom_.controls.empty())
    controls_ = std::make_unique<controls::ControlRig>(rest_mesh_, guides_, groom_.controls,
                                                       io::read_control_maps(groom_.controls, rest_mesh_.vertex_count()));
}

Pipeline::~Pipeline() = default;

Mesh posed_emitter(const GroomDesc &groom, const Mesh &rest_mesh, int frame) {
  const EmitterAnimation &animation = groom.animation;
  if (animation.kind == EmitterAnimation::Kind::obj_sequence)
    return io::read_obj_pose(expand_frame_pattern(animation.sequence_pattern, frame), rest_mesh);
  Mesh posed = rest_mesh;
  if (animation.kind == EmitterAnimation::Kind::rigid) {
    const Eigen::Affine3f pose = rigid_pose_at(animation, frame);
    for (Eigen::Vector3f &p : posed.positions) p = pose * p;
    posed.compute_normals();
  }
  return posed;
}

Mesh Pipeline::posed_mesh(int frame) const { return posed_emitter(groom_, rest_mesh_, frame); }

StrandSet Pipeline::guides_at(int frame, const Mesh &posed) {
  if (!groom_.dynamics.enabled) {
    StrandSet guides = carry_guides(rest_mesh_, posed, guides_);
    if (controls_) controls_->apply(frame, posed, guides);
    return guides;
  }

  if (!options_.guides_cache.empty()) return read_cached_guides(frame);

  // The controls turn the simulated guides' roots at every simulated frame.
  controls::GuidePose pose;
  auto turns_at = [&](int at, const Mesh &mesh) -> std::span<const Eigen::Quaternionf> {
    if (!controls_) return {};
    controls_->pose(at, mesh, pose);
    return pose.turns;
  };
  const int start = std::min(options_.simulation_start, frame) - groom_.dynamics.preroll_frames;
  if (!simulated_frame_ || *simulated_frame_ > frame) {
    const Mesh start_mesh = start == frame ? posed : posed_mesh(start);
    simulator_->reset(start_mesh, turns_at(start, start_mesh));
    simulated_frame_ = start;
  }
  while (*simulated_frame_ < frame) {
    const int next = *simulated_frame_ + 1;
    if (next == frame) {
      simulator_->step_frame(posed, turns_at(next, posed));
    } else {
      const Mesh next_mesh = posed_mesh(next);
      simulator_->step_frame(next_mesh, turns_at(next, next_mesh));
    }
    simulated_frame_ = next;
  }
  if (!controls_) return simulator_->guides();
  // The rig-driven guides, with the simulation mixed in by each control's dynamic blend.
  StrandSet guides = carry_guides(rest_mesh_, posed, guides_);
  controls_->pose(frame, posed, pose);
  controls_->apply(pose, guides);
  controls_->blend_dynamics(pose, simulator_->guides(), guides);
  return guides;
}

FrameResult Pipeline::produce(int frame, bool with_effects) {
  FrameResult result;
  result.frame = frame;
  result.mesh = posed_mesh(frame);
  result.guides = guides_at(frame, result.mesh);
  const MeshQuery query(result.mesh);
  interp::GrowOptions grow_options;
  grow_options.points_per_strand = groom_.points_per_strand;
  grow_options.width_root = groom_.width_root;
  grow_options.width_tip = groom_.width_tip;
  grow_options.with_widths = true;
  grow_options.separate = groom_.interpolation.separate;
  // Growth's skin bounds let the stack's closing skin pass skip the points it moved by less; both
  // search the skin through one grid built for this frame.
  std::vector<float> clearance;
  const skin::SkinGrid skin_grid(result.mesh, query);
  const skin::SkinGrid *grid = &skin_grid;
  interp::GrowStats grow_stats;
  grow_options.r_stats = &grow_stats;
  interp::grow(*binding_, result.mesh, query, roots_, result.guides, grow_options, result.strands, &clearance, grid);
  result.unseparated_pairs = grow_stats.unseparated_pairs;
  if (with_effects)
    effects_->apply(result.mesh, query, result.guides, binding_->skin_margin, result.strands, clearance,
                    grid);
  return result;
}

FrameResult Pipeline::produce_starts(int frame) {
  FrameResult result;
  result.frame = frame;
  result.mesh = posed_mesh(frame);
  result.guides = guides_at(frame, result.mesh);
  const MeshQuery query(result.mesh);
  const std::vector<Eigen::Vector3f> starts =
      interp::strand_starts(*binding_, result.mesh, query, roots_, result.guides);
  result.strands.resize_uniform(starts.size(), 1, false, StrandSet::Fill::unset);
  result.strands.positions = starts;
  result.strands.ids = roots_.ids;
  return result;
}

StrandSet Pipeline::read_cached_guides(int frame) const {
  const std::string path = expand_frame_pattern(options_.guides_cache, frame);
  if (!std::filesystem::exists(path))
    throw InputError("--guides-cache: " + path + " does not exist (write the cache with plume simulate first)");
  const StrandSet cached = io::read_strands(path);
  check_guide_points(cached, path);
  if (cached.offsets != guides_.strands.offsets)
    throw InputError(FileLoc{path}, "guide cache: expected " + std::to_string(guides_.size()) + " guides of " +
                                        "the groom's point counts, got " + std::to_string(cached.strand_count()) +
                                        " strands / " + std::to_string(cached.point_count()) + " points");
  // Keep the rest guides' ids and widths: only the positions are simulated.
  StrandSet result = guides_.strands;
  result.positions = cached.positions;
  return result;
}

void Pipeline::check_frame_inputs(const FrameRange &range) const {
  const bool cached = groom_.dynamics.enabled && !options_.guides_cache.empty();
  if (groom_.dynamics.enabled && !cached) {
    // Simulation is sequential: the last frame is reached from the simulation's start.
    const int64_t start = std::min(options_.simulation_start, range.first);
    const int64_t simulated = int64_t(range.last) - start + 1;
    if (simulated > kMaxFramesPerRun)
      throw InputError(groom_.dynamics_loc(),
                       "dynamics: frame " + std::to_string(range.last) + " is simulated from rest at frame " +
                           std::to_string(start) + " (the first of output.frames, or of the frames asked for when "
                           "earlier), " + std::to_string(simulated) +
                           " frames, expected at most " + std::to_string(kMaxFramesPerRun) +
                           " in one run besides dynamics.preroll (start output.frames nearer)");
  }
  if (cached) {
    check_frame_pattern(options_.guides_cache, range, "--guides-cache");
    for (int64_t i = 0; i < range.count(); ++i) read_cached_guides(range.at(i));
  }
  const EmitterAnimation &animation = groom_.animation;
  if (animation.kind != EmitterAnimation::Kind::obj_sequence) return;
  // Simulating without a cache poses the emitter at every frame from the simulation's start
  // (guides_at()); otherwise only the range's frames are posed.
  FrameRange posed = range;
  if (groom_.dynamics.enabled && !cached)
    posed = FrameRange{std::min(options_.simulation_start, range.first) - groom_.dynamics.preroll_frames, range.last, 1};
  const std::string what = groom_.source + ": emitter.animation.sequence";
  check_frame_pattern(animation.sequence_pattern, posed, what);
  // Existence first, so that a missing frame is named before the slower parse of the others.
  for (int64_t i = 0; i < posed.count(); ++i) {
    const std::string path = expand_frame_pattern(animation.sequence_pattern, posed.at(i));
    std::error_code error;
    if (!std::filesystem::is_regular_file(path, error))
      throw InputError(what + ": " + path + (std::filesystem::exists(path, error) ? " is not a file" : " does not exist"));
  }
  for (int64_t i = 0; i < posed.count(); ++i)
    io::read_obj_pose(expand_frame_pattern(animation.sequence_pattern, posed.at(i)), rest_mesh_);
}

void write_guide_cache(const std::string &path, const StrandSet &guides, int frame) {
  io::StrandWriteOptions options;
  options.time_code = frame;
  options.comment = "plume guide cache, frame " + std::to_string(frame);
  io::write_strands(path, guides, options);
}

}  // namespace plume
