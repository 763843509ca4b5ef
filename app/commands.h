// The subcommands of `plume`: each registers its options on the CLI11 app and runs when chosen.
// A command's callback throws InputError for bad input (exit 2) and sets r_exit_code otherwise.
#pragma once

#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

#include "app/frame_range.h"
#include "app/preview.h"
#include "groom/groom_desc.h"

namespace plume {

class Pipeline;

void add_regrow_command(CLI::App &app, int &r_exit_code);
void add_simulate_command(CLI::App &app, int &r_exit_code);
void add_preview_command(CLI::App &app, int &r_exit_code);
void add_info_command(CLI::App &app, int &r_exit_code);
void add_check_command(CLI::App &app, int &r_exit_code);
void add_view_command(CLI::App &app, int &r_exit_code);

/// Exit code of `plume check --strict` when the strands break a promise.
inline constexpr int kExitViolations = 3;

/// The most worker threads `--threads` accepts. libgomp starts one OS thread per requested thread,
/// each with its own stack; tens of thousands of them exceed the system's thread and mapping limits
/// (libgomp then fails or crashes). 1024 is above the hardware threads of today's largest
/// two-socket nodes (2 x 192 cores x 2 = 768), and more threads than cores only add overhead:
/// results do not depend on the count.
inline constexpr int kMaxThreads = 1024;

// Shared by the commands.

/// Throws InputError naming the variable when OMP_NUM_THREADS is set to anything but a thread count
/// as OpenMP reads it (a whole number >= 1, or a list of them such as "4,2"): libgomp only warns
/// and goes on with its own count. Every command checks it before it runs (main.cpp), with or
/// without --threads.
void check_omp_num_threads();
/// Sets the OpenMP thread count when `threads` > 0 (results do not depend on it). Otherwise OpenMP's
/// own count stands (OMP_NUM_THREADS, or the hardware threads), at most kMaxThreads: an
/// OMP_NUM_THREADS above it is an InputError naming the variable, more hardware threads are capped.
void set_thread_count(int threads);
/// Adds `--threads N`, N in [1, kMaxThreads], to `cmd`.
void add_threads_option(CLI::App &cmd, int &r_threads, const std::string &description);
/// Adds `--strands N`, N in [1, max_root_count] (groom_desc.h), to `cmd`.
void add_strands_option(CLI::App &cmd, int64_t &r_strands, const std::string &description);
/// A number >= 0 and finite as a float ("nan", "inf", 1e39 and negatives fail with a message
/// naming the value).
CLI::Validator finite_non_negative();
/// Checks at parse time that --frames is not empty (an empty range would silently mean the groom's):
/// the message names the accepted forms.
CLI::Validator non_empty_frames();
/// The frames to produce: `option` when given, else the groom's output.frames, else frame 1.
FrameRange frames_to_produce(const std::string &option, const GroomDesc &groom);
/// The first frame of the groom's own range (output.frames), 1 when it has none.
int groom_first_frame(const GroomDesc &groom);
/// The groom file's name without its folders ("sintel.groom.yaml"): what output files record of
/// their groom (a .usda doc line, a .hair header, a PLY/OBJ comment), so that the same groom in
/// any checkout or farm mount writes the same bytes.
std::string groom_file_name(const GroomDesc &groom);
/// check_frame_pattern(), and the pattern is not empty and ends with one of `extensions`.
void check_output_pattern(const std::string &pattern, const FrameRange &range, const std::string &what,
                          const std::vector<std::string> &extensions);
/// The files a run reads: the groom file, the files it names (emitter mesh, guides, roots, zone map,
/// effect maps) and, per frame, the emitter sequence's mesh and the guide cache's file. An output
/// must never be one of them (a typo in --out must not overwrite a groom's guides).
class RunInputs {
 public:
  /// `guides_cache`: the --guides-cache pattern, or empty.
  RunInputs(const GroomDesc &groom, const std::string &guides_cache);
  /// Which input the existing file `path` is (the same file, by device and inode, as one the run
  /// reads: a groom file, or the sequence's or cache's file of `frame` or of the frame its name
  /// reads as), described for a message; empty when it is none or does not exist.
  std::string input_at(const std::string &path, int frame) const;

 private:
  struct File {
    uintmax_t device, inode;
    std::string what;
  };
  std::vector<File> files_;
  std::string sequence_pattern_, guides_cache_;
};
/// Throws InputError naming `what` unless every file `pattern` names for `range` can be written: no
/// target is an existing directory or one of the run's `inputs`, and each target's folder exists as
/// a writable directory or can be created (its nearest existing ancestor is one). Called before the
/// first write of a run, so that a bad location exits with 2 before any output exists. Walks the
/// range without listing it.
void check_output_locations(const std::string &pattern, const FrameRange &range, const std::string &what,
                            const RunInputs &inputs);
/// Which frames of a range get a preview PNG, and where: every `every`-th frame of the range
/// (0: the first only), and only the first when the pattern has no frame field.
class PreviewSchedule {
 public:
  /// `pattern` empty: no previews. Otherwise checked as an output pattern (.png) for the frames it
  /// will name; throws InputError naming `what` (the option).
  PreviewSchedule(std::string pattern, int every, const FrameRange &range, const std::string &what);
  /// The preview path of frame `frame`, the i-th of the range, or empty when none is due.
  std::string path_at(int64_t i, int frame) const;
  /// check_output_locations() for the previews due in `range` (the range given to the constructor).
  void check_locations(const FrameRange &range, const RunInputs &inputs) const;
  /// The preview pattern, empty when there are no previews.
  const std::string &pattern() const { return pattern_; }

 private:
  std::string what_;
  std::string pattern_;
  int every_;
  bool sequence_ = false;  // the pattern has a frame field
};
/// The preview size: `option` when > 0, else the groom's output.preview_size (both checked to lie in
/// [16, max_preview_size] where they are read).
int preview_size_of(int option, const GroomDesc &groom);
/// Adds a preview size option `name` in [16, max_preview_size] to `cmd`.
void add_preview_size_option(CLI::App &cmd, const std::string &name, int &r_size, const std::string &description);
/// What the preview camera of a groom frames: the rest emitter and the rest guides, so that every
/// frame of a sequence is seen from the same place.
Eigen::AlignedBox3f groom_bounds(const Pipeline &pipeline);
/// The preview camera of a groom, seen from `angle`, fitted to groom_bounds().
PreviewCamera groom_camera(const Pipeline &pipeline, const CameraAngle &angle = {});

}  // namespace plume
