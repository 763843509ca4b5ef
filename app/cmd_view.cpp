// `plume view GROOM --out view.html [--frames 1-48]`, or `plume view hair.####.usda --mesh head.obj`:
// one self-contained HTML page in which to turn the strands in 3D: the skin, the strands (all of
// them, or a stated sample within the page's size budget, every strand the checker reports
// included), the guides, colours by attribute and by the checker's problems, and a frame slider
// for a range. What the page holds: docs/viewer.md.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>

#include "app/commands.h"
#include "app/feather_pipeline.h"
#include "app/groom_outputs.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/run_outputs.h"
#include "app/strand_colors.h"
#include "app/view_page.h"
#include "groom/error.h"
#include "groom/roots.h"
#include "io/file_scan.h"
#include "io/groom_file.h"
#include "io/obj_mesh.h"
#include "io/strand_file.h"

namespace plume {

namespace {

/// The most points (strand, skin and guide points over all frames) a page holds by default: 48 MB
/// of float32 positions, a page of about 65 MB. 100,000 strands of 32 points fit in one frame.
constexpr int64_t kDefaultViewPoints = 4'000'000;
/// Beyond this the positions alone exceed what a browser reads (kMaxPageDataBytes).
constexpr int64_t kMaxViewPoints = 32'000'000;

struct ViewArgs {
  std::string input;
  std::string frames;
  std::string out;
  std::string mesh;
  std::string guides;
  int64_t strands = -1;
  int64_t max_points = kDefaultViewPoints;
  float tolerance = 0.0f;
  float margin = 0.0f;
  int threads = 0;
  std::string guides_cache;
};

/// What a page is made of, whatever it comes from: a groom's pipeline, or strand files with the
/// skin they stand on.
struct ViewInput {
  std::string title;
  std::string source;
  float fps = 24.0f;
  Mesh skin;                           // the first frame's skin: its triangles and vertex count
  std::vector<int64_t> offsets{0};     // the strands' points, the same on every frame
  std::vector<uint64_t> ids;           // one stable id per strand
  std::vector<int64_t> guide_offsets{0};
  bool skin_moves = true;              // else the skin is stored once (the budget counts it once)
  bool guides_move = true;
  Eigen::AlignedBox3f bounds;          // what the page's first camera frames
  /// A groom's strand attributes (guide, clump, zone), one per strand; none for strand files.
  std::optional<StrandAttributes> attributes;
  /// The frame's skin, guides and strands (same offsets as above); frames are asked for in
  /// increasing order, and once more from the first for a second pass.
  std::function<FrameResult(int)> produce;
  /// A groom with effects: the frame's strands grown without them, after produce() of that frame
  /// (the checker judges their crossings, as plume check --groom does). Empty otherwise.
  std::function<StrandSet(int)> produce_before_effects;
  /// A feather groom: its curves (rachis and barbs) are the strands, and its vanes are a mesh whose
  /// triangles are the same on every frame; vane_positions() gives the vertices of the frame
  /// produce() made last. Empty for hair.
  std::vector<Eigen::Vector3i> vane_triangles;
  int64_t vane_vertex_count = 0;
  std::function<std::vector<float>()> vane_positions;
  /// Whether crossings are judged (hair); a feather's barbs meet its rachis by design, and feather
  /// against feather is not judged here: only points below the skin.
  bool judge_crossings = true;
};

/// One frame's findings, kept for the manifest: the counts and the strands flagged (sparse).
struct FrameCheck {
  StrandProblems counts;  // flags left empty
  std::vector<std::pair<uint32_t, uint8_t>> flagged;  // (strand, flags), ascending
};

/// Of `candidates`, the strands with the lowest hashed ids whose points over `frame_count` frames
/// fit in `r_budget` points (taken in that order, up to the first that does not fit), ascending
/// by index; r_budget loses what they take. The same strands on every frame, spread over the groom,
/// and for scattered roots the same whatever their count (ids are stable).
std::vector<uint32_t> hashed_sample(const ViewInput &input, std::vector<uint32_t> candidates, int64_t frame_count,
                                    int64_t &r_budget) {
  std::vector<std::pair<uint64_t, uint32_t>> keyed(candidates.size());
  for (size_t i = 0; i < candidates.size(); ++i)
    keyed[i] = {hash64(input.ids[candidates[i]] ^ 0x7669657765ull), candidates[i]};
  std::sort(keyed.begin(), keyed.end());
  std::vector<uint32_t> sample;
  for (const auto &[key, s] : keyed) {
    const int64_t cost = (input.offsets[s + 1] - input.offsets[s]) * frame_count;
    if (cost > r_budget) break;
    r_budget -= cost;
    sample.push_back(s);
  }
  std::sort(sample.begin(), sample.end());
  return sample;
}

/// The positions of strands `which` (ascending) of `strands`, flattened.
std::vector<float> gather(const StrandSet &strands, const std::vector<uint32_t> &which) {
  std::vector<float> out;
  for (uint32_t s : which)
    for (const Eigen::Vector3f &p : strands.points(s)) out.insert(out.end(), {p.x(), p.y(), p.z()});
  return out;
}

std::vector<float> flatten(const std::vector<Eigen::Vector3f> &points) {
  std::vector<float> out;
  out.reserve(points.size() * 3);
  for (const Eigen::Vector3f &p : points) out.insert(out.end(), {p.x(), p.y(), p.z()});
  return out;
}

void write_vector(JsonWriter &json, const Eigen::Vector3f &v) {
  json.begin_array().value(v.x()).value(v.y()).value(v.z()).end_array();
}

void write_color(JsonWriter &json, const Rgb8 &c) {
  json.begin_array().value(int(c[0])).value(int(c[1])).value(int(c[2])).end_array();
}

std::string with_commas(int64_t n) {
  std::string digits = std::to_string(n), out;
  for (size_t i = 0; i < digits.size(); ++i) {
    if (i > 0 && (digits.size() - i) % 3 == 0) out += ',';
    out += digits[i];
  }
  return out;
}

/// Produces every frame of `range` from `input`, checks it, chooses the strands shown within
/// args.max_points and writes the page.
void write_view(const ViewInput &input, const FrameRange &range, const ViewArgs &args) {
  RunSummary summary("view", range);
  // The budget: every point the page holds over its frames. A skin or guides that do not move are
  // stored once.
  const int64_t frame_count = range.count();
  const int64_t other_points = int64_t(input.skin.vertex_count()) * (input.skin_moves ? frame_count : 1) +
                               input.guide_offsets.back() * (input.guides_move ? frame_count : 1) +
                               input.vane_vertex_count * frame_count;
  const size_t strand_count = input.ids.size();
  int64_t fewest_points = std::numeric_limits<int64_t>::max();
  for (size_t s = 0; s < strand_count; ++s) fewest_points = std::min(fewest_points, input.offsets[s + 1] - input.offsets[s]);
  if (strand_count > 0 && other_points + fewest_points * frame_count > args.max_points)
    throw InputError("--max-points " + std::to_string(args.max_points) + ": the page cannot hold one strand over " +
                     std::to_string(frame_count) + " frames (the skin and guides take " + with_commas(other_points) +
                     " points" + (input.vane_vertex_count > 0 ? " with the vanes" : "") + ", the smallest strand " +
                     with_commas(fewest_points * frame_count) +
                     "): give fewer frames (--frames A-B:STEP) or a larger --max-points");
  std::vector<uint32_t> every(strand_count);
  std::iota(every.begin(), every.end(), 0u);
  // The strands kept in the first pass: the sample the whole budget allows (all when they fit).
  int64_t budget = args.max_points - other_points;
  const std::vector<uint32_t> kept = hashed_sample(input, every, frame_count, budget);

  ProblemOptions check_options;
  check_options.crossing_tolerance = args.tolerance;
  check_options.skin_margin = args.margin;
  check_options.judge_crossings = input.judge_crossings;
  std::vector<FrameCheck> checks(static_cast<size_t>(frame_count));
  std::vector<uint8_t> ever_flagged(strand_count, 0);
  std::vector<std::vector<float>> skin_positions, guide_positions, kept_positions, vane_positions;
  std::vector<int> skin_of_frame(static_cast<size_t>(frame_count)), guides_of_frame(static_cast<size_t>(frame_count));
  {
    Progress progress("view", int(frame_count));
    for (int64_t i = 0; i < frame_count; ++i) {
      const FrameResult result = input.produce(range.at(i));
      std::optional<StrandSet> before_effects;
      if (input.produce_before_effects) before_effects = input.produce_before_effects(range.at(i));
      try {
        StrandProblems problems =
            find_problems(result.strands, result.mesh, check_options, before_effects ? &*before_effects : nullptr);
        FrameCheck &check = checks[size_t(i)];
        for (size_t s = 0; s < problems.flags.size(); ++s) {
          if (!problems.flags[s]) continue;
          check.flagged.emplace_back(uint32_t(s), problems.flags[s]);
          // Touching (near-parallel) is no violation: it does not claim a place in the sample.
          if (problem_is_violation(problems.flags[s])) ever_flagged[s] = 1;
        }
        problems.flags.clear();
        check.counts = problems;
      } catch (const InputError &e) {
        if (!(args.tolerance > 0.0f)) throw InputError("frame " + std::to_string(range.at(i)) + ": " + e.what());
        char tolerance[32];
        std::snprintf(tolerance, sizeof tolerance, "%g", double(args.tolerance));
        throw InputError(std::string("--tolerance ") + tolerance + ": " + e.what());
      }
      // A frame's skin or guides identical to the previous frame's are stored once.
      std::vector<float> skin = flatten(result.mesh.positions);
      if (skin_positions.empty() || skin != skin_positions.back()) skin_positions.push_back(std::move(skin));
      skin_of_frame[size_t(i)] = int(skin_positions.size()) - 1;
      std::vector<float> guides = flatten(result.guides.positions);
      if (guide_positions.empty() || guides != guide_positions.back()) guide_positions.push_back(std::move(guides));
      guides_of_frame[size_t(i)] = int(guide_positions.size()) - 1;
      kept_positions.push_back(gather(result.strands, kept));
      if (input.vane_positions) vane_positions.push_back(input.vane_positions());
      progress.frame_done(range.at(i));
    }
  }

  // The strands shown: every strand with a violation in some frame (a sample of them when they
  // alone exceed the budget), then the kept sample up to the budget.
  std::vector<uint32_t> flagged_strands;
  for (size_t s = 0; s < strand_count; ++s)
    if (ever_flagged[s]) flagged_strands.push_back(uint32_t(s));
  budget = args.max_points - other_points;
  std::vector<uint32_t> shown = hashed_sample(input, flagged_strands, frame_count, budget);
  const size_t flagged_shown = shown.size();
  {
    std::vector<uint32_t> rest, merged;
    std::set_difference(kept.begin(), kept.end(), shown.begin(), shown.end(), std::back_inserter(rest));
    rest = hashed_sample(input, rest, frame_count, budget);
    std::merge(shown.begin(), shown.end(), rest.begin(), rest.end(), std::back_inserter(merged));
    shown = std::move(merged);
  }
  std::vector<std::vector<float>> shown_positions;
  if (std::includes(kept.begin(), kept.end(), shown.begin(), shown.end())) {
    // Every shown strand was kept: take its points from the first pass.
    std::vector<size_t> slot_begin(shown.size()), slot_end(shown.size());
    for (size_t k = 0, j = 0, at = 0; k < shown.size(); ++k) {
      for (; kept[j] != shown[k]; ++j) at += size_t(input.offsets[kept[j] + 1] - input.offsets[kept[j]]) * 3;
      slot_begin[k] = at;
      slot_end[k] = at + size_t(input.offsets[shown[k] + 1] - input.offsets[shown[k]]) * 3;
    }
    for (std::vector<float> &frame : kept_positions) {
      std::vector<float> out;
      for (size_t k = 0; k < shown.size(); ++k)
        out.insert(out.end(), frame.begin() + std::ptrdiff_t(slot_begin[k]), frame.begin() + std::ptrdiff_t(slot_end[k]));
      shown_positions.push_back(std::move(out));
      frame = {};
    }
  } else {
    // Flagged strands outside the sample: produce the frames again for their points.
    kept_positions.clear();
    Progress progress("view (strands the checker flagged)", int(frame_count));
    for (int64_t i = 0; i < frame_count; ++i) {
      shown_positions.push_back(gather(input.produce(range.at(i)).strands, shown));
      progress.frame_done(range.at(i));
    }
  }
  kept_positions.clear();

  ViewBlob blob;
  JsonWriter json;
  json.begin_object();
  json.key("format").value("plume-view").key("version").value(1);
  json.key("title").value(input.title).key("source").value(input.source).key("generator").value("plume " PLUME_VERSION);
  json.key("three").value(viewer_assets().three_version);
  json.key("up");
  write_vector(json, Eigen::Vector3f::UnitY());
  json.key("front");
  write_vector(json, Eigen::Vector3f::UnitZ());
  const CameraAngle camera;
  json.key("bounds").begin_object().key("min");
  write_vector(json, input.bounds.min());
  json.key("max");
  write_vector(json, input.bounds.max());
  json.end_object();
  json.key("camera").begin_object().key("azimuth").value(camera.azimuth_degrees);
  json.key("elevation").value(camera.elevation_degrees).key("fov").value(PreviewCamera().fov_y_degrees);
  json.end_object();
  json.key("fps").value(input.fps);
  json.key("frames").begin_array();
  for (int64_t i = 0; i < frame_count; ++i) json.value(range.at(i));
  json.end_array();

  // The skin: triangles once, positions per frame (frames sharing a pose share an array).
  std::vector<uint32_t> triangles;
  for (const Eigen::Vector3i &t : input.skin.triangles)
    triangles.insert(triangles.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
  json.key("skin").begin_object().key("vertex_count").value(input.skin.vertex_count());
  json.key("triangles").value(blob.add(std::span<const uint32_t>(triangles)));
  std::vector<int> skin_buffers;
  for (const std::vector<float> &positions : skin_positions) skin_buffers.push_back(blob.add(std::span<const float>(positions)));
  skin_positions.clear();
  json.key("positions").begin_array();
  for (int b : skin_of_frame) json.value(skin_buffers[size_t(b)]);
  json.end_array().end_object();

  // The strands: offsets into the points, stable ids, positions per frame.
  std::vector<uint32_t> offsets{0};
  std::vector<double> shown_ids;
  for (uint32_t s : shown) {
    offsets.push_back(offsets.back() + uint32_t(input.offsets[s + 1] - input.offsets[s]));
    shown_ids.push_back(double(input.ids[s]));
  }
  json.key("strands").begin_object();
  json.key("total").value(strand_count).key("shown").value(shown.size());
  json.key("sample").value(shown.size() < strand_count);
  json.key("flagged_shown").value(flagged_shown).key("flagged_total").value(flagged_strands.size());
  json.key("offsets").value(blob.add(std::span<const uint32_t>(offsets)));
  json.key("ids").value(blob.add(std::span<const double>(shown_ids)));
  json.key("positions").begin_array();
  for (const std::vector<float> &positions : shown_positions) json.value(blob.add(std::span<const float>(positions)));
  json.end_array().end_object();
  shown_positions.clear();

  // The guides.
  const std::vector<uint32_t> guide_offsets(input.guide_offsets.begin(), input.guide_offsets.end());
  json.key("guides").begin_object().key("count").value(guide_offsets.size() - 1);
  json.key("offsets").value(blob.add(std::span<const uint32_t>(guide_offsets)));
  std::vector<int> guide_buffers;
  for (const std::vector<float> &positions : guide_positions) guide_buffers.push_back(blob.add(std::span<const float>(positions)));
  json.key("positions").begin_array();
  for (int b : guides_of_frame) json.value(guide_buffers[size_t(b)]);
  json.end_array().end_object();

  // Feathers' vanes: triangles once, positions per frame.
  if (input.vane_positions) {
    std::vector<uint32_t> vane_triangles;
    vane_triangles.reserve(input.vane_triangles.size() * 3);
    for (const Eigen::Vector3i &t : input.vane_triangles)
      vane_triangles.insert(vane_triangles.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
    json.key("vanes").begin_object().key("vertex_count").value(input.vane_vertex_count);
    json.key("triangle_count").value(input.vane_triangles.size());
    json.key("triangles").value(blob.add(std::span<const uint32_t>(vane_triangles)));
    json.key("positions").begin_array();
    for (const std::vector<float> &positions : vane_positions) json.value(blob.add(std::span<const float>(positions)));
    json.end_array().end_object();
    vane_positions.clear();
  } else {
    json.key("vanes").null();
  }

  // Colours, one per shown strand (sRGB), as the preview PNGs draw them.
  StrandSet shown_strands;  // ids and counts only: what the colours read
  shown_strands.offsets.assign(offsets.begin(), offsets.end());
  shown_strands.positions.resize(size_t(offsets.back()));
  for (uint32_t s : shown) shown_strands.ids.push_back(input.ids[s]);
  StrandAttributes attributes;
  if (input.attributes) {
    attributes.zone_count = input.attributes->zone_count;
    for (uint32_t s : shown) {
      attributes.guide.push_back(input.attributes->guide[s]);
      attributes.zone.push_back(input.attributes->zone[s]);
      if (!input.attributes->clump.empty()) attributes.clump.push_back(input.attributes->clump[s]);
      if (!input.attributes->side.empty()) attributes.side.push_back(input.attributes->side[s]);
    }
  }
  const auto add_colors = [&](const std::vector<Rgb8> &colors) {
    std::vector<uint8_t> bytes;
    bytes.reserve(colors.size() * 3);
    for (const Rgb8 &c : colors) bytes.insert(bytes.end(), c.begin(), c.end());
    return blob.add(std::span<const uint8_t>(bytes));
  };
  json.key("colors").begin_array();
  for (ColorMode mode : kColorModes) {
    // Guide, clump and zone are a groom's: strand files have none.
    if (!input.attributes && mode != ColorMode::plain && mode != ColorMode::problems) continue;
    json.begin_object().key("mode").value(color_mode_name(mode));
    switch (mode) {
      case ColorMode::plain: json.key("label").value("Plain"); break;
      case ColorMode::guide: json.key("label").value("Guide").key("note").value("the guide that weighs most"); break;
      case ColorMode::clump:
        json.key("label").value("Clump");
        if (attributes.clump.empty()) json.key("note").value("no clump effect in this groom");
        break;
      case ColorMode::zone:
        json.key("label").value("Zone / parting side");
        json.key("note").value(std::to_string(attributes.zone_count) + (attributes.zone_count == 1 ? " zone" : " zones") +
                               (attributes.side.empty() ? ", no partial parting"
                                                        : "; the sides of a partial parting lighter and darker"));
        break;
      case ColorMode::problems: json.key("label").value("Problems (plume check)"); break;
    }
    if (mode != ColorMode::problems) json.key("colors").value(add_colors(strand_colors(mode, shown_strands, attributes, nullptr)));
    json.end_object();
  }
  json.end_array();

  // The checker's findings per frame, with the flags of the shown strands.
  json.key("check").begin_object();
  json.key("margin").value(args.margin).key("tolerance_option").value(args.tolerance);
  json.key("transversal_degrees").value(check_options.transversal_degrees);
  json.key("before_effects").value(bool(input.produce_before_effects));
  json.key("palette").begin_object();
  json.key("clean");
  write_color(json, kProblemClean);
  json.key("inside");
  write_color(json, kProblemInsideColor);
  json.key("crossing");
  write_color(json, kProblemCrossingColor);
  json.key("both");
  write_color(json, kProblemBothColor);
  json.key("touching");
  write_color(json, kProblemTouchingColor);
  json.end_object();
  json.key("frames").begin_array();
  int clean_flags = -1;
  for (const FrameCheck &check : checks) {
    std::vector<uint8_t> flags(shown.size(), 0);
    size_t flagged_here = 0, violations = 0, violations_here = 0;
    for (const auto &[s, f] : check.flagged) {
      violations += problem_is_violation(f);
      const auto at = std::lower_bound(shown.begin(), shown.end(), s);
      if (at != shown.end() && *at == s) {
        flags[size_t(at - shown.begin())] = f;
        ++flagged_here;
        violations_here += problem_is_violation(f);
      }
    }
    int buffer;
    if (flagged_here == 0) {
      if (clean_flags < 0) clean_flags = blob.add(std::span<const uint8_t>(flags));
      buffer = clean_flags;
    } else {
      buffer = blob.add(std::span<const uint8_t>(flags));
    }
    json.begin_object();
    json.key("points_inside").value(check.counts.points_inside).key("strands_inside").value(check.counts.strands_inside);
    json.key("tolerance").value(check.counts.tolerance);
    json.key("transversal_pairs").value(check.counts.transversal_pairs).key("touching_pairs").value(check.counts.touching_pairs);
    json.key("transversal_flagged").value(check.counts.transversal_flagged);
    json.key("touching_flagged").value(check.counts.touching_flagged);
    json.key("strands_flagged").value(violations).key("flagged_shown").value(violations_here);
    json.key("flags").value(buffer);
    json.end_object();
  }
  json.end_array().end_object();
  json.end_object();

  if (blob.byte_count() > kMaxPageDataBytes)
    throw InputError("--max-points " + std::to_string(args.max_points) + ": the page's data come to " +
                     std::to_string(blob.byte_count() >> 20) + " MB, more than a browser reads in one piece (" +
                     std::to_string(kMaxPageDataBytes >> 20) + " MB): give a smaller --max-points or fewer frames");
  write_view_page(args.out, input.title, json.text(), blob);
  summary.wrote(summary.add_output("page", args.out), args.out);
  summary.print();
}

/// The page of a feather groom: its rachis and barb curves as the strands (a sample keeps whole
/// feathers together: every curve of a feather carries its id), the guide stems as guides, and the
/// vanes as a mesh. The checker's colours mark points below the skin; feather against feather is
/// not judged here.
void view_feather_groom(const GroomDesc &groom, const PipelineOptions &options, const FrameRange &range,
                        const ViewArgs &args) {
  FeatherPipeline pipeline(groom, options);
  pipeline.base().check_frame_inputs(range);
  const feathers::CoatFrame rest = pipeline.rest_frame();

  ViewInput input;
  input.title = groom.name.empty() ? std::filesystem::path(groom.source).stem().string() : groom.name;
  input.source = groom_file_name(groom);
  input.fps = groom.dynamics.fps;
  input.skin = pipeline.base().rest_mesh();
  const StrandSet &curves = rest.curves.curves;
  input.offsets.assign(curves.offsets.begin(), curves.offsets.end());
  input.ids = curves.ids;
  input.guide_offsets = pipeline.base().guides().strands.offsets;
  input.skin_moves = groom.animation.kind != EmitterAnimation::Kind::none;
  input.guides_move = input.skin_moves || pipeline.base().dynamic();
  input.bounds = scene_bounds(input.skin, curves);
  for (const Eigen::Vector3f &p : rest.vanes.positions) input.bounds.extend(p);
  input.vane_triangles = rest.vanes.triangles;
  input.vane_vertex_count = int64_t(rest.vanes.positions.size());
  input.judge_crossings = false;
  auto last_vanes = std::make_shared<std::vector<float>>();
  input.produce = [&pipeline, last_vanes, &input](int frame) {
    FeatherPipeline::Frame grown = pipeline.produce(frame);
    if (grown.feathers.curves.curves.offsets.size() != input.offsets.size() ||
        int64_t(grown.feathers.vanes.positions.size()) != input.vane_vertex_count)
      throw InternalError("plume view: the coat's curves or vanes changed their counts at frame " +
                          std::to_string(frame));
    *last_vanes = flatten(grown.feathers.vanes.positions);
    FrameResult result;
    result.frame = frame;
    result.mesh = std::move(grown.mesh);
    result.guides = std::move(grown.stems);
    result.strands = std::move(grown.feathers.curves.curves);
    result.strands.ids.clear();  // the checker names curves by index (a feather's curves share its id)
    return result;
  };
  input.vane_positions = [last_vanes] { return std::move(*last_vanes); };
  write_view(input, range, args);
}

/// The page of a groom, from its pipeline.
void view_groom(const ViewArgs &args) {
  if (!args.mesh.empty()) throw InputError("--mesh: a groom names its emitter (--mesh is for strand files)");
  if (!args.guides.empty()) throw InputError("--guides: a groom names its guides (--guides is for strand files)");
  const GroomDesc groom = io::read_groom_file(args.input);
  require_one_group(groom, "plume view");
  const FrameRange range = frames_to_produce(args.frames, groom);
  const FrameRange first_only{range.first, range.first, 1};
  check_output_locations(args.out, first_only, "--out", RunInputs(groom, args.guides_cache));
  set_thread_count(args.threads);

  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  if (groom.feathers.enabled) {
    view_feather_groom(groom, options, range, args);
    return;
  }
  Pipeline pipeline(groom, options);
  pipeline.check_frame_inputs(range);

  ViewInput input;
  input.title = groom.name.empty() ? std::filesystem::path(groom.source).stem().string() : groom.name;
  input.source = groom_file_name(groom);
  input.fps = groom.dynamics.fps;
  input.skin = pipeline.rest_mesh();
  const size_t strand_count = pipeline.roots().size();
  input.offsets.resize(strand_count + 1);
  for (size_t s = 0; s <= strand_count; ++s) input.offsets[s] = int64_t(s) * groom.points_per_strand;
  input.ids = pipeline.roots().ids;
  input.guide_offsets = pipeline.guides().strands.offsets;
  input.skin_moves = groom.animation.kind != EmitterAnimation::Kind::none;
  input.guides_move = input.skin_moves || pipeline.dynamic();
  input.bounds = groom_bounds(pipeline);
  input.attributes = strand_attributes(pipeline);
  input.produce = [&pipeline](int frame) { return pipeline.produce(frame); };
  if (!groom.effects.empty())
    input.produce_before_effects = [&pipeline](int frame) { return pipeline.produce(frame, false).strands; };
  write_view(input, range, args);
}

/// The page of strand files (a file, or a pattern with a frame field and --frames), on the skin
/// of --mesh (a file, or a pattern) with the guides of --guides when given.
void view_strand_files(const ViewArgs &args) {
  if (args.mesh.empty())
    throw InputError("--mesh: expected the skin the strands stand on (.obj, or a pattern with a frame field), "
                     "or give a groom file");
  if (args.strands >= 0) throw InputError("--strands: strand files hold their strands (--strands is for grooms)");
  if (!args.guides_cache.empty()) throw InputError("--guides-cache: is for grooms (give --guides for strand files)");
  check_frame_syntax(args.input, "strand files");
  check_frame_syntax(args.mesh, "--mesh");
  if (!args.guides.empty()) check_frame_syntax(args.guides, "--guides");
  const bool sequence = has_frame_field(args.input);
  if (sequence && args.frames.empty())
    throw InputError("--frames: " + args.input + " names a file per frame: give the frames to show");
  const FrameRange range = args.frames.empty() ? FrameRange{1, 1, 1} : parse_frame_range(args.frames, "--frames");
  check_frames_per_run(range, "--frames");
  if (!sequence && range.count() > 1)
    throw InputError("--frames: " + args.input + " is one file: a range needs a pattern with a frame field (hair.####.usda)");
  if (io::detail::extension_of(args.mesh) != ".obj")
    throw InputError("--mesh: expected an .obj mesh, got \"" + args.mesh + "\"");
  set_thread_count(args.threads);

  // The first frame sets what every frame must match.
  const auto strands_at = [&](int frame) { return io::read_strands(expand_frame_pattern(args.input, frame)); };
  const StrandSet first = strands_at(range.first);
  const Mesh rest = io::read_obj_mesh(expand_frame_pattern(args.mesh, range.first));
  const bool mesh_moves = has_frame_field(args.mesh), guides_move = has_frame_field(args.guides);
  std::optional<StrandSet> fixed_guides;
  if (!args.guides.empty() && !guides_move) fixed_guides = io::read_strands(args.guides);

  ViewInput input;
  input.title = std::filesystem::path(expand_frame_pattern(args.input, range.first)).stem().string();
  input.source = std::filesystem::path(args.input).filename().string();
  input.skin = rest;
  input.offsets = first.offsets;
  input.ids = first.ids;
  if (input.ids.size() != first.strand_count()) {
    input.ids.resize(first.strand_count());
    std::iota(input.ids.begin(), input.ids.end(), uint64_t(0));
  }
  input.skin_moves = mesh_moves;
  input.guides_move = guides_move;
  input.bounds = scene_bounds(rest, first);
  if (fixed_guides) input.guide_offsets = fixed_guides->offsets;
  if (guides_move) input.guide_offsets = io::read_strands(expand_frame_pattern(args.guides, range.first)).offsets;
  input.produce = [&](int frame) {
    FrameResult result;
    result.frame = frame;
    const std::string path = expand_frame_pattern(args.input, frame);
    result.strands = frame == range.first && sequence ? first : strands_at(frame);
    if (result.strands.offsets != input.offsets)
      throw InputError(FileLoc{path}, "expected the strands of " + expand_frame_pattern(args.input, range.first) + " (" +
                                          std::to_string(first.strand_count()) + " strands, " +
                                          std::to_string(first.point_count()) + " points, the same per strand), got " +
                                          std::to_string(result.strands.strand_count()) + " strands, " +
                                          std::to_string(result.strands.point_count()) + " points");
    result.mesh = mesh_moves ? io::read_obj_pose(expand_frame_pattern(args.mesh, frame), rest) : rest;
    if (fixed_guides) result.guides = *fixed_guides;
    if (guides_move) {
      const std::string guides_path = expand_frame_pattern(args.guides, frame);
      result.guides = io::read_strands(guides_path);
      if (result.guides.offsets != input.guide_offsets)
        throw InputError(FileLoc{guides_path}, "expected the guides' strand and point counts of the first frame's file");
    }
    return result;
  };
  write_view(input, range, args);
}

void run_view(const ViewArgs &args) {
  check_frame_syntax(args.out, "--out");
  if (has_frame_field(args.out))
    throw InputError("--out: one page holds every frame of the range: expected a file name without a frame field, "
                     "got \"" + args.out + "\"");
  check_output_pattern(args.out, FrameRange{}, "--out", {".html"});
  const std::string ext = io::detail::extension_of(args.input);
  if (ext == ".yaml" || ext == ".yml") {
    view_groom(args);
    return;
  }
  if (ext != ".usda" && ext != ".hair" && ext != ".ply" && ext != ".obj")
    throw InputError("expected a groom (.yaml) or strand files (.usda .hair .ply .obj), got \"" + args.input + "\"");
  // Strand files are inputs too: the page must not overwrite one of them.
  std::error_code error;
  for (const std::string &input : {args.input, args.mesh, args.guides})
    if (!input.empty() && !has_frame_field(input) && std::filesystem::equivalent(args.out, input, error))
      throw InputError("--out: " + args.out + " is " + input + ", which this run reads: choose another output");
  check_output_locations(args.out, FrameRange{}, "--out", RunInputs(GroomDesc{}, {}));
  view_strand_files(args);
}

}  // namespace

void add_view_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App *cmd = app.add_subcommand(
      "view", "Write one self-contained HTML page to turn a groom, or strand files, in 3D in a browser (no server, "
              "no network).");
  cmd->add_option("input", args->input,
                  "Groom file (.yaml), or strand files (.usda .hair .ply .obj; a pattern with #### for a range)")
      ->required();
  cmd->add_option("--out", args->out, "The page (.html)")->required();
  cmd->add_option("--frames", args->frames,
                  "Frames: 7, 1-48, 1-48:4 or 1-48x4; a range gets a frame slider (default: a groom's output.frames)")
      ->check(non_empty_frames());
  cmd->add_option("--mesh", args->mesh,
                  "Strand files: the skin they stand on (.obj; a pattern with #### for a moving skin)");
  cmd->add_option("--guides", args->guides, "Strand files: guides to show with them (a file, or a pattern)");
  cmd->add_option("--max-points", args->max_points,
                  "The most points the page holds over all its frames (default 4,000,000: about 65 MB); beyond it "
                  "the page shows a stated sample of the strands, those with a violation first")
      ->check(CLI::Range(int64_t(1), kMaxViewPoints));
  cmd->add_option("--tolerance", args->tolerance,
                  "Crossing tolerance for the problems colours, as plume check's (scene units; default: 1e-3 of the "
                  "strands' median segment length)")
      ->check(finite_non_negative());
  cmd->add_option("--margin", args->margin, "Skin margin for the problems colours, as plume check's")
      ->check(finite_non_negative());
  add_threads_option(*cmd, args->threads, "Worker threads");
  add_strands_option(*cmd, args->strands, "A groom: override its root count");
  cmd->add_option("--guides-cache", args->guides_cache, "A groom with dynamics: read the guides from this cache pattern");
  cmd->callback([args, &r_exit_code] {
    run_view(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
