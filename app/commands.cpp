#include "app/commands.h"

#include <limits.h>
#include <omp.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <charconv>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>

#include "app/pipeline.h"
#include "groom/error.h"
#include "io/atomic_file.h"
#include "io/file_scan.h"

namespace plume {

namespace {

/// Whether `text` is a thread count as OpenMP reads OMP_NUM_THREADS: a positive integer, or a list
/// of them separated by commas (one per nesting level), blanks around each allowed. libgomp only
/// warns about anything else and goes on with its own count.
bool valid_omp_num_threads(std::string_view text) {
  size_t i = 0;
  const auto skip_blanks = [&] {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t' || text[i] == '\n')) ++i;
  };
  for (;;) {
    skip_blanks();
    unsigned long count = 0;
    const auto [end, error] = std::from_chars(text.data() + i, text.data() + text.size(), count);
    if (error != std::errc() || count == 0) return false;
    i = size_t(end - text.data());
    skip_blanks();
    if (i == text.size()) return true;
    if (text[i++] != ',') return false;
  }
}

}  // namespace

void check_omp_num_threads() {
  if (const char *variable = std::getenv("OMP_NUM_THREADS"); variable && !valid_omp_num_threads(variable))
    throw InputError("OMP_NUM_THREADS: expected a whole number of threads >= 1 (or a list such as 4,2), got " +
                     io::detail::quoted(variable));
}

void set_thread_count(int threads) {
  if (threads > 0) {
    omp_set_num_threads(threads);
    return;
  }
  // Without --threads, OpenMP takes OMP_NUM_THREADS, or the hardware's thread count.
  const int count = omp_get_max_threads();
  if (count <= kMaxThreads) return;
  if (std::getenv("OMP_NUM_THREADS"))
    throw InputError("OMP_NUM_THREADS: expected at most " + std::to_string(kMaxThreads) + " threads (as --threads), got " +
                     std::to_string(count));
  omp_set_num_threads(kMaxThreads);
}

void add_threads_option(CLI::App &cmd, int &r_threads, const std::string &description) {
  cmd.add_option("--threads", r_threads, description)->check(CLI::Range(1, kMaxThreads));
}

void add_strands_option(CLI::App &cmd, int64_t &r_strands, const std::string &description) {
  cmd.add_option("--strands", r_strands, description)->check(CLI::Range(int64_t(1), max_root_count));
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

CLI::Validator non_empty_frames() {
  return CLI::Validator(
      [](std::string &text) {
        return text.empty() ? std::string("expected a frame range: 7, 1-48, 1-240:2 or 1-240x2, got an empty one")
                            : std::string();
      },
      "RANGE");
}

int preview_size_of(int option, const GroomDesc &groom) { return option > 0 ? option : groom.output.preview_size; }

void add_preview_size_option(CLI::App &cmd, const std::string &name, int &r_size, const std::string &description) {
  cmd.add_option(name, r_size, description)->check(CLI::Range(16, max_preview_size));
}

FrameRange frames_to_produce(const std::string &option, const GroomDesc &groom) {
  const std::string &text = !option.empty() ? option : groom.output.frames;
  if (text.empty()) return FrameRange{};
  const std::string what = !option.empty() ? "--frames" : groom.source + ": output.frames";
  const FrameRange range = parse_frame_range(text, what);
  check_frames_per_run(range, what);
  return range;
}

int groom_first_frame(const GroomDesc &groom) {
  if (groom.output.frames.empty()) return 1;
  return parse_frame_range(groom.output.frames, groom.source + ": output.frames").first;
}

std::string groom_file_name(const GroomDesc &groom) {
  return std::filesystem::path(groom.source).filename().string();
}

PreviewSchedule::PreviewSchedule(std::string pattern, int every, const FrameRange &range, const std::string &what)
    : what_(what), pattern_(std::move(pattern)), every_(every) {
  if (pattern_.empty()) return;
  check_frame_syntax(pattern_, what);  // before has_frame_field(), whose message names no option or key
  sequence_ = has_frame_field(pattern_);
  check_output_pattern(pattern_, sequence_ ? range : FrameRange{range.first, range.first, 1}, what, {".png"});
}

std::string PreviewSchedule::path_at(int64_t i, int frame) const {
  const bool due = every_ > 0 ? i % every_ == 0 : i == 0;
  if (pattern_.empty() || !due || !(sequence_ || i == 0)) return {};
  return expand_frame_pattern(pattern_, frame);
}

namespace {

/// Device and inode of an existing file, false when `path` names none.
bool file_identity(const std::string &path, uintmax_t &r_device, uintmax_t &r_inode) {
  struct stat status;
  if (::stat(path.c_str(), &status) != 0) return false;
  r_device = uintmax_t(status.st_dev);
  r_inode = uintmax_t(status.st_ino);
  return true;
}

}  // namespace

RunInputs::RunInputs(const GroomDesc &groom, const std::string &guides_cache)
    : guides_cache_(groom.dynamics.enabled ? guides_cache : std::string()) {
  if (groom.animation.kind == EmitterAnimation::Kind::obj_sequence) sequence_pattern_ = groom.animation.sequence_pattern;
  auto add = [&](const std::string &path, const std::string &what) {
    File file{0, 0, what};
    if (!path.empty() && file_identity(path, file.device, file.inode)) files_.push_back(file);
  };
  add(groom.source, "the groom file");
  add(groom.emitter_path, "the groom's emitter.mesh");
  add(groom.guides_path, "the groom's guides.file");
  add(groom.roots.file, "the groom's roots.file");
  add(groom.partings.zone_map_path, "the groom's zone map");
  for (const EffectDesc &effect : groom.effects) add(effect.vertex_map_path, "an effect's vertex map");
  for (const std::string &path : groom.feathers.template_files) add(path, "a feather template file of the groom");
  add(groom.feathers.follicles.file, "the groom's feathers.follicles.file");
  add(groom.feathers.follicles.map_path, "the groom's feathers.follicles.map");
  add(groom.feathers.layer_map_path, "the groom's feathers.layers.map");
  for (const ControlDesc &control : groom.controls.controls) add(control.vertex_map_path, "a control's vertex map");
}

std::string RunInputs::input_at(const std::string &path, int frame) const {
  uintmax_t device = 0, inode = 0;
  if (!file_identity(path, device, inode)) return {};
  for (const File &file : files_)
    if (file.device == device && file.inode == inode) return file.what;
  // A frame's file of an input pattern: this frame's, or the frame the file name reads as (a
  // simulation reads frames before the range, and a pattern with other padding may name another).
  auto input_frame = [&](const std::string &pattern) -> std::optional<int> {
    if (pattern.empty()) return std::nullopt;
    auto same = [&](int at) {
      uintmax_t other_device = 0, other_inode = 0;
      return file_identity(expand_frame_pattern(pattern, at), other_device, other_inode) && other_device == device &&
             other_inode == inode;
    };
    if (same(frame)) return frame;
    const std::optional<int> named = frame_in_file_name(pattern, path);
    if (named && same(*named)) return named;
    return std::nullopt;
  };
  if (const std::optional<int> at = input_frame(sequence_pattern_))
    return "the emitter sequence's mesh of frame " + std::to_string(*at);
  if (const std::optional<int> at = input_frame(guides_cache_)) return "the --guides-cache file of frame " + std::to_string(*at);
  return {};
}

namespace {

// check_output_locations() for the frames frame_at(0) .. frame_at(count - 1).
template <typename FrameAt>
void check_locations_of(const std::string &pattern, int64_t count, const FrameAt &frame_at, const std::string &what,
                        const RunInputs &inputs) {
  namespace fs = std::filesystem;
  fs::path checked_folder;
  long name_max = 255;  // the longest file or folder name where the files go (pathconf)
  // A file is written under its name plus a temporary suffix (io/atomic_file.h), which must fit too.
  const long suffix = long(io::kMaxTempSuffixBytes);
  auto check_name = [&](const fs::path &path, const fs::path &name, bool is_file) {
    const long bytes = long(name.native().size());
    if (bytes > name_max)
      throw InputError(what + ": cannot write " + path.string() + ": the name " + io::detail::quoted(name.string(), 40, true) +
                       " has " + std::to_string(bytes) + " bytes, more than the " + std::to_string(name_max) +
                       " the file system allows");
    if (is_file && bytes + suffix > name_max)
      throw InputError(what + ": cannot write " + path.string() + ": the name " + io::detail::quoted(name.string(), 40, true) +
                       " has " + std::to_string(bytes) + " bytes; a file is written under its name plus up to " +
                       std::to_string(suffix) + " bytes (.tmp-<pid>) first, so at most " +
                       std::to_string(name_max - suffix) + " bytes fit the " + std::to_string(name_max) +
                       " the file system allows");
    if (is_file && path.native().size() + size_t(suffix) >= size_t(PATH_MAX))
      throw InputError(what + ": cannot write " + io::detail::quoted(path.string(), 60, true) + ": the path has " +
                       std::to_string(path.native().size()) + " bytes, with its temporary suffix more than the " +
                       std::to_string(PATH_MAX - 1) + " the system allows");
  };
  for (int64_t i = 0; i < count; ++i) {
    const int frame = frame_at(i);
    const fs::path path = expand_frame_pattern(pattern, frame);
    std::error_code error;
    if (fs::is_directory(path, error))
      throw InputError(what + ": " + path.string() + " is an existing directory, expected a file name");
    const std::string input = inputs.input_at(path.string(), frame);
    if (!input.empty())
      throw InputError(what + ": " + path.string() + " is " + input + ", which this run reads: choose another output");
    const fs::path folder = path.parent_path();
    if (i > 0 && folder == checked_folder) {
      check_name(path, path.filename(), true);
      continue;
    }
    // The nearest existing ancestor must be a directory one may write in: the writer creates the rest.
    fs::path existing = folder;
    while (!existing.empty() && !fs::exists(existing, error)) {
      const fs::path up = existing.parent_path();
      if (up == existing) break;
      existing = up;
    }
    if (existing.empty()) existing = ".";
    if (!fs::is_directory(existing, error))
      throw InputError(what + ": cannot write " + path.string() + ": " + existing.string() + " is not a directory");
    if (::access(existing.c_str(), W_OK | X_OK) != 0)
      throw InputError(what + ": cannot write " + path.string() + ": no permission to write in " + existing.string());
    const long limit = ::pathconf(existing.c_str(), _PC_NAME_MAX);
    name_max = limit > 0 ? limit : 255;
    // The folders the writer will make, and the file's own name.
    const fs::path made = path.lexically_relative(existing);
    for (auto name = made.begin(); name != made.end(); ++name) check_name(path, *name, std::next(name) == made.end());
    checked_folder = folder;
  }
}

}  // namespace

void check_output_locations(const std::string &pattern, const FrameRange &range, const std::string &what,
                            const RunInputs &inputs) {
  check_locations_of(pattern, range.count(), [&](int64_t i) { return range.at(i); }, what, inputs);
}

void PreviewSchedule::check_locations(const FrameRange &range, const RunInputs &inputs) const {
  if (pattern_.empty()) return;
  // The due frames are the i-th of the range for i = 0, every_, 2 every_, ... (path_at()).
  const int64_t stride = every_ > 0 && sequence_ ? every_ : range.count();
  const int64_t due_count = (range.count() - 1) / stride + 1;
  check_locations_of(pattern_, due_count, [&](int64_t k) { return range.at(k * stride); }, what_, inputs);
}

void check_output_pattern(const std::string &pattern, const FrameRange &range, const std::string &what,
                          const std::vector<std::string> &extensions) {
  if (pattern.empty()) throw InputError(what + ": expected an output path, got none");
  check_frame_pattern(pattern, range, what);
  const std::string ext = io::detail::extension_of(pattern);
  if (std::find(extensions.begin(), extensions.end(), ext) == extensions.end()) {
    std::string list;
    for (const std::string &e : extensions) list += (list.empty() ? "" : ", ") + e;
    throw InputError(what + ": expected a file ending in " + list + ", got \"" + pattern + "\"");
  }
}

Eigen::AlignedBox3f groom_bounds(const Pipeline &pipeline) {
  return scene_bounds(pipeline.rest_mesh(), pipeline.guides().strands);
}

PreviewCamera groom_camera(const Pipeline &pipeline, const CameraAngle &angle) {
  return fit_camera(groom_bounds(pipeline), angle);
}

}  // namespace plume
