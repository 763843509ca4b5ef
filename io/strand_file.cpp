#include "io/strand_file.h"

#include <algorithm>
#include <set>

#include "io/file_scan.h"
#include "io/strand_formats.h"

namespace plume::io {

namespace {

StrandSet read_by_extension(const std::string &path) {
  const std::string ext = detail::extension_of(path);
  if (ext == ".hair") return detail::read_hair(path);
  if (ext == ".ply") return detail::read_ply(path);
  if (ext == ".usda") return detail::read_usda(path);
  if (ext == ".obj") return detail::read_obj_strands(path);
  throw InputError(FileLoc{path}, "strand file: expected extension .hair, .ply, .usda or .obj, got " +
                                      detail::quoted(ext));
}

/// The promises every reader's strands keep, whatever the format.
void check_read_strands(const std::string &path, const StrandSet &strands) {
  strands.check_invariants();  // a reader's bug, not the file's
  // Each reader refuses a bad value where it reads it, naming its place; these are the promises
  // whatever the format.
  for (size_t s = 0; s < strands.strand_count(); ++s)
    if (strands.points_in(s) < 2)
      throw InputError(FileLoc{path}, "strand " + std::to_string(s) + ": expected at least 2 points, got " +
                                          std::to_string(strands.points_in(s)));
  for (size_t p = 0; p < strands.widths.size(); ++p)
    if (!detail::valid_width(strands.widths[p]))
      throw InputError(FileLoc{path}, "point " + std::to_string(p) + ": width: " + detail::width_message(strands.widths[p]));
}

}  // namespace

std::vector<std::pair<std::string, StrandSet>> read_strand_groups(const std::string &path) {
  if (detail::extension_of(path) != ".usda") return {{std::string(), read_strands(path)}};
  std::vector<std::pair<std::string, StrandSet>> groups = detail::read_usda_prims(path);
  for (const auto &[name, strands] : groups) check_read_strands(path, strands);
  return groups;
}

StrandSet read_strands(const std::string &path) {
  StrandSet strands = read_by_extension(path);
  check_read_strands(path, strands);
  return strands;
}

void write_strands(const std::string &path, const StrandSet &strands, const StrandWriteOptions &options) {
  strands.check_invariants();
  const std::string ext = detail::extension_of(path);
  if (ext != ".hair" && ext != ".ply" && ext != ".usda" && ext != ".obj")
    throw InputError(FileLoc{path}, "strand file: expected extension .hair, .ply, .usda or .obj, got " +
                                        detail::quoted(ext));
  if (!options.root_uvs.empty() && options.root_uvs.size() != strands.strand_count())
    throw InternalError("write_strands: root_uvs must be empty or one per strand (" +
                        std::to_string(strands.strand_count()) + "), got " + std::to_string(options.root_uvs.size()));
  if (!options.group_ids.empty() && options.group_ids.size() != strands.strand_count())
    throw InternalError("write_strands: group_ids must be empty or one per strand (" +
                        std::to_string(strands.strand_count()) + "), got " + std::to_string(options.group_ids.size()));
  for (size_t s = 0; s < strands.strand_count(); ++s)
    if (strands.points_in(s) < 2)
      throw InputError(FileLoc{path}, "strand " + std::to_string(s) + ": expected at least 2 points, got " +
                                          std::to_string(strands.points_in(s)));
  AtomicFile file(path);
  if (ext == ".hair") detail::write_hair(file, strands, options);
  if (ext == ".ply") detail::write_ply(file, strands, options);
  if (ext == ".usda") detail::write_usda(file, strands, options);
  if (ext == ".obj") detail::write_obj_strands(file, strands, options);
  file.commit();
}

bool is_usd_identifier(const std::string &name) {
  if (name.empty() || (name[0] >= '0' && name[0] <= '9')) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
  });
}

void write_strand_groups(const std::string &path, std::span<const StrandGroup> groups,
                         const StrandWriteOptions &options) {
  if (detail::extension_of(path) != ".usda")
    throw InputError(FileLoc{path}, "hair groups in one file: expected a .usda (one BasisCurves prim per group), got " +
                                        detail::quoted(detail::extension_of(path)));
  std::set<std::string> names;
  for (const StrandGroup &group : groups) {
    if (!is_usd_identifier(group.name))
      throw InputError(FileLoc{path}, "hair group " + detail::quoted(group.name) +
                                          ": expected a USD prim name (letters, digits, _; not starting with a digit)");
    if (!names.insert(group.name).second)
      throw InputError(FileLoc{path},
                       "hair group " + detail::quoted(group.name) + ": expected a name no other group has");
    if (!group.strands) throw InternalError("write_strand_groups: a group without strands");
    group.strands->check_invariants();
    if (!group.root_uvs.empty() && group.root_uvs.size() != group.strands->strand_count())
      throw InternalError("write_strand_groups: root_uvs must be empty or one per strand");
    for (size_t s = 0; s < group.strands->strand_count(); ++s)
      if (group.strands->points_in(s) < 2)
        throw InputError(FileLoc{path}, "hair group " + group.name + ", strand " + std::to_string(s) +
                                            ": expected at least 2 points, got " +
                                            std::to_string(group.strands->points_in(s)));
  }
  AtomicFile file(path);
  detail::write_usda_groups(file, groups, options);
  file.commit();
}

}  // namespace plume::io
