// Reads a list of root positions: a plain text file or the first points of a strand file.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace plume::io {

/// `.txt`: one `x y z` per line, `#` starts a comment, blank lines skipped.
/// Any strand format read_strands accepts: the first point of each strand.
/// Throws InputError with `file:line` (`.txt`) or the strand index on malformed or non-finite
/// values and on points beyond max_coordinate (groom/limits.h).
std::vector<Eigen::Vector3f> read_points(const std::string &path);

}  // namespace plume::io
