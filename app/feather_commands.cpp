#include "app/feather_commands.h"

#include <algorithm>
#include <cstdio>
#include <memory>
#include <unordered_map>
#include <vector>

#include "app/commands.h"
#include "app/feather_pipeline.h"
#include "app/feather_preview.h"
#include "app/progress.h"
#include "app/run_outputs.h"
#include "check/feather_layers.h"
#include "check/feather_motion.h"
#include "check/vanes.h"
#include "feathers/layering.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "io/feather_writers.h"
#include "io/groom_file.h"
#include "io/file_scan.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume {

namespace {

const std::vector<std::string> kCurveExtensions = {".usda", ".hair", ".ply", ".obj"};
const std::vector<std::string> kVaneExtensions = {".usda", ".obj"};

/// A feather's tone in previews: a warm grey-brown, lighter than hair.
PreviewStyle feather_style(int size) {
  PreviewStyle style;
  style.size = size;
  style.hair_color = Eigen::Vector3f(0.30f, 0.22f, 0.14f);
  style.strand_brush = 2;
  return style;
}

/// The first `most` coverings the layer order broke in cycles, as (covering, covered) feather ids.
std::vector<std::pair<uint64_t, uint64_t>> broken_by_id(const feathers::LayerOrder &order,
                                                        const std::vector<uint64_t> &ids, size_t most = 8) {
  std::vector<std::pair<uint64_t, uint64_t>> named;
  for (size_t k = 0; k < std::min(most, order.broken.size()); ++k)
    named.emplace_back(ids[size_t(order.broken[k].first)], ids[size_t(order.broken[k].second)]);
  return named;
}

/// Feather id pairs as "a/b c/d".
std::string text_pairs(const std::vector<std::pair<uint64_t, uint64_t>> &pairs) {
  std::string text;
  for (const auto &[a, b] : pairs) text += (text.empty() ? "" : " ") + std::to_string(a) + "/" + std::to_string(b);
  return text;
}

}  // namespace

void run_feather_regrow(const GroomDesc &groom, const FeatherRegrowArgs &args) {
  const FrameRange range = frames_to_produce(args.frames, groom);
  const std::string &out = args.out, &out_what = args.out_what;
  const std::string &vanes = args.vanes, &vanes_what = args.vanes_what;
  if (out.empty() && vanes.empty())
    throw InputError("--out: expected an output for the feather curves (or --vanes for the vane meshes), got none "
                     "(the groom has neither output.path nor output.vanes)");
  if (!out.empty()) check_output_pattern(out, range, out_what, kCurveExtensions);
  if (!vanes.empty()) check_output_pattern(vanes, range, vanes_what, kVaneExtensions);
  if (!out.empty() && out == vanes)
    throw InputError(vanes_what + ": expected another path than the curves' (" + out + ")");
  const PreviewSchedule previews(args.preview, args.preview_every >= 0 ? args.preview_every : groom.output.preview_every,
                                 range, args.preview_what);
  const RunInputs inputs(groom, args.guides_cache);
  if (!out.empty()) check_output_locations(out, range, out_what, inputs);
  if (!vanes.empty()) check_output_locations(vanes, range, vanes_what, inputs);
  previews.check_locations(range, inputs);
  const int preview_size = preview_size_of(args.preview_size, groom);
  set_thread_count(args.threads);

  RunSummary summary("regrow", range);
  const int curves_output = summary.add_output("curves", out);
  const int vanes_output = summary.add_output("vanes", vanes);
  const int previews_output = summary.add_output("previews", previews.pattern());
  const auto path_of = [](const std::string &pattern, int frame) {
    return pattern.empty() ? std::string() : expand_frame_pattern(pattern, frame);
  };
  // With --skip-existing, a frame whose files are all there (complete: they are renamed into place
  // whole) is not regrown.
  std::vector<bool> done_already(size_t(range.count()), false);
  int64_t to_grow = range.count();
  if (args.skip_existing)
    for (int64_t i = 0; i < range.count(); ++i) {
      const int frame = range.at(i);
      done_already[size_t(i)] = outputs_complete({path_of(out, frame), path_of(vanes, frame), previews.path_at(i, frame)});
      to_grow -= done_already[size_t(i)] ? 1 : 0;
    }

  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  std::unique_ptr<FeatherPipeline> pipeline;
  io::FeatherWriteOptions write_options;
  PreviewCamera camera;
  if (to_grow > 0) {
    pipeline = std::make_unique<FeatherPipeline>(groom, options);
    pipeline->check_frame_inputs(range);
    write_options = pipeline->write_options();
    if (!previews.pattern().empty())
      camera = feather_camera(pipeline->base().rest_mesh(), pipeline->rest_frame().curves.curves);
    const feathers::LayerOrder &order = pipeline->coat().layer_order();
    if (!order.broken.empty()) {
      const std::vector<std::pair<uint64_t, uint64_t>> named = broken_by_id(order, pipeline->coat().ids());
      std::fprintf(stderr, "plume: warning: the layer order at rest breaks %lld coverings in cycles (the feather "
                   "covering the fewest goes lower; covering/covered feather ids: %s%s)\n",
                   (long long)order.broken.size(), text_pairs(named).c_str(), order.broken.size() > 8 ? " ..." : "");
    }
  }
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  remove_stale_temp_files(out, range);
  remove_stale_temp_files(vanes, range);
  remove_stale_temp_files(previews.pattern(), range);

  Progress progress("regrow", int(to_grow));
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    const std::string curves_path = path_of(out, frame), vanes_path = path_of(vanes, frame);
    const std::string preview = previews.path_at(i, frame);
    if (done_already[size_t(i)]) {
      if (!out.empty()) summary.kept(curves_output, curves_path);
      if (!vanes.empty()) summary.kept(vanes_output, vanes_path);
      if (!preview.empty()) summary.kept(previews_output, preview);
      continue;
    }
    const FeatherPipeline::Frame result = pipeline->produce(frame);
    write_options.time_code = frame;
    if (!out.empty()) {
      io::write_feather_curves(curves_path, result.feathers.curves, write_options);
      summary.wrote(curves_output, curves_path);
    }
    if (!vanes.empty()) {
      io::write_vane_mesh(vanes_path, result.feathers.vanes, write_options);
      summary.wrote(vanes_output, vanes_path);
    }
    if (!preview.empty()) {
      write_png(preview, render_feather_preview(camera, result.mesh, result.feathers,
                                                args.preview_guides ? &result.stems : nullptr, feather_style(preview_size)));
      summary.wrote(previews_output, preview);
    }
    if (result.feathers.layering.unresolved > 0)
      std::fprintf(stderr, "plume: warning: frame %d: %lld feathers could not be turned clear of the feathers below them (shrunk toward their roots)\n",
                   frame, (long long)result.feathers.layering.unresolved);
    if (result.feathers.layering.left_under > 0)
      std::fprintf(stderr, "plume: warning: frame %d: %lld feathers are left under a feather the layer order puts below them (no turn frees them; plume check reports the pairs)\n",
                   frame, (long long)result.feathers.layering.left_under);
    progress.frame_done(frame);
  }
  progress.finish();
  summary.print();
}

void run_feather_preview(const GroomDesc &groom, int frame, const std::string &path, int size, bool stems, int threads,
                         int64_t strands, const std::string &guides_cache, const FeatherPreviewViews &views) {
  set_thread_count(threads);
  PipelineOptions options;
  options.strand_count = strands;
  options.guides_cache = guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), frame);
  FeatherPipeline pipeline(groom, options);
  const FrameRange single{frame, frame, 1};
  pipeline.check_frame_inputs(single);
  const Eigen::AlignedBox3f bounds = scene_bounds(pipeline.base().rest_mesh(), pipeline.rest_frame().curves.curves);
  const std::vector<PreviewCamera> cameras = views.turntable > 0 ? turntable_cameras(bounds, views.turntable, views.angle)
                                                                 : std::vector{fit_camera(bounds, views.angle)};
  const FeatherPipeline::Frame result = pipeline.produce(frame);
  std::vector<Image> images;
  for (const PreviewCamera &camera : cameras)
    images.push_back(render_feather_preview(camera, result.mesh, result.feathers, stems ? &result.stems : nullptr,
                                            feather_style(size)));
  write_png(path, images.size() == 1 ? images.front() : tile_images(images, views.columns));
}

bool is_vane_mesh_file(const std::string &path) {
  if (io::detail::extension_of(path) != ".usda") return false;
  std::string text;
  try {
    text = io::detail::read_file_bytes(path);
  } catch (const InputError &) {
    return false;  // the strand reader names the problem
  }
  return text.find("def Mesh") != std::string::npos && text.find("def BasisCurves") == std::string::npos;
}

void print_vane_mesh_info(const std::string &path) {
  const Mesh mesh = io::read_vane_mesh(path);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : mesh.positions) box.extend(p);
  double area = 0.0;
  for (size_t f = 0; f < mesh.triangle_count(); ++f) area += mesh.triangle_area(f);
  std::printf("%s: vane mesh\n", path.c_str());
  std::printf("  vertices   %zu\n", mesh.vertex_count());
  std::printf("  triangles  %zu\n", mesh.triangle_count());
  std::printf("  area       %g\n", area);
  std::printf("  bounds     (%g, %g, %g) .. (%g, %g, %g)\n", box.min().x(), box.min().y(), box.min().z(), box.max().x(),
              box.max().y(), box.max().z());
}

bool is_feather_check(const std::string &path, const std::string &groom_path) {
  if (!groom_path.empty() && io::read_groom_file(groom_path).feathers.enabled) return true;
  const std::string ext = io::detail::extension_of(path);
  if (ext == ".obj") return io::read_obj_file(path).mesh.has_value();
  if (ext != ".usda" && ext != ".ply") return false;
  std::string text;
  try {
    text = io::detail::read_file_bytes(path);
  } catch (const InputError &) {
    return false;  // the strand reader names the problem
  }
  if (ext == ".ply") return text.substr(0, std::min<size_t>(text.size(), 4096)).find("property uint feather\n") != std::string::npos;
  return is_vane_mesh_file(path) || text.find("primvars:feather_id") != std::string::npos;
}

namespace {

/// Per triangle of a vane mesh read back: its feather's id (from its group's name feather_<id>, or
/// the group's index for a mesh from elsewhere).
std::vector<uint64_t> vane_feather_ids(const Mesh &mesh) {
  std::vector<uint64_t> group_ids(mesh.group_names.size());
  for (size_t g = 0; g < group_ids.size(); ++g) {
    const std::string &name = mesh.group_names[g];
    group_ids[g] = g;
    if (name.rfind("feather_", 0) == 0 && name.size() > 8 &&
        name.find_first_not_of("0123456789", 8) == std::string::npos)
      group_ids[g] = std::stoull(name.substr(8));
  }
  std::vector<uint64_t> ids(mesh.triangle_count());
  for (size_t t = 0; t < ids.size(); ++t) ids[t] = group_ids[size_t(mesh.triangle_groups[t])];
  return ids;
}

}  // namespace

namespace {

std::string json_quote(const std::string &text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') out += '\\';
    if ((unsigned char)c < 32) {
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", unsigned((unsigned char)c));
      out += escaped;
      continue;
    }
    out += c;
  }
  return out + "\"";
}

std::string json_pairs(const std::vector<std::pair<uint64_t, uint64_t>> &pairs) {
  std::string text = "[";
  for (size_t e = 0; e < pairs.size(); ++e)
    text += (e ? ", [" : "[") + std::to_string(pairs[e].first) + ", " + std::to_string(pairs[e].second) + "]";
  return text + "]";
}

/// A vane mesh read back, with its feathers in file order: per feather its id and its vertices
/// (consecutive: [first_vertex[f], first_vertex[f + 1]), as Plume writes them).
struct VaneFile {
  Mesh mesh;
  std::vector<uint64_t> triangle_ids;
  std::vector<uint64_t> feather_ids;
  std::vector<int64_t> first_vertex;  // empty when a feather's vertices are not consecutive
};

VaneFile read_vane_file(const std::string &path) {
  VaneFile file;
  file.mesh = io::read_vane_mesh(path);
  file.triangle_ids = vane_feather_ids(file.mesh);
  // Each feather's vertices: the range its triangles use; consecutive when each range starts where
  // the one before ended and the last ends the file.
  std::vector<int64_t> lo, hi;
  for (size_t t = 0; t < file.triangle_ids.size(); ++t) {
    if (t == 0 || file.triangle_ids[t] != file.triangle_ids[t - 1]) {
      file.feather_ids.push_back(file.triangle_ids[t]);
      lo.push_back(INT64_MAX);
      hi.push_back(-1);
    }
    for (int k = 0; k < 3; ++k) {
      lo.back() = std::min<int64_t>(lo.back(), file.mesh.triangles[t][k]);
      hi.back() = std::max<int64_t>(hi.back(), file.mesh.triangles[t][k]);
    }
  }
  bool consecutive = !lo.empty() && lo.front() == 0 && hi.back() + 1 == int64_t(file.mesh.positions.size());
  for (size_t f = 1; consecutive && f < lo.size(); ++f) consecutive = lo[f] == hi[f - 1] + 1;
  if (consecutive) {
    file.first_vertex = lo;
    file.first_vertex.push_back(int64_t(file.mesh.positions.size()));
  }
  return file;
}

/// The skin at `frame` of the groom, or the mesh file.
Mesh posed_skin(const GroomDesc &groom, int frame) {
  return posed_emitter(groom, io::read_obj_mesh(groom.emitter_path), frame);
}

/// What a groom's coat says of a vane file: the layer order's ranks, and per feather of the file
/// its coat index.
struct CoatView {
  std::unique_ptr<FeatherPipeline> pipeline;
  feathers::CoatFrame rest;
  feathers::LayerOrder order;
  std::vector<size_t> coat_index;  // per feather of the file
  std::unordered_map<uint64_t, int64_t> rank;  // by id
};

CoatView view_coat(const GroomDesc &groom, const std::string &groom_path, const VaneFile &file,
                   const std::string &path) {
  CoatView view;
  // The coat without its layering pass: its rest frame is the template, and the order is the one the
  // pass freezes (built from this rest frame, as Coat does).
  GroomDesc unlayered = groom;
  unlayered.feathers.layers = false;
  const auto bind = [&](int64_t count) {
    PipelineOptions options;
    options.strand_count = count;
    view.pipeline = std::make_unique<FeatherPipeline>(unlayered, options);
  };
  const auto index_of = [&] {
    std::unordered_map<uint64_t, size_t> by_id;
    const std::vector<uint64_t> &ids = view.pipeline->coat().ids();
    for (size_t i = 0; i < ids.size(); ++i) by_id.emplace(ids[i], i);
    view.coat_index.clear();
    for (const uint64_t id : file.feather_ids) {
      const auto it = by_id.find(id);
      if (it == by_id.end()) return false;
      view.coat_index.push_back(it->second);
    }
    return by_id.size() == file.feather_ids.size();
  };
  // As many follicles as the file has feathers: the full coat, or the subset a proxy run
  // (plume regrow --strands N) grew, whose order is that of its own coat. Else the groom's count.
  bind(int64_t(file.feather_ids.size()));
  if (!index_of()) {
    bind(-1);
    if (!index_of())
      throw InputError(path + ": its feathers are not " + groom_path + "'s (" + std::to_string(file.feather_ids.size()) +
                       " feathers, not the groom's coat or a proxy of it)");
  }
  const feathers::Coat &coat = view.pipeline->coat();
  view.rest = view.pipeline->rest_frame();
  view.order = view.pipeline->layer_order();
  for (size_t i = 0; i < coat.size(); ++i) view.rank.emplace(coat.ids()[i], view.order.rank[i]);
  // The file's vertices must be laid out as the coat's, feather by feather.
  const feathers::FeatherRanges ranges = coat.ranges();
  bool layout = !file.first_vertex.empty();
  for (size_t f = 0; layout && f < view.coat_index.size(); ++f) {
    const size_t i = view.coat_index[f];
    layout = file.first_vertex[f + 1] - file.first_vertex[f] == ranges.first_vertex[i + 1] - ranges.first_vertex[i];
  }
  if (!layout)
    throw InputError(path + ": its feathers' vane vertices are not laid out as " + groom_path +
                     "'s coat grows them (another detail, or a mesh Plume did not write)");
  return view;
}

/// Per feather of the file, a per-coat-feather value.
template <class T, class F>
std::vector<T> per_file_feather(const CoatView &view, F value) {
  std::vector<T> out;
  for (const size_t i : view.coat_index) out.push_back(value(i));
  return out;
}

std::vector<SurfaceFrame> follicle_frames(const CoatView &view, const Mesh &posed) {
  const std::vector<SurfacePoint> &follicles = view.pipeline->coat().follicles();
  return per_file_feather<SurfaceFrame>(view, [&](size_t i) { return surface_frame(posed, follicles[i]); });
}

}  // namespace

int run_feather_check(const FeatherCheckArgs &args) {
  const bool vanes = is_vane_mesh_file(args.path) || io::detail::extension_of(args.path) == ".obj";
  if (!args.previous.empty() && args.groom.empty())
    throw InputError("--previous: needs --groom (the skin of both frames, the coat's follicles)");
  if (!args.previous.empty() && !vanes)
    throw InputError("--previous: compares vane meshes (.usda or .obj from plume regrow --vanes); " + args.path +
                     " holds feather curves");
  if (args.max_pop && args.previous.empty()) throw InputError("--max-pop: needs --previous, the frame to compare with");
  if (args.previous_frame && args.previous.empty()) throw InputError("--previous-frame: needs --previous");

  std::optional<GroomDesc> groom;
  Mesh skin;
  std::string skin_label;
  int at = 0;
  if (!args.groom.empty()) {
    groom = io::read_groom_file(args.groom);
    at = args.frame ? *args.frame : groom_first_frame(*groom);
    skin = posed_skin(*groom, at);
    skin_label = groom->emitter_path + " posed at frame " + std::to_string(at);
  } else {
    skin = io::read_obj_mesh(args.mesh);
    skin_label = args.mesh;
  }
  const MeshQuery query(skin);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : skin.positions) box.extend(p);
  const float eps = 1e-5f * box.diagonal().norm();
  // Vane meshes: every vertex; curves: every point, a curve's first point (on the skin or the
  // rachis) allowed down to -eps.
  std::vector<Eigen::Vector3f> points;
  std::vector<bool> first;
  size_t curve_count = 0, triangle_count = 0;
  check::VaneCheckReport meets;
  VaneFile file;
  if (vanes) {
    file = read_vane_file(args.path);
    points = file.mesh.positions;
    first.assign(points.size(), false);
    triangle_count = file.mesh.triangle_count();
  } else {
    const StrandSet curves = io::read_strands(args.path);
    points = curves.positions;
    first.assign(points.size(), false);
    for (size_t c = 0; c < curves.strand_count(); ++c) first[size_t(curves.offsets[c])] = true;
    curve_count = curves.strand_count();
  }
  // With the groom, the files are matched to its coat, and to each other, before anything is
  // measured: a bad input fails at once.
  const bool layered = vanes && groom.has_value() && !file.feather_ids.empty();
  std::optional<CoatView> coat_view;
  VaneFile before;
  if (layered) {
    coat_view = view_coat(*groom, args.groom, file, args.path);
    if (!args.previous.empty()) {
      before = read_vane_file(args.previous);
      if (before.feather_ids != file.feather_ids || before.first_vertex != file.first_vertex ||
          before.mesh.triangles != file.mesh.triangles)
        throw InputError("--previous: " + args.previous + " holds other feathers than " + args.path +
                         " (another groom, count or detail)");
    }
  }
  if (vanes) meets = check::check_vanes(file.mesh.positions, file.mesh.triangles, file.triangle_ids);
  size_t below = 0;
  float deepest = 0.0f;
  const float margin = args.margin;
#pragma omp parallel for schedule(static) reduction(+ : below) reduction(min : deepest)
  for (int64_t v = 0; v < int64_t(points.size()); ++v) {
    const float d = query.signed_distance(points[size_t(v)]);
    if (d < (first[size_t(v)] ? 0.0f : margin) - eps) ++below;
    deepest = std::min(deepest, d);
  }

  // With the groom: the order and the templates; with the previous frame: flips and popping.
  check::LayerOrderReport order;
  check::ShapeDrift drift;
  check::OrderFlips flips;
  check::Popping pop;
  int64_t samples = 0, broken_at_rest = 0, overridden_at_rest = 0;
  // Coverings at rest the order does not keep, by feather id (covering, covered): cycles broken.
  std::vector<std::pair<uint64_t, uint64_t>> broken_examples;
  int previous_at = 0;
  if (layered) {
    const CoatView &view = *coat_view;
    broken_at_rest = int64_t(view.order.broken.size());
    overridden_at_rest = int64_t(view.order.overridden.size());
    broken_examples = broken_by_id(view.order, view.pipeline->coat().ids());
    const check::VaneOverlaps overlaps =
        check::vane_overlaps(file.mesh.positions, file.mesh.triangles, file.triangle_ids, skin, query);
    samples = overlaps.samples;
    order = check::layer_order_violations(overlaps, view.rank);
    const feathers::Coat &coat = view.pipeline->coat();
    const feathers::FeatherRanges ranges = coat.ranges();
    std::vector<Eigen::Vector3f> template_positions;
    template_positions.reserve(points.size());
    for (const size_t i : view.coat_index)
      for (int64_t v = ranges.first_vertex[i]; v < ranges.first_vertex[i + 1]; ++v)
        template_positions.push_back(view.rest.vanes.positions[size_t(v)]);
    const std::vector<float> lengths = per_file_feather<float>(view, [&](size_t i) {
      return coat.shapes()[i].main.calamus_length + coat.shapes()[i].main.rachis_length;
    });
    drift = check::shape_drift(file.mesh.positions, template_positions, file.first_vertex, lengths, file.feather_ids);
    if (!args.previous.empty()) {
      previous_at = args.previous_frame ? *args.previous_frame : at - 1;
      const Mesh previous_skin = posed_skin(*groom, previous_at);
      // A frame against the same vertices on the same skin (a frame against itself) has the same
      // overlaps: they are not measured twice.
      if (previous_at == at && before.mesh.positions == file.mesh.positions) {
        flips = check::order_flips(overlaps, overlaps);
      } else {
        const MeshQuery previous_query(previous_skin);
        const check::VaneOverlaps previous_overlaps = check::vane_overlaps(
            before.mesh.positions, before.mesh.triangles, before.triangle_ids, previous_skin, previous_query);
        flips = check::order_flips(previous_overlaps, overlaps);
      }
      const std::vector<float> widths =
          per_file_feather<float>(view, [&](size_t i) { return coat.shapes()[i].main.rachis_width; });
      pop = check::popping(before.mesh.positions, file.mesh.positions, file.first_vertex,
                           follicle_frames(view, previous_skin), follicle_frames(view, skin), widths, file.feather_ids);
    }
  }
  const bool compared = layered && !args.previous.empty();
  const bool meet = meets.feather_pairs > 0;
  const bool popped = compared && args.max_pop && pop.largest > *args.max_pop;
  const bool clean = below == 0 && !meet && order.violations == 0 && flips.flips == 0 && !popped;
  const int exit_code = args.strict && !clean ? kExitViolations : 0;
  std::vector<std::string> violations;
  if (below > 0) violations.push_back(std::to_string(below) + " points below the skin");
  if (meet) violations.push_back(std::to_string(meets.feather_pairs) + " feather pairs meet");
  if (order.violations > 0) violations.push_back(std::to_string(order.violations) + " layer-order violations");
  if (flips.flips > 0) violations.push_back(std::to_string(flips.flips) + " order flips");
  if (popped) {
    char text[128];
    std::snprintf(text, sizeof text, "popping %.4g rachis widths over the bound %g", pop.largest, *args.max_pop);
    violations.push_back(text);
  }

  if (args.json) {
    std::printf("{\"file\": %s, \"kind\": \"%s\", \"mesh\": %s, \"curves\": %zu, \"points\": %zu, ",
                json_quote(args.path).c_str(), vanes ? "vane mesh" : "feather curves", json_quote(skin_label).c_str(),
                curve_count, points.size());
    std::printf("\"inside_skin\": {\"points\": %zu, \"margin\": %.9g, \"deepest\": %.9g}, ", below, double(margin),
                double(deepest));
    if (vanes) {
      std::printf("\"feathers\": %zu, \"vane_pairs\": {\"feather_pairs\": %lld, \"intersecting_triangle_pairs\": %lld, "
                  "\"touching_triangle_pairs\": %lld, \"triangle_pairs_tested\": %lld, \"thickness\": %.9g, "
                  "\"examples\": %s}, ",
                  meets.feathers, (long long)meets.feather_pairs, (long long)meets.intersecting_triangle_pairs,
                  (long long)meets.touching_triangle_pairs, (long long)meets.triangle_pairs_tested, meets.thickness,
                  json_pairs([&] {
                    std::vector<std::pair<uint64_t, uint64_t>> pairs;
                    for (const check::VanePair &p : meets.examples) pairs.emplace_back(p.a, p.b);
                    return pairs;
                  }()).c_str());
    }
    if (layered) {
      std::printf("\"layer_order\": {\"overlapping_pairs\": %lld, \"violations\": %lld, \"unranked_pairs\": %lld, "
                  "\"samples\": %lld, \"broken_at_rest\": %lld, \"broken_examples\": %s, "
                  "\"overridden_at_rest\": %lld, \"examples\": %s}, ",
                  (long long)order.overlapping_pairs, (long long)order.violations, (long long)order.unranked_pairs,
                  (long long)samples, (long long)broken_at_rest, json_pairs(broken_examples).c_str(),
                  (long long)overridden_at_rest, json_pairs(order.examples).c_str());
      std::printf("\"shape_drift\": {\"mean_percent\": %.9g, \"max_percent\": %.9g, \"worst_feather\": %llu}, ",
                  100.0 * drift.mean, 100.0 * drift.largest, (unsigned long long)drift.worst_feather);
    }
    if (compared) {
      std::printf("\"previous\": {\"file\": %s, \"frame\": %d, \"order_flips\": {\"pairs_in_both\": %lld, \"flips\": "
                  "%lld, \"examples\": %s}, \"popping\": {\"largest_rachis_widths\": %.9g, \"largest_distance\": %.9g, "
                  "\"worst_feather\": %llu, \"mean_rachis_widths\": %.9g, \"bound\": ",
                  json_quote(args.previous).c_str(), previous_at, (long long)flips.pairs_in_both,
                  (long long)flips.flips, json_pairs(flips.examples).c_str(), pop.largest, pop.largest_distance,
                  (unsigned long long)pop.worst_feather, pop.mean);
      if (args.max_pop)
        std::printf("%.9g", *args.max_pop);
      else
        std::printf("null");
      std::printf(", \"over_bound\": %s}}, ", popped ? "true" : "false");
    }
    std::printf("\"violations\": [");
    for (size_t v = 0; v < violations.size(); ++v) std::printf("%s%s", v ? ", " : "", json_quote(violations[v]).c_str());
    std::printf("], \"clean\": %s, \"strict\": %s, \"exit_code\": %d}\n", clean ? "true" : "false",
                args.strict ? "true" : "false", exit_code);
    return exit_code;
  }
  if (vanes)
    std::printf("%s: vane mesh, %zu vertices, %zu triangles, against %s\n", args.path.c_str(), points.size(),
                triangle_count, skin_label.c_str());
  else
    std::printf("%s: feather curves, %zu curves, %zu points, against %s\n", args.path.c_str(), curve_count,
                points.size(), skin_label.c_str());
  std::printf("  points below the skin (margin %g): %zu (deepest %g)\n", double(margin), below, double(deepest));
  if (vanes) {
    std::printf("  feather pairs whose vanes meet: %lld of %zu feathers (%lld triangle pairs intersect, %lld touch "
                "within %g; %lld tested)\n",
                (long long)meets.feather_pairs, meets.feathers, (long long)meets.intersecting_triangle_pairs,
                (long long)meets.touching_triangle_pairs, meets.thickness, (long long)meets.triangle_pairs_tested);
    for (const check::VanePair &pair : meets.examples)
      std::printf("    feathers %llu and %llu\n", (unsigned long long)pair.a, (unsigned long long)pair.b);
  } else {
    std::printf("  feather against feather: judged on vane meshes\n");
  }
  if (layered) {
    std::printf("  layer order (frozen at rest; %lld coverings broken there in cycles%s%s; %lld reversed by the groom's "
                "order): %lld feather pairs overlap along the skin normal, %lld with a lower feather outside a higher "
                "one%s%s\n",
                (long long)broken_at_rest, broken_examples.empty() ? "" : ", covering/covered: ",
                text_pairs(broken_examples).c_str(), (long long)overridden_at_rest, (long long)order.overlapping_pairs,
                (long long)order.violations, order.examples.empty() ? "" : "  lower/higher: ",
                text_pairs(order.examples).c_str());
    std::printf("  shape drift from the rest shape: mean %.3g%%, largest %.3g%% of the feather's length (feather %llu)\n",
                100.0 * drift.mean, 100.0 * drift.largest, (unsigned long long)drift.worst_feather);
  } else if (vanes) {
    std::printf("  layer order and shape drift: not checked (give --groom)\n");
  }
  if (compared) {
    std::printf("  against %s (frame %d): %lld order flips of %lld pairs overlapping in both%s%s\n",
                args.previous.c_str(), previous_at, (long long)flips.flips, (long long)flips.pairs_in_both,
                flips.examples.empty() ? "" : "  outer before/now: ", text_pairs(flips.examples).c_str());
    std::printf("    popping: largest %.4g rachis widths (feather %llu, %g), mean %.4g", pop.largest,
                (unsigned long long)pop.worst_feather, pop.largest_distance, pop.mean);
    if (args.max_pop) std::printf("; bound %g", *args.max_pop);
    std::printf("\n");
  }
  std::printf("  %s\n", clean ? "clean" : "VIOLATIONS");
  return exit_code;
}

}  // namespace plume
