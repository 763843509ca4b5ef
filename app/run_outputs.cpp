#include "app/run_outputs.h"

#include <sys/stat.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>

#include "groom/error.h"

namespace plume {

namespace {

/// Where the frame field of a file name begins (the first '#', "%d"-like or $F field, as
/// app/frame_range.h reads them), npos when it has none.
size_t frame_field_start(const std::string &name) {
  for (size_t i = 0; i < name.size(); ++i) {
    if (name[i] == '#') return i;
    if (name.compare(i, 2, "$F") == 0 &&
        !(i + 2 < name.size() && (std::isalpha(static_cast<unsigned char>(name[i + 2])) || name[i + 2] == '_')))
      return i;
    if (name[i] == '%') {
      if (i + 1 < name.size() && name[i + 1] == '%') {
        ++i;
        continue;
      }
      return i;
    }
  }
  return std::string::npos;
}

std::string size_text(uint64_t bytes) {
  char text[64];
  if (bytes < 1000)
    std::snprintf(text, sizeof text, "%llu bytes", (unsigned long long)bytes);
  else if (bytes < 1000000)
    std::snprintf(text, sizeof text, "%llu bytes (%.3g kB)", (unsigned long long)bytes, double(bytes) / 1e3);
  else if (bytes < 1000000000)
    std::snprintf(text, sizeof text, "%llu bytes (%.3g MB)", (unsigned long long)bytes, double(bytes) / 1e6);
  else
    std::snprintf(text, sizeof text, "%llu bytes (%.3g GB)", (unsigned long long)bytes, double(bytes) / 1e9);
  return text;
}

}  // namespace

std::string proxy_pattern(const std::string &pattern, int64_t strands) {
  const std::string tag = "_proxy" + std::to_string(strands);
  const size_t name_begin = pattern.size() - std::filesystem::path(pattern).filename().string().size();
  const std::string name = pattern.substr(name_begin);
  size_t at = frame_field_start(name);
  if (at != std::string::npos) {
    // Before the separator in front of the field: hair.####.usda -> hair_proxyN.####.usda.
    if (at > 0 && (name[at - 1] == '.' || name[at - 1] == '_' || name[at - 1] == '-')) --at;
  } else {
    at = name.rfind('.');
    if (at == std::string::npos || at == 0) at = name.size();
  }
  if (at == 0) return pattern.substr(0, name_begin) + tag.substr(1) + "_" + name;  // "####.usda"
  return pattern.substr(0, name_begin) + name.substr(0, at) + tag + name.substr(at);
}

std::string chosen_preview(const std::string &option, bool option_given, bool no_preview,
                           const std::string &groom_pattern, const std::string &groom_what, std::string &r_what) {
  if (option_given) {
    if (option.empty())
      throw InputError("--preview: expected a PNG path pattern, got an empty one (--no-preview turns previews off)");
    r_what = "--preview";
    return option;
  }
  r_what = groom_what;
  return no_preview ? std::string() : groom_pattern;
}

std::string chosen_output(const std::string &option, bool option_given, const std::string &name,
                          const std::string &groom_pattern) {
  if (!option_given) return groom_pattern;
  if (option.empty()) throw InputError(name + ": expected a path pattern, got an empty one");
  return option;
}

bool outputs_complete(const std::vector<std::string> &paths) {
  for (const std::string &path : paths) {
    struct stat status;
    if (!path.empty() && !(::stat(path.c_str(), &status) == 0 && S_ISREG(status.st_mode))) return false;
  }
  return true;
}

RunSummary::RunSummary(std::string command, const FrameRange &range)
    : command_(std::move(command)), range_(range), start_(std::chrono::steady_clock::now()) {}

int RunSummary::add_output(const std::string &what, const std::string &pattern) {
  Output output;
  output.what = what;
  if (!pattern.empty()) output.pattern = std::filesystem::absolute(pattern).lexically_normal().string();
  outputs_.push_back(output);
  return int(outputs_.size()) - 1;
}

void RunSummary::wrote(int output, const std::string &path) {
  Output &o = outputs_.at(size_t(output));
  ++o.written;
  struct stat status;
  if (::stat(path.c_str(), &status) == 0) o.bytes += uint64_t(status.st_size);
}

void RunSummary::kept(int output, const std::string &) { ++outputs_.at(size_t(output)).kept; }

std::string RunSummary::text() const {
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  char head[160];
  std::string frames = std::to_string(range_.first);
  if (range_.last != range_.first)
    frames += "-" + std::to_string(range_.last) + (range_.step > 1 ? ":" + std::to_string(range_.step) : "");
  std::snprintf(head, sizeof head, "plume %s: frame%s %s (%lld) in %.2f s\n", command_.c_str(),
                range_.count() > 1 ? "s" : "", frames.c_str(), (long long)range_.count(), seconds);
  std::string text = head;
  size_t width = 0;
  for (const Output &o : outputs_) width = std::max(width, o.what.size());
  for (const Output &o : outputs_) {
    text += "  " + o.what + std::string(width - o.what.size() + 2, ' ');
    if (o.pattern.empty()) {
      text += "none\n";
      continue;
    }
    text += o.pattern + ": " + std::to_string(o.written) + (o.written == 1 ? " file, " : " files, ") + size_text(o.bytes);
    if (o.kept > 0) text += "; " + std::to_string(o.kept) + " complete already, kept (--skip-existing)";
    text += "\n";
  }
  return text;
}

void RunSummary::print() const {
  std::fputs(text().c_str(), stdout);
  std::fflush(stdout);
}

}  // namespace plume
