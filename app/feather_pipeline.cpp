#include "app/feather_pipeline.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <unordered_map>

#include "app/commands.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "io/feather_lifts.h"
#include "io/point_list.h"
#include "io/vertex_map.h"
#include "skin/skin_grid.h"

namespace plume {

namespace {

/// The follicles the groom asks for: scattered on its tracts, or snapped from its file.
feathers::Follicles make_follicles(const GroomDesc &groom, const Mesh &rest_mesh, int64_t count_override) {
  const FollicleSettings &settings = groom.feathers.follicles;
  if (settings.source == FollicleSettings::Source::file) {
    const std::vector<Eigen::Vector3f> points = io::read_points(settings.file);
    const size_t count = count_override >= 0 ? std::min(points.size(), size_t(count_override)) : points.size();
    const MeshQuery query(rest_mesh);
    feathers::Follicles follicles;
    for (size_t i = 0; i < count; ++i) {
      follicles.points.push_back(query.closest(points[i]));
      follicles.ids.push_back(i);  // the point's index in the file: stable as long as the file is
    }
    return follicles;
  }
  std::vector<float> map;
  if (!settings.map_path.empty())
    map = io::read_vertex_map(settings.map_path, rest_mesh.vertex_count(), groom.source + ": feathers.follicles.map");
  return feathers::scatter_follicles(rest_mesh, settings, map, count_override);
}

/// Throws InputError before the coat is bound when one frame of `count` feathers would not fit in
/// memory: per feather its parameters (about 2 kB), per curve point its position, width and two
/// texture coordinates and the writer's text (about 60 bytes), per vane vertex 40 bytes; the largest
/// template's barb count stands for every feather.
void check_memory_for_feathers(const GroomDesc &groom, size_t count, const std::string &what) {
  const FeatherDetail &d = groom.feathers.detail;
  double points = 0.0;
  for (const FeatherTemplate &t : groom.feathers.templates) {
    const double barbs = 2.0 * double(barb_positions(t).size()) * (1.0 + (t.afterfeather > 0.0f ? 1.0 : 0.0));
    points = std::max(points, barbs * d.barb_points + 2.0 * (d.rachis_points + 1));
  }
  const double vertices = 4.0 * d.vane_rows * (d.vane_columns + 1);
  const double needed = double(count) * (2048.0 + 60.0 * points + 40.0 * vertices);
  const double usable = usable_memory_bytes();
  if (usable <= 0.0 || needed <= usable) return;
  char figures[160];
  std::snprintf(figures, sizeof figures, "need about %.1f GB per frame, more than the %.1f GB of memory", needed / 1e9,
                usable / 1e9);
  throw InputError(groom.feathers.follicles.loc, what + ": " + std::to_string(count) + " feathers " + figures +
                                                     " this run may use (fewer follicles, barbs or barb_points)");
}

}  // namespace

FeatherPipeline::FeatherPipeline(const GroomDesc &groom, const PipelineOptions &options)
    : groom_(groom), options_(options) {
  if (!groom_.feathers.enabled) throw InternalError("FeatherPipeline: the groom has no feathers section");
  // The base pipeline grows no strands: it poses the emitter and carries, simulates or reads the stems.
  PipelineOptions base_options = options;
  base_options.strand_count = 0;
  base_ = std::make_unique<Pipeline>(groom_, base_options);
  const Mesh &rest = base_->rest_mesh();
  feathers::Follicles follicles = make_follicles(groom_, rest, options.strand_count);
  check_memory_for_feathers(groom_, follicles.size(),
                            options.strand_count >= 0 ? std::string("--strands") : std::string("feathers.follicles"));
  if (!groom_.feathers.layer_map_path.empty())
    layer_map_ = io::read_vertex_map(groom_.feathers.layer_map_path, rest.vertex_count(),
                                     groom_.source + ": feathers.layers.map");
  coat_ = std::make_unique<feathers::Coat>(rest, base_->guides(), groom_.feathers, std::move(follicles), layer_map_);
}

FeatherPipeline::~FeatherPipeline() = default;

std::vector<feathers::LayerKey> FeatherPipeline::layer_keys() const {
  return coat_->order_keys(base_->rest_mesh(), groom_.feathers, layer_map_);
}

FeatherPipeline::Frame FeatherPipeline::produce_from(int frame, const feathers::CoatState *previous) {
  Frame result;
  result.frame = frame;
  result.mesh = base_->posed_mesh(frame);
  result.stems = base_->guides_at(frame, result.mesh);
  const MeshQuery query(result.mesh);
  const skin::SkinGrid grid(result.mesh, query);
  coat_->grow(result.mesh, query, result.stems, result.feathers, &grid, previous ? &previous->skin_pass : nullptr,
              previous ? &previous->layers : nullptr);
  return result;
}

FeatherPipeline::Frame FeatherPipeline::produce(int frame) {
  Frame result = produce_from(frame, warm_start(frame));
  state_ = {result.feathers.skin_pass, result.feathers.layer_state};
  state_frame_ = frame;
  return result;
}

FeatherPipeline::StateFrame FeatherPipeline::carried_from(int frame, const feathers::CoatState *previous) {
  StateFrame result;
  if (coat_->layered()) {
    // The layering pass turns the vanes of the whole coat.
    Frame grown = produce_from(frame, previous);
    result.mesh = std::move(grown.mesh);
    result.stems = std::move(grown.stems);
    result.state = {std::move(grown.feathers.skin_pass), std::move(grown.feathers.layer_state)};
    return result;
  }
  result.mesh = base_->posed_mesh(frame);
  result.stems = base_->guides_at(frame, result.mesh);
  const MeshQuery query(result.mesh);
  coat_->skin_pass(result.mesh, query, result.stems, previous ? &previous->skin_pass : nullptr,
                   result.state.skin_pass);
  return result;
}

FeatherPipeline::StateFrame FeatherPipeline::carried(int frame) {
  StateFrame result = carried_from(frame, warm_start(frame));
  state_ = result.state;
  state_frame_ = frame;
  return result;
}

bool FeatherPipeline::carries() const { return groom_.feathers.lift || coat_->layered(); }

io::FeatherLifts FeatherPipeline::lifts_record(int frame, const feathers::CoatState &state) const {
  io::FeatherLifts lifts;
  lifts.frame = frame;
  lifts.ids = coat_->ids();
  lifts.lifts = state.skin_pass.lifts;
  lifts.scales = state.skin_pass.scales;
  if (lifts.lifts.empty()) {
    // The skin pass lifts nothing: every feather unturned, at its size.
    lifts.lifts.assign(lifts.ids.size(), 0.0f);
    lifts.scales.assign(lifts.ids.size(), 1.0f);
  }
  lifts.layered = !state.layers.empty();
  lifts.layer_turns = state.layers.turns;
  lifts.layer_scales = state.layers.scales;
  lifts.layer_yaws = state.layers.yaws;
  lifts.layer_bends = state.layers.bends;
  lifts.layer_bend_starts = state.layers.bend_starts;
  return lifts;
}

bool FeatherPipeline::cached() const { return base_->dynamic() && !options_.guides_cache.empty(); }

std::optional<feathers::CoatState> FeatherPipeline::read_cached_state(int frame) const {
  const std::string path = expand_frame_pattern(io::feather_lifts_pattern(options_.guides_cache), frame);
  std::error_code error;
  if (!std::filesystem::exists(path, error) &&
      !std::filesystem::exists(expand_frame_pattern(options_.guides_cache, frame), error))
    return std::nullopt;
  const io::FeatherLifts lifts = io::read_feather_lifts(path);
  if (lifts.frame != frame)
    throw InputError(FileLoc{path, 2}, "frame: expected " + std::to_string(frame) + " (the file's name), got " +
                                           std::to_string(lifts.frame));
  const bool layered = coat_->layered();
  if (layered && !lifts.layered)
    throw InputError(FileLoc{path}, "layers: the file holds the skin pass's state only, and this groom keeps its "
                                    "feathers in layers (a cache written before the layering pass carried its "
                                    "state, or of the groom without layers? Write it again with plume simulate)");
  if (layered && lifts.layer_yaws.empty())
    throw InputError(FileLoc{path}, "layer_yaw: the file holds no yaw of the feathers turned aside (version 2, "
                                    "written before the layering pass carried it; write it again with plume "
                                    "simulate)");
  if (layered && lifts.layer_bends.empty())
    throw InputError(FileLoc{path}, "layer_bend: the file holds no bend of the feathers bent (version 3, "
                                    "written before the layering pass carried it; write it again with plume "
                                    "simulate)");
  std::unordered_map<uint64_t, size_t> by_id;
  by_id.reserve(lifts.ids.size());
  for (size_t k = 0; k < lifts.ids.size(); ++k) by_id.emplace(lifts.ids[k], k);
  const std::vector<uint64_t> &ids = coat_->ids();
  feathers::CoatState state;
  if (groom_.feathers.lift) {
    state.skin_pass.lifts.resize(ids.size());
    state.skin_pass.scales.resize(ids.size());
  }
  if (layered) {
    state.layers.turns.resize(ids.size());
    state.layers.scales.resize(ids.size());
    state.layers.yaws.resize(ids.size());
    state.layers.bends.resize(ids.size());
    state.layers.bend_starts.resize(ids.size());
  }
  for (size_t i = 0; i < ids.size(); ++i) {
    const auto it = by_id.find(ids[i]);
    if (it == by_id.end())
      throw InputError(FileLoc{path}, "feathers: no feather id " + std::to_string(ids[i]) + " (the file holds " +
                                          std::to_string(lifts.ids.size()) + " feathers, the coat " +
                                          std::to_string(ids.size()) + ": a cache of another groom? Write it again "
                                          "with plume simulate)");
    const size_t k = it->second;
    if (groom_.feathers.lift) {
      state.skin_pass.lifts[i] = lifts.lifts[k];
      state.skin_pass.scales[i] = lifts.scales[k];
    }
    if (layered) {
      state.layers.turns[i] = lifts.layer_turns[k];
      state.layers.scales[i] = lifts.layer_scales[k];
      state.layers.yaws[i] = lifts.layer_yaws[k];
      state.layers.bends[i] = lifts.layer_bends[k];
      state.layers.bend_starts[i] = lifts.layer_bend_starts[k];
    }
  }
  return state;
}

const feathers::CoatState *FeatherPipeline::warm_start(int frame) {
  if (!carries()) return nullptr;
  if (cached()) {
    std::optional<feathers::CoatState> state = read_cached_state(frame - 1);
    if (!state) return nullptr;
    cached_state_ = std::move(*state);
    return &cached_state_;
  }
  const int start = std::min(options_.simulation_start, frame);
  if (frame <= start) return nullptr;
  // Carried from the last frame, or replayed from the start (stateless there) through the frames
  // not produced.
  int next = state_frame_ && *state_frame_ < frame && *state_frame_ >= start ? *state_frame_ + 1 : start;
  if (next == start) state_ = {};
  for (; next < frame; ++next) {
    state_ = carried_from(next, next == start ? nullptr : &state_).state;
    state_frame_ = next;
  }
  return &state_;
}

void FeatherPipeline::check_frame_inputs(const FrameRange &range) const {
  if (!carries() || cached() || range.first <= options_.simulation_start) {
    base_->check_frame_inputs(range);
  } else {
    base_->check_frame_inputs(FrameRange{options_.simulation_start, range.last, 1});
  }
  if (!carries() || !cached()) return;
  for (int64_t i = 0; i < range.count(); ++i) read_cached_state(range.at(i) - 1);
}

feathers::CoatFrame FeatherPipeline::rest_frame() const {
  const Mesh &rest = base_->rest_mesh();
  const MeshQuery query(rest);
  feathers::CoatFrame frame;
  coat_->grow(rest, query, base_->guides().strands, frame);
  return frame;
}

feathers::LayerOrder FeatherPipeline::layer_order() const {
  if (coat_->layered()) return coat_->layer_order();
  const Mesh &rest = base_->rest_mesh();
  const MeshQuery query(rest);
  feathers::CoatFrame frame;
  coat_->grow(rest, query, base_->guides().strands, frame);  // no layers: the coat grown as the order reads it
  return feathers::layer_order_from_coverage(frame, coat_->ranges(), layer_keys(), &query);
}

io::FeatherWriteOptions FeatherPipeline::write_options() const {
  io::FeatherWriteOptions options;
  for (const FeatherTemplate &t : groom_.feathers.templates) options.template_names.push_back(t.name);
  options.fps = groom_.dynamics.fps;
  options.meters_per_unit = groom_.output.meters_per_unit;
  options.up_axis = groom_.output.up_axis;
  options.obj_uv_along_barbs = groom_.feathers.detail.uv == FeatherDetail::Uv::barb;
  options.comment = "plume regrow of " + groom_file_name(groom_);
  return options;
}

}  // namespace plume
