// Reads and writes strand sets in the interchange formats of ../shared/FORMATS.md:
// USD BasisCurves `.usda`, Cem Yuksel's `.hair`, binary `.ply` with edges, and OBJ `l` segments.
#pragma once

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "groom/strand_set.h"

namespace plume::io {

/// Reads strands, choosing the format by extension (case-insensitive):
/// - `.hair`: segments (or the default segment count), points, thickness as widths when present;
///   ids 0..n-1.
/// - `.ply`: ascii or binary_little_endian; `vertex` x/y/z (float or double), optional `width`;
///   either `edge` vertex1/vertex2 chained into strands, or a per-vertex `strand`/`curve` id
///   (consecutive vertices with the same id form one strand); ids 0..n-1.
/// - `.usda`: the BasisCurves subset write_strands produces: curveVertexCounts, points, widths
///   (constant, uniform or vertex); ids from primvars:plume_id, else primvars:groom_id (files from
///   other tools), else 0..n-1. A file with several BasisCurves prims (one per hair group) reads
///   as their strands one prim after the other, in file order.
/// - `.obj`: `v` lines and `l` lines; consecutive `l` lines that share an end point are chained
///   into one strand; ids 0..n-1.
/// Every strand has at least 2 points, every coordinate is a finite float and every width a finite
/// float >= 0 (a value beyond float range, such as 1e300 in a .usda or a double PLY, is refused, not
/// read as infinity). Points are not held to the scene bound here (files round-trip any float):
/// the stages that take them as guides, roots or caches check it. Throws InputError with
/// `file:line` (text) or `file@byte N` (binary) and what was expected, for any malformed,
/// truncated, non-finite or out-of-range input.
StrandSet read_strands(const std::string &path);

/// The hair groups of a strand file: for a `.usda`, each BasisCurves prim's name and strands, in
/// file order (a file write_strand_groups() wrote holds one per group); for the other formats, one
/// entry with an empty name holding read_strands(). Checked as read_strands() checks.
std::vector<std::pair<std::string, StrandSet>> read_strand_groups(const std::string &path);

struct StrandWriteOptions {
  /// Empty, or one (u, v) per strand: the root's UV on the emitter, written as
  /// `texCoord2f[] primvars:groom_root_uv` (.usda; the name Unreal's groom importer reads).
  std::vector<Eigen::Vector2f> root_uvs;
  /// Empty (every strand in group 0), or one hair group id per strand, written as
  /// `int[] primvars:groom_group_id` (.usda): Unreal's groom importer makes one hair group of the
  /// curves that share one. The per-strand stable ids go in `int64[] primvars:plume_id`.
  std::vector<int32_t> group_ids;
  /// Diameter written when the set has no widths (scene units).
  float constant_width = 0.01f;
  /// USD layer metadata `metersPerUnit` (0.01: scene units are centimetres).
  double meters_per_unit = 0.01;
  /// USD layer metadata `upAxis`: "Y" or "Z".
  std::string up_axis = "Y";
  /// When set, the USD layer gets startTimeCode = endTimeCode = *time_code and the points are
  /// authored as a time sample at that code.
  std::optional<double> time_code;
  /// USD `timeCodesPerSecond` (written only with a time code).
  double fps = 24.0;
  /// Free text: the `.usda` layer doc, the `.hair` header info (first 87 bytes), a PLY/OBJ comment.
  std::string comment;
};

/// Writes strands, choosing the format by extension: `.usda`, `.hair`, `.ply` (binary little
/// endian, vertex + one edge per segment, `width` per vertex when present) or `.obj` (`v` lines and
/// one two-index `l` per segment). Floats are written in their shortest form that reads back
/// exactly. The file appears whole or not at all (AtomicFile). Throws InputError on an unknown
/// extension or a strand the format cannot hold (.hair: more than 65,536 points per strand),
/// InternalError when `strands` breaks its invariants.
void write_strands(const std::string &path, const StrandSet &strands, const StrandWriteOptions &options = {});

/// One hair group of a frame, for write_strand_groups().
struct StrandGroup {
  /// The BasisCurves prim's name: a USD identifier (letters, digits, '_', not starting with a digit).
  std::string name;
  const StrandSet *strands = nullptr;
  /// Empty, or one root UV per strand (`primvars:groom_root_uv`).
  std::vector<Eigen::Vector2f> root_uvs;
  /// Written for every curve of the group as `primvars:groom_group_id`.
  int32_t group_id = 0;
};

/// Writes several hair groups into one `.usda` layer: one BasisCurves prim per group under the
/// Groom Xform, in the order given, each as write_strands() writes its single prim (`options`'
/// root_uvs and group_ids are not used: each group brings its own). Throws InputError when `path`
/// is not a `.usda` or a name is not a USD identifier or repeats, and as write_strands() does.
void write_strand_groups(const std::string &path, std::span<const StrandGroup> groups,
                         const StrandWriteOptions &options = {});

/// True when `name` can name a USD prim: ASCII letters, digits and '_', not starting with a digit.
bool is_usd_identifier(const std::string &name);

}  // namespace plume::io
