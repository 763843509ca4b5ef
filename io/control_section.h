// The `controls` section of a groom file (docs/groom-format.md, "controls"): the animator's
// regional controls and their keyframed behaviours, and the vertex maps they weigh guides by.
#pragma once

#include <string>
#include <vector>

#include "groom/groom_desc.h"
#include "io/yaml_fields.h"

namespace plume::io {

/// Reads `controls` from the groom file's top-level map into r_groom.controls (left empty when the
/// section is absent). Call after the dynamics section: a dynamic blend needs dynamics. Paths are
/// made absolute against the folder of `groom_file`. Throws InputError "file:line:col: key.path:
/// expected X, got Y" for every bad value.
void read_controls_section(YamlMap &root, const std::string &groom_file, GroomDesc &r_groom);

/// Every control's vertex map: one vector per control of `settings` (empty when it has none),
/// each `vertex_count` numbers in [0, 1] (one per line, `#` starts a comment). Throws InputError
/// naming the file and line, or the control's `map` key for a count that differs.
std::vector<std::vector<float>> read_control_maps(const ControlSettings &settings, size_t vertex_count);

}  // namespace plume::io
