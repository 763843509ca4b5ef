#include "io/usda_stage.h"

#include <filesystem>

#include "groom/error.h"
#include "io/atomic_file.h"
#include "io/file_scan.h"

namespace plume::io {

namespace {

namespace fs = std::filesystem;
using detail::append_string_literal;


/// `path` relative to `folder`, as a USD asset path ("./name" or "../x/name").
std::string relative_asset(const std::string &path, const fs::path &folder) {
  const fs::path absolute = fs::absolute(path).lexically_normal();
  std::string relative = absolute.lexically_relative(folder).generic_string();
  if (relative.empty()) relative = absolute.generic_string();
  if (relative.rfind("../", 0) != 0 && relative.front() != '/') relative = "./" + relative;
  return "@" + relative + "@";
}

}  // namespace

std::string usd_manifest_path(const std::string &stage_path) {
  const fs::path path(stage_path);
  return (path.parent_path() / (path.stem().string() + ".manifest.usda")).string();
}

void write_usd_stage(const std::string &stage_path, const UsdStageOptions &options) {
  const FileLoc loc{stage_path};
  if (options.time_codes.empty()) throw InputError(loc, "USD stage: expected at least one frame, got none");
  if (options.time_codes.size() != options.frame_paths.size())
    throw InternalError("write_usd_stage: one frame path per time code expected");
  for (size_t i = 1; i < options.time_codes.size(); ++i)
    if (!(options.time_codes[i] > options.time_codes[i - 1]))
      throw InputError(loc, "USD stage: expected increasing time codes");
  const std::string manifest_path = usd_manifest_path(stage_path);
  for (const std::string &path : options.frame_paths)
    if (path.find('@') != std::string::npos)
      throw InputError(loc, "USD stage: cannot name " + path + " as a USD asset (the path holds '@')");
  if (manifest_path.find('@') != std::string::npos)
    throw InputError(loc, "USD stage: cannot name " + manifest_path + " as a USD asset (the path holds '@')");
  const fs::path folder = fs::absolute(stage_path).lexically_normal().parent_path();

  std::string manifest = "#usda 1.0\n(\n";
  manifest += "    doc = \"Value clip manifest: the attributes the frame layers animate\"\n)\n\n";
  manifest += "over \"Groom\"\n{\n";
  for (const std::string &prim : options.curves_prims) {
    manifest += "    over ";
    append_string_literal(manifest, prim);
    manifest += "\n    {\n        point3f[] points\n        float3[] extent\n    }\n";
  }
  manifest += "}\n";

  std::string out = "#usda 1.0\n(\n";
  if (!options.comment.empty()) {
    out += "    doc = ";
    append_string_literal(out, options.comment);
    out += '\n';
  }
  out += "    defaultPrim = \"Groom\"\n    metersPerUnit = ";
  detail::append_number(out, options.meters_per_unit);
  out += "\n    upAxis = ";
  append_string_literal(out, options.up_axis);
  out += "\n    startTimeCode = ";
  detail::append_number(out, options.time_codes.front());
  out += "\n    endTimeCode = ";
  detail::append_number(out, options.time_codes.back());
  out += "\n    timeCodesPerSecond = ";
  detail::append_number(out, options.fps);
  out += "\n)\n\n";
  out += "def Xform \"Groom\" (\n    kind = \"component\"\n    prepend apiSchemas = [\"GroomAPI\"]\n";
  out += "    prepend references = " + relative_asset(options.frame_paths.front(), folder) + "\n";
  out += "    clips = {\n        dictionary default = {\n";
  auto append_pairs = [&](const char *name, bool identity) {
    out += std::string("            double2[] ") + name + " = [";
    for (size_t i = 0; i < options.time_codes.size(); ++i) {
      if (i > 0) out += ", ";
      out += '(';
      detail::append_number(out, options.time_codes[i]);
      out += ", ";
      if (identity)
        detail::append_number(out, options.time_codes[i]);
      else
        detail::append_number(out, (long long)i);
      out += ')';
    }
    out += "]\n";
  };
  append_pairs("active", false);
  out += "            asset[] assetPaths = [";
  for (size_t i = 0; i < options.frame_paths.size(); ++i) {
    if (i > 0) out += ", ";
    out += relative_asset(options.frame_paths[i], folder);
  }
  out += "]\n";
  out += "            asset manifestAssetPath = " + relative_asset(manifest_path, folder) + "\n";
  out += "            string primPath = \"/Groom\"\n";
  append_pairs("times", true);
  out += "        }\n    }\n)\n{\n}\n";

  AtomicFile manifest_file(manifest_path);
  manifest_file.write(manifest);
  manifest_file.commit();
  AtomicFile stage_file(stage_path);
  stage_file.write(out);
  stage_file.commit();
}

}  // namespace plume::io
