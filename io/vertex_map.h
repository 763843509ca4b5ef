// Reads a vertex map: one number per emitter vertex, a text file with one number per line.
#pragma once

#include <string>
#include <vector>

#include "groom/error.h"

namespace plume::io {

/// One number in [0, 1] per line ('#' starts a comment, blank lines are skipped), exactly
/// `vertex_count` numbers. Throws InputError "file:line:col: ..." for a value that is not a number,
/// not finite or outside [0, 1], and names the file and both counts when they differ; `what` (the
/// key that names the file) leads the message when the file cannot be opened, and ends it, in
/// parentheses, otherwise.
std::vector<float> read_vertex_map(const std::string &path, size_t vertex_count, const std::string &what);

}  // namespace plume::io
