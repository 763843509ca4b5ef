// `plume regrow GROOM --frames 1-48 --out out/hair.####.usda`: the batch job. Every frame is grown
// from the groom alone (and, with dynamics, from the simulation or the guide cache), so any frame or
// chunk of frames computed on any machine gives the same bytes.
#include <filesystem>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/groom_outputs.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/run_outputs.h"
#include "groom/error.h"
#include "io/file_scan.h"
#include "io/groom_file.h"
#include "io/strand_file.h"
#include "io/usda_stage.h"

namespace plume {

namespace {

struct RegrowArgs {
  std::string groom;
  std::string frames;
  std::string out;
  std::string vanes;
  std::string preview;
  bool out_given = false, vanes_given = false, preview_given = false;  // on the command line, even empty
  bool no_preview = false;
  bool skip_existing = false;
  int preview_every = -1;
  int preview_size = 0;
  bool preview_guides = false;
  int threads = 0;
  int64_t strands = -1;
  std::string guides_cache;
  std::string stage;
  std::string stage_frames;
  bool no_stage = false;
};

const std::vector<std::string> kStrandExtensions = {".usda", ".hair", ".ply", ".obj"};

/// The top-level USD stage a run writes: its path (empty: none), the option or key that named it,
/// and the frames it spans.
struct StageRun {
  std::string path;
  std::string what;
  FrameRange range;
};

/// A .usda output sequence gets a stage: --stage, else the groom's output.stage, else the pattern
/// without its frame field; none with --no-stage or another format. Throws InputError when the
/// stage would be one of the frame files or its manifest.
StageRun stage_run(const RegrowArgs &args, const std::string &out, const FrameRange &range, const GroomDesc &groom) {
  StageRun stage;
  if (args.no_stage || io::detail::extension_of(out) != ".usda") return stage;
  if (!args.stage.empty()) {
    stage.what = "--stage";
    stage.path = args.stage;
  } else if (!groom.output.stage_path.empty()) {
    stage.what = groom.source + ": output.stage";
    stage.path = groom.output.stage_path;
  } else {
    stage.what = "--out";
    stage.path = default_stage_path(out);
  }
  if (stage.path.empty()) return stage;
  if (io::detail::extension_of(stage.path) != ".usda")
    throw InputError(stage.what + ": expected a stage path ending in .usda, got \"" + stage.path + "\"");
  if (has_frame_field(stage.path))
    throw InputError(stage.what + ": expected a stage path without a frame field, got \"" + stage.path + "\"");
  stage.range = stage_frames(args.stage_frames, groom, range);
  const std::string manifest = io::usd_manifest_path(stage.path);
  for (const std::string &path : {stage.path, manifest}) {
    const std::optional<int> frame = frame_in_file_name(out, path);
    if (frame && std::filesystem::path(expand_frame_pattern(out, *frame)).lexically_normal() ==
                     std::filesystem::path(path).lexically_normal())
      throw InputError(stage.what + ": the stage " + path + " would be the file of frame " + std::to_string(*frame) +
                       " (choose another --stage)");
  }
  return stage;
}

void run_regrow(const RegrowArgs &args) {
  const GroomDesc groom = io::read_groom_file(args.groom);
  // The outputs: the command line's as given, else the groom's (relative to the groom file), which a
  // proxy run (--strands) renames so that it never overwrites the full groom's files.
  const bool proxy = args.strands >= 0;
  const auto groom_output = [&](const std::string &pattern, bool given) {
    return proxy && !given && !pattern.empty() ? proxy_pattern(pattern, args.strands) : pattern;
  };
  const std::string out =
      groom_output(chosen_output(args.out, args.out_given, "--out", groom.output.path_pattern), args.out_given);
  const std::string out_what = args.out_given ? "--out" : groom.source + ": output.path";
  std::string preview_what;
  const std::string preview = groom_output(chosen_preview(args.preview, args.preview_given, args.no_preview,
                                                          groom.output.preview_pattern, groom.source + ": output.preview",
                                                          preview_what),
                                           args.preview_given);
  if (groom.feathers.enabled) {
    const std::string vanes =
        groom_output(chosen_output(args.vanes, args.vanes_given, "--vanes", groom.output.vanes_pattern), args.vanes_given);
    return run_feather_regrow(groom, {args.frames, out, out_what, vanes,
                                      args.vanes_given ? "--vanes" : groom.source + ": output.vanes", preview,
                                      preview_what, args.preview_every, args.preview_size, args.preview_guides,
                                      args.threads, args.strands, args.guides_cache, args.skip_existing});
  }
  if (args.vanes_given) throw InputError("--vanes: expected a feather groom (" + args.groom + " grows hair)");
  const FrameRange range = frames_to_produce(args.frames, groom);
  check_output_pattern(out, range, out_what, kStrandExtensions);
  const PreviewSchedule previews(preview, args.preview_every >= 0 ? args.preview_every : groom.output.preview_every,
                                 range, preview_what);
  // Hair groups: one BasisCurves prim each in a .usda, one file each in the other formats.
  const std::vector<GroomDesc> groups = hair_groups(groom);
  const bool grouped = !groom.groups.empty();
  const bool usda = io::detail::extension_of(out) == ".usda";
  if (grouped && !args.guides_cache.empty())
    throw InputError("--guides-cache: a guide cache holds one group's guides; " + args.groom +
                     " has hair groups, which regrow simulates themselves");
  std::vector<std::string> patterns;
  if (grouped && !usda) {
    for (const GroomDesc &group : groups) patterns.push_back(group_file_pattern(out, group.group_name));
  } else {
    patterns.push_back(out);
  }
  const StageRun stage = stage_run(args, out, range, groom);
  for (const GroomDesc &group : groups) {
    const RunInputs inputs(group, args.guides_cache);
    for (const std::string &pattern : patterns) check_output_locations(pattern, range, out_what, inputs);
    previews.check_locations(range, inputs);
    if (!stage.path.empty()) {
      const FrameRange once{stage.range.first, stage.range.first, 1};
      check_output_locations(stage.path, once, stage.what, inputs);
      check_output_locations(io::usd_manifest_path(stage.path), once, stage.what, inputs);
    }
  }
  const int preview_size = preview_size_of(args.preview_size, groom);
  set_thread_count(args.threads);

  RunSummary summary("regrow", range);
  std::vector<int> strands_outputs;
  for (const std::string &pattern : patterns) strands_outputs.push_back(summary.add_output("strands", pattern));
  const int previews_output = summary.add_output("previews", previews.pattern());
  const int stage_output = stage.path.empty() ? -1 : summary.add_output("stage", stage.path);
  // With --skip-existing, a frame whose files are all there (complete: they are renamed into place
  // whole) is not regrown.
  std::vector<bool> done_already(size_t(range.count()), false);
  int64_t to_grow = range.count();
  if (args.skip_existing)
    for (int64_t i = 0; i < range.count(); ++i) {
      const int frame = range.at(i);
      std::vector<std::string> files{previews.path_at(i, frame)};
      for (const std::string &pattern : patterns) files.push_back(expand_frame_pattern(pattern, frame));
      done_already[size_t(i)] = outputs_complete(files);
      to_grow -= done_already[size_t(i)] ? 1 : 0;
    }

  std::vector<std::unique_ptr<Pipeline>> pipelines;
  if (to_grow > 0) {
    PipelineOptions options;
    options.strand_count = args.strands;
    options.guides_cache = args.guides_cache;
    options.simulation_start = std::min(groom_first_frame(groom), range.first);
    for (const GroomDesc &group : groups) {
      pipelines.push_back(std::make_unique<Pipeline>(group, options));
      pipelines.back()->check_frame_inputs(range);
    }
  }
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  for (const std::string &pattern : patterns) remove_stale_temp_files(pattern, range);
  remove_stale_temp_files(previews.pattern(), range);

  io::StrandWriteOptions write_options;
  PreviewStyle style;
  style.size = preview_size;
  PreviewCamera camera;
  if (!pipelines.empty()) {
    write_options.root_uvs = pipelines.front()->root_uvs();
    write_options.fps = groom.dynamics.fps;
    write_options.meters_per_unit = groom.output.meters_per_unit;
    write_options.up_axis = groom.output.up_axis;
    write_options.comment = "plume regrow of " + groom_file_name(groom);
    camera = groom_camera(*pipelines.front());
  }

  Progress progress("regrow", int(to_grow));
  std::vector<FrameResult> results(pipelines.size());
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    const std::string preview_path = previews.path_at(i, frame);
    if (done_already[size_t(i)]) {
      for (size_t p = 0; p < patterns.size(); ++p)
        summary.kept(strands_outputs[p], expand_frame_pattern(patterns[p], frame));
      if (!preview_path.empty()) summary.kept(previews_output, preview_path);
      continue;
    }
    // Later frames of a simulation step through the skipped ones.
    for (size_t g = 0; g < pipelines.size(); ++g) {
      results[g] = pipelines[g]->produce(frame);
      if (results[g].unseparated_pairs > 0)
        std::fprintf(stderr,
                     "plume: warning: frame %d%s%s: the separation pass left %lld segment pairs nearer than plume "
                     "check's crossing tolerance (plume check reports them; docs/interpolation.md, \"The separation "
                     "pass\")\n",
                     frame, grouped ? ", group " : "", grouped ? groups[g].group_name.c_str() : "",
                     static_cast<long long>(results[g].unseparated_pairs));
    }
    write_options.time_code = frame;
    if (!grouped) {
      io::write_strands(expand_frame_pattern(out, frame), results[0].strands, write_options);
    } else if (usda) {
      std::vector<io::StrandGroup> written(groups.size());
      for (size_t g = 0; g < groups.size(); ++g)
        written[g] = {groups[g].group_name, &results[g].strands, pipelines[g]->root_uvs(), int32_t(g)};
      io::write_strand_groups(expand_frame_pattern(out, frame), written, write_options);
    } else {
      for (size_t g = 0; g < groups.size(); ++g) {
        write_options.root_uvs = pipelines[g]->root_uvs();
        io::write_strands(expand_frame_pattern(patterns[g], frame), results[g].strands, write_options);
      }
    }
    for (size_t p = 0; p < patterns.size(); ++p) summary.wrote(strands_outputs[p], expand_frame_pattern(patterns[p], frame));
    if (!preview_path.empty()) {
      std::vector<const StrandSet *> strands, guides;
      for (const FrameResult &result : results) {
        strands.push_back(&result.strands);
        guides.push_back(&result.guides);
      }
      const StrandSet all_guides = concatenate_strands(guides);
      write_png(preview_path, render_preview(camera, results[0].mesh, concatenate_strands(strands),
                                             args.preview_guides ? &all_guides : nullptr, style));
      summary.wrote(previews_output, preview_path);
    }
    progress.frame_done(frame);
  }
  if (!stage.path.empty()) {
    std::vector<std::string> prims;
    for (const GroomDesc &group : groups) prims.push_back(grouped ? group.group_name : "hair");
    write_groom_stage(stage.path, out, stage.range, prims, groom);
    summary.wrote(stage_output, stage.path);
  }
  progress.finish();
  summary.print();
}

}  // namespace

void add_regrow_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<RegrowArgs>();
  CLI::App *cmd = app.add_subcommand("regrow", "Regrow the dense strands of a groom for a range of frames.");
  cmd->add_option("groom", args->groom, "Groom file (.yaml)")->required();
  cmd->add_option("--frames", args->frames, "Frames: 7, 1-48, 1-240:2 or 1-240x2 (default: the groom's output.frames)")
      ->check(non_empty_frames());
  CLI::Option *out_option = cmd->add_option("--out", args->out,
                  "Output path pattern, e.g. out/hair.####.usda, hair.%04d.ply or hair.$F4.hair; format from the extension "
                  "(.usda .hair .ply .obj) (default: the groom's output.path)");
  CLI::Option *vanes_option = cmd->add_option("--vanes", args->vanes,
                  "Feather grooms: vane mesh pattern, e.g. out/vanes.####.obj (.usda .obj) (default: the groom's "
                  "output.vanes)");
  CLI::Option *preview_option =
      cmd->add_option("--preview", args->preview,
                      "Preview PNG pattern, e.g. out/preview.####.png (default: the groom's output.preview)");
  cmd->add_flag("--no-preview", args->no_preview, "Write no preview (not even the groom's output.preview)")
      ->excludes(preview_option);
  cmd->add_option("--preview-every", args->preview_every,
                  "Write a preview every N frames of the range (0: first frame only)")
      ->check(CLI::NonNegativeNumber);
  add_preview_size_option(*cmd, "--preview-size", args->preview_size, "Preview size in pixels (default 800)");
  cmd->add_flag("--preview-guides", args->preview_guides, "Draw the guides over the strands in the previews");
  add_threads_option(*cmd, args->threads, "Worker threads (default: all cores; output does not depend on it)");
  add_strands_option(*cmd, args->strands,
                     "Override the groom's root count (a proxy of the full groom; the groom's output names get "
                     "_proxyN, e.g. hair_proxy3000.####.usda)");
  cmd->add_flag("--skip-existing", args->skip_existing,
                "Regrow only the frames whose files are missing (a rerun after a crash or a preempted task)");
  cmd->add_option("--guides-cache", args->guides_cache,
                  "Dynamics: read the simulated guides of every frame from this cache (written by plume simulate), "
                  "e.g. cache/guides.####.hair");
  cmd->add_option("--stage", args->stage,
                  "USD: the top-level stage that composes a .usda sequence as one animated groom (value clips) "
                  "(default: the groom's output.stage, else --out without its frame field: out/hair.usda)");
  cmd->add_option("--stage-frames", args->stage_frames,
                  "USD: the frames the stage spans (default: the groom's output.frames, else --frames); farm "
                  "chunks of one shot give the same stage");
  cmd->add_flag("--no-stage", args->no_stage, "USD: write the per-frame layers only, no stage");
  cmd->callback([args, out_option, vanes_option, preview_option, &r_exit_code] {
    args->out_given = out_option->count() > 0;
    args->vanes_given = vanes_option->count() > 0;
    args->preview_given = preview_option->count() > 0;
    run_regrow(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
