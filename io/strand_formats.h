// One reader and one writer per strand format; read_strands/write_strands choose between them.
#pragma once

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "groom/strand_set.h"
#include "io/atomic_file.h"
#include "io/file_scan.h"
#include "io/strand_file.h"

namespace plume::io::detail {

StrandSet read_hair(const std::string &path);
StrandSet read_ply(const std::string &path);
StrandSet read_usda(const std::string &path);
/// Each BasisCurves prim of a .usda: its name and its strands, in file order.
std::vector<std::pair<std::string, StrandSet>> read_usda_prims(const std::string &path);
StrandSet read_obj_strands(const std::string &path);
/// read_obj_strands() of `text`, the contents of `path`.
StrandSet read_obj_strands_text(const std::string &path, const std::string &text);

void write_hair(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options);
void write_ply(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options);
void write_usda(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options);
void write_obj_strands(AtomicFile &file, const StrandSet &strands, const StrandWriteOptions &options);
/// The groups' strands checked (names, counts) by write_strand_groups().
void write_usda_groups(AtomicFile &file, std::span<const StrandGroup> groups, const StrandWriteOptions &options);

/// Output is built in a buffer and handed to the file in blocks of about this size.
constexpr size_t kWriteBlockBytes = 1 << 20;

/// Hands `block` to `file` and empties it once it holds kWriteBlockBytes or more.
inline void flush_block_if_full(AtomicFile &file, std::string &block) {
  if (block.size() >= kWriteBlockBytes) {
    file.write(block);
    block.clear();
  }
}

/// Appends one OBJ `v x y z` line per point to `block`, handing it to `file` in blocks.
inline void append_obj_vertices(AtomicFile &file, std::string &block, std::span<const Eigen::Vector3f> points) {
  for (const Eigen::Vector3f &p : points) {
    block += "v ";
    append_number(block, p.x());
    block += ' ';
    append_number(block, p.y());
    block += ' ';
    append_number(block, p.z());
    block += '\n';
    flush_block_if_full(file, block);
  }
}

}  // namespace plume::io::detail
