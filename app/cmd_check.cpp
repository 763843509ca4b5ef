// `plume check STRANDS (--mesh M.obj | --groom GROOM [--frame N]) [--guides G] [--roots R] [--json]`:
// checks Plume's promises on a strand file (no point inside the skin, no transversal crossing, no influence across a hard parting, strands at guide roots reproduce their
// guide, every requested root has a strand) and prints the figures, as text or JSON. With --strict a
// violation gives exit code 3. Feather frames go to run_feather_check (app/feather_commands.h): vanes
// through each other, layer order, and with --previous order flips and popping. Rules: docs/check.md.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <unordered_map>

#include "app/commands.h"
#include "app/feather_commands.h"
#include "app/frame_range.h"
#include "app/pipeline.h"
#include "check/check.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "interp/interpolate.h"
#include "io/file_scan.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/point_list.h"
#include "io/strand_file.h"
#include "partings/parting_field.h"

namespace plume {

namespace {

struct CheckArgs {
  std::string strands;
  std::string mesh;
  std::string guides;
  std::string groom;
  std::string roots;
  std::string guides_cache;
  std::string group;
  std::optional<int> frame;
  /// A range of frames: `strands` is a pattern (####, %04d, $F4) naming each frame's file.
  std::string frames;
  float tolerance = 0.0f;
  float transversal_degrees = check::kTransversalDegrees;
  float margin = 0.0f;
  double guide_limit_percent = 100.0 * check::kGuideDeviationLimit;
  int threads = 0;
  bool strict = false;
  bool strict_touching = false;
  bool json = false;
  // Feather frames: the previous frame's vane meshes, its frame, the popping bound (rachis widths).
  std::string previous;
  std::optional<int> previous_frame;
  std::optional<double> max_pop;
};

/// What was checked, for the report's header.
struct CheckedScene {
  std::string group;            // the hair group checked, empty for a groom without groups
  std::string mesh;             // the mesh's file, or "GROOM's emitter at frame N"
  std::optional<int> frame;     // with --groom
  bool has_effects = false;     // the groom has an effects stack
  size_t strands_off_groom_roots = 0;  // with --groom: strands growing from none of its roots
};

// ---- text -------------------------------------------------------------------------------------

std::string id_list(const std::vector<uint64_t> &ids) {
  std::string text;
  for (uint64_t id : ids) text += (text.empty() ? "" : " ") + std::to_string(id);
  return text;
}

std::string pair_list(const std::vector<std::pair<uint64_t, uint64_t>> &pairs) {
  std::string text;
  for (const auto &[a, b] : pairs) text += (text.empty() ? "" : " ") + std::to_string(a) + "/" + std::to_string(b);
  return text;
}

void print_crossings(const char *title, const check::CrossingCount &count, float degrees, bool made_by_effects = false) {
  std::printf("  %s (tolerance %g): %zu transversal (angle above %g degrees), %zu touching (near-parallel)",
              title, double(count.tolerance), count.transversal_pairs, double(degrees), count.touching_pairs);
  if (count.pairs > 0) std::printf(", largest angle %.1f degrees", count.largest_angle_degrees);
  if (made_by_effects)
    std::printf("; made by the effects (not crossing before them): %zu, %zu transversal", count.pairs_new,
                count.transversal_pairs_new);
  std::printf("\n");
  if (!count.transversal_examples.empty())
    std::printf("    transversal: %s\n", pair_list(count.transversal_examples).c_str());
  if (!count.touching_examples.empty()) std::printf("    touching: %s\n", pair_list(count.touching_examples).c_str());
}

void print_text(const CheckArgs &args, const CheckedScene &scene, const check::CheckReport &report, int exit_code) {
  const std::string group = scene.group.empty() ? "" : " (hair group " + scene.group + ")";
  std::printf("%s%s: %zu strands, %zu points, median segment %g\n", args.strands.c_str(), group.c_str(),
              report.strand_count, report.point_count, report.median_segment_length);
  std::printf("  skin: %s\n", scene.mesh.c_str());
  std::printf("  points inside the skin (margin %g): %zu%s%s\n", double(report.skin_margin), report.points_inside_skin,
              report.inside_examples.empty() ? "" : "  strands: ", id_list(report.inside_examples).c_str());
  if (scene.strands_off_groom_roots > 0)
    std::printf("  strands that are not the groom's regrown at this frame: %zu (another groom or frame?%s)\n",
                scene.strands_off_groom_roots,
                scene.has_effects ? " the crossings are judged after the effects, which the groom's strands avoid" : "");
  if (report.crossings_before_effects) {
    print_crossings("crossing strand pairs before effects", report.crossings, report.transversal_degrees);
    print_crossings("crossing strand pairs after effects, a figure", report.crossings_after_effects,
                    report.transversal_degrees, true);
  } else {
    print_crossings("crossing strand pairs", report.crossings, report.transversal_degrees);
  }
  if (report.zones_checked)
    std::printf("  influences across hard partings: %zu%s%s\n", report.cross_zone_influences,
                report.cross_zone_examples.empty() ? "" : "  strands: ", id_list(report.cross_zone_examples).c_str());
  else
    std::printf("  influences across hard partings: not checked (give --groom)\n");
  if (report.guides_checked) {
    const check::GuideDeviation &guides = report.guide_deviation;
    std::printf("  strands at guide roots%s: %zu", report.guides_before_effects ? " before effects" : "",
                guides.strands_at_guide_roots);
    if (guides.strands_at_guide_roots > guides.near_skin)
      std::printf(", largest deviation from their guide %g (%.3g%% of its length, strand %llu); over %g%%: %zu",
                  guides.largest, 100.0 * guides.largest_relative, (unsigned long long)guides.worst_strand,
                  100.0 * report.guide_deviation_limit, guides.over_limit);
    std::printf("%s%s\n", guides.over_limit_examples.empty() ? "" : "  strands: ",
                id_list(guides.over_limit_examples).c_str());
    if (guides.near_skin > 0)
      std::printf("    of them at guides running into the skin band (%g) or the skin, not held to the limit: %zu, "
                  "largest deviation %.3g%% (strand %llu)\n",
                  guides.skin_band, guides.near_skin, 100.0 * guides.near_skin_largest_relative,
                  (unsigned long long)guides.near_skin_worst_strand);
  } else {
    std::printf("  deviation from guides: not checked (give --guides or --groom)\n");
  }
  if (report.roots_checked) {
    std::printf("  requested roots without a strand: %zu of %zu", report.requested_roots.missing,
                report.requested_roots.requested);
    if (!report.requested_roots.missing_examples.empty()) {
      std::printf("  (indices in %s:", args.roots.c_str());
      for (size_t index : report.requested_roots.missing_examples) std::printf(" %zu", index);
      std::printf(")");
    }
    std::printf("\n");
  }
  const std::vector<std::string> violations = report.violations();
  if (violations.empty()) {
    std::printf("  clean\n");
  } else {
    std::printf("  VIOLATIONS%s:\n", exit_code != 0 ? "" : " (exit code 0 without --strict)");
    for (const std::string &v : violations) std::printf("    %s\n", v.c_str());
  }
}

// ---- JSON -------------------------------------------------------------------------------------

/// A JSON text built by hand: objects and arrays opened and closed in order, strings escaped,
/// non-finite numbers written as null.
class Json {
 public:
  void open(const char *key, char bracket) {
    comma(key);
    text_ += bracket;
    first_ = true;
  }
  void close(char bracket) {
    text_ += bracket;
    first_ = false;
  }
  void number(const char *key, double value) {
    comma(key);
    if (!std::isfinite(value)) {
      text_ += "null";
      return;
    }
    char buffer[40];
    std::snprintf(buffer, sizeof buffer, "%.9g", value);
    text_ += buffer;
  }
  void count(const char *key, uint64_t value) {
    comma(key);
    text_ += std::to_string(value);
  }
  void boolean(const char *key, bool value) {
    comma(key);
    text_ += value ? "true" : "false";
  }
  void null(const char *key) {
    comma(key);
    text_ += "null";
  }
  void string(const char *key, const std::string &value) {
    comma(key);
    text_ += '"';
    for (const unsigned char c : value) {
      if (c == '"' || c == '\\') {
        text_ += '\\';
        text_ += char(c);
      } else if (c < 0x20) {
        char buffer[8];
        std::snprintf(buffer, sizeof buffer, "\\u%04x", unsigned(c));
        text_ += buffer;
      } else {
        text_ += char(c);
      }
    }
    text_ += '"';
  }
  void ids(const char *key, const std::vector<uint64_t> &values) {
    open(key, '[');
    for (uint64_t v : values) count(nullptr, v);
    close(']');
  }
  void pairs(const char *key, const std::vector<std::pair<uint64_t, uint64_t>> &values) {
    open(key, '[');
    for (const auto &[a, b] : values) {
      open(nullptr, '[');
      count(nullptr, a);
      count(nullptr, b);
      close(']');
    }
    close(']');
  }
  const std::string &text() const { return text_; }

 private:
  void comma(const char *key) {
    if (!first_) text_ += ',';
    first_ = false;
    if (key) {
      text_ += '"';
      text_ += key;
      text_ += "\":";
    }
  }
  std::string text_;
  bool first_ = true;
};

void json_crossings(Json &json, const char *key, const check::CrossingCount &count, float degrees,
                    bool made_by_effects = false) {
  json.open(key, '{');
  json.number("tolerance", count.tolerance);
  json.number("transversal_degrees", degrees);
  json.count("pairs", count.pairs);
  json.count("transversal_pairs", count.transversal_pairs);
  json.count("touching_pairs", count.touching_pairs);
  json.number("largest_angle_degrees", count.largest_angle_degrees);
  json.pairs("transversal_examples", count.transversal_examples);
  json.pairs("touching_examples", count.touching_examples);
  json.count("segment_pairs_examined", count.segment_pairs_examined);
  json.count("piece_pairs_binned", count.piece_pairs_binned);
  if (made_by_effects) {
    json.count("pairs_made_by_effects", count.pairs_new);
    json.count("transversal_pairs_made_by_effects", count.transversal_pairs_new);
  }
  json.close('}');
}

void print_json(const CheckArgs &args, const CheckedScene &scene, const check::CheckReport &report, int exit_code) {
  Json json;
  json.open(nullptr, '{');
  json.string("strands", args.strands);
  if (!scene.group.empty()) json.string("group", scene.group);
  json.string("skin", scene.mesh);
  if (scene.frame)
    json.number("frame", double(*scene.frame));
  else
    json.null("frame");
  json.boolean("groom_effects", scene.has_effects);
  json.count("strands_off_groom_roots", scene.strands_off_groom_roots);
  json.count("strand_count", report.strand_count);
  json.count("point_count", report.point_count);
  json.number("median_segment_length", report.median_segment_length);
  json.number("root_tolerance", report.root_tolerance);

  json.open("inside_skin", '{');
  json.number("margin", report.skin_margin);
  json.count("points", report.points_inside_skin);
  json.ids("examples", report.inside_examples);
  json.close('}');

  json.string("crossings_judged_on", report.crossings_before_effects ? "strands before effects" : "strands");
  json.boolean("touching_is_violation", report.touching_is_violation);
  json_crossings(json, "crossings", report.crossings, report.transversal_degrees);
  if (report.crossings_before_effects)
    json_crossings(json, "crossings_after_effects", report.crossings_after_effects, report.transversal_degrees, true);
  else
    json.null("crossings_after_effects");

  json.open("zones", '{');
  json.boolean("checked", report.zones_checked);
  json.count("cross_zone_influences", report.cross_zone_influences);
  json.ids("examples", report.cross_zone_examples);
  json.close('}');

  const check::GuideDeviation &guides = report.guide_deviation;
  json.open("guides", '{');
  json.boolean("checked", report.guides_checked);
  json.boolean("before_effects", report.guides_before_effects);
  json.count("strands_at_guide_roots", guides.strands_at_guide_roots);
  json.number("largest_deviation", guides.largest);
  json.number("largest_deviation_percent", 100.0 * guides.largest_relative);
  // A strand id, or null when there is no such strand.
  const auto strand_or_null = [&](const char *name, bool any, uint64_t id) {
    if (any)
      json.count(name, id);
    else
      json.null(name);
  };
  strand_or_null("worst_strand", guides.strands_at_guide_roots > guides.near_skin, guides.worst_strand);
  json.number("limit_percent", 100.0 * report.guide_deviation_limit);
  json.count("over_limit", guides.over_limit);
  json.ids("over_limit_examples", guides.over_limit_examples);
  json.number("skin_band", guides.skin_band);
  json.count("near_skin", guides.near_skin);
  json.number("near_skin_largest_deviation_percent", 100.0 * guides.near_skin_largest_relative);
  strand_or_null("near_skin_worst_strand", guides.near_skin > 0, guides.near_skin_worst_strand);
  json.close('}');

  json.open("requested_roots", '{');
  json.boolean("checked", report.roots_checked);
  json.string("file", args.roots);
  json.count("requested", report.requested_roots.requested);
  json.count("missing", report.requested_roots.missing);
  json.open("missing_examples", '[');
  for (size_t index : report.requested_roots.missing_examples) json.count(nullptr, index);
  json.close(']');
  json.close('}');

  json.open("violations", '[');
  for (const std::string &v : report.violations()) json.string(nullptr, v);
  json.close(']');
  json.boolean("clean", report.clean());
  json.boolean("strict", args.strict);
  json.count("exit_code", uint64_t(exit_code));
  json.close('}');
  std::printf("%s\n", json.text().c_str());
}

// ---- the check --------------------------------------------------------------------------------

/// With --groom: what the groom says about the strands at their frame.
struct GroomView {
  std::unique_ptr<Pipeline> pipeline;
  Mesh rest_mesh;
  Roots roots;                             // the strands' roots, in the strands' order
  size_t strands_off_groom_roots = 0;      // strands that are not the groom's regrown at this frame
  std::optional<StrandSet> interpolated;   // with effects: the strands before them
  std::optional<Guides> guides;            // the guides at the frame
};

/// Loads the groom and finds the strands' roots among its own: `plume regrow` writes strand i of a
/// run of N roots from root i of the groom's first N (scattering and roots files keep their order
/// under the count), with its root id where the format keeps ids (.usda). A strand whose first point
/// is not the one growth gives its root at this frame is not the groom's (another groom, another
/// frame), and gets the closest surface point of its first point as a guessed root (for the zone
/// check only). Without effects only those first points are found (no strand is grown); with
/// effects the strands are regrown without them, and when every strand is the groom's, they are the
/// ones the effects start from.
GroomView view_groom(const GroomDesc &groom, const StrandSet &strands, const Mesh &posed, const MeshQuery &posed_query,
                     int frame, const check::CheckOptions &options, const CheckArgs &args, bool need_guides) {
  GroomView view;
  view.rest_mesh = io::read_obj_mesh(groom.emitter_path);
  const Guides rest_guides =
      bind_guides(MeshQuery(view.rest_mesh), io::read_strands(groom.guides_path), groom.guides_path);
  if (rest_guides.size() == 0) throw InputError(groom.guides_loc, "guides: " + groom.guides_path + " holds no strands");
  const size_t count = strands.strand_count();
  const Roots candidates = groom_roots(groom, view.rest_mesh, rest_guides, int64_t(count));
  // Ids 0..n-1 are those of a format without ids: then strand i is root i.
  bool carries_ids = false;
  for (size_t s = 0; s < count && !carries_ids; ++s) carries_ids = strands.ids[s] != uint64_t(s);
  std::unordered_map<uint64_t, size_t> index_of_id;
  if (carries_ids)
    for (size_t r = 0; r < candidates.size(); ++r) index_of_id.emplace(candidates.ids[r], r);
  const Roots guessed = check::roots_of(strands, posed_query);
  view.roots = guessed;
  std::vector<bool> matched(count, false);
  for (size_t s = 0; s < count; ++s) {
    size_t r = s;
    if (carries_ids) {
      const auto found = index_of_id.find(strands.ids[s]);
      if (found == index_of_id.end()) continue;
      r = found->second;
    }
    if (r >= candidates.size()) continue;
    view.roots.points[s] = candidates.points[r];
    matched[s] = true;
  }

  PipelineOptions pipeline_options;
  pipeline_options.roots = view.roots;
  pipeline_options.guides_cache = args.guides_cache;
  pipeline_options.simulation_start = std::min(groom_first_frame(groom), frame);
  view.pipeline = std::make_unique<Pipeline>(groom, pipeline_options);
  view.pipeline->check_frame_inputs(FrameRange{frame, frame, 1});
  // Without effects only the strands' first points and the guides are read: they are found without
  // growing the strands.
  FrameResult before =
      groom.effects.empty() ? view.pipeline->produce_starts(frame) : view.pipeline->produce(frame, false);
  const float tolerance = check::root_tolerance_for(posed, options);
  for (size_t s = 0; s < count; ++s) {
    matched[s] = matched[s] && strands.points_in(s) > 0 && before.strands.points_in(s) > 0 &&
                 (strands.points(s).front() - before.strands.points(s).front()).norm() <= tolerance;
    if (!matched[s]) {
      ++view.strands_off_groom_roots;
      view.roots.points[s] = guessed.points[s];
    }
  }
  if (view.strands_off_groom_roots > 0) {
    // The binding must be that of the roots the zone check reads.
    pipeline_options.roots = view.roots;
    view.pipeline = std::make_unique<Pipeline>(groom, pipeline_options);
  } else if (!groom.effects.empty()) {
    before.strands.ids = strands.ids;
    view.interpolated = std::move(before.strands);
  }
  if (need_guides) view.guides = Guides{std::move(before.guides), view.pipeline->guides().roots};
  return view;
}

int check_strand_set(const CheckArgs &args, const std::optional<GroomDesc> &groom, const StrandSet &strands,
                     const std::string &group_name);

int run_check(const CheckArgs &args);

/// `plume check PATTERN --groom G --frames A-B`: every frame of the range in turn, feather vane
/// meshes each against the frame before it in the range (order flips, popping). Returns the worst
/// exit code; the text report ends with the frames that broke a promise (under --strict).
int run_check_frames(const CheckArgs &args) {
  if (args.groom.empty()) throw InputError("--frames: needs --groom, whose emitter it poses at each frame");
  if (args.frame) throw InputError("--frames: give --frames or --frame, not both");
  if (!args.previous.empty() || args.previous_frame)
    throw InputError("--frames: each frame is compared with the one before it in the range; leave --previous out");
  if (!args.guides.empty())
    throw InputError("--frames: --guides names one frame's guides; leave it out (the groom's guides are posed at each "
                     "frame)");
  const FrameRange range = parse_frame_range(args.frames, "--frames");
  check_frames_per_run(range, "--frames");
  if (!has_frame_field(args.strands))
    throw InputError("--frames: " + args.strands + " has no frame field (####, %04d or $F4) to name each frame's file");
  check_frame_syntax(args.strands, "strands");
  // Every frame's file first: a missing one stops the run before any check.
  for (int64_t i = 0; i < range.count(); ++i) {
    const std::string path = expand_frame_pattern(args.strands, range.at(i));
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec))
      throw InputError("--frames: frame " + std::to_string(range.at(i)) + ": " + path + " does not exist");
  }
  const std::string first = expand_frame_pattern(args.strands, range.first);
  const bool vanes = is_feather_check(first, args.groom) &&
                     (is_vane_mesh_file(first) || io::detail::extension_of(first) == ".obj");
  int worst = 0;
  std::vector<int> failed;
  if (args.json) std::printf("{\"frames\": [\n");
  for (int64_t i = 0; i < range.count(); ++i) {
    CheckArgs one = args;
    one.frames.clear();
    one.frame = range.at(i);
    one.strands = expand_frame_pattern(args.strands, range.at(i));
    if (vanes && i > 0) {
      one.previous = expand_frame_pattern(args.strands, range.at(i - 1));
      one.previous_frame = range.at(i - 1);
    } else {
      one.max_pop.reset();
    }
    if (args.json && i > 0) std::printf(",\n");
    const int code = run_check(one);
    std::fflush(stdout);
    if (code != 0) failed.push_back(range.at(i));
    worst = std::max(worst, code);
  }
  std::string list;
  for (const int f : failed) list += (list.empty() ? "" : ", ") + std::to_string(f);
  if (args.json) {
    std::printf("], \"frames_checked\": %lld, \"frames_failed\": [%s]}\n", (long long)range.count(), list.c_str());
  } else {
    std::printf("frames %s: %lld checked%s%s\n", args.frames.c_str(), (long long)range.count(),
                failed.empty() ? (args.strict || args.strict_touching ? ", every one keeps its promises" : "")
                               : ", broken promises at frames ",
                list.c_str());
  }
  return worst;
}

int run_check(const CheckArgs &args) {
  if (!args.frames.empty()) return run_check_frames(args);
  if (args.mesh.empty() && args.groom.empty())
    throw InputError("--mesh: expected the emitter mesh (.obj) at the strands' pose, or --groom to pose the groom's emitter");
  if (!args.mesh.empty() && !args.groom.empty())
    throw InputError("--mesh: give --mesh or --groom, not both (--groom poses its own emitter at --frame)");
  if (args.frame && args.groom.empty()) throw InputError("--frame: needs --groom, whose emitter it poses");
  if (!args.guides_cache.empty() && args.groom.empty()) throw InputError("--guides-cache: needs --groom");
  if (!args.mesh.empty() && io::detail::extension_of(args.mesh) != ".obj")
    throw InputError("--mesh: expected an .obj mesh, got \"" + args.mesh + "\"");
  set_thread_count(args.threads);
  if (is_feather_check(args.strands, args.groom))
    return run_feather_check({args.strands, args.mesh, args.groom, args.frame, args.margin, args.strict, args.json,
                              args.previous, args.previous_frame, args.max_pop});
  if (!args.previous.empty() || args.previous_frame || args.max_pop)
    throw InputError("--previous: compares feather frames (vane meshes of a feather groom); " + args.strands +
                     " holds strands");

  std::optional<GroomDesc> groom;
  if (!args.groom.empty()) groom = io::read_groom_file(args.groom);
  if (!args.group.empty() && !groom) throw InputError("--group: needs --groom, whose hair group it names");
  if (!groom || groom->groups.empty()) {
    if (!args.group.empty())
      throw InputError("--group: " + args.groom + " has no hair groups (no groups list): leave --group out");
    return check_strand_set(args, groom, io::read_strands(args.strands), "");
  }
  // A groom of hair groups: each group's strands (a .usda's BasisCurves prim of its name) are
  // checked against that group, --group naming one or every group in turn.
  std::string names;
  for (const GroomDesc &group : groom->groups) names += (names.empty() ? "" : ", ") + group.group_name;
  const std::vector<std::pair<std::string, StrandSet>> sets = io::read_strand_groups(args.strands);
  const bool named = !(sets.size() == 1 && sets[0].first.empty());
  std::vector<size_t> chosen;
  for (size_t g = 0; g < groom->groups.size(); ++g)
    if (args.group.empty() || groom->groups[g].group_name == args.group) chosen.push_back(g);
  if (chosen.empty())
    throw InputError("--group: no hair group \"" + args.group + "\" in " + args.groom + " (groups: " + names + ")");
  if (!named && args.group.empty())
    throw InputError("--group: " + args.groom + " has hair groups (" + names + "); name the one " + args.strands +
                     " holds (a .usda with one BasisCurves prim per group is checked group by group)");
  int exit_code = 0;
  if (args.json && chosen.size() > 1) std::printf("[\n");
  for (size_t c = 0; c < chosen.size(); ++c) {
    const GroomDesc &group = groom->groups[chosen[c]];
    const StrandSet *strands = nullptr;
    for (const auto &[name, set] : sets)
      if (!named || name == group.group_name) strands = &set;
    if (!strands)
      throw InputError(args.strands + ": no BasisCurves prim \"" + group.group_name + "\" (the hair group of " +
                       args.groom + ")");
    if (args.json && c > 0) std::printf(",\n");
    exit_code = std::max(exit_code, check_strand_set(args, group, *strands, group.group_name));
  }
  if (args.json && chosen.size() > 1) std::printf("]\n");
  return exit_code;
}

/// Checks `strands` (those of args.strands, or of its hair group `group_name`) against the skin and,
/// with `groom` (the groom, or one hair group of it), against what the groom grows; prints the
/// report and returns the exit code.
int check_strand_set(const CheckArgs &args, const std::optional<GroomDesc> &groom, const StrandSet &strands,
                     const std::string &group_name) {
  check::CheckOptions options;
  options.crossing_tolerance = args.tolerance;
  options.transversal_degrees = args.transversal_degrees;
  options.touching_is_violation = args.strict_touching;
  options.skin_margin = args.margin;
  options.guide_deviation_limit = args.guide_limit_percent / 100.0;

  CheckedScene scene;
  scene.group = group_name;
  Mesh mesh;
  if (groom) {
    scene.frame = args.frame ? *args.frame : groom_first_frame(*groom);
    scene.mesh = groom->emitter_path + " posed at frame " + std::to_string(*scene.frame);
    scene.has_effects = !groom->effects.empty();
    mesh = posed_emitter(*groom, io::read_obj_mesh(groom->emitter_path), *scene.frame);
  } else {
    mesh = io::read_obj_mesh(args.mesh);
    scene.mesh = args.mesh;
  }
  const MeshQuery query(mesh);

  std::optional<GroomView> view;
  if (groom) {
    view = view_groom(*groom, strands, mesh, query, *scene.frame, options, args, args.guides.empty());
    scene.strands_off_groom_roots = view->strands_off_groom_roots;
  }
  std::optional<Guides> guides;
  if (!args.guides.empty()) {
    guides = bind_guides(query, io::read_strands(args.guides), args.guides);
    if (guides->size() == 0) throw InputError("--guides: " + args.guides + " holds no strands");
  } else if (view) {
    guides = std::move(view->guides);
  }

  // Requested roots are snapped to the skin at rest, as the groom's roots.file is.
  std::optional<std::vector<SurfacePoint>> requested;
  if (!args.roots.empty()) {
    const std::vector<Eigen::Vector3f> points = io::read_points(args.roots);
    const MeshQuery rest_query(view ? view->rest_mesh : mesh);
    requested.emplace(points.size());
    for (size_t i = 0; i < points.size(); ++i) (*requested)[i] = surface_point_below(rest_query, points[i]);
  }

  check::CheckInputs inputs;
  inputs.guides = guides ? &*guides : nullptr;
  if (view) {
    inputs.partings = &view->pipeline->partings();
    inputs.roots = &view->roots;
    inputs.roots_grown = view->strands_off_groom_roots == 0;
    inputs.binding = &view->pipeline->binding();
    inputs.interpolated = view->interpolated ? &*view->interpolated : nullptr;
  }
  inputs.requested_roots = requested ? &*requested : nullptr;

  // The inputs check_strands refuses are a crossing tolerance beyond the crossing count's budget and
  // strands without a length to derive one from.
  check::CheckReport report;
  try {
    report = check::check_strands(strands, query, options, inputs);
  } catch (const InputError &e) {
    if (args.tolerance > 0.0f) {
      char tolerance[32];
      std::snprintf(tolerance, sizeof tolerance, "%g", double(args.tolerance));
      throw InputError(std::string("--tolerance ") + tolerance + ": " + e.what());
    }
    throw InputError(args.strands + ": " + e.what());
  }
  const int exit_code = (args.strict || args.strict_touching) && !report.clean() ? kExitViolations : 0;
  if (args.json)
    print_json(args, scene, report, exit_code);
  else
    print_text(args, scene, report, exit_code);
  return exit_code;
}

CLI::Validator finite_positive() {
  return CLI::Validator(
      [](std::string &text) {
        char *end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || *end != '\0' || !(value > 0.0 && value <= 3.0e38))
          return "expected a finite number > 0, got \"" + text + "\"";
        return std::string();
      },
      "FINITE>0");
}

}  // namespace

void add_check_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<CheckArgs>();
  CLI::App *cmd = app.add_subcommand(
      "check",
      "Check strands: points inside the skin, crossing pairs, influence across partings, guide reproduction, "
      "requested roots.");
  cmd->add_option("strands", args->strands, "Strand file (.usda .hair .ply .obj)")->required();
  cmd->add_option("--mesh", args->mesh, "Emitter mesh (.obj) at the strands' pose (or give --groom)");
  cmd->add_option("--groom", args->groom,
                  "Groom file: its emitter posed at --frame, its guides at that frame, partings, settings and effects");
  cmd->add_option("--frame", args->frame,
                  "With --groom: the strands' frame (default: the first of the groom's output.frames, else 1)")
      ->check(CLI::Range(-kMaxFrame, kMaxFrame));
  cmd->add_option("--frames", args->frames,
                  "With --groom: check every frame of a range (7, 1-48, 1-240:2), STRANDS a pattern (####, %04d, $F4) "
                  "naming each frame's file; feather vane meshes are each compared with the frame before")
      ->check(non_empty_frames());
  cmd->add_option("--guides", args->guides,
                  "Guide strands at the strands' pose to measure reproduction against (default: the groom's)");
  cmd->add_option("--guides-cache", args->guides_cache,
                  "With --groom and dynamics: read the frame's guides from this cache instead of simulating");
  cmd->add_option("--roots", args->roots,
                  "Roots that must each have a strand (.txt x y z lines, or a strand file's first points; rest pose)");
  cmd->add_option("--group", args->group,
                  "With --groom of hair groups: the group the strands are (default: every group, each the "
                  ".usda's BasisCurves prim of its name)");
  cmd->add_option("--tolerance", args->tolerance,
                  "Two strands cross when segments come closer than this (scene units; default 1e-3 x the median "
                  "segment length)")
      ->check(finite_positive());
  cmd->add_option("--transversal-angle", args->transversal_degrees,
                  "Crossings at a larger angle (degrees) are transversal, others touching (default 10)")
      ->check(CLI::Range(0.0f, 90.0f));
  cmd->add_option("--guide-limit", args->guide_limit_percent,
                  "Largest deviation of a strand at a guide root from its guide, % of the guide's length (default 0.1)")
      ->check(CLI::Range(0.0, 1e6));
  cmd->add_option("--margin", args->margin, "Skin margin: points closer to the skin than this count as inside")
      ->check(finite_non_negative());
  cmd->add_option("--previous", args->previous,
                  "Feather frames, with --groom: the previous frame's vane meshes, for order flips and popping");
  cmd->add_option("--previous-frame", args->previous_frame, "The frame of --previous (default: --frame - 1)")
      ->check(CLI::Range(-kMaxFrame, kMaxFrame));
  cmd->add_option("--max-pop", args->max_pop,
                  "With --previous: the largest popping --strict accepts (rachis widths; default: reported only)")
      ->check(finite_non_negative());
  add_threads_option(*cmd, args->threads, "Worker threads");
  cmd->add_flag("--strict", args->strict, "Exit with code 3 when a promise is broken");
  cmd->add_flag("--strict-touching", args->strict_touching,
                "As --strict, and near-parallel touching pairs count as violations too");
  cmd->add_flag("--json", args->json,
                "Print the report as one JSON object (hair groups checked in turn: a list of them, one per group)");
  cmd->callback([args, &r_exit_code] { r_exit_code = run_check(*args); });
}

}  // namespace plume
