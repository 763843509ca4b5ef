#include "app/groom_outputs.h"

#include <cctype>
#include <filesystem>
#include <optional>
#include <utility>

#include "groom/error.h"
#include "io/usda_stage.h"

namespace plume {

namespace {

namespace fs = std::filesystem;

/// Where the frame field of `name` (a file name) starts and how long it is: a run of '#', a printf
/// field %d / %0Nd, or Houdini's $F / $FN.
std::optional<std::pair<size_t, size_t>> frame_field_in(const std::string &name) {
  for (size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '#') {
      size_t j = i;
      while (j < name.size() && name[j] == '#') ++j;
      return std::make_pair(i, j - i);
    }
    if (name[i] == '%') {
      size_t j = i + 1;
      while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
      if (j < name.size() && name[j] == 'd') return std::make_pair(i, j + 1 - i);
    }
    if (name[i] == '$' && i + 1 < name.size() && name[i + 1] == 'F') {
      size_t j = i + 2;
      while (j < name.size() && std::isdigit(static_cast<unsigned char>(name[j]))) ++j;
      return std::make_pair(i, j - i);
    }
  }
  return std::nullopt;
}

bool is_separator(char c) { return c == '.' || c == '_' || c == '-'; }

}  // namespace

std::vector<GroomDesc> hair_groups(const GroomDesc &groom) {
  if (groom.groups.empty()) return {groom};
  return groom.groups;
}

void require_one_group(const GroomDesc &groom, const std::string &command) {
  if (groom.groups.empty()) return;
  std::string names;
  for (const GroomDesc &group : groom.groups) names += (names.empty() ? "" : ", ") + group.group_name;
  throw InputError(FileLoc{groom.source}, "groups: " + command + " grows a groom of one hair group; this one has " +
                                              std::to_string(groom.groups.size()) + " (" + names +
                                              "): use plume regrow, which writes every group");
}

StrandSet concatenate_strands(const std::vector<const StrandSet *> &sets) {
  StrandSet all;
  bool widths = true;
  for (const StrandSet *set : sets) widths = widths && (!set->widths.empty() || set->point_count() == 0);
  for (const StrandSet *set : sets) {
    const int64_t base = all.offsets.back();
    for (size_t s = 1; s < set->offsets.size(); ++s) all.offsets.push_back(base + set->offsets[s]);
    all.positions.insert(all.positions.end(), set->positions.begin(), set->positions.end());
    all.ids.insert(all.ids.end(), set->ids.begin(), set->ids.end());
    if (widths) all.widths.insert(all.widths.end(), set->widths.begin(), set->widths.end());
  }
  return all;
}

std::string group_file_pattern(const std::string &pattern, const std::string &group_name) {
  const fs::path path(pattern);
  const std::string name = path.filename().string();
  size_t at = name.size();
  if (const auto field = frame_field_in(name)) {
    at = field->first;
    if (at > 0 && is_separator(name[at - 1])) --at;
  } else {
    const size_t dot = name.rfind('.');
    if (dot != std::string::npos && dot > 0) at = dot;
  }
  return (path.parent_path() / (name.substr(0, at) + "." + group_name + name.substr(at))).string();
}

std::string default_stage_path(const std::string &pattern) {
  const fs::path path(pattern);
  if (path.extension() != ".usda") return {};
  const std::string name = path.filename().string();
  const auto field = frame_field_in(name);
  if (!field) return {};
  size_t start = field->first, end = field->first + field->second;
  // The separator before the field goes with it (hair.####.usda: "hair" + ".usda"); with none
  // before it, the one after it does (####_hair.usda: "hair.usda").
  if (start > 0 && is_separator(name[start - 1])) --start;
  else if (end < name.size() && is_separator(name[end]) && name[end] != '.') ++end;
  const std::string stage = name.substr(0, start) + name.substr(end);
  if (stage == ".usda" || frame_field_in(stage)) return {};
  return (path.parent_path() / stage).string();
}

FrameRange stage_frames(const std::string &option, const GroomDesc &groom, const FrameRange &run) {
  if (!option.empty()) {
    const FrameRange range = parse_frame_range(option, "--stage-frames");
    check_frames_per_run(range, "--stage-frames");
    return range;
  }
  if (!groom.output.frames.empty()) return parse_frame_range(groom.output.frames, groom.source + ": output.frames");
  return run;
}

void write_groom_stage(const std::string &stage_path, const std::string &pattern, const FrameRange &range,
                       const std::vector<std::string> &curves_prims, const GroomDesc &groom) {
  io::UsdStageOptions options;
  options.time_codes.reserve(size_t(range.count()));
  options.frame_paths.reserve(size_t(range.count()));
  for (int64_t i = 0; i < range.count(); ++i) {
    options.time_codes.push_back(range.at(i));
    options.frame_paths.push_back(expand_frame_pattern(pattern, range.at(i)));
  }
  options.curves_prims = curves_prims;
  options.meters_per_unit = groom.output.meters_per_unit;
  options.up_axis = groom.output.up_axis;
  options.fps = groom.dynamics.fps;
  // Appended piece by piece: GCC 12 warns (-Wrestrict, falsely) on ":" + std::to_string(...).
  std::string comment = "plume regrow of " + groom.name + ": frames " + std::to_string(range.first) + "-" +
                        std::to_string(range.last);
  if (range.step > 1) {
    comment += ':';
    comment += std::to_string(range.step);
  }
  comment += " as value clips";
  options.comment = comment;
  io::write_usd_stage(stage_path, options);
}

}  // namespace plume
