// Where a groom's outputs go beyond the per-frame pattern: the hair groups' files, and the
// top-level USD stage that composes a .usda sequence into one animated groom.
#pragma once

#include <string>
#include <vector>

#include "app/frame_range.h"
#include "groom/groom_desc.h"
#include "groom/strand_set.h"

namespace plume {

/// The hair groups of `groom`: its groups list, or the groom itself when it has none.
std::vector<GroomDesc> hair_groups(const GroomDesc &groom);

/// Throws InputError (at the groom's groups) when `groom` has hair groups: `command` grows one.
void require_one_group(const GroomDesc &groom, const std::string &command);

/// The strands of every set in `sets`, one set after the other (offsets, positions, ids; widths
/// when every set has them).
StrandSet concatenate_strands(const std::vector<const StrandSet *> &sets);

/// The file pattern of hair group `group_name` for a format that holds one group a file (.hair,
/// .ply, .obj): `.<group_name>` inserted in the file name before its frame field and the separator
/// before it (`hair.####.ply` gives `hair.brows.####.ply`), or before the extension when the name
/// has no frame field (`hair.ply` gives `hair.brows.ply`).
std::string group_file_pattern(const std::string &pattern, const std::string &group_name);

/// The top-level stage of a `.usda` output pattern: the pattern's file name without its frame
/// field and the separator before it (`out/hair.####.usda` gives `out/hair.usda`,
/// `hair_%04d.usda` gives `hair.usda`). Empty when the pattern is not a `.usda`, or its frame field
/// is not in the file name (a folder per frame), or the name is the frame field alone.
std::string default_stage_path(const std::string &pattern);

/// The frames a stage spans: `option` (--stage-frames) when given, else the groom's output.frames
/// when it has them (every farm chunk of the shot then writes the same stage), else `run`.
FrameRange stage_frames(const std::string &option, const GroomDesc &groom, const FrameRange &run);

/// Writes the stage at `stage_path` (and its manifest) for the frames of `range` of `pattern`,
/// the BasisCurves prims `curves_prims` animated, with the groom's units, up axis and frame rate.
void write_groom_stage(const std::string &stage_path, const std::string &pattern, const FrameRange &range,
                       const std::vector<std::string> &curves_prims, const GroomDesc &groom);

}  // namespace plume
