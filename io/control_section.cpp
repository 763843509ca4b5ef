#include "io/control_section.h"

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <set>

#include "groom/limits.h"
#include "io/vertex_map.h"

namespace plume::io {

namespace {

namespace fs = std::filesystem;

/// Frames of keys: beyond a billion, a typo (output frame ranges hold at most 9 digits).
constexpr double max_key_frame = 1e9;
constexpr double max_lift_fraction = 1.0, max_lift_degrees = 180.0, max_twist_degrees = 180.0;
constexpr double max_direction = 10.0;

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string indexed(const std::string &path, size_t i) { return path + "[" + std::to_string(i) + "]"; }

std::string range_text(double lo, double hi) {
  std::string text(1, '[');
  text.append(format_number(lo)).append(", ").append(format_number(hi)).append("]");
  return text;
}

class ControlReader {
 public:
  explicit ControlReader(const std::string &file)
      : file_(file), folder_(fs::absolute(fs::path(file)).lexically_normal().parent_path()) {}

  ControlDesc read_control(const YAML::Node &node, const std::string &path, size_t index, bool dynamics);

 private:
  double number_in(const YAML::Node &node, const std::string &path, double lo, double hi,
                   const std::string &what = "") {
    const double v = node_number(node, path, file_);
    if (!(v >= lo && v <= hi))
      fail_expected(file_, node, path, (what.empty() ? "a number" : what) + " in " + range_text(lo, hi));
    return v;
  }
  Eigen::Vector3f position(const YAML::Node &node, const std::string &path) {
    const Eigen::Vector3f v = node_vec3(node, path, file_);
    for (int i = 0; i < 3; ++i)
      if (!(std::abs(v[i]) <= max_coordinate))
        fail_expected(file_, node[i], indexed(path, size_t(i)),
                      "a coordinate in " + range_text(-max_coordinate, max_coordinate));
    return v;
  }
  /// The frame of key `i`, after the previous key's.
  double key_frame(const YAML::Node &node, const std::string &path, const std::vector<double> &frames) {
    const double frame = number_in(node, path, -max_key_frame, max_key_frame, "a frame");
    if (!frames.empty() && !(frame > frames.back()))
      fail_expected(file_, node, path, "a frame after the previous key's (" + format_number(frames.back()) + ")");
    return frame;
  }
  KeyInterpolation interpolation(YamlMap &m) {
    return m.choice("interpolation", "linear", {"linear", "smooth"}) == "smooth" ? KeyInterpolation::smooth
                                                                                 : KeyInterpolation::linear;
  }
  Keyed<float> keys(const YAML::Node &node, const std::string &path, double lo, double hi);
  Keyed<float> amount(const YAML::Node &node, const std::string &path, double lo, double hi,
                      const std::vector<std::string> &own_keys, std::optional<YamlMap> &r_map);
  Keyed<Eigen::Vector3f> offset(const YAML::Node &node, const std::string &path);
  Ramp ramp(const YAML::Node &node, const std::string &path);
  void mirror(YamlMap &m, ControlDesc &c);

  std::string file_;
  fs::path folder_;
};

// [[frame, value], ...], frames increasing, values in [lo, hi].
Keyed<float> ControlReader::keys(const YAML::Node &node, const std::string &path, double lo, double hi) {
  if (!node.IsSequence() || node.size() == 0) fail_expected(file_, node, path, "a list of [frame, value] keys");
  Keyed<float> k;
  for (size_t i = 0; i < node.size(); ++i) {
    const YAML::Node key = node[i];
    const std::string key_path = indexed(path, i);
    if (!key.IsSequence() || key.size() != 2) fail_expected(file_, key, key_path, "a [frame, value] key");
    k.frames.push_back(key_frame(key[0], indexed(key_path, 0), k.frames));
    k.values.push_back(float(number_in(key[1], indexed(key_path, 1), lo, hi)));
  }
  return k;
}

// A behaviour's amount: a number (constant), a list of [frame, value] keys (linear), or a map with
// `amount` or `keys`, `interpolation` and the behaviour's own keys, which the caller reads from
// r_map (then finishes it). r_map stays empty for the other forms.
Keyed<float> ControlReader::amount(const YAML::Node &node, const std::string &path, double lo, double hi,
                                   const std::vector<std::string> &own_keys, std::optional<YamlMap> &r_map) {
  if (node.IsScalar()) return Keyed<float>::constant(float(number_in(node, path, lo, hi)));
  if (node.IsSequence()) return keys(node, path, lo, hi);
  if (!node.IsMap()) {
    std::string expected = "a number, a list of [frame, value] keys, or a map with amount or keys";
    for (const std::string &key : own_keys) expected += ", " + key;
    fail_expected(file_, node, path, expected);
  }
  YamlMap &m = r_map.emplace(node, path, file_);
  if (m.given("amount") == m.given("keys"))
    fail_expected(file_, node, path, "a map with either amount (a number) or keys (a list of [frame, value])");
  Keyed<float> k = m.given("amount")
                       ? Keyed<float>::constant(float(number_in(m.node("amount"), m.key_path("amount"), lo, hi)))
                       : keys(m.node("keys"), m.key_path("keys"), lo, hi);
  k.interpolation = interpolation(m);
  return k;
}

// [x, y, z], or {keys: [[frame, [x, y, z]], ...], interpolation}.
Keyed<Eigen::Vector3f> ControlReader::offset(const YAML::Node &node, const std::string &path) {
  if (node.IsSequence()) return Keyed<Eigen::Vector3f>::constant(position(node, path));
  if (!node.IsMap())
    fail_expected(file_, node, path, "a vector [x, y, z] or a map with keys: [[frame, [x, y, z]], ...]");
  YamlMap m(node, path, file_);
  if (!m.given("keys"))
    throw InputError(m.loc(), m.key_path("keys") + ": missing required key (a list of [frame, [x, y, z]])");
  const YAML::Node list = m.node("keys");
  const std::string list_path = m.key_path("keys");
  if (!list.IsSequence() || list.size() == 0)
    fail_expected(file_, list, list_path, "a list of [frame, [x, y, z]] keys");
  Keyed<Eigen::Vector3f> k;
  for (size_t i = 0; i < list.size(); ++i) {
    const YAML::Node key = list[i];
    const std::string key_path = indexed(list_path, i);
    if (!key.IsSequence() || key.size() != 2) fail_expected(file_, key, key_path, "a [frame, [x, y, z]] key");
    k.frames.push_back(key_frame(key[0], indexed(key_path, 0), k.frames));
    k.values.push_back(position(key[1], indexed(key_path, 1)));
  }
  k.interpolation = interpolation(m);
  m.finish();
  return k;
}

// [[t, value], ...], t sorted in [0, 1], values in [0, 1].
Ramp ControlReader::ramp(const YAML::Node &node, const std::string &path) {
  if (!node.IsSequence() || node.size() == 0) fail_expected(file_, node, path, "a list of [t, value] points");
  Ramp r;
  for (size_t i = 0; i < node.size(); ++i) {
    const YAML::Node point = node[i];
    const std::string point_path = indexed(path, i);
    if (!point.IsSequence() || point.size() != 2) fail_expected(file_, point, point_path, "a [t, value] pair");
    const double lo = r.t.empty() ? 0.0 : r.t.back();
    const double t = node_number(point[0], indexed(point_path, 0), file_);
    if (!(t >= lo && t <= 1.0))
      fail_expected(file_, point[0], indexed(point_path, 0),
                    "t in [" + format_number(lo) + ", 1]" + (r.t.empty() ? "" : " (t sorted from root to tip)"));
    r.t.push_back(float(t));
    r.value.push_back(float(number_in(point[1], indexed(point_path, 1), 0.0, 1.0, "a value")));
  }
  return r;
}

// mirror: x | y | z (the plane through the origin across that axis), or {point, normal}.
void ControlReader::mirror(YamlMap &m, ControlDesc &c) {
  if (!m.given("mirror")) return;
  const YAML::Node node = m.node("mirror");
  const std::string path = m.key_path("mirror");
  c.mirror = true;
  if (node.IsScalar()) {
    const std::string axis = m.choice("mirror", "", {"x", "y", "z"});
    c.mirror_normal = axis == "x"   ? Eigen::Vector3f::UnitX()
                      : axis == "y" ? Eigen::Vector3f::UnitY()
                                    : Eigen::Vector3f::UnitZ();
    return;
  }
  if (!node.IsMap()) fail_expected(file_, node, path, "x, y, z or a plane {point: [x, y, z], normal: [x, y, z]}");
  YamlMap plane(node, path, file_);
  if (plane.given("point")) c.mirror_point = position(plane.node("point"), plane.key_path("point"));
  if (!plane.given("normal"))
    throw InputError(plane.loc(), plane.key_path("normal") + ": missing required key (a vector [x, y, z])");
  const Eigen::Vector3f normal = position(plane.node("normal"), plane.key_path("normal"));
  if (!(normal.norm() > 0.0f))
    fail_expected(file_, plane.node("normal"), plane.key_path("normal"), "a non-zero vector");
  c.mirror_normal = normal.normalized();
  plane.finish();
}

ControlDesc ControlReader::read_control(const YAML::Node &node, const std::string &path, size_t index, bool dynamics) {
  YamlMap m(node, path, file_);
  ControlDesc c;
  c.loc = m.loc();
  c.name = m.string("name", "control" + std::to_string(index));
  for (const char ch : c.name)
    if ((unsigned char)ch < 32 || ch == 127)
      fail_expected(file_, m.node("name"), m.key_path("name"), "a name without control characters");
  c.place =
      m.choice("place", "skin", {"skin", "space"}) == "skin" ? ControlDesc::Place::skin : ControlDesc::Place::space;
  if (!m.given("position"))
    throw InputError(m.loc(), m.key_path("position") + ": missing required key (a point [x, y, z])");
  c.position = position(m.node("position"), m.key_path("position"));
  if (m.given("offset")) c.offset = offset(m.node("offset"), m.key_path("offset"));

  if (m.given("radius")) {
    const YAML::Node radius = m.node("radius");
    const double r = node_number(radius, m.key_path("radius"), file_);
    if (!(r > 0.0 && r <= max_coordinate))
      fail_expected(file_, radius, m.key_path("radius"),
                    "a number in (0, " + format_number(max_coordinate) +
                        "] (leave radius out for a control that reaches every guide)");
    c.radius = float(r);
  }
  if (m.given("falloff") && c.radius == 0.0f)
    throw InputError(node_loc(file_, m.node("falloff")),
                     m.key_path("falloff") +
                         ": not allowed without radius (a control without one reaches every guide at full weight)");
  const std::string falloff = m.choice("falloff", "smooth", {"smooth", "linear", "constant"});
  c.falloff = falloff == "smooth"   ? ControlDesc::Falloff::smooth
              : falloff == "linear" ? ControlDesc::Falloff::linear
                                    : ControlDesc::Falloff::constant;
  c.groups = m.string_list("groups");
  if (m.given("groups")) {
    c.groups_loc = m.loc("groups");
    c.groups_key = m.key_path("groups");
  }
  if (m.given("map")) {
    const std::string written = m.string("map");
    const YAML::Node map_node = m.node("map");
    if (written.find('\0') != std::string::npos)
      throw InputError(node_loc(file_, map_node),
                       m.key_path("map") + ": expected a path without a NUL character (\\0)");
    const fs::path p(written);
    c.vertex_map_path = (p.is_absolute() ? p : folder_ / p).lexically_normal().string();
    c.vertex_map_loc = node_loc(file_, map_node);
    std::error_code ec;
    if (!fs::is_regular_file(c.vertex_map_path, ec))
      throw InputError(c.vertex_map_loc,
                       m.key_path("map") + ": expected an existing file, got \"" + written + "\" (" +
                           c.vertex_map_path +
                           (fs::exists(c.vertex_map_path, ec) ? " is not a regular file)" : " does not exist)"));
  }
  mirror(m, c);

  if (m.given("lift")) {
    const YAML::Node lift = m.node("lift");
    std::optional<YamlMap> own;
    if (lift.IsMap()) {
      YamlMap peek(lift, m.key_path("lift"), file_);
      c.lift_by = peek.choice("by", "fraction", {"fraction", "angle"}) == "angle" ? ControlDesc::LiftBy::angle
                                                                                  : ControlDesc::LiftBy::fraction;
    }
    const double hi = c.lift_by == ControlDesc::LiftBy::angle ? max_lift_degrees : max_lift_fraction;
    c.lift = amount(lift, m.key_path("lift"), -hi, hi, {"by"}, own);
    if (own) {
      own->choice("by", "fraction", {"fraction", "angle"});
      own->finish();
    }
  }
  if (m.given("aim")) {
    std::optional<YamlMap> own;
    c.aim = amount(m.node("aim"), m.key_path("aim"), 0.0, 1.0, {}, own);
    if (own) own->finish();
  }
  if (m.given("direction")) {
    std::optional<YamlMap> own;
    c.direction = amount(m.node("direction"), m.key_path("direction"), -max_direction, max_direction, {}, own);
    if (own) own->finish();
  }
  if (m.given("random_twist")) {
    std::optional<YamlMap> own;
    c.random_twist = amount(m.node("random_twist"), m.key_path("random_twist"), 0.0, max_twist_degrees, {"seed"}, own);
    if (own) {
      c.twist_seed = uint64_t(own->integer("seed", 0, 0, int64_t(1) << 53));
      own->finish();
    }
  }
  if (m.given("dynamic_blend")) {
    const YAML::Node blend = m.node("dynamic_blend");
    if (!dynamics)
      throw InputError(node_loc(file_, blend),
                       m.key_path("dynamic_blend") +
                           ": expected a groom with dynamics (the dynamic blend mixes the simulated guides "
                           "into the rig-driven ones), got dynamics off");
    std::optional<YamlMap> own;
    c.dynamic_blend = amount(blend, m.key_path("dynamic_blend"), 0.0, 1.0, {"ramp"}, own);
    if (own) {
      if (own->given("ramp")) c.blend_ramp = ramp(own->node("ramp"), own->key_path("ramp"));
      own->finish();
    }
  }
  m.finish();
  return c;
}

}  // namespace

void read_controls_section(YamlMap &root, const std::string &groom_file, GroomDesc &r_groom) {
  if (!root.given("controls")) return;
  YamlMap section = root.map("controls");
  ControlSettings &settings = r_groom.controls;
  settings.loc = section.loc();
  settings.binding = section.choice("binding", "blend", {"nearest", "blend"}) == "nearest"
                         ? ControlSettings::Binding::nearest
                         : ControlSettings::Binding::blend;
  ControlReader reader(groom_file);
  const std::vector<YAML::Node> list = section.sequence("list");
  std::set<std::string> names;
  for (size_t i = 0; i < list.size(); ++i) {
    const std::string path = indexed(section.key_path("list"), i);
    ControlDesc c = reader.read_control(list[i], path, i, r_groom.dynamics.enabled);
    if (!names.insert(c.name).second || (c.mirror && !names.insert(c.name + ".mirror").second)) {
      const YAML::Node name = list[i]["name"];
      throw InputError(
          node_loc(groom_file, name.IsDefined() ? name : list[i]),
          path + ".name: expected a name no other control (or mirrored twin, name.mirror) has, got \"" + c.name + "\"");
    }
    settings.controls.push_back(std::move(c));
  }
  section.finish();
}

std::vector<std::vector<float>> read_control_maps(const ControlSettings &settings, size_t vertex_count) {
  std::vector<std::vector<float>> maps(settings.controls.size());
  for (size_t i = 0; i < settings.controls.size(); ++i) {
    const ControlDesc &c = settings.controls[i];
    if (c.vertex_map_path.empty()) continue;
    maps[i] = read_vertex_map(c.vertex_map_path, vertex_count, c.vertex_map_loc.str() + ": controls: vertex_map");
  }
  return maps;
}

}  // namespace plume::io
