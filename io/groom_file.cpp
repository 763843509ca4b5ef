#include "io/groom_file.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <sstream>

#include "groom/limits.h"
#include "io/feather_file.h"
#include "io/control_section.h"
#include "io/yaml_fields.h"

namespace plume::io {

namespace {

namespace fs = std::filesystem;

/// Seeds go through a double while parsed, so they are limited to the integers a double holds exactly.
constexpr int64_t max_seed = (int64_t(1) << 53);
constexpr int max_points_per_strand = 65536;
/// Every number a groom gives lies in [-max_number, max_number] unless its key has a tighter range:
/// lengths are bounded like coordinates (groom/limits.h), so sums and squares of them stay finite.
constexpr float max_number = max_coordinate;
/// Turn counts (clump twist, curl turns per unit) and noise frequencies: 2 pi x 1000 turns ~ 6283 rad
/// stays in the range where skin/lanes.h's sin_cos4 is accurate (|x| < 1e4), and a frequency of
/// 1000 times a coordinate of 1e6 stays below the 2^31 of the noise lattice's integer cells.
constexpr float max_turns = 1000.0f;
constexpr float max_frequency = 1000.0f;
/// Guide weights ~ 1 / distance^falloff in floats: distances are below ~3.5e6 (two points within the
/// coordinate bound), and 3.5e6^4 ~ 1.5e26 is finite where a larger power would overflow toward 1e38.
constexpr float max_falloff = 4.0f;
/// Uniform scale of the emitter's rigid keys: within [1/100, 100] a posed coordinate stays below
/// ~3.5e8 (squares ~1e17) and a valid rest triangle keeps a non-zero float area.
constexpr float min_key_scale = 0.01f, max_key_scale = 100.0f;

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string quoted(const std::string &s) { return "\"" + s + "\""; }

std::string lower_extension(const std::string &path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext;
}

std::string join(const std::vector<std::string> &items, const std::string &separator) {
  std::string out;
  for (size_t i = 0; i < items.size(); ++i) out += (i ? separator : "") + items[i];
  return out;
}

std::string indexed(const std::string &path, size_t i) { return path + "[" + std::to_string(i) + "]"; }

/// True when `pattern` holds a frame field: a run of '#', a printf field %d / %0Nd, or Houdini's
/// $F / $FN (not followed by a letter or '_'), as app/frame_range.h reads them.
bool has_frame_field(const std::string &pattern) {
  if (pattern.find('#') != std::string::npos) return true;
  for (size_t i = pattern.find("$F"); i != std::string::npos; i = pattern.find("$F", i + 1))
    if (i + 2 == pattern.size() || !(std::isalpha(static_cast<unsigned char>(pattern[i + 2])) || pattern[i + 2] == '_'))
      return true;
  for (size_t i = 0; i + 1 < pattern.size(); ++i) {
    if (pattern[i] != '%') continue;
    size_t j = i + 1;
    while (j < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[j]))) ++j;
    if (j < pattern.size() && pattern[j] == 'd') return true;
  }
  return false;
}

/// "A", "A-B", "A-B:S" or "A-BxS" with integers A <= B (either may be negative, "-5-10") and S >= 1.
bool valid_frame_range(const std::string &text) {
  size_t pos = 0;
  auto integer = [&](long long &r_value) {
    const size_t start = pos;
    if (pos < text.size() && text[pos] == '-') ++pos;
    const size_t digits = pos;
    while (pos < text.size() && std::isdigit(static_cast<unsigned char>(text[pos]))) ++pos;
    if (pos == digits || pos - digits > 9) return false;
    r_value = std::stoll(text.substr(start, pos - start));
    return true;
  };
  long long first = 0, last = 0, step = 1;
  if (!integer(first)) return false;
  last = first;
  if (pos < text.size() && text[pos] == '-') {
    ++pos;
    if (!integer(last)) return false;
    if (pos < text.size() && (text[pos] == ':' || text[pos] == 'x')) {
      ++pos;
      if (!integer(step)) return false;
    }
  }
  return pos == text.size() && first <= last && step >= 1;
}

/// Reads one groom file; holds the file's name (for messages) and folder (for relative paths).
class GroomReader {
 public:
  explicit GroomReader(const std::string &path)
      : file_(path), folder_(fs::absolute(fs::path(path)).lexically_normal().parent_path()) {}

  GroomDesc read(const YAML::Node &document);

 private:
  // --- numbers with ranges; each marks the key as known and reports the key path on failure ---
  /// A number in [-hi, hi].
  float real(YamlMap &m, const std::string &key, float fallback, float hi = max_number) {
    const double v = m.number(key, fallback);
    if (!(std::abs(v) <= hi))
      fail_expected(file_, m.node(key), m.key_path(key),
                    "a number in [" + format_number(-hi) + ", " + format_number(hi) + "]");
    return float(v);
  }
  /// A number in [lo, hi]; below lo the message gives the lower bound alone, as most keys have only
  /// the general upper bound.
  float at_least(YamlMap &m, const std::string &key, float fallback, float lo, float hi = max_number) {
    return float(at_least_double(m, key, fallback, lo, hi));
  }
  /// at_least() for the settings held in doubles, kept at full precision.
  double at_least_double(YamlMap &m, const std::string &key, double fallback, double lo, double hi = max_number) {
    const double v = m.number(key, fallback);
    if (!(v >= lo)) fail_expected(file_, m.node(key), m.key_path(key), "a number >= " + format_number(lo));
    if (!(v <= hi))
      fail_expected(file_, m.node(key), m.key_path(key),
                    "a number in [" + format_number(lo) + ", " + format_number(hi) + "]");
    return v;
  }
  /// A number in (lo, hi].
  float above(YamlMap &m, const std::string &key, float fallback, float lo, float hi = max_number) {
    const double v = m.number(key, fallback);
    if (!(v > lo)) fail_expected(file_, m.node(key), m.key_path(key), "a number > " + format_number(lo));
    if (!(v <= hi))
      fail_expected(file_, m.node(key), m.key_path(key),
                    "a number in (" + format_number(lo) + ", " + format_number(hi) + "]");
    return float(v);
  }
  /// A vector whose components are in [-max_number, max_number] (a direction or a rate).
  Eigen::Vector3f vector(YamlMap &m, const std::string &key, const Eigen::Vector3f &fallback) {
    const Eigen::Vector3f v = m.vec3(key, fallback);
    if (m.given(key)) check_components(m.node(key), m.key_path(key), "a number");
    return v;
  }
  /// A scene position: components within max_coordinate (groom/limits.h).
  Eigen::Vector3f position(YamlMap &m, const std::string &key, const Eigen::Vector3f &fallback) {
    const Eigen::Vector3f v = m.vec3(key, fallback);
    if (m.given(key)) check_components(m.node(key), m.key_path(key), "a coordinate");
    return v;
  }
  Eigen::Vector3f position(const YAML::Node &node, const std::string &path) {
    const Eigen::Vector3f v = node_vec3(node, path, file_);
    check_components(node, path, "a coordinate");
    return v;
  }
  /// `node` is a list of 3 finite numbers: each must lie in [-max_number, max_number].
  void check_components(const YAML::Node &node, const std::string &path, const std::string &what) {
    for (int i = 0; i < 3; ++i)
      if (!(std::abs(node_number(node[i], indexed(path, size_t(i)), file_)) <= max_number))
        fail_expected(file_, node[i], indexed(path, size_t(i)),
                      what + " in [" + format_number(-max_number) + ", " + format_number(max_number) + "]");
  }
  float between(YamlMap &m, const std::string &key, float fallback, float lo, float hi) {
    return float(m.number_in(key, fallback, lo, hi));
  }
  uint64_t seed(YamlMap &m, const std::string &key, uint64_t fallback) {
    return uint64_t(m.integer(key, int64_t(fallback), 0, max_seed));
  }

  // --- paths ---
  /// The path as written, made absolute against the groom file's folder and normalised.
  std::string absolute(const std::string &written) const {
    if (written.empty()) return written;
    const fs::path p(written);
    return (p.is_absolute() ? p : folder_ / p).lexically_normal().string();
  }
  /// A path to a file that must exist now, with one of `extensions` (lower case, with the dot).
  std::string existing_file(YamlMap &m, const std::string &key, const std::vector<std::string> &extensions) {
    const std::string written = m.string(key);
    return check_existing(m, key, written, extensions);
  }
  /// A path holds no NUL character (YAML's "\0"): the system would open the name cut at it.
  void check_no_nul(YamlMap &m, const std::string &key, const std::string &written) {
    if (written.find('\0') != std::string::npos)  // not echoed: the message would be cut at the NUL
      throw InputError(node_loc(file_, m.node(key)), m.key_path(key) + ": expected a path without a NUL character (\\0)");
  }
  std::string check_existing(YamlMap &m, const std::string &key, const std::string &written,
                             const std::vector<std::string> &extensions) {
    const YAML::Node node = m.node(key);
    check_no_nul(m, key, written);
    const std::string path = absolute(written);
    if (!extensions.empty() &&
        std::find(extensions.begin(), extensions.end(), lower_extension(written)) == extensions.end())
      fail_expected(file_, node, m.key_path(key), "a file ending in " + join(extensions, ", "));
    std::error_code ec;
    if (!fs::exists(path, ec))
      throw InputError(node_loc(file_, node), m.key_path(key) + ": expected an existing file, got " +
                                                  quoted(written) + " (" + path + " does not exist)");
    if (!fs::is_regular_file(path, ec))
      throw InputError(node_loc(file_, node), m.key_path(key) + ": expected a file, got " + quoted(written) +
                                                  " (" + path + " is not a regular file)");
    return path;
  }
  /// An output path pattern (need not exist), with one of `extensions`; `needs_frame` requires a
  /// frame field (####, %04d or $F4).
  std::string output_pattern(YamlMap &m, const std::string &key, const std::vector<std::string> &extensions,
                             bool needs_frame) {
    const std::string written = m.string(key, "");
    if (written.empty()) return written;
    const YAML::Node node = m.node(key);
    check_no_nul(m, key, written);
    if (std::find(extensions.begin(), extensions.end(), lower_extension(written)) == extensions.end())
      fail_expected(file_, node, m.key_path(key), "a path ending in " + join(extensions, ", "));
    if (needs_frame && !has_frame_field(written))
      fail_expected(file_, node, m.key_path(key), "a path with a frame field (####, %04d or $F4)");
    return absolute(written);
  }

  /// A key that makes no sense given another key's value: an error that says why.
  void forbid(YamlMap &m, const std::string &key, const std::string &because) {
    if (m.given(key))
      throw InputError(node_loc(file_, m.node(key)), m.key_path(key) + ": not allowed " + because);
  }

  Ramp ramp(const YAML::Node &node, const std::string &path, float value_lo, float value_hi);

  void read_emitter(YamlMap &root, GroomDesc &groom);
  void read_roots(YamlMap &root, GroomDesc &groom);
  void read_strands(YamlMap &root, GroomDesc &groom);
  void read_interpolation(YamlMap &root, GroomDesc &groom);
  void read_partings(YamlMap &root, GroomDesc &groom);
  EffectDesc read_effect(const YAML::Node &node, const std::string &path);
  void read_dynamics(YamlMap &root, GroomDesc &groom);
  CollisionShape read_shape(const YAML::Node &node, const std::string &path);
  void read_output(YamlMap &root, GroomDesc &groom);
  void read_group(YamlMap &root, GroomDesc &groom);
  void read_groups(YamlMap &root, GroomDesc &groom);
  void read_output_units(YamlMap &out, OutputSettings &o);

  std::string file_;
  fs::path folder_;
};

Ramp GroomReader::ramp(const YAML::Node &node, const std::string &path, float value_lo, float value_hi) {
  const std::string expected = "a list of [t, value] points";
  if (!node.IsSequence() || node.size() == 0) fail_expected(file_, node, path, expected);
  Ramp r;
  for (size_t i = 0; i < node.size(); ++i) {
    const YAML::Node point = node[i];
    const std::string point_path = indexed(path, i);
    if (!point.IsSequence() || point.size() != 2) fail_expected(file_, point, point_path, "a [t, value] pair");
    const double t = node_number(point[0], indexed(point_path, 0), file_);
    const double lo = r.t.empty() ? 0.0 : r.t.back();
    if (t < lo || t > 1.0) {
      const std::string why = r.t.empty() ? "" : " (t sorted from root to tip)";
      fail_expected(file_, point[0], indexed(point_path, 0),
                    "t in [" + format_number(lo) + ", 1]" + why);
    }
    const double v = node_number(point[1], indexed(point_path, 1), file_);
    if (v < value_lo || v > value_hi) {
      const std::string range = v < value_lo && value_hi == max_number ? "a value >= " + format_number(value_lo)
                                                    : "a value in [" + format_number(value_lo) + ", " +
                                                          format_number(value_hi) + "]";
      fail_expected(file_, point[1], indexed(point_path, 1), range);
    }
    r.t.push_back(float(t));
    r.value.push_back(float(v));
  }
  return r;
}

void GroomReader::read_emitter(YamlMap &root, GroomDesc &groom) {
  if (!root.given("emitter")) throw InputError(root.loc(), "emitter: missing required key (a map with mesh)");
  YamlMap emitter = root.map("emitter");
  if (!emitter.given("mesh")) throw InputError(emitter.loc(), "emitter.mesh: missing required key (an .obj path)");
  groom.emitter_path = existing_file(emitter, "mesh", {".obj"});
  groom.emitter_loc = emitter.loc("mesh");

  if (emitter.given("animation")) {
    YamlMap anim = emitter.map("animation");
    EmitterAnimation &a = groom.animation;
    a.loc = anim.loc();
    if (anim.given("sequence") == anim.given("keys"))
      fail_expected(file_, emitter.node("animation"), anim.path(), "either sequence or keys (not both)");
    if (anim.given("sequence")) {
      forbid(anim, "pivot", "with a sequence (pivot is for keys)");
      const std::string written = anim.string("sequence");
      check_no_nul(anim, "sequence", written);
      if (lower_extension(written) != ".obj" || !has_frame_field(written))
        fail_expected(file_, anim.node("sequence"), anim.key_path("sequence"),
                      "an .obj path with a frame field (head.####.obj or head.%04d.obj)");
      a.kind = EmitterAnimation::Kind::obj_sequence;
      a.sequence_pattern = absolute(written);
    } else {
      a.kind = EmitterAnimation::Kind::rigid;
      a.pivot = position(anim, "pivot", a.pivot);
      const std::vector<YAML::Node> keys = anim.sequence("keys");
      if (keys.empty()) fail_expected(file_, anim.node("keys"), anim.key_path("keys"), "a list of at least one key");
      for (size_t i = 0; i < keys.size(); ++i) {
        YamlMap key(keys[i], indexed(anim.key_path("keys"), i), file_);
        RigidKey k;
        k.frame = key.number("frame");
        if (!(std::abs(k.frame) <= max_number))
          fail_expected(file_, key.node("frame"), key.key_path("frame"),
                        "a frame in [" + format_number(-max_number) + ", " + format_number(max_number) + "]");
        if (!a.keys.empty() && !(k.frame > a.keys.back().frame))
          fail_expected(file_, key.node("frame"), key.key_path("frame"),
                        "a frame after " + format_number(a.keys.back().frame) + " (keys sorted by frame)");
        k.translate = position(key, "translate", k.translate);
        k.rotate_degrees = vector(key, "rotate", k.rotate_degrees);
        k.scale = between(key, "scale", k.scale, min_key_scale, max_key_scale);
        key.finish();
        a.keys.push_back(k);
      }
    }
    anim.finish();
  }
  emitter.finish();
}

void GroomReader::read_roots(YamlMap &root, GroomDesc &groom) {
  if (!root.given("roots"))
    throw InputError(root.loc(), root.key_path("roots") + ": missing required key (a map with count, density or file)");
  YamlMap roots = root.map("roots");
  RootSettings &r = groom.roots;
  r.loc = roots.loc();
  r.seed = seed(roots, "seed", r.seed);
  if (roots.given("file")) {
    for (const char *key : {"count", "density", "groups", "near_guides"})
      forbid(roots, key, "with roots.file (the file gives the roots)");
    r.source = RootSettings::Source::file;
    r.file = existing_file(roots, "file", {".hair", ".ply", ".usda", ".obj", ".txt"});
  } else {
    if (roots.given("count") == roots.given("density"))
      fail_expected(file_, root.node("roots"), root.key_path("roots"), "one of count, density or file");
    r.source = RootSettings::Source::scatter;
    r.count = roots.integer("count", r.count, 1, max_root_count);
    r.density = roots.number_in("density", r.density, 0.0, double(max_root_count));
    r.groups = roots.string_list("groups");
    r.near_guides = at_least_double(roots, "near_guides", r.near_guides, 0.0);
  }
  roots.finish();
}

void GroomReader::read_strands(YamlMap &root, GroomDesc &groom) {
  YamlMap strands = root.map("strands");
  groom.points_per_strand = int(strands.integer("points", groom.points_per_strand, 2, max_points_per_strand));
  YamlMap width = strands.map("width");
  if (width.has("root")) groom.width_root = at_least(width, "root", 0.0f, 0.0f);
  if (width.has("tip")) groom.width_tip = at_least(width, "tip", 0.0f, 0.0f);
  width.finish();
  strands.finish();
}

void GroomReader::read_interpolation(YamlMap &root, GroomDesc &groom) {
  YamlMap interp = root.map("interpolation");
  InterpolationSettings &s = groom.interpolation;
  s.loc = interp.loc();
  const std::string method = interp.choice("method", "streamline", {"streamline", "fur", "linear"});
  s.method = method == "streamline" ? InterpolationSettings::Method::streamline
             : method == "fur"      ? InterpolationSettings::Method::fur
                                    : InterpolationSettings::Method::linear;
  s.k = int(interp.integer("k", s.k, 1, max_guides_per_root));
  s.radius = at_least_double(interp, "radius", s.radius, 0.0);
  s.falloff = above(interp, "falloff", s.falloff, 0.0f, max_falloff);
  if (interp.has("skin_margin")) s.skin_margin = at_least(interp, "skin_margin", 0.0f, 0.0f);
  s.separate = interp.boolean("separate", s.separate);
  interp.finish();
}

void GroomReader::read_partings(YamlMap &root, GroomDesc &groom) {
  YamlMap partings = root.map("partings");
  PartingSettings &p = groom.partings;
  p.loc = partings.loc();

  std::set<std::string> names;
  const std::vector<YAML::Node> lines = partings.sequence("lines");
  for (size_t i = 0; i < lines.size(); ++i) {
    YamlMap line(lines[i], indexed(partings.key_path("lines"), i), file_);
    PartingLine l;
    l.loc = line.loc();
    l.name = line.string("name", "line" + std::to_string(i));
    if (!names.insert(l.name).second)
      fail_expected(file_, line.node("name"), line.key_path("name"), "a name no other parting line has");
    l.closed = line.boolean("closed", l.closed);
    const size_t min_points = l.closed ? 3 : 2;
    const std::vector<YAML::Node> points = line.sequence("points");
    if (points.size() < min_points)
      throw InputError(line.loc(line.given("points") ? "points" : ""),
                       line.key_path("points") + ": expected a list of at least " + std::to_string(min_points) +
                           " points [x, y, z]" + (l.closed ? " (a closed line)" : "") + ", got " +
                           std::to_string(points.size()));
    for (size_t j = 0; j < points.size(); ++j)
      l.points.push_back(position(points[j], indexed(line.key_path("points"), j)));
    l.gamma = at_least(line, "gamma", l.gamma, 1.0f);
    l.hard = line.boolean("hard", l.hard);
    line.finish();
    p.lines.push_back(std::move(l));
  }

  if (partings.given("zones")) {
    YamlMap zones = partings.map("zones");
    const std::string from = zones.choice("from", "none", {"none", "groups", "map", "lines"});
    if (from != "groups") forbid(zones, "groups", "unless zones.from is groups");
    if (from != "map") forbid(zones, "map", "unless zones.from is map");
    if (from == "groups") {
      p.zone_source = PartingSettings::ZoneSource::face_groups;
      p.zone_groups = zones.string_list("groups");
      if (zones.given("groups")) p.zone_groups_loc = zones.loc("groups");
    } else if (from == "map") {
      p.zone_source = PartingSettings::ZoneSource::zone_map;
      if (!zones.given("map"))
        throw InputError(zones.loc(), zones.key_path("map") + ": missing required key (a zone map file)");
      p.zone_map_path = existing_file(zones, "map", {});
    } else if (from == "lines") {
      p.zone_source = PartingSettings::ZoneSource::lines;
      const bool any_hard = std::any_of(p.lines.begin(), p.lines.end(), [](const PartingLine &l) { return l.hard; });
      if (!any_hard)
        fail_expected(file_, zones.node("from"), zones.key_path("from"),
                      "lines only with at least one partings.lines entry that has hard: true");
    }
    zones.finish();
  }
  partings.finish();
}

/// Keys every effect accepts, and the keys only some types accept.
const std::vector<std::string> &common_effect_keys() {
  static const std::vector<std::string> keys{"type", "seed", "amount", "ramp", "groups", "map"};
  return keys;
}
const std::map<std::string, std::vector<std::string>> &effect_type_keys() {
  static const std::map<std::string, std::vector<std::string>> keys{
      {"clump", {"centers", "radius", "twist", "strays"}},
      {"tension", {}},
      {"length", {"distribution", "variation", "cut", "max_length"}},
      {"wave", {"frequency", "amplitude", "fraction"}},
      {"frizz", {"frequency", "amplitude", "fraction"}},
      {"curl", {"radius", "turns_per_unit", "fraction"}},
  };
  return keys;
}

EffectDesc GroomReader::read_effect(const YAML::Node &node, const std::string &path) {
  YamlMap m(node, path, file_);
  EffectDesc e;
  e.loc = m.loc();
  if (!m.given("type")) throw InputError(m.loc(), m.key_path("type") + ": missing required key (clump, tension, length, wave, frizz or curl)");
  const std::string type = m.choice("type", "", {"clump", "tension", "length", "wave", "frizz", "curl"});

  // A key of another effect type gets a message that says so, before any value is read.
  const std::vector<std::string> &own = effect_type_keys().at(type);
  for (auto it = node.begin(); it != node.end(); ++it) {
    const std::string key = it->first.Scalar();
    const auto &common = common_effect_keys();
    if (std::find(common.begin(), common.end(), key) != common.end()) continue;
    if (std::find(own.begin(), own.end(), key) != own.end()) continue;
    std::vector<std::string> owners;
    for (const auto &[other, keys] : effect_type_keys())
      if (std::find(keys.begin(), keys.end(), key) != keys.end()) owners.push_back(other);
    if (owners.empty()) continue;  // not an effect key at all: finish() reports it as unknown
    std::vector<std::string> accepted = common;
    accepted.insert(accepted.end(), own.begin(), own.end());
    throw InputError(node_loc(file_, it->first),
                     m.key_path(key) + ": expected a key of a " + type + " effect (" + join(accepted, ", ") +
                         "), got " + key + " (a key of " + join(owners, ", ") + ")");
  }

  e.seed = seed(m, "seed", e.seed);
  e.amount = between(m, "amount", e.amount, 0.0f, 1.0f);
  if (m.given("ramp")) e.ramp = ramp(m.node("ramp"), m.key_path("ramp"), 0.0f, 1.0f);
  e.groups = m.string_list("groups");
  if (m.given("groups")) {
    e.groups_loc = m.loc("groups");
    e.groups_key = m.key_path("groups");
  }
  if (m.given("map")) e.vertex_map_path = existing_file(m, "map", {});

  if (type == "clump") {
    e.type = EffectType::clump;
    const std::string centers = m.choice("centers", "poisson", {"poisson", "per_guide"});
    e.clump_centers = centers == "poisson" ? EffectDesc::ClumpCenters::poisson : EffectDesc::ClumpCenters::per_guide;
    e.clump_radius = above(m, "radius", e.clump_radius, 0.0f);
    e.clump_twist = real(m, "twist", e.clump_twist, max_turns);
    e.stray_fraction = between(m, "strays", e.stray_fraction, 0.0f, 1.0f);
  } else if (type == "tension") {
    e.type = EffectType::tension;
  } else if (type == "length") {
    e.type = EffectType::length;
    const std::string distribution = m.choice("distribution", "uniform", {"uniform", "normal"});
    e.length_distribution = distribution == "uniform" ? EffectDesc::LengthDistribution::uniform
                                                      : EffectDesc::LengthDistribution::normal;
    e.length_variation = between(m, "variation", e.length_variation, 0.0f, 1.0f);
    if (m.given("cut")) {
      YamlMap cut = m.map("cut");
      e.cut_plane = true;
      e.cut_point = position(cut, "point", e.cut_point);
      const Eigen::Vector3f normal = vector(cut, "normal", e.cut_normal);
      if (!(normal.norm() > 0.0f)) fail_expected(file_, cut.node("normal"), cut.key_path("normal"), "a non-zero vector");
      e.cut_normal = normal.normalized();
      cut.finish();
    }
    e.max_length = at_least(m, "max_length", e.max_length, 0.0f);
  } else if (type == "wave" || type == "frizz") {
    e.type = type == "wave" ? EffectType::wave : EffectType::frizz;
    e.frequency = above(m, "frequency", e.frequency, 0.0f, max_frequency);
    e.amplitude = at_least(m, "amplitude", e.amplitude, 0.0f);
    e.fraction = between(m, "fraction", e.fraction, 0.0f, 1.0f);
  } else {
    e.type = EffectType::curl;
    e.curl_radius = at_least(m, "radius", e.curl_radius, 0.0f);
    e.turns_per_unit = at_least(m, "turns_per_unit", e.turns_per_unit, 0.0f, max_turns);
    e.fraction = between(m, "fraction", e.fraction, 0.0f, 1.0f);
  }
  m.finish();
  return e;
}

CollisionShape GroomReader::read_shape(const YAML::Node &node, const std::string &path) {
  YamlMap m(node, path, file_);
  CollisionShape s;
  s.loc = m.loc();
  if (m.given("sphere") == m.given("capsule"))
    fail_expected(file_, node, path, "a shape with either sphere: {center, radius} or capsule: {a, b, radius}");
  if (m.given("sphere")) {
    YamlMap sphere = m.map("sphere");
    s.kind = CollisionShape::Kind::sphere;
    s.a = position(sphere, "center", s.a);
    s.b = s.a;
    s.radius = above(sphere, "radius", s.radius, 0.0f);
    sphere.finish();
  } else {
    YamlMap capsule = m.map("capsule");
    s.kind = CollisionShape::Kind::capsule;
    if (!capsule.given("a") || !capsule.given("b"))
      throw InputError(capsule.loc(), capsule.key_path(capsule.given("a") ? "b" : "a") + ": missing required key (a point [x, y, z])");
    s.a = position(capsule, "a", s.a);
    s.b = position(capsule, "b", s.b);
    s.radius = above(capsule, "radius", s.radius, 0.0f);
    capsule.finish();
  }
  s.friction = at_least(m, "friction", s.friction, 0.0f);
  m.finish();
  return s;
}

void GroomReader::read_dynamics(YamlMap &root, GroomDesc &groom) {
  DynamicsSettings &d = groom.dynamics;
  if (!root.given("dynamics")) return;
  YamlMap dyn = root.map("dynamics");
  d.loc = dyn.loc();
  // Writing a dynamics section means simulating, unless it says enabled: false.
  d.enabled = dyn.boolean("enabled", true);
  d.substeps = int(dyn.integer("substeps", d.substeps, 1, 1000));
  d.fps = above(dyn, "fps", d.fps, 0.0f);
  d.preroll_frames = int(dyn.integer("preroll", d.preroll_frames, 0, 100000));
  d.gravity = vector(dyn, "gravity", d.gravity);
  d.compensate_gravity = dyn.boolean("compensate_gravity", d.compensate_gravity);

  if (dyn.given("stiffness")) {
    const YAML::Node node = dyn.node("stiffness");
    const std::string path = dyn.key_path("stiffness");
    if (node.IsSequence()) {
      d.stiffness = ramp(node, path, 0.0f, max_number);
    } else {
      YamlMap stiffness(node, path, file_);
      if (stiffness.given("ramp")) {
        forbid(stiffness, "root", "with stiffness.ramp");
        forbid(stiffness, "tip", "with stiffness.ramp");
        d.stiffness = ramp(stiffness.node("ramp"), stiffness.key_path("ramp"), 0.0f, max_number);
      } else {
        const float at_root = at_least(stiffness, "root", d.stiffness.at(0.0f), 0.0f);
        const float at_tip = at_least(stiffness, "tip", d.stiffness.at(1.0f), 0.0f);
        d.stiffness = Ramp::linear(at_root, at_tip);
      }
      d.stiffness_scale = at_least(stiffness, "scale", d.stiffness_scale, 0.0f);
      stiffness.finish();
    }
  }
  d.damping = at_least(dyn, "damping", d.damping, 0.0f);
  d.drag = at_least(dyn, "drag", d.drag, 0.0f);
  d.mass_per_unit = above(dyn, "mass", d.mass_per_unit, 0.0f);

  YamlMap wind = dyn.map("wind");
  d.wind = vector(wind, "vector", d.wind);
  d.wind_gust = at_least(wind, "gust", d.wind_gust, 0.0f);
  d.wind_gust_frequency = at_least(wind, "gust_frequency", d.wind_gust_frequency, 0.0f);
  wind.finish();

  d.seed = seed(dyn, "seed", d.seed);
  d.collide_with_emitter = dyn.boolean("collide_with_emitter", d.collide_with_emitter);
  d.emitter_friction = at_least(dyn, "emitter_friction", d.emitter_friction, 0.0f);
  d.collision_margin = at_least(dyn, "margin", d.collision_margin, 0.0f);
  const std::vector<YAML::Node> shapes = dyn.sequence("shapes");
  for (size_t i = 0; i < shapes.size(); ++i) d.shapes.push_back(read_shape(shapes[i], indexed(dyn.key_path("shapes"), i)));
  d.cache_pattern = output_pattern(dyn, "cache", {".hair", ".usda", ".ply", ".obj"}, true);
  dyn.finish();
}

void GroomReader::read_output(YamlMap &root, GroomDesc &groom) {
  YamlMap out = root.map("output");
  OutputSettings &o = groom.output;
  o.loc = out.loc();
  o.path_pattern = output_pattern(out, "path", {".usda", ".hair", ".ply", ".obj"}, false);
  if (groom.feathers.enabled)
    o.vanes_pattern = output_pattern(out, "vanes", {".usda", ".obj"}, false);
  else
    forbid(out, "vanes", "without a feathers section (vanes are feather meshes)");
  o.frames = out.string("frames", o.frames);
  if (!o.frames.empty() && !valid_frame_range(o.frames))
    fail_expected(file_, out.node("frames"), out.key_path("frames"), "a frame range A, A-B, A-B:S or A-BxS (A <= B, S >= 1)");
  o.preview_pattern = output_pattern(out, "preview", {".png"}, false);
  o.preview_every = int(out.integer("preview_every", o.preview_every, 0, 1000000));
  o.preview_size = int(out.integer("preview_size", o.preview_size, 16, max_preview_size));
  read_output_units(out, o);
  out.finish();
}

/// output.units (a unit's name or metres per unit), output.up_axis and output.stage.
void GroomReader::read_output_units(YamlMap &out, OutputSettings &o) {
  static const std::vector<std::pair<std::string, double>> units{
      {"mm", 0.001}, {"cm", 0.01}, {"dm", 0.1}, {"m", 1.0}, {"km", 1000.0}, {"in", 0.0254}, {"ft", 0.3048}};
  if (out.given("units")) {
    const YAML::Node node = out.node("units");
    const std::string expected = "a length unit (mm, cm, dm, m, km, in, ft) or metres per unit (a number in (0, 1e6])";
    if (!node.IsScalar()) fail_expected(file_, node, out.key_path("units"), expected);
    const auto named = std::find_if(units.begin(), units.end(), [&](const auto &unit) { return unit.first == node.Scalar(); });
    if (named != units.end()) {
      o.meters_per_unit = named->second;
    } else {
      double value = 0.0;
      try {
        value = node_number(node, out.key_path("units"), file_);
      } catch (const InputError &) {
        fail_expected(file_, node, out.key_path("units"), expected);
      }
      if (!(value > 0.0 && value <= 1e6)) fail_expected(file_, node, out.key_path("units"), expected);
      o.meters_per_unit = value;
    }
  }
  o.up_axis = out.choice("up_axis", o.up_axis, {"Y", "Z"});
  o.stage_path = output_pattern(out, "stage", {".usda"}, false);
  if (!o.stage_path.empty() && has_frame_field(o.stage_path))
    fail_expected(file_, out.node("stage"), out.key_path("stage"), "a path without a frame field (one stage for the range)");
}

/// Everything a hair group says, from `root` (the groom file's top level, or one item of its
/// groups list): guides, then roots, strands, interpolation, partings and effects (or feathers),
/// dynamics and controls.
void GroomReader::read_group(YamlMap &root, GroomDesc &groom) {
  if (!root.given("guides")) throw InputError(root.loc(), root.key_path("guides") + ": missing required key (a map with file)");
  YamlMap guides = root.map("guides");
  if (!guides.given("file"))
    throw InputError(guides.loc(), guides.key_path("file") + ": missing required key (a .hair, .ply, .usda or .obj path)");
  groom.guides_path = existing_file(guides, "file", {".hair", ".ply", ".usda", ".obj"});
  groom.guides_loc = guides.loc("file");
  guides.finish();

  if (root.given("feathers")) {
    // A feather groom: its follicles, templates and stems say where and what grows.
    for (const char *key : {"roots", "strands", "interpolation", "partings", "effects"})
      forbid(root, key, "in a feather groom (feathers.follicles places the feathers)");
    groom.feathers = read_feathers_section(root.node("feathers"), file_, folder_.string());
    set_feather_dynamics_defaults(groom.dynamics);
  } else {
    read_roots(root, groom);
    read_strands(root, groom);
    read_interpolation(root, groom);
    read_partings(root, groom);
    const std::vector<YAML::Node> effects = root.sequence("effects");
    for (size_t i = 0; i < effects.size(); ++i)
      groom.effects.push_back(read_effect(effects[i], indexed(root.key_path("effects"), i)));
  }

  read_dynamics(root, groom);
  read_controls_section(root, file_, groom);
}

/// A groom of several hair groups: the top level holds the shared keys (name, emitter, output) and
/// `groups`, a list of full hair group descriptions, each with a unique name.
void GroomReader::read_groups(YamlMap &root, GroomDesc &groom) {
  for (const char *key : {"guides", "roots", "strands", "interpolation", "partings", "effects", "dynamics", "controls"})
    forbid(root, key, "beside groups (each group has its own: move it into the groups)");
  forbid(root, "feathers", "with groups (hair groups grow strands; a feather groom has no groups)");
  read_emitter(root, groom);
  read_output(root, groom);
  const std::vector<YAML::Node> items = root.sequence("groups");
  if (items.empty())
    fail_expected(file_, root.node("groups"), "groups", "a list of at least one hair group (a map with name, guides, roots...)");
  std::map<std::string, size_t> names;
  std::vector<GroomDesc> groups;
  for (size_t i = 0; i < items.size(); ++i) {
    YamlMap item(items[i], indexed("groups", i), file_);
    GroomDesc group = groom;  // the shared source, name, emitter, animation and output
    group.group_index = int(i);
    group.group_loc = item.loc();
    if (!item.given("name"))
      throw InputError(item.loc(), item.key_path("name") + ": missing required key (the group's name, e.g. brows)");
    group.group_name = item.string("name");
    const bool identifier = !group.group_name.empty() && !std::isdigit(static_cast<unsigned char>(group.group_name[0])) &&
                            std::all_of(group.group_name.begin(), group.group_name.end(), [](unsigned char c) {
                              return std::isalnum(c) || c == '_';
                            });
    if (!identifier || group.group_name.size() > 64)
      fail_expected(file_, item.node("name"), item.key_path("name"),
                    "a name of at most 64 ASCII letters, digits and _, not starting with a digit (it names the "
                    "group's USD prim and files)");
    const auto [first, inserted] = names.emplace(group.group_name, i);
    if (!inserted)
      fail_expected(file_, item.node("name"), item.key_path("name"),
                    "a name no other group has (groups[" + std::to_string(first->second) + "] is \"" + group.group_name + "\")");
    forbid(item, "feathers", "in a hair group (hair groups grow strands)");
    read_group(item, group);
    item.finish();
    groups.push_back(std::move(group));
  }
  root.finish();
  groom = groups.front();
  groom.groups = std::move(groups);
}

GroomDesc GroomReader::read(const YAML::Node &document) {
  YamlMap root(document, "", file_);
  GroomDesc groom;
  groom.source = fs::absolute(fs::path(file_)).lexically_normal().string();

  if (!root.given("plume"))
    throw InputError(root.loc(), "plume: missing required key (the format version: plume: 1)");
  const YAML::Node version = root.node("plume");
  if (!version.IsScalar() || version.Scalar() != "1") fail_expected(file_, version, "plume", "the format version 1");

  // Default name: the file name without ".groom.yaml" (or its last extension).
  std::string stem = fs::path(file_).filename().string();
  for (const std::string suffix : {".groom.yaml", ".groom.yml", ".yaml", ".yml"}) {
    if (stem.size() > suffix.size() && stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
      stem.resize(stem.size() - suffix.size());
      break;
    }
  }
  groom.name = root.string("name", stem);

  if (root.given("groups")) {
    read_groups(root, groom);
    return groom;
  }
  read_emitter(root, groom);
  read_group(root, groom);
  read_output(root, groom);
  root.finish();
  return groom;
}

}  // namespace

GroomDesc read_groom_file(const std::string &path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) throw InputError(FileLoc{path}, "cannot read the groom file: no such file");
  if (!fs::is_regular_file(path, ec)) throw InputError(FileLoc{path}, "cannot read the groom file: not a regular file");
  const YAML::Node document = load_yaml_file(path, "groom file");
  return GroomReader(path).read(document);
}

namespace {

/// The lines describe_groom() gives for one hair group (guides to controls), each after `indent`.
std::string describe_group(const GroomDesc &groom, const std::string &indent) {
  static const char *methods[] = {"streamline", "fur", "linear"};
  static const char *effect_names[] = {"clump", "tension", "length", "wave", "frizz", "curl"};
  std::ostringstream out;
  out << indent << "guides: " << groom.guides_path << "\n";
  if (groom.feathers.enabled) {
    std::istringstream lines(describe_feathers(groom.feathers));
    for (std::string line; std::getline(lines, line);) out << indent << line << "\n";
  } else {
    const RootSettings &r = groom.roots;
    if (r.source == RootSettings::Source::file) {
      out << indent << "roots: from " << r.file << "\n";
    } else {
      out << indent << "roots: ";
      if (r.count > 0) out << r.count << " scattered";
      else out << format_number(r.density) << " per unit area";
      if (!r.groups.empty()) out << " on " << join(r.groups, ", ");
      if (r.near_guides > 0.0) out << ", within " << format_number(r.near_guides) << " of a guide root";
      out << ", seed " << r.seed << "\n";
    }
    const auto width = [](float w) { return w < 0.0f ? std::string("auto") : format_number(w); };
    out << indent << "strands: " << groom.points_per_strand << " points, width " << width(groom.width_root) << " to "
        << width(groom.width_tip) << "\n";
    const InterpolationSettings &s = groom.interpolation;
    out << indent << "interpolation: " << methods[int(s.method)] << ", k " << s.k << ", falloff "
        << format_number(s.falloff) << ", skin margin "
        << (s.skin_margin < 0.0f ? std::string("auto") : format_number(s.skin_margin))
        << (s.separate ? ", separation pass" : "") << "\n";
    const PartingSettings &p = groom.partings;
    static const char *zone_sources[] = {"none", "face groups", "zone map", "hard lines"};
    out << indent << "partings: zones " << zone_sources[int(p.zone_source)] << ", " << p.lines.size() << " lines\n";
    out << indent << "effects:";
    if (groom.effects.empty()) out << " none";
    for (const EffectDesc &e : groom.effects) out << " " << effect_names[int(e.type)] << "(" << format_number(e.amount) << ")";
    out << "\n";
  }
  const DynamicsSettings &d = groom.dynamics;
  if (d.enabled)
    out << indent << "dynamics: " << d.substeps << " substeps at " << format_number(d.fps) << " fps, " << d.shapes.size()
        << " collision shapes" << (d.collide_with_emitter ? " + emitter" : "") << "\n";
  else
    out << indent << "dynamics: off\n";
  if (!groom.controls.empty())
    out << indent << "controls: " << groom.controls.controls.size() << ", "
        << (groom.controls.binding == ControlSettings::Binding::nearest ? "nearest" : "blended") << " binding\n";
  return out.str();
}

}  // namespace

std::string describe_groom(const GroomDesc &groom) {
  std::ostringstream out;
  out << "groom: " << groom.name << " (" << groom.source << ")\n";
  out << "emitter: " << groom.emitter_path;
  switch (groom.animation.kind) {
    case EmitterAnimation::Kind::none: out << ", static\n"; break;
    case EmitterAnimation::Kind::obj_sequence: out << ", sequence " << groom.animation.sequence_pattern << "\n"; break;
    case EmitterAnimation::Kind::rigid: out << ", " << groom.animation.keys.size() << " rigid keys\n"; break;
  }
  if (groom.groups.empty()) {
    out << describe_group(groom, "");
  } else {
    std::vector<std::string> names;
    for (const GroomDesc &group : groom.groups) names.push_back(group.group_name);
    out << "groups: " << groom.groups.size() << " (" << join(names, ", ") << ")\n";
    for (const GroomDesc &group : groom.groups) {
      out << "group " << group.group_name << " (groom_group_id " << group.group_index << "):\n";
      out << describe_group(group, "  ");
    }
  }
  const OutputSettings &o = groom.output;
  out << "output: " << (o.path_pattern.empty() ? "(none)" : o.path_pattern)
      << ", frames " << (o.frames.empty() ? "1" : o.frames) << "\n";
  out << "units: " << format_number(o.meters_per_unit) << " metres per unit, up axis " << o.up_axis << "\n";
  if (!o.stage_path.empty()) out << "stage: " << o.stage_path << "\n";
  if (!o.vanes_pattern.empty()) out << "vanes: " << o.vanes_pattern << "\n";
  return out.str();
}

}  // namespace plume::io
