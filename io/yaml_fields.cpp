#include "io/yaml_fields.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <map>

#include "io/file_scan.h"

namespace plume::io {

namespace {
/// A scalar as a message shows it: quoted, control characters escaped (\x0a), and cut after 80
/// characters with its size, so that a file that is not YAML at all (a mesh given as a groom) is not
/// echoed whole.
std::string shown_scalar(const std::string &text) {
  constexpr size_t kMaxShown = 80;
  const std::string shown = detail::quoted(text, kMaxShown, true);
  return text.size() > kMaxShown ? shown + " (" + std::to_string(text.size()) + " characters)" : shown;
}

std::string describe(const YAML::Node &node) {
  switch (node.Type()) {
    case YAML::NodeType::Undefined:
    case YAML::NodeType::Null: return "nothing";
    case YAML::NodeType::Sequence: return "a list";
    case YAML::NodeType::Map: return "a map";
    case YAML::NodeType::Scalar: return shown_scalar(node.Scalar());
  }
  return "something else";
}

std::optional<double> as_number(const YAML::Node &node) {
  if (!node.IsScalar()) return std::nullopt;
  const std::string &s = node.Scalar();
  if (s.empty()) return std::nullopt;
  char *end = nullptr;
  errno = 0;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size() || errno == ERANGE) return std::nullopt;
  return v;
}

/// Shortest readable form of a number for messages ("0.5", "1e+08").
std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}
}  // namespace

YAML::Node load_yaml_file(const std::string &path, const std::string &what) {
  try {
    return YAML::LoadFile(path);
  } catch (const YAML::ParserException &e) {
    FileLoc loc{path};
    if (e.mark.line >= 0) {
      loc.line = e.mark.line + 1;
      loc.column = e.mark.column + 1;
    }
    throw InputError(loc, "YAML syntax error: " + e.msg);
  } catch (const YAML::BadFile &) {
    throw InputError(FileLoc{path}, "cannot read the " + what + ": it could not be opened");
  }
}

FileLoc node_loc(const std::string &file, const YAML::Node &node) {
  FileLoc loc{file};
  const YAML::Mark mark = node.Mark();
  if (mark.line >= 0) {
    loc.line = mark.line + 1;
    loc.column = mark.column + 1;
  }
  return loc;
}

void fail_expected(const std::string &file, const YAML::Node &node, const std::string &path,
                   const std::string &expected) {
  throw InputError(node_loc(file, node), path + ": expected " + expected + ", got " + describe(node));
}

double node_number(const YAML::Node &node, const std::string &path, const std::string &file) {
  const std::optional<double> v = as_number(node);
  if (!v) fail_expected(file, node, path, "a number");
  // Every number ends up in a 32-bit float: one beyond its range would become inf there.
  if (!std::isfinite(*v) || std::abs(*v) > double(std::numeric_limits<float>::max()))
    fail_expected(file, node, path, "a finite number");
  return *v;
}

Eigen::Vector3f node_vec3(const YAML::Node &node, const std::string &path, const std::string &file) {
  if (!node.IsSequence() || node.size() != 3) fail_expected(file, node, path, "a list of 3 numbers [x, y, z]");
  Eigen::Vector3f v;
  for (int i = 0; i < 3; ++i) {
    const std::string item = path + "[" + std::to_string(i) + "]";
    v[i] = float(node_number(node[i], item, file));
  }
  return v;
}

YamlMap::YamlMap(const YAML::Node &node, std::string path, const std::string &file)
    : node_(node), path_(std::move(path)), file_(file) {
  if (node_.IsDefined() && !node_.IsNull() && !node_.IsMap())
    fail_expected(file_, node_, path_.empty() ? "groom" : path_, "a map of key: value");
}

bool YamlMap::has(const std::string &key) const {
  return node_.IsMap() && node_[key].IsDefined() && !node_[key].IsNull();
}

bool YamlMap::given(const std::string &key) {
  asked_.insert(key);
  return has(key);
}

FileLoc YamlMap::loc(const std::string &key) const {
  return has(key) ? node_loc(file_, node_[key]) : loc();
}

double YamlMap::number(const std::string &key, double fallback) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  return node_number(node_[key], key_path(key), file_);
}

double YamlMap::number(const std::string &key) {
  asked_.insert(key);
  if (!has(key)) throw InputError(loc(), key_path(key) + ": missing required key (a number)");
  return node_number(node_[key], key_path(key), file_);
}

double YamlMap::number_in(const std::string &key, double fallback, double lo, double hi) {
  const double v = number(key, fallback);
  if (v < lo || v > hi) {
    std::string range = "a number in [" + format_number(lo) + ", " + format_number(hi) + "]";
    fail_expected(file_, node_[key], key_path(key), range);
  }
  return v;
}

int64_t YamlMap::integer(const std::string &key, int64_t fallback, int64_t lo, int64_t hi) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  const std::optional<double> v = as_number(n);
  const std::string expected = "a whole number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (!v || std::floor(*v) != *v || *v < double(lo) || *v > double(hi)) fail_expected(file_, n, key_path(key), expected);
  return int64_t(*v);
}

bool YamlMap::boolean(const std::string &key, bool fallback) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  if (n.IsScalar()) {
    const std::string &s = n.Scalar();
    if (s == "true" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "no" || s == "off") return false;
  }
  fail_expected(file_, n, key_path(key), "true or false");
}

std::string YamlMap::string(const std::string &key, const std::string &fallback) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  const YAML::Node n = node_[key];
  if (!n.IsScalar()) fail_expected(file_, n, key_path(key), "a string");
  return n.Scalar();
}

std::string YamlMap::string(const std::string &key) {
  asked_.insert(key);
  if (!has(key)) throw InputError(loc(), key_path(key) + ": missing required key (a string)");
  return string(key, "");
}

std::string YamlMap::choice(const std::string &key, const std::string &fallback,
                            const std::vector<std::string> &choices) {
  const std::string v = string(key, fallback);
  for (const std::string &c : choices)
    if (c == v) return v;
  std::string expected = "one of";
  for (size_t i = 0; i < choices.size(); ++i) expected += (i ? ", " : " ") + choices[i];
  fail_expected(file_, node_[key], key_path(key), expected);
}

Eigen::Vector3f YamlMap::vec3(const std::string &key, const Eigen::Vector3f &fallback) {
  asked_.insert(key);
  if (!has(key)) return fallback;
  return node_vec3(node_[key], key_path(key), file_);
}

std::vector<std::string> YamlMap::string_list(const std::string &key) {
  asked_.insert(key);
  std::vector<std::string> out;
  if (!has(key)) return out;
  const YAML::Node n = node_[key];
  // Names (face groups, zones) are printed in messages and matched against OBJ names, which hold
  // no control characters: a NUL or a line break here is a mistake, and would cut a message short.
  auto name_of = [&](const YAML::Node &item, const std::string &path) {
    if (!item.IsScalar()) fail_expected(file_, item, path, "a string");
    const std::string &name = item.Scalar();
    for (const char c : name)
      if ((unsigned char)c < 32 || c == 127)
        throw InputError(node_loc(file_, item),
                         path + ": expected a name without control characters, got " + detail::quoted(name));
    return name;
  };
  if (n.IsScalar()) return {name_of(n, key_path(key))};
  if (!n.IsSequence()) fail_expected(file_, n, key_path(key), "a list of strings");
  for (size_t i = 0; i < n.size(); ++i) out.push_back(name_of(n[i], key_path(key) + "[" + std::to_string(i) + "]"));
  return out;
}

std::vector<double> YamlMap::number_list(const std::string &key) {
  asked_.insert(key);
  std::vector<double> out;
  if (!has(key)) return out;
  const YAML::Node n = node_[key];
  if (!n.IsSequence()) fail_expected(file_, n, key_path(key), "a list of numbers");
  for (size_t i = 0; i < n.size(); ++i)
    out.push_back(node_number(n[i], key_path(key) + "[" + std::to_string(i) + "]", file_));
  return out;
}

YamlMap YamlMap::map(const std::string &key) {
  asked_.insert(key);
  return YamlMap(has(key) ? node_[key] : YAML::Node(), key_path(key), file_);
}

std::vector<YAML::Node> YamlMap::sequence(const std::string &key) {
  asked_.insert(key);
  std::vector<YAML::Node> out;
  if (!has(key)) return out;
  const YAML::Node n = node_[key];
  if (!n.IsSequence()) fail_expected(file_, n, key_path(key), "a list");
  for (size_t i = 0; i < n.size(); ++i) out.push_back(n[i]);
  return out;
}

YAML::Node YamlMap::node(const std::string &key) {
  asked_.insert(key);
  return has(key) ? node_[key] : YAML::Node();
}

void YamlMap::finish() const {
  if (!node_.IsMap()) return;
  // yaml-cpp keeps the first of two equal keys and drops the other silently: report it instead.
  std::map<std::string, int> first_line;
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.Scalar();
    const FileLoc key_loc = node_loc(file_, it->first);
    const auto [seen, inserted] = first_line.emplace(key, key_loc.line);
    if (!inserted)
      throw InputError(key_loc, key_path(key) + ": duplicate key (first given at line " +
                                    std::to_string(seen->second) + ")");
  }
  for (auto it = node_.begin(); it != node_.end(); ++it) {
    const std::string key = it->first.Scalar();
    if (asked_.count(key)) continue;
    std::string known;
    for (const std::string &k : asked_) known += (known.empty() ? "" : ", ") + k;
    throw InputError(node_loc(file_, it->first),
                     key_path(key) + ": unknown key; expected one of: " + (known.empty() ? "(none)" : known));
  }
}

}  // namespace plume::io
