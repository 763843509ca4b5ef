#include "app/strand_colors.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <unordered_map>

#include "app/pipeline.h"
#include "check/check.h"
#include "effects/effects.h"
#include "groom/error.h"
#include "groom/mesh_query.h"
#include "groom/roots.h"
#include "interp/interpolate.h"
#include "partings/parting_field.h"

namespace plume {

const char *color_mode_name(ColorMode mode) {
  switch (mode) {
    case ColorMode::plain: return "plain";
    case ColorMode::guide: return "guide";
    case ColorMode::clump: return "clump";
    case ColorMode::zone: return "zone";
    case ColorMode::problems: return "problems";
  }
  return "plain";
}

ColorMode parse_color_mode(const std::string &text, const std::string &what) {
  for (ColorMode mode : kColorModes)
    if (text == color_mode_name(mode)) return mode;
  throw InputError(what + ": expected plain, guide, clump, zone or problems, got \"" + text + "\"");
}

namespace {

// The side of the nearest partial parting line of each root (StrandAttributes::side).
std::vector<int8_t> parting_sides(const Pipeline &pipeline) {
  const Mesh &mesh = pipeline.rest_mesh();
  const Roots &roots = pipeline.roots();
  std::vector<const PartingLine *> lines;
  for (const PartingLine &line : pipeline.groom().partings.lines)
    if (!line.hard && line.points.size() >= 2) lines.push_back(&line);
  if (lines.empty()) return {};
  std::vector<int8_t> sides(roots.size(), 0);
#pragma omp parallel for schedule(static)
  for (int64_t r = 0; r < int64_t(roots.size()); ++r) {
    const Eigen::Vector3f p = surface_position(mesh, roots.points[size_t(r)]);
    const Eigen::Vector3f n = surface_normal(mesh, roots.points[size_t(r)]);
    float best = std::numeric_limits<float>::infinity();
    int8_t side = 0;
    for (const PartingLine *line : lines) {
      const std::vector<Eigen::Vector3f> &q = line->points;
      const size_t segment_count = line->closed ? q.size() : q.size() - 1;
      float length = 0.0f;
      for (size_t i = 0; i < segment_count; ++i) length += (q[(i + 1) % q.size()] - q[i]).norm();
      for (size_t i = 0; i < segment_count; ++i) {
        const Eigen::Vector3f &a = q[i], &b = q[(i + 1) % q.size()];
        const Eigen::Vector3f ab = b - a;
        const float ab2 = ab.squaredNorm();
        if (ab2 <= 0.0f) continue;
        const float t = std::clamp((p - a).dot(ab) / ab2, 0.0f, 1.0f);
        const float d = (p - (a + t * ab)).norm();
        if (!(d < best)) continue;
        best = d;
        // Past an open line's ends the parting does not part: no side there.
        const bool past_end = !line->closed && ((i == 0 && t <= 0.0f) || (i + 1 == segment_count && t >= 1.0f));
        const float across = (p - a).dot(ab.cross(n));
        side = past_end || d > 0.25f * length || across == 0.0f ? 0 : across > 0.0f ? 1 : -1;
      }
    }
    sides[size_t(r)] = side;
  }
  return sides;
}

// A colour for category `key` (a guide, a clump): hue, saturation and value hashed from the key,
// so that neighbours are told apart and a category keeps its colour from frame to frame.
Rgb8 category_color(int64_t key) {
  if (key < 0) return {90, 90, 90};
  const uint64_t h = hash64(uint64_t(key) ^ 0x706c756d65ull);
  const float hue = hash_to_unit(h) * 6.0f;
  const float saturation = 0.5f + 0.4f * hash_to_unit(hash64(h));
  const float value = 0.7f + 0.3f * hash_to_unit(hash64(h + 1));
  const int sector = std::min(int(hue), 5);
  const float f = hue - float(sector);
  const float p = value * (1.0f - saturation), q = value * (1.0f - saturation * f),
              t = value * (1.0f - saturation * (1.0f - f));
  Eigen::Vector3f rgb;
  switch (sector) {
    case 0: rgb = {value, t, p}; break;
    case 1: rgb = {q, value, p}; break;
    case 2: rgb = {p, value, t}; break;
    case 3: rgb = {p, q, value}; break;
    case 4: rgb = {t, p, value}; break;
    default: rgb = {value, p, q}; break;
  }
  return {uint8_t(std::lround(rgb[0] * 255.0f)), uint8_t(std::lround(rgb[1] * 255.0f)),
          uint8_t(std::lround(rgb[2] * 255.0f))};
}

// Zones take well-separated hues in order (a few zones, side by side on the head).
Rgb8 zone_color(int zone, int8_t side) {
  static constexpr Rgb8 kZones[] = {{86, 150, 230}, {235, 150, 60}, {110, 200, 110}, {215, 90, 160},
                                    {160, 120, 225}, {225, 210, 80}, {80, 200, 200},  {230, 100, 90}};
  const Rgb8 base = zone >= 0 && zone < 8 ? kZones[zone] : category_color(zone);
  if (side == 0) return base;
  // The two sides of a partial parting: lighter on the left, darker on the right.
  Rgb8 out;
  for (int k = 0; k < 3; ++k)
    out[k] = side < 0 ? uint8_t(base[k] + (255 - base[k]) * 45 / 100) : uint8_t(base[k] * 50 / 100);
  return out;
}

}  // namespace

StrandAttributes strand_attributes(const Pipeline &pipeline) {
  StrandAttributes attributes;
  const size_t root_count = pipeline.roots().size();
  const interp::Binding &binding = pipeline.binding();
  attributes.guide.resize(root_count, -1);
  // Slots are ordered by decreasing weight: the first is the guide that weighs most.
  for (size_t r = 0; r < root_count && binding.k > 0; ++r) attributes.guide[r] = binding.guide_ids[r * size_t(binding.k)];
  const std::vector<EffectDesc> &effects = pipeline.groom().effects;
  for (size_t e = 0; e < effects.size(); ++e) {
    if (effects[e].type != EffectType::clump) continue;
    attributes.clump = pipeline.effects().clump_centres(e);
    break;
  }
  const partings::PartingField &partings = pipeline.partings();
  attributes.zone_count = partings.zone_count();
  attributes.zone.resize(root_count);
  for (size_t r = 0; r < root_count; ++r) attributes.zone[r] = partings.zone_of(pipeline.roots().points[r]);
  attributes.side = parting_sides(pipeline);
  return attributes;
}

StrandProblems find_problems(const StrandSet &strands, const Mesh &mesh, const ProblemOptions &options,
                             const StrandSet *before_effects) {
  StrandProblems problems;
  const size_t strand_count = strands.strand_count();
  problems.flags.assign(strand_count, 0);
  if (before_effects && before_effects->strand_count() != strand_count)
    throw InternalError("find_problems: " + std::to_string(before_effects->strand_count()) +
                        " strands before effects for " + std::to_string(strand_count));
  // The checker names strands by id (by index when they have none).
  const bool has_ids = strands.ids.size() == strand_count;
  std::unordered_map<uint64_t, uint32_t> index_of;
  if (has_ids) {
    index_of.reserve(strand_count);
    for (size_t s = 0; s < strand_count; ++s) index_of.emplace(strands.ids[s], uint32_t(s));
  }
  const auto flag = [&](uint64_t id, uint8_t bit) {
    if (!has_ids) {
      if (id < strand_count) problems.flags[size_t(id)] |= bit;
      return;
    }
    const auto found = index_of.find(id);
    if (found != index_of.end()) problems.flags[found->second] |= bit;
  };
  const MeshQuery query(mesh);
  std::vector<uint64_t> inside;
  problems.points_inside = check::count_points_inside(strands, query, options.skin_margin, strand_count, inside);
  problems.strands_inside = inside.size();
  for (uint64_t id : inside) flag(id, kProblemInside);
  if (!options.judge_crossings) return problems;

  check::CheckOptions check_options;
  check_options.crossing_tolerance = options.crossing_tolerance;
  problems.tolerance = check::crossing_tolerance_for(strands, check_options);
  problems.crossings_before_effects = before_effects != nullptr;
  // The strands judged keep the checked strands' ids, so that the examples name them.
  StrandSet judged_copy;
  const StrandSet *judged = &strands;
  if (before_effects) {
    judged_copy = *before_effects;
    judged_copy.ids = strands.ids;
    judged = &judged_copy;
  }
  check::CrossingCount crossings =
      check::count_crossings(*judged, problems.tolerance, options.max_pairs, options.transversal_degrees);
  problems.transversal_pairs = crossings.transversal_pairs;
  problems.touching_pairs = crossings.touching_pairs;
  if (crossings.transversal_pairs > crossings.transversal_examples.size() ||
      crossings.touching_pairs > crossings.touching_examples.size()) {
    // The checker keeps its lowest pairs by strand index, and neighbouring roots have neighbouring
    // indices: with more pairs than are flagged, the strands go to it again in an order hashed from
    // their ids, so that the pairs flagged are a sample spread over the whole groom, not one patch.
    // The counts stay the first ones, made in the order plume check uses (the order may change the
    // verdict on a segment pair whose distance rounds to the tolerance). The shuffled set's ids are
    // the strands' indices, so its examples name them directly.
    std::vector<uint32_t> order(strand_count);
    std::vector<uint64_t> keys(strand_count);
    for (size_t s = 0; s < strand_count; ++s) {
      order[s] = uint32_t(s);
      keys[s] = hash64((has_ids ? strands.ids[s] : s) ^ 0x63726f7373ull);
    }
    std::sort(order.begin(), order.end(),
              [&](uint32_t a, uint32_t b) { return keys[a] != keys[b] ? keys[a] < keys[b] : a < b; });
    StrandSet shuffled;
    shuffled.offsets.reserve(strand_count + 1);
    shuffled.positions.reserve(judged->point_count());
    shuffled.ids.reserve(strand_count);
    for (uint32_t s : order) shuffled.append(judged->points(s), s);
    const check::CrossingCount sample =
        check::count_crossings(shuffled, problems.tolerance, options.max_pairs, options.transversal_degrees);
    crossings.transversal_examples = sample.transversal_examples;
    crossings.touching_examples = sample.touching_examples;
    for (auto &examples : {&crossings.transversal_examples, &crossings.touching_examples})
      for (auto &[a, b] : *examples) {
        a = has_ids ? strands.ids[size_t(a)] : a;
        b = has_ids ? strands.ids[size_t(b)] : b;
      }
  }
  for (const auto &[a, b] : crossings.transversal_examples) {
    flag(a, kProblemCrossing);
    flag(b, kProblemCrossing);
  }
  for (const auto &[a, b] : crossings.touching_examples) {
    flag(a, kProblemTouching);
    flag(b, kProblemTouching);
  }
  problems.transversal_flagged = crossings.transversal_examples.size();
  problems.touching_flagged = crossings.touching_examples.size();
  return problems;
}

Rgb8 problem_color(uint8_t flags) {
  switch (flags & (kProblemInside | kProblemCrossing)) {
    case kProblemInside: return kProblemInsideColor;
    case kProblemCrossing: return kProblemCrossingColor;
    case kProblemInside | kProblemCrossing: return kProblemBothColor;
    default: return flags & kProblemTouching ? kProblemTouchingColor : kProblemClean;
  }
}

std::vector<Rgb8> strand_colors(ColorMode mode, const StrandSet &strands, const StrandAttributes &attributes,
                                const StrandProblems *problems, const PreviewStyle &style) {
  const size_t strand_count = strands.strand_count();
  const auto covers = [&](size_t size) { return size == strand_count; };
  if ((mode == ColorMode::guide && !covers(attributes.guide.size())) ||
      (mode == ColorMode::zone && !covers(attributes.zone.size())) ||
      (mode == ColorMode::clump && !attributes.clump.empty() && !covers(attributes.clump.size())) ||
      (mode == ColorMode::problems && problems && !covers(problems->flags.size())))
    throw InternalError(std::string("strand_colors: the ") + color_mode_name(mode) + " data do not cover the " +
                        std::to_string(strand_count) + " strands");
  std::vector<Rgb8> colors(strand_count);
  for (size_t s = 0; s < strand_count; ++s) {
    const uint64_t id = s < strands.ids.size() ? strands.ids[s] : s;
    switch (mode) {
      case ColorMode::plain: colors[s] = srgb_from_linear(plain_hair_color(style, id)); break;
      case ColorMode::guide: colors[s] = category_color(attributes.guide[s]); break;
      case ColorMode::clump:
        colors[s] = attributes.clump.empty() ? srgb_from_linear(plain_hair_color(style, id))
                                             : category_color(attributes.clump[s]);
        break;
      case ColorMode::zone:
        colors[s] = zone_color(attributes.zone[s], attributes.side.empty() ? int8_t(0) : attributes.side[s]);
        break;
      case ColorMode::problems: colors[s] = problem_color(problems ? problems->flags[s] : 0); break;
    }
  }
  return colors;
}

Rgb8 srgb_from_linear(const Eigen::Vector3f &linear) {
  Rgb8 out;
  for (int k = 0; k < 3; ++k) {
    const float c = std::clamp(linear[k], 0.0f, 1.0f);
    const float encoded = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f;
    out[k] = uint8_t(std::lround(encoded * 255.0f));
  }
  return out;
}

Eigen::Vector3f linear_from_srgb(const Rgb8 &srgb) {
  Eigen::Vector3f out;
  for (int k = 0; k < 3; ++k) {
    const float c = float(srgb[k]) / 255.0f;
    out[k] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
  }
  return out;
}

std::vector<Eigen::Vector3f> linear_colors(const std::vector<Rgb8> &colors) {
  std::vector<Eigen::Vector3f> out(colors.size());
  for (size_t i = 0; i < colors.size(); ++i) out[i] = linear_from_srgb(colors[i]);
  return out;
}

}  // namespace plume
