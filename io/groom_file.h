// Reading a groom file (YAML, documented in docs/groom-format.md) into a validated GroomDesc,
// with every path made absolute against the groom file's folder.
#pragma once

#include <string>

#include "groom/groom_desc.h"

namespace plume::io {

/// Reads and validates the groom file at `path`. Every problem is an InputError whose message is
/// "file:line:col: key.path: expected X, got Y" (key paths with indices, e.g. `effects[2].amount`):
/// a missing or unreadable file, a YAML syntax error, unknown keys, wrong types, out-of-range values,
/// missing required keys, and referenced files (emitter mesh, guides, zone map, vertex maps, roots
/// file) that do not exist. Paths in the file are relative to the groom file's folder; the returned
/// description holds them absolute (output patterns too, though their folders need not exist yet).
GroomDesc read_groom_file(const std::string &path);

/// A short human-readable summary of a groom (emitter, guides, roots, strands, method, partings,
/// effects stack, dynamics, output), one item per line, for `plume info`.
std::string describe_groom(const GroomDesc &groom);

}  // namespace plume::io
