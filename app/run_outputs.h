// Where a run's outputs go and what it says about them: the names a proxy run (--strands) writes
// instead of the groom's, the preview options, --skip-existing, and the summary every run that
// writes files ends with (files written per output: pattern, count, bytes; time).
#pragma once

#include <chrono>
#include <cstdint>
#include <string>
#include <vector>

#include "app/frame_range.h"

namespace plume {

/// The pattern a proxy run (--strands N) writes instead of a groom file's `pattern`, so that it
/// never overwrites the full groom's files: "_proxyN" is added to the file name, before the
/// separator ('.', '_' or '-') in front of its frame field, else before the extension:
/// hair.####.usda -> hair_proxy3000.####.usda, preview.png -> preview_proxy3000.png.
/// Folders are unchanged.
std::string proxy_pattern(const std::string &pattern, int64_t strands);

/// A run's preview pattern: `option` when `option_given` (an empty one is an InputError naming
/// --preview: it would silently mean the groom's previews, or none), none with `no_preview`, else
/// `groom_pattern` (may be empty: none). `r_what` names where it came from, for messages.
std::string chosen_preview(const std::string &option, bool option_given, bool no_preview,
                           const std::string &groom_pattern, const std::string &groom_what, std::string &r_what);

/// The output pattern of option `name` (--out, --vanes, --cache): `option` when `option_given`
/// (an empty one is an InputError naming the option), else `groom_pattern`.
std::string chosen_output(const std::string &option, bool option_given, const std::string &name,
                          const std::string &groom_pattern);

/// Whether every one of `paths` exists as a regular file: with --skip-existing a frame whose
/// outputs are all there is not regrown. Outputs are renamed into place only when complete
/// (io/atomic_file.h), so an existing file is a complete one; an empty path counts as present.
bool outputs_complete(const std::vector<std::string> &paths);

/// The summary a run prints on stdout when it is done: what it wrote, where, how much, how long.
///
///   plume regrow: frames 1-48 (48) in 8.52 s
///     strands   /home/ana/shot/out/hair.####.usda: 48 files, 612345678 bytes (612 MB)
///     previews  /home/ana/shot/out/preview.####.png: 8 files, 2113344 bytes (2.1 MB)
///
/// Paths are absolute, so a log says where files went whatever the folder the run started in.
class RunSummary {
 public:
  /// `command`: "regrow", "simulate", ...; the clock starts now.
  RunSummary(std::string command, const FrameRange &range);
  /// An output of the run, `what` ("strands", "previews", ...) written to `pattern`; returns its
  /// index for wrote() and kept(). An empty pattern is no output (listed as "none").
  int add_output(const std::string &what, const std::string &pattern);
  /// `path`, a file of output `output`, was written: counts it and its size.
  void wrote(int output, const std::string &path);
  /// --skip-existing: `path`, a file of output `output`, was complete already and was left alone.
  void kept(int output, const std::string &path);
  /// The summary's text.
  std::string text() const;
  /// Prints text() on stdout.
  void print() const;

 private:
  struct Output {
    std::string what, pattern;
    int64_t written = 0, kept = 0;
    uint64_t bytes = 0;
  };
  std::string command_;
  FrameRange range_;
  std::chrono::steady_clock::time_point start_;
  std::vector<Output> outputs_;
};

}  // namespace plume
