// `plume preview GROOM --frame N --out x.png`: one picture of a groom at one frame, from a chosen
// camera or as a turntable sheet, coloured plain, by attribute or by the checker's problems.
#include <cmath>
#include <cstdio>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "app/groom_outputs.h"
#include "app/feather_commands.h"
#include "app/pipeline.h"
#include "app/run_outputs.h"
#include "app/strand_colors.h"
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
  std::string camera = "three-quarter";
  int turntable = 0;
  int columns = 0;
  std::string color = "plain";
  float tolerance = 0.0f;
  float margin = 0.0f;
  int threads = 0;
  int64_t strands = -1;
  std::string guides_cache;
};

/// Columns of a turntable sheet of `count` pictures: about twice as wide as tall, one row up to 4.
int sheet_columns(int count) {
  const int rows = std::max(1, int(std::lround(std::sqrt(double(count) / 2.0))));
  return (count + rows - 1) / rows;
}

void run_preview(const PreviewArgs &args) {
  const CameraAngle angle = parse_camera_angle(args.camera, "--camera");
  const ColorMode mode = parse_color_mode(args.color, "--color");
  const int views = std::max(args.turntable, 1);
  const int columns = args.turntable > 0 ? std::min(args.columns > 0 ? args.columns : sheet_columns(views), views) : 1;
  const int rows = (views + columns - 1) / columns;
  if (double(columns) * double(args.size) * double(rows) * double(args.size) >
      double(max_preview_size) * double(max_preview_size))
    throw InputError("--turntable " + std::to_string(args.turntable) + ": " + std::to_string(columns) + " x " +
                     std::to_string(rows) + " pictures of " + std::to_string(args.size) +
                     " pixels exceed the largest picture, " + std::to_string(max_preview_size) + " x " +
                     std::to_string(max_preview_size) + " pixels (give a smaller --size)");

  const GroomDesc groom = io::read_groom_file(args.groom);
  require_one_group(groom, "plume preview");
  const FrameRange single{args.frame, args.frame, 1};
  RunSummary summary("preview", single);
  check_output_pattern(args.out, single, "--out", {".png"});
  check_output_locations(args.out, single, "--out", RunInputs(groom, args.guides_cache));
  const std::string path = expand_frame_pattern(args.out, args.frame);
  const auto done = [&] {
    summary.wrote(summary.add_output("preview", args.out), path);
    summary.print();
  };
  if (groom.feathers.enabled) {
    if (mode != ColorMode::plain)
      throw InputError("--color " + args.color + ": a feather groom's preview is drawn plain (colours by guide, " +
                       "clump, zone and problems are for hair strands)");
    run_feather_preview(groom, args.frame, path, args.size, args.guides, args.threads, args.strands, args.guides_cache,
                        {angle, args.turntable, columns});
    done();
    return;
  }
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
  StrandPaint paint;
  if (mode != ColorMode::plain) {
    StrandProblems problems;
    if (mode == ColorMode::problems) {
      ProblemOptions check;
      check.crossing_tolerance = args.tolerance;
      check.skin_margin = args.margin;
      // As plume check --groom: the crossings of a groom with effects are judged before them.
      std::optional<StrandSet> before_effects;
      if (!groom.effects.empty()) before_effects = pipeline.produce(args.frame, false).strands;
      try {
        problems = find_problems(result.strands, result.mesh, check, before_effects ? &*before_effects : nullptr);
      } catch (const InputError &e) {
        if (!(args.tolerance > 0.0f)) throw;
        char tolerance[32];
        std::snprintf(tolerance, sizeof tolerance, "%g", double(args.tolerance));
        throw InputError(std::string("--tolerance ") + tolerance + ": " + e.what());
      }
      paint.on_top.resize(problems.flags.size());
      for (size_t s = 0; s < problems.flags.size(); ++s) paint.on_top[s] = problem_is_violation(problems.flags[s]);
      std::printf("frame %d: %zu points inside the skin (margin %g) in %zu strands; crossing strand pairs%s "
                  "(tolerance %g): %zu transversal, %zu touching; drawn: %zu transversal, %zu touching\n",
                  args.frame, problems.points_inside, double(args.margin), problems.strands_inside,
                  problems.crossings_before_effects ? " before effects" : "", double(problems.tolerance),
                  problems.transversal_pairs, problems.touching_pairs, problems.transversal_flagged,
                  problems.touching_flagged);
    }
    paint.colors = linear_colors(strand_colors(mode, result.strands, strand_attributes(pipeline), &problems, style));
  }

  const std::vector<PreviewCamera> cameras =
      args.turntable > 0 ? turntable_cameras(groom_bounds(pipeline), views, angle) : std::vector{groom_camera(pipeline, angle)};
  std::vector<Image> images;
  for (const PreviewCamera &camera : cameras)
    images.push_back(render_preview(camera, result.mesh, result.strands, args.guides ? &result.guides : nullptr, style, paint));
  write_png(path, images.size() == 1 ? images.front() : tile_images(images, columns));
  done();
}

}  // namespace

void add_preview_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<PreviewArgs>();
  CLI::App *cmd = app.add_subcommand("preview", "Render a preview PNG of a groom at one frame.");
  cmd->add_option("groom", args->groom, "Groom file (.yaml)")->required();
  cmd->add_option("--frame", args->frame, "Frame to render (default 1)")->check(CLI::Range(-kMaxFrame, kMaxFrame));
  cmd->add_option("--out", args->out, "Output PNG (a #### field is replaced by the frame)")->required();
  add_preview_size_option(*cmd, "--size", args->size, "Image size in pixels (square, default 800; per view of a turntable)");
  cmd->add_flag("--guides", args->guides, "Draw the guides over the strands in a bright colour");
  cmd->add_option("--camera", args->camera,
                  "front, back, left, right, top, three-quarter (default), or an orbit angle in degrees about the up "
                  "axis from the front, AZ or AZ,EL (90: from the right of the front view)");
  cmd->add_option("--turntable", args->turntable,
                  "N views around the head in one picture (a strip up to 4, else a sheet), starting at --camera")
      ->check(CLI::Range(1, kMaxSheetImages));
  cmd->add_option("--columns", args->columns, "Views per row of a turntable sheet (default: about twice as wide as tall)")
      ->check(CLI::Range(1, kMaxSheetImages));
  cmd->add_option("--color", args->color,
                  "Strand colours: plain (default), guide (the guide that weighs most), clump, zone (hard zone; the "
                  "sides of a partial parting lighter and darker), problems (plume check's findings, drawn on top)");
  cmd->add_option("--tolerance", args->tolerance,
                  "With --color problems: crossing tolerance as plume check's (scene units; default: 1e-3 of the "
                  "strands' median segment length)")
      ->check(finite_non_negative());
  cmd->add_option("--margin", args->margin, "With --color problems: skin margin, as plume check's")
      ->check(finite_non_negative());
  add_threads_option(*cmd, args->threads, "Worker threads");
  add_strands_option(*cmd, args->strands, "Override the groom's root count");
  cmd->add_option("--guides-cache", args->guides_cache, "Dynamics: read the guides from this cache pattern");
  cmd->callback([args, &r_exit_code] {
    run_preview(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
