// `plume simulate GROOM --frames 1-48 --cache cache/guides.####.hair`: runs the guide dynamics over
// the range (sequential in time) and writes the simulated guides of every frame, so that dense
// regrowth (`plume regrow --guides-cache`) can then run per frame or per chunk, anywhere. A feather
// groom's coat also runs its skin pass (and, with layers, its layering pass), whose state of every
// frame goes beside the cache (the next frame's warm start: io/feather_lifts.h).
#include <memory>

#include "app/commands.h"
#include "app/feather_pipeline.h"
#include "app/groom_outputs.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/run_outputs.h"
#include "groom/error.h"
#include "io/feather_lifts.h"
#include "io/groom_file.h"

namespace plume {

namespace {

struct SimulateArgs {
  std::string groom;
  std::string frames;
  std::string cache;
  std::string preview;
  bool cache_given = false, preview_given = false;  // on the command line, even empty
  bool no_preview = false;
  int preview_every = 0;
  int preview_size = 0;
  int threads = 0;
};

void run_simulate(const SimulateArgs &args) {
  const GroomDesc groom = io::read_groom_file(args.groom);
  require_one_group(groom, "plume simulate");
  if (!groom.dynamics.enabled)
    throw InputError(groom.dynamics_loc(), "dynamics.enabled: expected true for plume simulate (the groom has no "
                                           "dynamics: its guides only follow the skin)");
  const FrameRange range = frames_to_produce(args.frames, groom);
  const std::string cache = chosen_output(args.cache, args.cache_given, "--cache", groom.dynamics.cache_pattern);
  const std::string cache_what = args.cache_given ? "--cache" : groom.source + ": dynamics.cache";
  check_output_pattern(cache, range, cache_what, {".hair", ".usda", ".ply", ".obj"});
  std::string preview_what;
  const PreviewSchedule previews(chosen_preview(args.preview, args.preview_given, args.no_preview, {}, {}, preview_what),
                                 args.preview_every, range, preview_what);
  const RunInputs inputs(groom, {});
  check_output_locations(cache, range, cache_what, inputs);
  previews.check_locations(range, inputs);
  const int preview_size = preview_size_of(args.preview_size, groom);
  set_thread_count(args.threads);

  PipelineOptions options;
  options.strand_count = 0;  // guides only: no dense roots are needed
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  // A feather groom whose frames carry a state (the skin pass lifts feathers, or the coat has layers):
  // its whole coat, for that state.
  std::unique_ptr<FeatherPipeline> coat;
  std::unique_ptr<Pipeline> guides_only;
  std::string lifts;
  if (groom.feathers.enabled && (groom.feathers.lift || groom.feathers.layers)) {
    PipelineOptions coat_options = options;
    coat_options.strand_count = -1;
    coat = std::make_unique<FeatherPipeline>(groom, coat_options);
    coat->check_frame_inputs(range);
    lifts = io::feather_lifts_pattern(cache);
    check_output_locations(lifts, range, cache_what + " (its feather lifts)", inputs);
  } else {
    guides_only = std::make_unique<Pipeline>(groom, options);
    guides_only->check_frame_inputs(range);
  }
  Pipeline &pipeline = coat ? coat->base() : *guides_only;
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  remove_stale_temp_files(cache, range);
  if (!lifts.empty()) remove_stale_temp_files(lifts, range);
  remove_stale_temp_files(previews.pattern(), range);
  PreviewStyle style;
  style.size = preview_size;
  const PreviewCamera camera = groom_camera(pipeline);
  const StrandSet no_strands;
  RunSummary summary("simulate", range);
  const int cache_output = summary.add_output("guide cache", cache);
  const int lifts_output = lifts.empty() ? -1 : summary.add_output("feather lifts", lifts);
  const int previews_output = summary.add_output("previews", previews.pattern());

  Progress progress("simulate", int(range.count()));
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    Mesh posed;
    StrandSet guides;
    io::FeatherLifts state;
    if (coat) {
      FeatherPipeline::StateFrame grown = coat->carried(frame);
      posed = std::move(grown.mesh);
      guides = std::move(grown.stems);
      state = coat->lifts_record(frame, grown.state);
    } else {
      posed = pipeline.posed_mesh(frame);
      guides = pipeline.guides_at(frame, posed);
    }
    const std::string path = expand_frame_pattern(cache, frame);
    write_guide_cache(path, guides, frame);
    summary.wrote(cache_output, path);
    if (coat) {
      const std::string lifts_path = expand_frame_pattern(lifts, frame);
      io::write_feather_lifts(lifts_path, state);
      summary.wrote(lifts_output, lifts_path);
    }
    const std::string preview = previews.path_at(i, frame);
    if (!preview.empty()) {
      write_png(preview, render_preview(camera, posed, no_strands, &guides, style));
      summary.wrote(previews_output, preview);
    }
    progress.frame_done(frame);
  }
  progress.finish();
  summary.print();
}

}  // namespace

void add_simulate_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App *cmd = app.add_subcommand("simulate", "Simulate the guides of a groom with dynamics and write a guide cache.");
  cmd->add_option("groom", args->groom, "Groom file (.yaml) with dynamics.enabled: true")->required();
  cmd->add_option("--frames", args->frames, "Frames: 1-48, 1-240:2 or 1-240x2 (default: the groom's output.frames)")
      ->check(non_empty_frames());
  CLI::Option *cache_option = cmd->add_option("--cache", args->cache,
                  "Guide cache pattern, one file per frame: cache/guides.####.hair (or .usda) "
                  "(default: the groom's dynamics.cache)");
  CLI::Option *preview_option =
      cmd->add_option("--preview", args->preview, "PNG pattern showing the guides, e.g. out/guides.####.png");
  cmd->add_flag("--no-preview", args->no_preview, "Write no preview (the default)")->excludes(preview_option);
  cmd->add_option("--preview-every", args->preview_every, "Write a preview every N frames (0: first frame only)")
      ->check(CLI::NonNegativeNumber);
  add_preview_size_option(*cmd, "--preview-size", args->preview_size, "Preview size in pixels (default 800)");
  add_threads_option(*cmd, args->threads, "Worker threads (output does not depend on it)");
  cmd->callback([args, cache_option, preview_option, &r_exit_code] {
    args->cache_given = cache_option->count() > 0;
    args->preview_given = preview_option->count() > 0;
    run_simulate(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
