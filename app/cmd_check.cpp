// `plume check STRANDS --mesh M.obj [--guides G] [--groom GROOM]`: checks Plume's promises on a
// strand file (no point inside the skin, no crossing strands, no influence across a hard parting,
// strands at guide roots follow their guide) and prints the figures. With --strict a violation
// gives exit code 3.
#include <cstdio>
#include <memory>
#include <optional>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "check/check.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"
#include "io/file_scan.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume {

namespace {

struct CheckArgs {
  std::string strands;
  std::string mesh;
  std::string guides;
  std::string groom;
  float tolerance = 0.0f;
  float margin = 0.0f;
  int threads = 0;
  bool strict = false;
};

std::string id_list(const std::vector<uint64_t> &ids) {
  std::string text;
  for (uint64_t id : ids) text += (text.empty() ? "" : " ") + std::to_string(id);
  return text;
}

int run_check(const CheckArgs &args) {
  std::optional<GroomDesc> groom;
  if (!args.groom.empty()) groom = io::read_groom_file(args.groom);
  const std::string mesh_path = !args.mesh.empty() ? args.mesh : groom ? groom->emitter_path : std::string();
  if (mesh_path.empty()) throw InputError("--mesh: expected the emitter mesh (.obj), or --groom to take its emitter");
  if (!args.mesh.empty() && io::detail::extension_of(args.mesh) != ".obj")
    throw InputError("--mesh: expected an .obj mesh, got \"" + args.mesh + "\"");
  set_thread_count(args.threads);
  if (is_vane_mesh_file(args.strands) || (io::detail::extension_of(args.strands) == ".obj" &&
                                          io::read_obj_file(args.strands).mesh))
    return run_vane_check(args.strands, mesh_path, args.margin, args.strict);

  const StrandSet strands = io::read_strands(args.strands);
  const Mesh mesh = io::read_obj_mesh(mesh_path);
  const MeshQuery query(mesh);

  check::CheckOptions options;
  options.crossing_tolerance = args.tolerance;
  options.skin_margin = args.margin;

  std::optional<Guides> guides;
  // A feather groom's guides are stems, which feathers do not follow point for point: only the skin
  // and crossings are checked on its curves.
  const bool feathered = groom && groom->feathers.enabled;
  const std::string guides_path =
      !args.guides.empty() ? args.guides : groom && !feathered ? groom->guides_path : std::string();
  if (!guides_path.empty()) guides = bind_guides(query, io::read_strands(guides_path), guides_path);
  if (guides && guides->size() == 0) {
    if (!args.guides.empty()) throw InputError("--guides: " + guides_path + " holds no strands");
    throw InputError(groom->guides_loc, "guides: " + guides_path + " holds no strands");
  }

  // The zone check binds the strands' roots with the groom's partings and interpolation settings.
  std::unique_ptr<partings::PartingField> partings;
  std::optional<Roots> roots;
  std::optional<interp::Binding> binding;
  if (groom && guides && !feathered) {
    partings = std::make_unique<partings::PartingField>(mesh, *guides, groom->partings);
    roots = check::roots_of(strands, query);
    binding = interp::bind(mesh, *guides, *roots, groom->interpolation, partings->empty() ? nullptr : partings.get());
  }

  // The only input check_strands refuses is a crossing tolerance beyond the crossing count's budget.
  check::CheckReport report;
  try {
    report = check::check_strands(strands, query, options, guides ? &*guides : nullptr, partings.get(),
                                   roots ? &*roots : nullptr, binding ? &*binding : nullptr);
  } catch (const InputError &e) {
    char tolerance[32];
    std::snprintf(tolerance, sizeof tolerance, "%g", double(args.tolerance));
    throw InputError(std::string("--tolerance ") + tolerance + ": " + e.what());
  }

  std::printf("%s: %zu strands, %zu points\n", args.strands.c_str(), report.strand_count, report.point_count);
  std::printf("  points inside the skin (margin %g): %zu%s%s\n", double(args.margin), report.points_inside_skin,
              report.inside_examples.empty() ? "" : "  strands: ", id_list(report.inside_examples).c_str());
  if (report.crossings_checked) {
    std::printf("  crossing strand pairs (tolerance %g): %zu", double(args.tolerance), report.crossing_pairs);
    for (const auto &[a, b] : report.crossing_examples) std::printf("  %llu/%llu", (unsigned long long)a, (unsigned long long)b);
    std::printf("  (%zu segment pairs examined of %zu binned)\n", report.segment_pairs_examined,
                report.piece_pairs_binned);
  } else {
    std::printf("  crossing strand pairs: not checked (give --tolerance)\n");
  }
  if (report.zones_checked)
    std::printf("  influences across hard partings: %zu%s%s\n", report.cross_zone_influences,
                report.cross_zone_examples.empty() ? "" : "  strands: ", id_list(report.cross_zone_examples).c_str());
  else
    std::printf("  influences across hard partings: not checked (give --groom)\n");
  if (report.guides_checked)
    std::printf("  strands at guide roots: %zu, largest deviation from their guide %g (%.3g%% of its length, strand %llu)\n",
                report.strands_at_guide_roots, report.max_guide_deviation, 100.0 * report.max_guide_deviation_relative,
                (unsigned long long)report.worst_guide_strand);
  else
    std::printf("  deviation from guides: not checked (give --guides or --groom)\n");
  std::printf("  %s\n", report.clean() ? "clean" : "VIOLATIONS");
  return args.strict && !report.clean() ? kExitViolations : 0;
}

}  // namespace

void add_check_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App *cmd = app.add_subcommand(
      "check", "Check strands: points inside the skin, crossing pairs, influence across partings, guide deviation.");
  cmd->add_option("strands", args->strands, "Strand file (.usda .hair .ply .obj)")->required();
  cmd->add_option("--mesh", args->mesh, "Emitter mesh (.obj) at the strands' pose (default: the groom's emitter)");
  cmd->add_option("--guides", args->guides, "Guide strands to measure the deviation against (default: the groom's)");
  cmd->add_option("--groom", args->groom,
                  "Groom file: its guides, partings and interpolation settings (strands at the rest pose)");
  cmd->add_option("--tolerance", args->tolerance,
                  "Two strands cross when segments come closer than this (scene units); 0 skips the count")
      ->check(finite_non_negative());
  cmd->add_option("--margin", args->margin, "Skin margin: points closer to the skin than this count as inside")
      ->check(finite_non_negative());
  add_threads_option(*cmd, args->threads, "Worker threads");
  cmd->add_flag("--strict", args->strict, "Exit with code 3 when a violation is found");
  cmd->callback([args, &r_exit_code] { r_exit_code = run_check(*args); });
}

}  // namespace plume
