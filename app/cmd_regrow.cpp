// `plume regrow GROOM --frames 1-48 --out out/hair.####.usda`: the batch job. Every frame is grown
// from the groom alone (and, with dynamics, from the simulation or the guide cache), so any frame or
// chunk of frames computed on any machine gives the same bytes.
#include <memory>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/run_outputs.h"
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
  bool out_given = false, vanes_given = false, preview_given = false;  // on the command line, even empty
  bool no_preview = false;
  bool skip_existing = false;
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
  const RunInputs inputs(groom, args.guides_cache);
  check_output_locations(out, range, out_what, inputs);
  previews.check_locations(range, inputs);
  const int preview_size = preview_size_of(args.preview_size, groom);
  set_thread_count(args.threads);

  RunSummary summary("regrow", range);
  const int strands_output = summary.add_output("strands", out);
  const int previews_output = summary.add_output("previews", previews.pattern());
  // With --skip-existing, a frame whose files are all there (complete: they are renamed into place
  // whole) is not regrown.
  std::vector<bool> done_already(size_t(range.count()), false);
  int64_t to_grow = range.count();
  if (args.skip_existing)
    for (int64_t i = 0; i < range.count(); ++i) {
      const int frame = range.at(i);
      done_already[size_t(i)] = outputs_complete({expand_frame_pattern(out, frame), previews.path_at(i, frame)});
      to_grow -= done_already[size_t(i)] ? 1 : 0;
    }

  std::unique_ptr<Pipeline> pipeline;
  if (to_grow > 0) {
    PipelineOptions options;
    options.strand_count = args.strands;
    options.guides_cache = args.guides_cache;
    options.simulation_start = std::min(groom_first_frame(groom), range.first);
    pipeline = std::make_unique<Pipeline>(groom, options);
    pipeline->check_frame_inputs(range);
  }
  // What runs killed by SIGKILL left of these outputs goes, now that the run is known to start.
  remove_stale_temp_files(out, range);
  remove_stale_temp_files(previews.pattern(), range);

  io::StrandWriteOptions write_options;
  PreviewStyle style;
  style.size = preview_size;
  PreviewCamera camera;
  if (pipeline) {
    write_options.root_uvs = pipeline->root_uvs();
    write_options.fps = groom.dynamics.fps;
    write_options.comment = "plume regrow of " + groom_file_name(groom);
    camera = groom_camera(*pipeline);
  }

  Progress progress("regrow", int(to_grow));
  for (int64_t i = 0; i < range.count(); ++i) {
    const int frame = range.at(i);
    const std::string path = expand_frame_pattern(out, frame);
    const std::string preview_path = previews.path_at(i, frame);
    if (done_already[size_t(i)]) {
      summary.kept(strands_output, path);
      if (!preview_path.empty()) summary.kept(previews_output, preview_path);
      continue;
    }
    // Later frames of a simulation step through the skipped ones.
    const FrameResult result = pipeline->produce(frame);
    write_options.time_code = frame;
    io::write_strands(path, result.strands, write_options);
    summary.wrote(strands_output, path);
    if (!preview_path.empty()) {
      write_png(preview_path, render_preview(camera, result.mesh, result.strands,
                                             args.preview_guides ? &result.guides : nullptr, style));
      summary.wrote(previews_output, preview_path);
    }
    progress.frame_done(frame);
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
  cmd->callback([args, out_option, vanes_option, preview_option, &r_exit_code] {
    args->out_given = out_option->count() > 0;
    args->vanes_given = vanes_option->count() > 0;
    args->preview_given = preview_option->count() > 0;
    run_regrow(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
