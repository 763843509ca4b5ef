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
#include "groom/error.h"
#include "io/groom_file.h"
#include "io/file_scan.h"
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
  if (groom.feathers.enabled)
    return run_feather_regrow(groom, {args.frames, args.out, args.vanes, args.preview, args.preview_every,
                                      args.preview_size, args.preview_guides, args.threads, args.strands,
                                      args.guides_cache});
  if (!args.vanes.empty()) throw InputError("--vanes: expected a feather groom (" + args.groom + " grows hair)");
  const FrameRange range = frames_to_produce(args.frames, groom);
  const std::string out = args.out.empty() ? groom.output.path_pattern : args.out;
  const std::string out_what = args.out.empty() ? groom.source + ": output.path" : "--out";
  check_output_pattern(out, range, out_what, kStrandExtensions);
  const PreviewSchedule previews(args.preview.empty() ? groom.output.preview_pattern : args.preview,
                                 args.preview_every >= 0 ? args.preview_every : groom.output.preview_every, range,
                                 args.preview.empty() ? groom.source + ": output.preview" : "--preview");
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

  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  std::vector<std::unique_ptr<Pipeline>> pipelines;
  for (const GroomDesc &group : groups) {
    pipelines.push_back(std::make_unique<Pipeline>(group, options));
    pipelines.back()->check_frame_inputs(range);
  }
  Pipeline &pipeline = *pipelines.front();
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  for (const std::string &pattern : patterns) remove_stale_temp_files(pattern, range);
  remove_stale_temp_files(previews.pattern(), range);

  io::StrandWriteOptions write_options;
  write_options.root_uvs = pipeline.root_uvs();
  write_options.fps = groom.dynamics.fps;
  write_options.meters_per_unit = groom.output.meters_per_unit;
  write_options.up_axis = groom.output.up_axis;
  write_options.comment = "plume regrow of " + groom.source;
  PreviewStyle style;
  style.size = preview_size;
  const PreviewCamera camera = groom_camera(pipeline);

  Progress progress("regrow", int(range.count()));
  std::vector<FrameResult> results(pipelines.size());
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    for (size_t g = 0; g < pipelines.size(); ++g) results[g] = pipelines[g]->produce(frame);
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
    const std::string preview = previews.path_at(i, frame);
    if (!preview.empty()) {
      std::vector<const StrandSet *> strands, guides;
      for (const FrameResult &result : results) {
        strands.push_back(&result.strands);
        guides.push_back(&result.guides);
      }
      const StrandSet all_guides = concatenate_strands(guides);
      write_png(preview, render_preview(camera, results[0].mesh, concatenate_strands(strands),
                                        args.preview_guides ? &all_guides : nullptr, style));
    }
    progress.frame_done(frame);
  }
  if (!stage.path.empty()) {
    std::vector<std::string> prims;
    for (const GroomDesc &group : groups) prims.push_back(grouped ? group.group_name : "hair");
    write_groom_stage(stage.path, out, stage.range, prims, groom);
  }
}

}  // namespace

void add_regrow_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<RegrowArgs>();
  CLI::App *cmd = app.add_subcommand("regrow", "Regrow the dense strands of a groom for a range of frames.");
  cmd->add_option("groom", args->groom, "Groom file (.yaml)")->required();
  cmd->add_option("--frames", args->frames, "Frames: 7, 1-48 or 1-240:2 (default: the groom's output.frames)");
  cmd->add_option("--out", args->out,
                  "Output path pattern, e.g. out/hair.####.usda or hair.%04d.ply; format from the extension "
                  "(.usda .hair .ply .obj) (default: the groom's output.path)");
  cmd->add_option("--vanes", args->vanes,
                  "Feather grooms: vane mesh pattern, e.g. out/vanes.####.obj (.usda .obj) (default: the groom's "
                  "output.vanes)");
  cmd->add_option("--preview", args->preview,
                  "Preview PNG pattern, e.g. out/preview.####.png (default: the groom's output.preview)");
  cmd->add_option("--preview-every", args->preview_every,
                  "Write a preview every N frames of the range (0: first frame only)")
      ->check(CLI::NonNegativeNumber);
  add_preview_size_option(*cmd, "--preview-size", args->preview_size, "Preview size in pixels (default 800)");
  cmd->add_flag("--preview-guides", args->preview_guides, "Draw the guides over the strands in the previews");
  add_threads_option(*cmd, args->threads, "Worker threads (default: all cores; output does not depend on it)");
  add_strands_option(*cmd, args->strands, "Override the groom's root count (a proxy of the full groom)");
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
  cmd->callback([args, &r_exit_code] {
    run_regrow(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
