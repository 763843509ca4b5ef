// How strands are coloured in the preview PNGs and in the viewer, the same in both: plain hair, the
// guide that weighs most, the clump, the hard zone and the side of a partial parting, and the
// checker's problems (points inside the skin, crossing pairs).
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "app/preview.h"
#include "check/check.h"
#include "groom/mesh.h"
#include "groom/strand_set.h"

namespace plume {

class Pipeline;

enum class ColorMode { plain, guide, clump, zone, problems };

/// Every mode, in the order menus list them.
inline constexpr std::array<ColorMode, 5> kColorModes = {ColorMode::plain, ColorMode::guide, ColorMode::clump,
                                                         ColorMode::zone, ColorMode::problems};
/// "plain", "guide", "clump", "zone", "problems".
const char *color_mode_name(ColorMode mode);
/// The mode named `text` (color_mode_name()); throws InputError naming `what` otherwise.
ColorMode parse_color_mode(const std::string &text, const std::string &what);

/// What the rest pose decided for each root of a groom, one entry per strand in root order.
struct StrandAttributes {
  /// The guide that weighs most in the strand's binding (-1: none).
  std::vector<int32_t> guide;
  /// The clump of the groom's first clump effect: the index of the clump's centre strand (-1: in
  /// no clump). A stray keeps the clump it was left out of. Empty when the groom has no clump effect.
  std::vector<int32_t> clump;
  /// The hard zone, in [0, zone_count).
  std::vector<int32_t> zone;
  int zone_count = 1;
  /// The side of the nearest partial parting line: -1 left, +1 right (looking along the line's
  /// points, the skin's normal up), 0 farther than a quarter of the line's length from it or past
  /// its ends. Empty when the groom has no partial line.
  std::vector<int8_t> side;
};

/// The attributes of the pipeline's roots (its binding, partings and effects stack).
StrandAttributes strand_attributes(const Pipeline &pipeline);

/// Flags of StrandProblems::flags.
inline constexpr uint8_t kProblemInside = 1;    // a point of the strand inside the skin
inline constexpr uint8_t kProblemCrossing = 2;  // the strand crosses another one transversally
inline constexpr uint8_t kProblemTouching = 4;  // it touches another, near-parallel (not a violation)

/// What the checker looks for, as `plume check` takes it (check::CheckOptions).
struct ProblemOptions {
  /// Crossing tolerance (scene units); 0: check::kToleranceOfMedianSegment x the strands' median
  /// segment length, as `plume check` derives it.
  float crossing_tolerance = 0.0f;
  float transversal_degrees = check::kTransversalDegrees;
  float skin_margin = 0.0f;
  /// The most crossing pairs of each kind flagged: beyond it, a sample of the pairs spread over
  /// the groom (keeping the checker's memory and time bounded whatever the number of pairs).
  size_t max_pairs = 16384;
  /// False: points inside the skin only (a feather's barbs meet its rachis by design).
  bool judge_crossings = true;
};

/// The checker's findings on one frame's strands, per strand.
struct StrandProblems {
  std::vector<uint8_t> flags;  // one per strand, kProblemInside | kProblemCrossing | kProblemTouching
  size_t points_inside = 0;
  size_t strands_inside = 0;
  float tolerance = 0.0f;  // the crossing tolerance used, scene units
  bool crossings_before_effects = false;  // judged on the strands before the effects stack
  size_t transversal_pairs = 0;  // every pair the checker counted, as `plume check` does
  size_t touching_pairs = 0;
  /// The pairs whose two strands are flagged: all of them, or max_pairs of each kind spread over
  /// the groom.
  size_t transversal_flagged = 0;
  size_t touching_flagged = 0;
};

/// Runs the checker (check/check.h) on `strands` against `mesh` (the emitter at their pose) as
/// `plume check` does, and flags every strand it reports: points inside the skin on `strands`,
/// crossings on `before_effects` when given (the same strands grown without the effects stack,
/// which gathers and crosses strands on purpose: `plume check --groom` judges those), else on
/// `strands`, at the tolerance derived from `strands`. Throws InputError when the tolerance is beyond
/// the checker's budget or cannot be derived (its message, unprefixed).
StrandProblems find_problems(const StrandSet &strands, const Mesh &mesh, const ProblemOptions &options,
                             const StrandSet *before_effects = nullptr);

using Rgb8 = std::array<uint8_t, 3>;

/// The colours (sRGB, 8 bits) of the problems mode: a strand without a problem, with a point inside
/// the skin, crossing another (transversally), both, touching another (near-parallel, not a
/// violation: a pale tone, drawn among the others).
inline constexpr Rgb8 kProblemClean = {112, 104, 98};
inline constexpr Rgb8 kProblemInsideColor = {236, 40, 40};
inline constexpr Rgb8 kProblemCrossingColor = {255, 170, 0};
inline constexpr Rgb8 kProblemBothColor = {230, 40, 230};
inline constexpr Rgb8 kProblemTouchingColor = {190, 200, 140};
Rgb8 problem_color(uint8_t flags);
/// Whether a strand with `flags` breaks a promise (inside the skin, crossing): drawn over the others.
inline bool problem_is_violation(uint8_t flags) { return (flags & (kProblemInside | kProblemCrossing)) != 0; }

/// One colour per strand of `strands` (sRGB, 8 bits) in `mode`. `attributes` covers the strands
/// (StrandAttributes of their roots, same order) for guide, clump and zone; `problems` covers them
/// for the problems mode. A mode without its data (no clump effect, no problems given) colours
/// every strand alike: plain hair for clump, the clean colour for problems.
std::vector<Rgb8> strand_colors(ColorMode mode, const StrandSet &strands, const StrandAttributes &attributes,
                                const StrandProblems *problems, const PreviewStyle &style = {});

/// `colors` as linear RGB, for the rasteriser.
std::vector<Eigen::Vector3f> linear_colors(const std::vector<Rgb8> &colors);
/// Linear RGB in [0, 1] to 8-bit sRGB, and back.
Rgb8 srgb_from_linear(const Eigen::Vector3f &linear);
Eigen::Vector3f linear_from_srgb(const Rgb8 &srgb);

}  // namespace plume
