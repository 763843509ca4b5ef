#include "app/feather_commands.h"

#include <cstdio>
#include <memory>

#include "app/commands.h"
#include "app/feather_pipeline.h"
#include "app/feather_preview.h"
#include "app/progress.h"
#include "app/run_outputs.h"
#include "check/vanes.h"
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
    pipeline->base().check_frame_inputs(range);
    write_options = pipeline->write_options();
    if (!previews.pattern().empty())
      camera = feather_camera(pipeline->base().rest_mesh(), pipeline->rest_frame().curves.curves);
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
  pipeline.base().check_frame_inputs(single);
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

int run_feather_check(const std::string &path, const std::string &mesh_path, const std::string &groom_path,
                      std::optional<int> frame, float margin, bool strict, bool json) {
  Mesh skin;
  std::string skin_label;
  if (!groom_path.empty()) {
    const GroomDesc groom = io::read_groom_file(groom_path);
    const int at = frame ? *frame : groom_first_frame(groom);
    skin = posed_emitter(groom, io::read_obj_mesh(groom.emitter_path), at);
    skin_label = groom.emitter_path + " posed at frame " + std::to_string(at);
  } else {
    skin = io::read_obj_mesh(mesh_path);
    skin_label = mesh_path;
  }
  const MeshQuery query(skin);
  Eigen::AlignedBox3f box;
  for (const Eigen::Vector3f &p : skin.positions) box.extend(p);
  const float eps = 1e-5f * box.diagonal().norm();
  // Vane meshes: every vertex; curves: every point, a curve's first point (on the skin or the
  // rachis) allowed down to -eps.
  std::vector<Eigen::Vector3f> points;
  std::vector<bool> first;
  const bool vanes = is_vane_mesh_file(path) || io::detail::extension_of(path) == ".obj";
  size_t curve_count = 0, triangle_count = 0;
  check::VaneCheckReport meets;
  if (vanes) {
    const Mesh mesh = io::read_vane_mesh(path);
    points = mesh.positions;
    first.assign(points.size(), false);
    triangle_count = mesh.triangle_count();
    meets = check::check_vanes(mesh.positions, mesh.triangles, vane_feather_ids(mesh));
  } else {
    const StrandSet curves = io::read_strands(path);
    points = curves.positions;
    first.assign(points.size(), false);
    for (size_t c = 0; c < curves.strand_count(); ++c) first[size_t(curves.offsets[c])] = true;
    curve_count = curves.strand_count();
  }
  size_t below = 0;
  float deepest = 0.0f;
#pragma omp parallel for schedule(static) reduction(+ : below) reduction(min : deepest)
  for (int64_t v = 0; v < int64_t(points.size()); ++v) {
    const float d = query.signed_distance(points[size_t(v)]);
    if (d < (first[size_t(v)] ? 0.0f : margin) - eps) ++below;
    deepest = std::min(deepest, d);
  }
  const bool meet = meets.feather_pairs > 0;
  const int exit_code = strict && (below > 0 || meet) ? kExitViolations : 0;
  if (json) {
    auto quote = [](const std::string &text) {
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
    };
    std::printf("{\"file\": %s, \"kind\": \"%s\", \"mesh\": %s, \"curves\": %zu, \"points\": %zu, ", quote(path).c_str(),
                vanes ? "vane mesh" : "feather curves", quote(skin_label).c_str(), curve_count, points.size());
    std::printf("\"inside_skin\": {\"points\": %zu, \"margin\": %.9g, \"deepest\": %.9g}, ", below, double(margin),
                double(deepest));
    if (vanes) {
      std::printf("\"feathers\": %zu, \"vane_pairs\": {\"feather_pairs\": %lld, \"intersecting_triangle_pairs\": %lld, "
                  "\"touching_triangle_pairs\": %lld, \"triangle_pairs_tested\": %lld, \"thickness\": %.9g, "
                  "\"examples\": [",
                  meets.feathers, (long long)meets.feather_pairs, (long long)meets.intersecting_triangle_pairs,
                  (long long)meets.touching_triangle_pairs, (long long)meets.triangle_pairs_tested, meets.thickness);
      for (size_t e = 0; e < meets.examples.size(); ++e)
        std::printf("%s[%llu, %llu]", e ? ", " : "", (unsigned long long)meets.examples[e].a,
                    (unsigned long long)meets.examples[e].b);
      std::printf("]}, ");
    }
    std::printf("\"violations\": [");
    if (below > 0) std::printf("\"%zu points below the skin\"%s", below, meet ? ", " : "");
    if (meet) std::printf("\"%lld feather pairs meet\"", (long long)meets.feather_pairs);
    std::printf("], \"clean\": %s, \"strict\": %s, \"exit_code\": %d}\n", below == 0 && !meet ? "true" : "false",
                strict ? "true" : "false", exit_code);
    return exit_code;
  }
  if (vanes)
    std::printf("%s: vane mesh, %zu vertices, %zu triangles, against %s\n", path.c_str(), points.size(), triangle_count,
                skin_label.c_str());
  else
    std::printf("%s: feather curves, %zu curves, %zu points, against %s\n", path.c_str(), curve_count, points.size(),
                skin_label.c_str());
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
  std::printf("  %s\n", below == 0 && !meet ? "clean" : "VIOLATIONS");
  return exit_code;
}

}  // namespace plume
