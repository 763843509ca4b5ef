#include "io/feather_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <set>
#include <sstream>
#include <tuple>

#include "groom/limits.h"
#include "io/file_scan.h"
#include "io/yaml_fields.h"

namespace plume::io {

namespace {

namespace fs = std::filesystem;

constexpr double max_number = max_coordinate;
constexpr int64_t max_seed = int64_t(1) << 53;
constexpr int64_t max_follicles = 100'000'000;
constexpr int max_detail_points = 4096;

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string indexed(const std::string &path, size_t i) { return path + "[" + std::to_string(i) + "]"; }

/// Reads the feather keys of one YAML file (the groom file, or a template file it names).
class FeatherReader {
 public:
  FeatherReader(std::string file, fs::path folder) : file_(std::move(file)), folder_(std::move(folder)) {}

  FeatherDesc read(const YAML::Node &node);
  /// A `templates` map (name -> template) at `path`, appended to r_templates; names must be new.
  void read_templates(const YAML::Node &node, const std::string &path, std::vector<FeatherTemplate> &r_templates);

 private:
  // --- numbers: each marks the key as known and names the key path and range on failure ---
  float positive(YamlMap &m, const std::string &key, float fallback) {
    const double v = m.number(key, fallback);
    if (!(v > 0.0)) fail_expected(file_, m.node(key), m.key_path(key), "a number > 0");
    if (!(v <= max_number)) fail_expected(file_, m.node(key), m.key_path(key), "a number in (0, 1e+06]");
    return float(v);
  }
  float non_negative(YamlMap &m, const std::string &key, float fallback, double hi = max_number) {
    const double v = m.number(key, fallback);
    if (!(v >= 0.0)) fail_expected(file_, m.node(key), m.key_path(key), "a number >= 0");
    if (!(v <= hi)) fail_expected(file_, m.node(key), m.key_path(key), "a number in [0, " + format_number(hi) + "]");
    return float(v);
  }
  float within(YamlMap &m, const std::string &key, float fallback, double lo, double hi) {
    return float(m.number_in(key, fallback, lo, hi));
  }
  /// A number, or a map {base, tip}: the value at the rachis base and tip.
  void base_tip(YamlMap &m, const std::string &key, float &r_base, float &r_tip, double lo, double hi,
                bool positive_only);
  Ramp silhouette(YamlMap &m, const std::string &key);
  std::vector<KeyBarb> key_barbs(YamlMap &m, const std::string &key);
  void read_vane(YamlMap &vane, VaneDesc &r_vane);
  FeatherTemplate read_template(const YAML::Node &node, const std::string &path, const std::string &name);
  KeyFeather read_key_feather(const YAML::Node &node, const std::string &path);
  void read_follicles(YamlMap &m, FollicleSettings &r_follicles);

  std::string absolute(const std::string &written) const {
    const fs::path p(written);
    return (p.is_absolute() ? p : folder_ / p).lexically_normal().string();
  }
  /// A path to a file that must exist now, with one of `extensions` (empty: any).
  std::string existing_file(YamlMap &m, const std::string &key, const std::vector<std::string> &extensions);
  /// The same for a path `written` at `node` (key path `path`).
  std::string existing_path(const YAML::Node &node, const std::string &written, const std::string &path,
                            const std::vector<std::string> &extensions);

  std::string file_;
  fs::path folder_;
};

void FeatherReader::base_tip(YamlMap &m, const std::string &key, float &r_base, float &r_tip, double lo, double hi,
                             bool positive_only) {
  if (!m.given(key)) return;
  const YAML::Node node = m.node(key);
  const std::string range = positive_only ? "a number in (" + format_number(lo) + ", " + format_number(hi) + "]"
                                          : "a number in [" + format_number(lo) + ", " + format_number(hi) + "]";
  auto check = [&](const YAML::Node &n, const std::string &path) {
    const double v = node_number(n, path, file_);
    if (!(positive_only ? v > lo : v >= lo) || !(v <= hi)) fail_expected(file_, n, path, range);
    return float(v);
  };
  if (node.IsScalar()) {
    r_base = r_tip = check(node, m.key_path(key));
    return;
  }
  YamlMap pair(node, m.key_path(key), file_);
  if (pair.given("base")) r_base = check(pair.node("base"), pair.key_path("base"));
  if (pair.given("tip")) r_tip = check(pair.node("tip"), pair.key_path("tip"));
  pair.finish();
}

Ramp FeatherReader::silhouette(YamlMap &m, const std::string &key) {
  const YAML::Node node = m.node(key);
  const std::string path = m.key_path(key);
  if (!node.IsSequence()) fail_expected(file_, node, path, "a list of [t, length] points");
  if (node.size() == 0)
    throw InputError(node_loc(file_, node), path + ": expected at least one [t, length] point, got an empty list");
  Ramp ramp;
  for (size_t i = 0; i < node.size(); ++i) {
    const YAML::Node point = node[i];
    const std::string at = indexed(path, i);
    if (!point.IsSequence() || point.size() != 2) fail_expected(file_, point, at, "a [t, length] pair");
    const double t = node_number(point[0], indexed(at, 0), file_);
    const double lo = ramp.t.empty() ? 0.0 : ramp.t.back();
    if (!(t >= lo && t <= 1.0))
      fail_expected(file_, point[0], indexed(at, 0),
                    "t in [" + format_number(lo) + ", 1]" + (ramp.t.empty() ? "" : " (t sorted from base to tip)"));
    const double length = node_number(point[1], indexed(at, 1), file_);
    if (!(length >= 0.0 && length <= max_number))
      fail_expected(file_, point[1], indexed(at, 1), "a length in [0, 1e+06]");
    ramp.t.push_back(float(t));
    ramp.value.push_back(float(length));
  }
  return ramp;
}

std::vector<KeyBarb> FeatherReader::key_barbs(YamlMap &m, const std::string &key) {
  std::vector<KeyBarb> keys;
  const std::vector<YAML::Node> items = m.sequence(key);
  for (size_t k = 0; k < items.size(); ++k) {
    const std::string path = indexed(m.key_path(key), k);
    YamlMap item(items[k], path, file_);
    KeyBarb barb;
    barb.loc = item.loc();
    if (!item.given("position"))
      throw InputError(item.loc(), item.key_path("position") + ": missing required key (a number in [0, 1])");
    const float lo = keys.empty() ? 0.0f : keys.back().position;
    const double position = item.number("position");
    if (!(position >= lo && position <= 1.0))
      fail_expected(file_, item.node("position"), item.key_path("position"),
                    "a position in [" + format_number(lo) + ", 1]" +
                        (keys.empty() ? "" : " (key barbs sorted from base to tip)"));
    barb.position = float(position);
    if (!item.given("points"))
      throw InputError(item.loc(), item.key_path("points") + ": missing required key (a list of 2 to " +
                                       std::to_string(max_barb_control_points) + " control vertices [x, y, z])");
    const YAML::Node points = item.node("points");
    if (!points.IsSequence() || points.size() < 2 || points.size() > size_t(max_barb_control_points))
      fail_expected(file_, points, item.key_path("points"),
                    "a list of 2 to " + std::to_string(max_barb_control_points) + " control vertices [x, y, z]");
    for (size_t i = 0; i < points.size(); ++i) {
      const std::string at = indexed(item.key_path("points"), i);
      const Eigen::Vector3f p = node_vec3(points[i], at, file_);
      for (int axis = 0; axis < 3; ++axis)
        if (!(std::abs(p[axis]) <= max_number))
          fail_expected(file_, points[i][axis], indexed(at, size_t(axis)), "a number in [-1e+06, 1e+06]");
      barb.points.push_back(p);
    }
    barb.plumulaceous = within(item, "plumulaceous", barb.plumulaceous, 0.0, 1.0);
    item.finish();
    keys.push_back(std::move(barb));
  }
  return keys;
}

void FeatherReader::read_vane(YamlMap &vane, VaneDesc &r_vane) {
  base_tip(vane, "angle", r_vane.angle_base, r_vane.angle_tip, 0.0, 180.0, false);
  if (vane.given("length") && vane.given("silhouette"))
    throw InputError(node_loc(file_, vane.node("silhouette")),
                     vane.key_path("silhouette") + ": not allowed with " + vane.key_path("length") +
                         " (a barb length is constant or from a silhouette)");
  if (vane.given("length")) {
    r_vane.barb_length = non_negative(vane, "length", r_vane.barb_length);
    r_vane.silhouette = Ramp{};
  }
  if (vane.given("silhouette")) r_vane.silhouette = silhouette(vane, "silhouette");
  if (vane.given("key_barbs")) r_vane.key_barbs = key_barbs(vane, "key_barbs");
}

FeatherTemplate FeatherReader::read_template(const YAML::Node &node, const std::string &path, const std::string &name) {
  YamlMap m(node, path, file_);
  FeatherTemplate t;
  t.name = name;
  t.loc = m.loc();
  YamlMap rachis = m.map("rachis");
  if (!rachis.given("length"))
    throw InputError(m.has("rachis") ? rachis.loc() : m.loc(),
                     rachis.key_path("length") + ": missing required key (the rachis length, a number > 0)");
  // Defaults scale with the feather: a template in millimetres behaves like one in centimetres.
  const float length = positive(rachis, "length", 1.0f);
  t.rachis_length = length;
  t.rachis_width = non_negative(rachis, "width", 0.02f * length);
  YamlMap curvature = rachis.map("curvature");
  t.curvature_side = within(curvature, "side", t.curvature_side, -1.0, 1.0);
  t.curvature_front = within(curvature, "front", t.curvature_front, -1.0, 1.0);
  curvature.finish();
  rachis.finish();

  YamlMap calamus = m.map("calamus");
  t.calamus_length = non_negative(calamus, "length", 0.1f * length);
  t.calamus_width_ratio = non_negative(calamus, "width_ratio", t.calamus_width_ratio, 100.0);
  calamus.finish();

  YamlMap barbs = m.map("barbs");
  t.spacing_base = t.spacing_tip = length / 30.0f;
  base_tip(barbs, "spacing", t.spacing_base, t.spacing_tip, 0.0, max_number, true);
  const FileLoc spacing_loc = barbs.loc("spacing");
  const std::string spacing_path = barbs.key_path("spacing");
  t.barb_width = non_negative(barbs, "width", 0.1f * t.rachis_width);
  VaneDesc shared;
  shared.barb_length = 0.3f * length;
  read_vane(barbs, shared);
  t.left = t.right = shared;
  for (const std::string side : {"left", "right"}) {
    YamlMap vane = barbs.map(side);
    read_vane(vane, side == "left" ? t.left : t.right);
    vane.finish();
  }
  barbs.finish();
  t.afterfeather = within(m, "afterfeather", t.afterfeather, 0.0, 1.0);
  m.finish();
  // The barb count is bounded before any feather allocates its barbs.
  try {
    barb_positions(t);
  } catch (const InputError &) {
    throw InputError(spacing_loc, spacing_path + ": expected at most " + std::to_string(max_barbs_per_vane) +
                                      " barbs per vane over the rachis length " + format_number(t.rachis_length) +
                                      ", got more");
  }
  return t;
}

void FeatherReader::read_templates(const YAML::Node &node, const std::string &path,
                                   std::vector<FeatherTemplate> &r_templates) {
  if (!node.IsMap()) fail_expected(file_, node, path, "a map of template name: template");
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string name = it->first.Scalar();
    const std::string at = path + "." + name;
    if (name.empty() || std::any_of(name.begin(), name.end(), [](char c) { return (unsigned char)c < 32 || c == 127; }))
      throw InputError(node_loc(file_, it->first), at + ": expected a template name without control characters");
    for (const FeatherTemplate &other : r_templates)
      if (other.name == name)
        throw InputError(node_loc(file_, it->first),
                         at + ": a template of this name is already given at " + other.loc.str());
    r_templates.push_back(read_template(it->second, at, name));
  }
}

KeyFeather FeatherReader::read_key_feather(const YAML::Node &node, const std::string &path) {
  YamlMap m(node, path, file_);
  KeyFeather k;
  k.loc = m.loc();
  if (!m.given("template")) throw InputError(m.loc(), m.key_path("template") + ": missing required key (a template name)");
  k.template_name = m.string("template");
  if (m.given("groups") == m.given("at"))
    fail_expected(file_, node, path, "a key feather with either groups (tracts) or at (a point)");
  if (m.given("groups")) {
    k.groups = m.string_list("groups");
    k.groups_loc = m.loc("groups");
    if (k.groups.empty()) fail_expected(file_, m.node("groups"), m.key_path("groups"), "at least one face group");
  } else {
    k.point = m.vec3("at", k.point);
    for (int axis = 0; axis < 3; ++axis)
      if (!(std::abs(k.point[axis]) <= max_number))
        fail_expected(file_, m.node("at")[axis], indexed(m.key_path("at"), size_t(axis)),
                      "a coordinate in [-1e+06, 1e+06]");
  }
  k.radius = non_negative(m, "radius", k.radius);
  k.stage = within(m, "stage", k.stage, 0.0, 1.0);
  k.layer_given = m.given("layer");
  k.layer = within(m, "layer", k.layer, -max_number, max_number);
  m.finish();
  return k;
}

std::string FeatherReader::existing_file(YamlMap &m, const std::string &key, const std::vector<std::string> &extensions) {
  const std::string written = m.string(key);
  return existing_path(m.node(key), written, m.key_path(key), extensions);
}

std::string FeatherReader::existing_path(const YAML::Node &node, const std::string &written, const std::string &path,
                                         const std::vector<std::string> &extensions) {
  if (written.find('\0') != std::string::npos)
    throw InputError(node_loc(file_, node), path + ": expected a path without a NUL character (\\0)");
  if (!extensions.empty() &&
      std::find(extensions.begin(), extensions.end(), detail::extension_of(written)) == extensions.end()) {
    std::string list;
    for (const std::string &e : extensions) list += (list.empty() ? "" : ", ") + e;
    fail_expected(file_, node, path, "a file ending in " + list);
  }
  const std::string absolute_path = absolute(written);
  std::error_code ec;
  if (!fs::exists(absolute_path, ec))
    throw InputError(node_loc(file_, node), path + ": expected an existing file, got " +
                                                detail::quoted(written, 200, true) + " (" + absolute_path +
                                                " does not exist)");
  if (!fs::is_regular_file(absolute_path, ec))
    throw InputError(node_loc(file_, node), path + ": expected a file, got " + detail::quoted(written, 200, true) +
                                                " (" + absolute_path + " is not a regular file)");
  return absolute_path;
}

void FeatherReader::read_follicles(YamlMap &m, FollicleSettings &f) {
  f.loc = m.loc();
  f.seed = uint64_t(m.integer("seed", int64_t(f.seed), 0, max_seed));
  const int sources = int(m.given("count")) + int(m.given("density")) + int(m.given("file"));
  if (sources != 1) {
    if (sources == 0)
      throw InputError(m.loc(), m.path() + ": missing required key (one of count, density or file)");
    fail_expected(file_, m.node(m.given("file") ? "file" : "density"), m.path(), "one of count, density or file");
  }
  if (m.given("file")) {
    for (const char *key : {"groups", "map"})
      if (m.given(key))
        throw InputError(node_loc(file_, m.node(key)), m.key_path(key) + ": not allowed with " + m.key_path("file") +
                                                           " (the file gives the follicles)");
    f.source = FollicleSettings::Source::file;
    f.file = existing_file(m, "file", {".hair", ".ply", ".usda", ".obj", ".txt"});
  } else {
    f.count = m.integer("count", f.count, 1, max_follicles);
    f.density = m.number_in("density", f.density, 0.0, double(max_follicles));
    f.groups = m.string_list("groups");
    if (m.given("map")) f.map_path = existing_file(m, "map", {});
  }
  m.finish();
}

FeatherDesc FeatherReader::read(const YAML::Node &node) {
  YamlMap m(node, "feathers", file_);
  FeatherDesc d;
  d.enabled = true;
  d.loc = m.loc();
  if (m.given("templates")) read_templates(m.node("templates"), m.key_path("templates"), d.templates);
  const std::vector<YAML::Node> files = m.sequence("template_files");
  for (size_t i = 0; i < files.size(); ++i) {
    const std::string at = indexed(m.key_path("template_files"), i);
    if (!files[i].IsScalar()) fail_expected(file_, files[i], at, "a path to a template file (.yaml)");
    const std::string path = existing_path(files[i], files[i].Scalar(), at, {".yaml", ".yml"});
    d.template_files.push_back(path);
    for (FeatherTemplate &t : read_template_file(path)) {
      for (const FeatherTemplate &other : d.templates)
        if (other.name == t.name)
          throw InputError(t.loc, "templates." + t.name + ": a template of this name is already given at " +
                                      other.loc.str());
      d.templates.push_back(std::move(t));
    }
  }
  if (d.templates.empty())
    throw InputError(m.loc(), "feathers.templates: missing required key (at least one template, in templates or "
                              "template_files)");

  const std::vector<YAML::Node> keys = m.sequence("key_feathers");
  for (size_t i = 0; i < keys.size(); ++i) {
    KeyFeather k = read_key_feather(keys[i], indexed(m.key_path("key_feathers"), i));
    k.template_index = d.template_index(k.template_name);
    if (k.template_index < 0) {
      std::string names;
      for (const FeatherTemplate &t : d.templates) names += (names.empty() ? "" : ", ") + t.name;
      YamlMap item(keys[i], indexed(m.key_path("key_feathers"), i), file_);
      fail_expected(file_, item.node("template"), item.key_path("template"), "a template name (" + names + ")");
    }
    d.key_feathers.push_back(std::move(k));
  }
  if (d.key_feathers.empty())
    throw InputError(m.loc(), "feathers.key_feathers: missing required key (at least one key feather placing a template)");

  if (!m.given("follicles"))
    throw InputError(m.loc(), "feathers.follicles: missing required key (a map with count, density or file)");
  YamlMap follicles = m.map("follicles");
  read_follicles(follicles, d.follicles);

  YamlMap stems = m.map("stems");
  d.guides_per_feather = int(stems.integer("k", d.guides_per_feather, 1, 16));
  d.falloff = float(stems.number_in("falloff", d.falloff, 1e-3, 4.0));
  stems.finish();

  YamlMap variation = m.map("variation");
  FeatherVariation &v = d.variation;
  v.length = within(variation, "length", v.length, 0.0, 0.9);
  v.direction = within(variation, "direction", v.direction, 0.0, 180.0);
  v.lift = within(variation, "lift", v.lift, 0.0, 90.0);
  v.barb_angle = within(variation, "barb_angle", v.barb_angle, 0.0, 90.0);
  v.stage = within(variation, "stage", v.stage, 0.0, 1.0);
  v.seed = uint64_t(variation.integer("seed", int64_t(v.seed), 0, max_seed));
  variation.finish();

  YamlMap detail = m.map("detail");
  FeatherDetail &e = d.detail;
  e.rachis_points = int(detail.integer("rachis_points", e.rachis_points, 2, max_detail_points));
  e.barb_points = int(detail.integer("barb_points", e.barb_points, 2, max_detail_points));
  e.vane_rows = int(detail.integer("vane_rows", e.vane_rows, 2, max_detail_points));
  e.vane_columns = int(detail.integer("vane_columns", e.vane_columns, 1, max_detail_points));
  e.uv = detail.choice("uv", "vane", {"vane", "barb"}) == "vane" ? FeatherDetail::Uv::vane : FeatherDetail::Uv::barb;
  detail.finish();

  YamlMap skin = m.map("skin");
  d.lift = skin.boolean("lift", d.lift);
  d.clearance = within(skin, "clearance", d.clearance, 0.0, 1.0);
  skin.finish();

  YamlMap layers = m.map("layers");
  d.layers = layers.boolean("enabled", d.layers);
  d.layer_offset = within(layers, "offset", d.layer_offset, 0.0, 0.5);
  if (layers.given("map")) d.layer_map_path = existing_file(layers, "map", {});
  for (auto [key, list, loc] : {std::tuple{"front", &d.layer_front, &d.layer_front_loc},
                                std::tuple{"rear", &d.layer_rear, &d.layer_rear_loc}}) {
    if (!layers.given(key)) continue;
    *list = layers.string_list(key);
    *loc = layers.loc(key);
    if (list->empty()) fail_expected(file_, layers.node(key), layers.key_path(key), "at least one face group");
  }
  for (const std::string &name : d.layer_front)
    if (std::find(d.layer_rear.begin(), d.layer_rear.end(), name) != d.layer_rear.end())
      throw InputError(d.layer_rear_loc, layers.key_path("rear") + ": the face group \"" + name +
                                             "\" is also in " + layers.key_path("front") +
                                             " (a tract is either in front or at the rear)");
  layers.finish();
  m.finish();
  return d;
}

}  // namespace

FeatherDesc read_feathers_section(const YAML::Node &node, const std::string &file, const std::string &folder) {
  return FeatherReader(file, fs::path(folder)).read(node);
}

std::vector<FeatherTemplate> read_template_file(const std::string &path) {
  const YAML::Node document = load_yaml_file(path, "template file");
  FeatherReader reader(path, fs::absolute(fs::path(path)).parent_path());
  YamlMap root(document, "", path);
  if (!root.given("templates")) throw InputError(root.loc(), "templates: missing required key (a map of name: template)");
  std::vector<FeatherTemplate> templates;
  reader.read_templates(root.node("templates"), "templates", templates);
  root.finish();
  return templates;
}

void set_feather_dynamics_defaults(DynamicsSettings &r_dynamics) {
  r_dynamics.stiffness = Ramp::linear(10.0f, 4.0f);
  r_dynamics.damping = 2.0f;
}

std::string describe_feathers(const FeatherDesc &feathers) {
  std::ostringstream out;
  out << "feathers: " << feathers.templates.size() << " templates (";
  for (size_t i = 0; i < feathers.templates.size(); ++i) out << (i ? ", " : "") << feathers.templates[i].name;
  out << "), " << feathers.key_feathers.size() << " key feathers\n";
  const FollicleSettings &f = feathers.follicles;
  out << "follicles: ";
  if (f.source == FollicleSettings::Source::file) {
    out << "from " << f.file;
  } else {
    if (f.count > 0) out << f.count << " scattered";
    else out << format_number(f.density) << " per unit area";
    if (!f.groups.empty()) {
      out << " on";
      for (const std::string &g : f.groups) out << " " << g;
    }
    if (!f.map_path.empty()) out << ", map " << f.map_path;
    out << ", seed " << f.seed;
  }
  out << "\n";
  const FeatherDetail &e = feathers.detail;
  out << "feather detail: rachis " << e.rachis_points << " points, barbs " << e.barb_points << " points, vanes "
      << e.vane_rows << " x " << e.vane_columns << ", stems from " << feathers.guides_per_feather << " guides\n";
  out << "layers: ";
  if (!feathers.layers) {
    out << "off\n";
    return out.str();
  }
  out << "on, offset " << format_number(feathers.layer_offset) << ", order: ";
  std::string given;
  const auto tracts = [&](const char *name, const std::vector<std::string> &groups) {
    if (groups.empty()) return;
    given += std::string(given.empty() ? "" : "; ") + name;
    for (const std::string &g : groups) given += " " + g;
  };
  tracts("front", feathers.layer_front);
  tracts("rear", feathers.layer_rear);
  if (std::any_of(feathers.key_feathers.begin(), feathers.key_feathers.end(),
                  [](const KeyFeather &k) { return k.layer_given; }))
    given += std::string(given.empty() ? "" : "; ") + "key feathers' layers";
  if (!feathers.layer_map_path.empty()) given += std::string(given.empty() ? "" : "; ") + "map " + feathers.layer_map_path;
  if (!given.empty()) out << "the groom's (" << given << "), then ";
  out << "coverage at rest\n";
  return out.str();
}

}  // namespace plume::io
