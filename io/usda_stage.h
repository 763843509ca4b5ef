// The top-level USD stage of an animated groom: one small `.usda` that composes the per-frame
// layers of a frame range as value clips, so that USD readers (Houdini, Unreal, usdview) open the
// whole range as one animated groom. It is written from the range alone and names the frame files
// by paths relative to itself: every farm chunk that writes it writes the same bytes, and it never
// reads a frame another chunk writes.
#pragma once

#include <string>
#include <vector>

namespace plume::io {

struct UsdStageOptions {
  /// The time codes of the range, increasing (the frames), and for each the frame layer's path
  /// (absolute, or relative to the current directory): the stage names them relative to itself.
  std::vector<double> time_codes;
  std::vector<std::string> frame_paths;
  /// The BasisCurves prims under /Groom whose `points` and `extent` are animated ("hair", or one
  /// per hair group): the manifest declares them.
  std::vector<std::string> curves_prims;
  double meters_per_unit = 0.01;
  std::string up_axis = "Y";
  double fps = 24.0;
  /// The stage's `doc`, empty for none.
  std::string comment;
};

/// The value-clip manifest written beside `stage_path`: `<stem>.manifest.usda` (`hair.usda` gives
/// `hair.manifest.usda`).
std::string usd_manifest_path(const std::string &stage_path);

/// Writes the stage at `stage_path` and its manifest (usd_manifest_path()), each atomically:
/// - the stage: layer metadata (defaultPrim "Groom", metersPerUnit, upAxis, start/endTimeCode of
///   the range, timeCodesPerSecond), and `def Xform "Groom"` that references the range's first
///   frame layer (its topology, widths and primvars, which do not change with time) and holds
///   `clips` = { assetPaths: every frame layer, active: frame i from time code i, times: identity,
///   primPath "/Groom", manifestAssetPath };
/// - the manifest: `points` and `extent` of each curves prim, declared without values.
/// Throws InputError naming the stage when the range is empty, the lists differ in size, the time
/// codes do not increase, or a path holds '@' (USD asset paths cannot), and as AtomicFile does.
void write_usd_stage(const std::string &stage_path, const UsdStageOptions &options);

}  // namespace plume::io
