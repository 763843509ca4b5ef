// `plume preview GROOM --frame N --out x.png`: one picture of a groom at one frame.
#include <memory>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/pipeline.h"
#include "groom/error.h"
#include "io/groom_file.h"

namespace plume {

namespace {

struct PreviewArgs {
  std::string groom;
  int frame = 1;
  std::string out;
  int size = 800;
  bool guides = false;
  int threads = 0;
  int64_t strands = -1;
  std::string guides_cache;
};

void run_preview(const PreviewArgs &args) {
  const GroomDesc groom = io::read_groom_file(args.groom);
  const FrameRange single{args.frame, args.frame, 1};
  check_output_pattern(args.out, single, "--out", {".png"});
  check_output_locations(args.out, single, "--out", RunInputs(groom, args.guides_cache));
  if (groom.feathers.enabled)
    return run_feather_preview(groom, args.frame, args.out, args.size, args.guides, args.threads, args.strands,
                               args.guides_cache);
  set_thread_count(args.threads);
  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), args.frame);
  Pipeline pipeline(groom, options);
  pipeline.check_frame_inputs(single);
  remove_stale_temp_files(args.out, single);  // what a run killed by SIGKILL left of this picture
  const FrameResult result = pipeline.produce(args.frame);
  PreviewStyle style;
  style.size = args.size;
  write_png(expand_frame_pattern(args.out, args.frame),
            render_preview(groom_camera(pipeline), result.mesh, result.strands, args.guides ? &result.guides : nullptr,
                           style, groom_scalp(pipeline)));
}

}  // namespace

void add_preview_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<PreviewArgs>();
  CLI::App *cmd = app.add_subcommand("preview", "Render a preview PNG of a groom at one frame.");
  cmd->add_option("groom", args->groom, "Groom file (.yaml)")->required();
  cmd->add_option("--frame", args->frame, "Frame to render (default 1)")->check(CLI::Range(-kMaxFrame, kMaxFrame));
  cmd->add_option("--out", args->out, "Output PNG (a #### field is replaced by the frame)")->required();
  add_preview_size_option(*cmd, "--size", args->size, "Image size in pixels (square, default 800)");
  cmd->add_flag("--guides", args->guides, "Draw the guides over the strands in a bright colour");
  add_threads_option(*cmd, args->threads, "Worker threads");
  add_strands_option(*cmd, args->strands, "Override the groom's root count");
  cmd->add_option("--guides-cache", args->guides_cache, "Dynamics: read the guides from this cache pattern");
  cmd->callback([args, &r_exit_code] {
    run_preview(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
