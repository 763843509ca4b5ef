#include "app/frame_range.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>

#include "groom/error.h"
#include "io/atomic_file.h"

namespace plume {

namespace {

// Reads an optionally signed integer at text[pos], advancing pos; false if there is none.
bool read_int(const std::string &text, size_t &pos, int &r_value) {
  const char *begin = text.data() + pos;
  const char *end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(begin, end, r_value);
  if (ec != std::errc() || ptr == begin) return false;
  pos += size_t(ptr - begin);
  return true;
}

struct FrameField {
  size_t begin = std::string::npos;  // npos: no field
  size_t length = 0;
  int padding = 0;
};

FrameField find_frame_field(const std::string &pattern) {
  FrameField found;
  auto add = [&](size_t begin, size_t length, int padding) {
    if (found.begin != std::string::npos)
      throw InputError("path pattern \"" + pattern + "\": expected one frame field (####, %04d or $F4), got two");
    if (padding > kMaxFramePadding)
      throw InputError("path pattern \"" + pattern + "\": expected a frame field of at most " +
                       std::to_string(kMaxFramePadding) + " digits (a longer one cannot fit a file name)");
    found = {begin, length, padding};
  };
  for (size_t i = 0; i < pattern.size();) {
    if (pattern[i] == '#') {
      size_t j = i;
      while (j < pattern.size() && pattern[j] == '#') ++j;
      add(i, j - i, int(std::min(j - i, size_t(kMaxFramePadding) + 1)));
      i = j;
    } else if (pattern[i] == '$' && i + 1 < pattern.size() && pattern[i + 1] == 'F' &&
               !(i + 2 < pattern.size() && (std::isalpha(static_cast<unsigned char>(pattern[i + 2])) || pattern[i + 2] == '_'))) {
      // Houdini's $F (the frame) and $F4 (padded to 4 digits); $FF or $Foo are other variables,
      // kept as text.
      size_t j = i + 2;
      int padding = 0;
      while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j])))
        padding = std::min(padding * 10 + (pattern[j++] - '0'), kMaxFramePadding + 1);
      add(i, j - i, padding);
      i = j;
    } else if (pattern[i] == '%') {
      size_t j = i + 1;
      if (j < pattern.size() && pattern[j] == '%') {  // a literal percent sign
        i = j + 1;
        continue;
      }
      int padding = 0;
      while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j])))
        padding = std::min(padding * 10 + (pattern[j++] - '0'), kMaxFramePadding + 1);
      if (j >= pattern.size() || pattern[j] != 'd')
        throw InputError("path pattern \"" + pattern + "\": expected a frame field like %04d after '%'");
      add(i, j + 1 - i, padding);
      i = j + 1;
    } else {
      ++i;
    }
  }
  return found;
}

}  // namespace

FrameRange parse_frame_range(const std::string &text, const std::string &what) {
  auto fail = [&](const std::string &why) {
    return InputError(what + ": expected a frame range: 7, 1-48, 1-240:2 or 1-240x2 (every 2nd frame of 1-240), got \"" +
                      text + "\"" + (why.empty() ? "" : " (" + why + ")"));
  };
  FrameRange range;
  size_t pos = 0;
  if (!read_int(text, pos, range.first)) throw fail("");
  range.last = range.first;
  if (pos < text.size() && text[pos] == '-') {
    ++pos;
    if (!read_int(text, pos, range.last)) throw fail("");
    if (pos < text.size() && (text[pos] == ':' || text[pos] == 'x')) {
      ++pos;
      if (!read_int(text, pos, range.step)) throw fail("");
    }
  } else if (pos < text.size() && (text[pos] == ':' || text[pos] == 'x')) {
    // "1:240" reads as frames 1 to 240 in some tools and as frame 1 every 240 in others: neither guess is safe.
    throw fail("a step follows a range A-B; frames 1 to 240 are 1-240");
  }
  if (pos != text.size()) throw fail("");
  if (range.last < range.first) throw fail("the last frame is before the first");
  if (range.step < 1) throw fail("the step must be at least 1");
  const auto beyond = [](int value) { return value < -kMaxFrame || value > kMaxFrame; };
  if (beyond(range.first) || beyond(range.last) || beyond(range.step))
    throw fail("frames and steps have at most 9 digits");
  return range;
}

void check_frames_per_run(const FrameRange &range, const std::string &what) {
  if (range.count() > kMaxFramesPerRun)
    throw InputError(what + ": frames " + std::to_string(range.first) + " to " + std::to_string(range.last) +
                     (range.step > 1 ? " every " + std::to_string(range.step) : "") + " are " +
                     std::to_string(range.count()) + " frames, expected at most " + std::to_string(kMaxFramesPerRun) +
                     " in one run (run a long shot in chunks of frames)");
}

bool has_frame_field(const std::string &pattern) { return find_frame_field(pattern).begin != std::string::npos; }

std::string expand_frame_pattern(const std::string &pattern, int frame) {
  const FrameField field = find_frame_field(pattern);
  std::string result = pattern;
  if (field.begin != std::string::npos) {
    // Zero-padded to the field's width, the sign counted in it, as printf's %0Nd.
    const std::string magnitude = std::to_string(frame < 0 ? -int64_t(frame) : int64_t(frame));
    const size_t width = size_t(field.padding) - (frame < 0 && field.padding > 0 ? 1 : 0);
    std::string digits = frame < 0 ? "-" : "";
    if (magnitude.size() < width) digits.append(width - magnitude.size(), '0');
    digits += magnitude;
    result.replace(field.begin, field.length, digits);
  }
  // Literal "%%" stands for one percent sign in printf-style patterns.
  for (size_t i = result.find("%%"); i != std::string::npos; i = result.find("%%", i + 1)) result.erase(i, 1);
  return result;
}

std::optional<int> frame_in_file_name(const std::string &pattern, const std::string &path) {
  const FrameField field = find_frame_field(pattern);
  if (field.begin == std::string::npos) return std::nullopt;
  const size_t name_begin = pattern.size() - std::filesystem::path(pattern).filename().string().size();
  if (field.begin < name_begin) return std::nullopt;
  auto unescaped = [](std::string text) {  // "%%" is one percent sign, as in expand_frame_pattern()
    for (size_t i = text.find("%%"); i != std::string::npos; i = text.find("%%", i + 1)) text.erase(i, 1);
    return text;
  };
  const std::string prefix = unescaped(pattern.substr(name_begin, field.begin - name_begin));
  const std::string suffix = unescaped(pattern.substr(field.begin + field.length));
  const std::string name = std::filesystem::path(path).filename().string();
  if (name.size() <= prefix.size() + suffix.size() || name.compare(0, prefix.size(), prefix) != 0 ||
      name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return std::nullopt;
  const char *first = name.data() + prefix.size(), *last = name.data() + name.size() - suffix.size();
  int frame = 0;
  const auto [end, error] = std::from_chars(first, last, frame);
  if (error != std::errc() || end != last || frame < -kMaxFrame || frame > kMaxFrame) return std::nullopt;
  return frame;
}

void check_frame_syntax(const std::string &pattern, const std::string &what) {
  try {
    find_frame_field(pattern);
  } catch (const InputError &error) {
    throw InputError(what + ": " + error.what());
  }
}

void check_frame_pattern(const std::string &pattern, const FrameRange &range, const std::string &what) {
  check_frame_syntax(pattern, what);
  if (pattern.find('\0') != std::string::npos) {
    // The system would end the file name at the NUL: every frame would go to one truncated name.
    std::string shown;
    for (const char c : pattern) shown += c == '\0' ? std::string("\\0") : std::string(1, c);
    throw InputError(what + ": a path cannot hold a NUL character, got \"" + shown + "\"");
  }
  if (range.count() > 1 && !has_frame_field(pattern))
    throw InputError(what + ": " + std::to_string(range.count()) +
                     " frames need a frame field in the path (####, %04d or $F4), got \"" + pattern + "\"");
}

std::vector<std::string> remove_stale_temp_files(const std::string &pattern, const FrameRange &range) {
  namespace fs = std::filesystem;
  std::vector<std::string> removed;
  if (pattern.empty()) return removed;
  const FrameField field = find_frame_field(pattern);
  const size_t name_begin = pattern.size() - fs::path(pattern).filename().string().size();
  const bool field_in_name = field.begin != std::string::npos && field.begin >= name_begin;
  // A frame field in a folder name gives a folder per frame, each holding one name; otherwise one
  // folder holds the files of every frame (those of other runs' ranges too).
  const int64_t folder_count = field.begin == std::string::npos || field_in_name ? 1 : range.count();
  fs::path last_folder;
  for (int64_t i = 0; i < folder_count; ++i) {
    const fs::path path = expand_frame_pattern(pattern, range.at(i));
    if (i > 0 && path.parent_path() == last_folder) continue;
    last_folder = path.parent_path();
    const std::string own_name = path.filename().string();
    const auto is_output_name = [&](const std::string &name) {
      if (!field_in_name) return name == own_name;
      const std::optional<int> frame = frame_in_file_name(pattern, name);
      return frame && fs::path(expand_frame_pattern(pattern, *frame)).filename().string() == name;
    };
    for (std::string &stale : io::remove_stale_temp_files(last_folder.string(), is_output_name))
      removed.push_back(std::move(stale));
  }
  return removed;
}

}  // namespace plume
