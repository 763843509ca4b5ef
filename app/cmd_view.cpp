// `plume view GROOM --out view.html [--frames 1-48]`: one self-contained HTML page in which to turn
// the groom in 3D: the skin, the strands (all of them, or a stated sample within the page's size
// budget, every strand the checker reports included), the guides, colours by attribute and by the
// checker's problems, and a frame slider for a range. Layout of the page: docs/viewer.md.
#include <algorithm>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <numeric>

#include "app/commands.h"
#include "app/pipeline.h"
#include "app/progress.h"
#include "app/strand_colors.h"
#include "app/view_page.h"
#include "groom/error.h"
#include "groom/roots.h"
#include "io/groom_file.h"

namespace plume {

namespace {

/// The most points (strand, skin and guide points over all frames) a page holds by default: 48 MB
/// of float32 positions, a page of about 70 MB that a browser loads in seconds. 100,000 strands of
/// 32 points fit in one frame.
constexpr int64_t kDefaultViewPoints = 4'000'000;
/// Beyond this a page (1.2 GB of text) is more than a browser opens.
constexpr int64_t kMaxViewPoints = 64'000'000;

struct ViewArgs {
  std::string groom;
  std::string frames;
  std::string out;
  int64_t strands = -1;
  int64_t max_points = kDefaultViewPoints;
  float tolerance = 0.0f;
  float margin = 0.0f;
  int threads = 0;
  std::string guides_cache;
};

/// One frame's findings, kept for the manifest: the counts and the strands flagged (sparse).
struct FrameCheck {
  StrandProblems counts;  // flags left empty
  std::vector<std::pair<uint32_t, uint8_t>> flagged;  // (strand, flags), ascending
};

/// The `count` strands of `ids` with the lowest hashed ids, ascending by index: a sample spread over
/// the groom that keeps the same strands whatever the frame (and, for scattered roots, whatever the
/// count: ids are stable).
std::vector<uint32_t> hashed_sample(const std::vector<uint64_t> &ids, const std::vector<uint32_t> &candidates,
                                    size_t count) {
  std::vector<uint32_t> sample = candidates;
  const auto key = [&](uint32_t s) { return std::pair(hash64(ids[s] ^ 0x7669657765ull), s); };
  if (sample.size() > count) {
    std::nth_element(sample.begin(), sample.begin() + std::ptrdiff_t(count), sample.end(),
                     [&](uint32_t a, uint32_t b) { return key(a) < key(b); });
    sample.resize(count);
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

void run_view(const ViewArgs &args) {
  const GroomDesc groom = io::read_groom_file(args.groom);
  const FrameRange range = frames_to_produce(args.frames, groom);
  check_frame_syntax(args.out, "--out");
  if (has_frame_field(args.out))
    throw InputError("--out: one page holds every frame of the range: expected a file name without a frame field, "
                     "got \"" + args.out + "\"");
  const FrameRange first_only{range.first, range.first, 1};
  check_output_pattern(args.out, first_only, "--out", {".html"});
  check_output_locations(args.out, first_only, "--out", RunInputs(groom, args.guides_cache));
  set_thread_count(args.threads);

  PipelineOptions options;
  options.strand_count = args.strands;
  options.guides_cache = args.guides_cache;
  options.simulation_start = std::min(groom_first_frame(groom), range.first);
  Pipeline pipeline(groom, options);
  pipeline.check_frame_inputs(range);

  // The budget: every point the page holds over its frames. The skin moves with a rigid or OBJ
  // sequence animation, the guides with it or with dynamics; otherwise each is stored once.
  const int64_t frame_count = range.count();
  const bool skin_moves = groom.animation.kind != EmitterAnimation::Kind::none;
  const bool guides_move = skin_moves || pipeline.dynamic();
  const int64_t other_points = int64_t(pipeline.rest_mesh().vertex_count()) * (skin_moves ? frame_count : 1) +
                               int64_t(pipeline.guides().strands.point_count()) * (guides_move ? frame_count : 1);
  const int64_t strand_points = int64_t(groom.points_per_strand) * frame_count;
  if (other_points + strand_points > args.max_points)
    throw InputError("--max-points " + std::to_string(args.max_points) + ": the page cannot hold one strand over " +
                     std::to_string(frame_count) + " frames (the skin and guides take " + with_commas(other_points) +
                     " points, a strand " + with_commas(strand_points) +
                     "): give fewer frames (--frames A-B:STEP) or a larger --max-points");
  const size_t strand_count = pipeline.roots().size();
  const size_t shown_max = size_t(std::min<int64_t>(int64_t(strand_count), (args.max_points - other_points) / strand_points));
  const std::vector<uint64_t> &ids = pipeline.roots().ids;
  std::vector<uint32_t> every(strand_count);
  std::iota(every.begin(), every.end(), 0u);
  // The strands kept in the first pass: the sample, or all of them.
  const std::vector<uint32_t> kept = hashed_sample(ids, every, shown_max);

  ProblemOptions check_options;
  check_options.crossing_tolerance = args.tolerance;
  check_options.skin_margin = args.margin;
  std::vector<FrameCheck> checks(static_cast<size_t>(frame_count));
  std::vector<uint8_t> ever_flagged(strand_count, 0);
  std::vector<std::vector<float>> skin_positions, guide_positions, kept_positions;
  std::vector<int> skin_of_frame(static_cast<size_t>(frame_count)), guides_of_frame(static_cast<size_t>(frame_count));
  {
    Progress progress("view", int(frame_count));
    for (int64_t i = 0; i < frame_count; ++i) {
      const FrameResult result = pipeline.produce(range.at(i));
      try {
        StrandProblems problems = find_problems(result.strands, result.mesh, check_options);
        FrameCheck &check = checks[size_t(i)];
        for (size_t s = 0; s < problems.flags.size(); ++s) {
          if (!problems.flags[s]) continue;
          check.flagged.emplace_back(uint32_t(s), problems.flags[s]);
          ever_flagged[s] = 1;
        }
        problems.flags.clear();
        check.counts = problems;
      } catch (const InputError &e) {
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
      progress.frame_done(range.at(i));
    }
  }

  // The strands shown: every strand the checker flagged in some frame (a sample of them when they
  // alone exceed the budget), then the kept sample up to the budget.
  std::vector<uint32_t> flagged_strands;
  for (size_t s = 0; s < strand_count; ++s)
    if (ever_flagged[s]) flagged_strands.push_back(uint32_t(s));
  std::vector<uint32_t> shown = hashed_sample(ids, flagged_strands, shown_max);
  size_t flagged_shown = shown.size();
  if (shown.size() < shown_max) {
    std::vector<uint32_t> rest;
    std::set_difference(kept.begin(), kept.end(), shown.begin(), shown.end(), std::back_inserter(rest));
    rest = hashed_sample(ids, rest, shown_max - shown.size());
    std::vector<uint32_t> merged;
    std::merge(shown.begin(), shown.end(), rest.begin(), rest.end(), std::back_inserter(merged));
    shown = std::move(merged);
  }
  std::vector<std::vector<float>> shown_positions;
  if (std::includes(kept.begin(), kept.end(), shown.begin(), shown.end())) {
    // Every shown strand was kept: take its points from the first pass.
    std::vector<size_t> slot(shown.size());
    for (size_t k = 0, j = 0; k < shown.size(); ++k) {
      while (kept[j] != shown[k]) ++j;
      slot[k] = j;
    }
    const size_t points = size_t(groom.points_per_strand) * 3;
    for (std::vector<float> &frame : kept_positions) {
      std::vector<float> out;
      out.reserve(shown.size() * points);
      for (size_t k = 0; k < shown.size(); ++k)
        out.insert(out.end(), frame.begin() + std::ptrdiff_t(slot[k] * points),
                   frame.begin() + std::ptrdiff_t((slot[k] + 1) * points));
      shown_positions.push_back(std::move(out));
    }
  } else {
    // Flagged strands outside the sample: grow the frames again for their points.
    kept_positions.clear();
    Progress progress("view (strands the checker flagged)", int(frame_count));
    for (int64_t i = 0; i < frame_count; ++i) {
      shown_positions.push_back(gather(pipeline.produce(range.at(i)).strands, shown));
      progress.frame_done(range.at(i));
    }
  }
  kept_positions.clear();

  // The shown strands as a set (first frame), for their colours.
  StrandSet shown_strands;
  shown_strands.resize_uniform(shown.size(), groom.points_per_strand, false, StrandSet::Fill::unset);
  for (size_t k = 0; k < shown.size(); ++k) shown_strands.ids[k] = ids[shown[k]];
  const StrandAttributes all_attributes = strand_attributes(pipeline);
  StrandAttributes attributes;
  attributes.zone_count = all_attributes.zone_count;
  for (uint32_t s : shown) {
    attributes.guide.push_back(all_attributes.guide[s]);
    attributes.zone.push_back(all_attributes.zone[s]);
    if (!all_attributes.clump.empty()) attributes.clump.push_back(all_attributes.clump[s]);
    if (!all_attributes.side.empty()) attributes.side.push_back(all_attributes.side[s]);
  }

  ViewBlob blob;
  JsonWriter json;
  const std::string title = groom.name.empty() ? std::filesystem::path(groom.source).stem().string() : groom.name;
  json.begin_object();
  json.key("format").value("plume-view").key("version").value(1);
  json.key("title").value(title).key("source").value(groom.source).key("generator").value("plume " PLUME_VERSION);
  json.key("three").value(viewer_assets().three_version);
  json.key("up");
  write_vector(json, Eigen::Vector3f::UnitY());
  json.key("front");
  write_vector(json, Eigen::Vector3f::UnitZ());
  const Eigen::AlignedBox3f bounds = groom_bounds(pipeline);
  const CameraAngle camera;
  json.key("bounds").begin_object().key("min");
  write_vector(json, bounds.min());
  json.key("max");
  write_vector(json, bounds.max());
  json.end_object();
  json.key("camera").begin_object().key("azimuth").value(camera.azimuth_degrees);
  json.key("elevation").value(camera.elevation_degrees).key("fov").value(PreviewCamera().fov_y_degrees);
  json.end_object();
  json.key("fps").value(groom.dynamics.fps);
  json.key("frames").begin_array();
  for (int64_t i = 0; i < frame_count; ++i) json.value(range.at(i));
  json.end_array();

  // The skin: triangles once, positions per frame (frames sharing a pose share a buffer).
  std::vector<uint32_t> triangles;
  for (const Eigen::Vector3i &t : pipeline.rest_mesh().triangles) triangles.insert(triangles.end(), {uint32_t(t[0]), uint32_t(t[1]), uint32_t(t[2])});
  json.key("skin").begin_object().key("vertex_count").value(pipeline.rest_mesh().vertex_count());
  json.key("triangles").value(blob.add(std::span<const uint32_t>(triangles)));
  std::vector<int> skin_buffers;
  for (const std::vector<float> &positions : skin_positions) skin_buffers.push_back(blob.add(std::span<const float>(positions)));
  skin_positions.clear();
  json.key("positions").begin_array();
  for (int b : skin_of_frame) json.value(skin_buffers[size_t(b)]);
  json.end_array().end_object();

  // The strands: offsets into the points, stable ids, positions per frame.
  std::vector<uint32_t> offsets(shown.size() + 1);
  for (size_t k = 0; k <= shown.size(); ++k) offsets[k] = uint32_t(k * size_t(groom.points_per_strand));
  std::vector<double> shown_ids(shown.size());
  for (size_t k = 0; k < shown.size(); ++k) shown_ids[k] = double(ids[shown[k]]);
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
  const StrandSet &guides = pipeline.guides().strands;
  std::vector<uint32_t> guide_offsets(guides.offsets.begin(), guides.offsets.end());
  json.key("guides").begin_object().key("count").value(guides.strand_count());
  json.key("offsets").value(blob.add(std::span<const uint32_t>(guide_offsets)));
  std::vector<int> guide_buffers;
  for (const std::vector<float> &positions : guide_positions) guide_buffers.push_back(blob.add(std::span<const float>(positions)));
  json.key("positions").begin_array();
  for (int b : guides_of_frame) json.value(guide_buffers[size_t(b)]);
  json.end_array().end_object();

  // Feathers' vanes: none in this groom.
  json.key("vanes").null();

  // Colours, one per shown strand (sRGB), as the preview PNGs draw them.
  const auto add_colors = [&](const std::vector<Rgb8> &colors) {
    std::vector<uint8_t> bytes;
    bytes.reserve(colors.size() * 3);
    for (const Rgb8 &c : colors) bytes.insert(bytes.end(), c.begin(), c.end());
    return blob.add(std::span<const uint8_t>(bytes));
  };
  json.key("colors").begin_array();
  for (ColorMode mode : kColorModes) {
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
  json.key("margin").value(args.margin).key("tolerance").value(args.tolerance);
  json.key("crossings_checked").value(args.tolerance > 0.0f);
  json.key("palette").begin_object();
  json.key("clean");
  write_color(json, kProblemClean);
  json.key("inside");
  write_color(json, kProblemInsideColor);
  json.key("crossing");
  write_color(json, kProblemCrossingColor);
  json.key("both");
  write_color(json, kProblemBothColor);
  json.end_object();
  json.key("frames").begin_array();
  int clean_flags = -1;
  for (const FrameCheck &check : checks) {
    std::vector<uint8_t> flags(shown.size(), 0);
    size_t flagged_here = 0;
    for (const auto &[s, f] : check.flagged) {
      const auto at = std::lower_bound(shown.begin(), shown.end(), s);
      if (at != shown.end() && *at == s) {
        flags[size_t(at - shown.begin())] = f;
        ++flagged_here;
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
    json.key("crossing_pairs").value(check.counts.crossing_pairs).key("pairs_flagged").value(check.counts.pairs_flagged);
    json.key("strands_flagged").value(check.flagged.size()).key("flagged_shown").value(flagged_here);
    json.key("flags").value(buffer);
    json.end_object();
  }
  json.end_array().end_object();
  json.end_object();

  write_view_page(args.out, title, json.text(), blob);
}

}  // namespace

void add_view_command(CLI::App &app, int &r_exit_code) {
  auto args = std::make_shared<ViewArgs>();
  CLI::App *cmd = app.add_subcommand(
      "view", "Write one self-contained HTML page to turn a groom in 3D in a browser (no server, no network).");
  cmd->add_option("groom", args->groom, "Groom file (.yaml)")->required();
  cmd->add_option("--out", args->out, "The page (.html)")->required();
  cmd->add_option("--frames", args->frames,
                  "Frames: 7, 1-48 or 1-48:2; a range gets a frame slider (default: the groom's output.frames)");
  cmd->add_option("--max-points", args->max_points,
                  "The most points the page holds over all its frames (default 4,000,000: about 70 MB); beyond it "
                  "the page shows a stated sample of the strands, with every strand the checker flags")
      ->check(CLI::Range(int64_t(1), kMaxViewPoints));
  cmd->add_option("--tolerance", args->tolerance,
                  "Crossing tolerance for the problems colours, as plume check's (scene units; 0, the default, skips "
                  "crossings)")
      ->check(finite_non_negative());
  cmd->add_option("--margin", args->margin, "Skin margin for the problems colours, as plume check's")
      ->check(finite_non_negative());
  add_threads_option(*cmd, args->threads, "Worker threads");
  add_strands_option(*cmd, args->strands, "Override the groom's root count");
  cmd->add_option("--guides-cache", args->guides_cache, "Dynamics: read the guides from this cache pattern");
  cmd->callback([args, &r_exit_code] {
    run_view(*args);
    r_exit_code = 0;
  });
}

}  // namespace plume
