// `plume regrow GROOM --frames 1-48 --out out/hair.####.usda`: the batch job. Every frame is grown
// from the groom alone (and, with dynamics, from the simulation or the guide cache), so any frame or
// chunk of frames computed on any machine gives the same bytes.
#include <memory>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "groom/error.h"
#include "io/groom_file.h"
#include "io/strand_file.h"

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
};

const std::vector<std::string> kStrandExtensions = {".usda", ".hair", ".ply", ".obj"};

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
  const RunInputs inputs(groom, args.guides_cache);
  check_output_locations(out, range, out_what, inputs);
  previews.check_locations(range, inputs);
  const int preview_size = preview_size_of(args.preview_size, groom);
  set_thread_count(args.threads);

  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  Pipeline pipeline(groom, options);
  pipeline.check_frame_inputs(range);
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  remove_stale_temp_files(out, range);
  remove_stale_temp_files(previews.pattern(), range);

  io::StrandWriteOptions write_options;
  write_options.root_uvs = pipeline.root_uvs();
  write_options.fps = groom.dynamics.fps;
  write_options.comment = "plume regrow of " + groom.source;
  PreviewStyle style;
  style.size = preview_size;
  const PreviewCamera camera = groom_camera(pipeline);

  Progress progress("regrow", int(range.count()));
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    const FrameResult result = pipeline.produce(frame);
    write_options.time_code = frame;
    io::write_strands(expand_frame_pattern(out, frame), result.strands, write_options);
    const std::string preview = previews.path_at(i, frame);
    if (!preview.empty())
      write_png(preview, render_preview(camera, result.mesh, result.strands,
                                        args.preview_guides ? &result.guides : nullptr, style));
    progress.frame_done(frame);
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
  cmd->callback([args, &r_exit_code] {
    run_regrow(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
