#include "app/commands.h"

#include <omp.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <utility>

#include "app/pipeline.h"
#include "groom/error.h"

namespace plume {

void set_thread_count(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

void add_threads_option(CLI::App &cmd, int &r_threads, const std::string &description) {
  cmd.add_option("--threads", r_threads, description)->check(CLI::Range(1, kMaxThreads));
}

void add_strands_option(CLI::App &cmd, int64_t &r_strands, const std::string &description) {
  cmd.add_option("--strands", r_strands, description)->check(CLI::Range(int64_t(1), kMaxRootCount));
}

CLI::Validator finite_non_negative() {
  return CLI::Validator(
      [](std::string &text) {
        char *end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        // Also finite as a float: the options it checks are floats.
        if (text.empty() || *end != '\0' || !(value >= 0.0 && value <= std::numeric_limits<float>::max()))
          return "expected a finite number >= 0, got \"" + text + "\"";
        return std::string();
      },
      "FINITE>=0");
}

FrameRange frames_to_produce(const std::string &option, const GroomDesc &groom) {
  if (!option.empty()) return parse_frame_range(option, "--frames");
  if (!groom.output.frames.empty()) return parse_frame_range(groom.output.frames, groom.source + ": output.frames");
  return FrameRange{};
}

int groom_first_frame(const GroomDesc &groom) {
  if (groom.output.frames.empty()) return 1;
  return parse_frame_range(groom.output.frames, groom.source + ": output.frames").first;
}

std::string extension_of(const std::string &path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

PreviewSchedule::PreviewSchedule(std::string pattern, int every, const FrameRange &range, const std::string &what)
    : pattern_(std::move(pattern)), every_(every), sequence_(!pattern_.empty() && has_frame_field(pattern_)) {
  if (!pattern_.empty())
    check_output_pattern(pattern_, sequence_ ? range : FrameRange{range.first, range.first, 1}, what, {".png"});
}

std::string PreviewSchedule::path_at(int64_t i, int frame) const {
  const bool due = every_ > 0 ? i % every_ == 0 : i == 0;
  if (pattern_.empty() || !due || !(sequence_ || i == 0)) return {};
  return expand_frame_pattern(pattern_, frame);
}

void check_output_pattern(const std::string &pattern, const FrameRange &range, const std::string &what,
                          const std::vector<std::string> &extensions) {
  if (pattern.empty()) throw InputError(what + ": expected an output path, got none");
  check_frame_pattern(pattern, range, what);
  const std::string ext = extension_of(pattern);
  if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) {
    std::string list;
    for (const std::string &e : extensions) list += (list.empty() ? "" : ", ") + e;
    throw InputError(what + ": expected a file ending in " + list + ", got \"" + pattern + "\"");
  }
}

PreviewCamera groom_camera(const Pipeline &pipeline) {
  return fit_camera(scene_bounds(pipeline.rest_mesh(), pipeline.guides().strands));
}

std::vector<bool> groom_scalp(const Pipeline &pipeline) {
  std::vector<int32_t> triangles;
  triangles.reserve(pipeline.roots().size());
  for (const SurfacePoint &p : pipeline.roots().points) triangles.push_back(p.triangle);
  return scalp_mask(pipeline.rest_mesh(), triangles);
}

}  // namespace plume
