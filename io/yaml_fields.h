// Typed, located access to YAML nodes for groom files: every getter knows the file, the
// line:column and the key path, and every map rejects keys nobody asked for.
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "groom/error.h"

namespace plume::io {

/// The YAML document of the file at `path`: InputError "path:line:col: YAML syntax error: ..." for a
/// syntax error, and "path: cannot read the <what>: it could not be opened" when it cannot be read.
YAML::Node load_yaml_file(const std::string &path, const std::string &what);

/// FileLoc of a node (yaml-cpp marks are 0-based; FileLoc is 1-based).
FileLoc node_loc(const std::string &file, const YAML::Node &node);
/// InputError "file:line:col: path: expected <expected>, got <what the node holds>".
[[noreturn]] void fail_expected(const std::string &file, const YAML::Node &node, const std::string &path,
                                const std::string &expected);

/// A YAML map being read. Call finish() after the last get: any key that was never asked for
/// is reported as unknown, with the list of keys this map accepts.
class YamlMap {
 public:
  /// Throws InputError if `node` is not a map (an absent or null node reads as an empty map).
  YamlMap(const YAML::Node &node, std::string path, const std::string &file);

  bool has(const std::string &key) const;
  /// has(), and marks `key` as known (so a key written with no value, `key:`, is not "unknown").
  bool given(const std::string &key);
  const std::string &path() const { return path_; }
  const std::string &file() const { return file_; }
  std::string key_path(const std::string &key) const { return path_.empty() ? key : path_ + "." + key; }
  FileLoc loc() const { return node_loc(file_, node_); }
  FileLoc loc(const std::string &key) const;

  /// Each getter marks the key as known. The optional form returns `fallback` when absent;
  /// the other throws "missing required key".
  double number(const std::string &key, double fallback);
  double number(const std::string &key);
  /// A number in [lo, hi]; out-of-range values are errors that name the range.
  double number_in(const std::string &key, double fallback, double lo, double hi);
  int64_t integer(const std::string &key, int64_t fallback, int64_t lo, int64_t hi);
  bool boolean(const std::string &key, bool fallback);
  std::string string(const std::string &key, const std::string &fallback);
  std::string string(const std::string &key);
  /// One of `choices`; the error lists them.
  std::string choice(const std::string &key, const std::string &fallback, const std::vector<std::string> &choices);
  Eigen::Vector3f vec3(const std::string &key, const Eigen::Vector3f &fallback);
  std::vector<std::string> string_list(const std::string &key);
  std::vector<double> number_list(const std::string &key);
  /// A nested map (empty if absent) and a sequence (empty if absent) of nodes.
  YamlMap map(const std::string &key);
  std::vector<YAML::Node> sequence(const std::string &key);
  /// The raw node, marked as known (for custom parsing). Null if absent.
  YAML::Node node(const std::string &key);

  void finish() const;

 private:
  YAML::Node node_;
  std::string path_;
  std::string file_;
  std::set<std::string> asked_;
};

/// Scalar readers for nodes that are not map entries (sequence items); `path` is for messages.
double node_number(const YAML::Node &node, const std::string &path, const std::string &file);
Eigen::Vector3f node_vec3(const YAML::Node &node, const std::string &path, const std::string &file);

}  // namespace plume::io
