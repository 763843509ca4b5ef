#include "io/strand_file.h"

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

}  // namespace

StrandSet read_strands(const std::string &path) {
  StrandSet strands = read_by_extension(path);
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

}  // namespace plume::io
