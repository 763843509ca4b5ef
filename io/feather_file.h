// The `feathers` section of a groom file (docs/groom-format.md, "Feathers"): templates, given in the
// groom file or in template files it names, key feathers, follicles, variation, detail and skin
// clearance, validated with the same file:line:column messages as the rest of the format.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

#include "groom/dynamics_desc.h"
#include "groom/feather_desc.h"

namespace plume::io {

/// Reads the `feathers` map of groom file `file` (paths relative to `folder`). Every problem is an
/// InputError "file:line:col: feathers.key.path: expected X, got Y", in the template file's own name
/// for templates read from one. Checks that each key feather names a template, and each template's
/// values (validate_template's rules: negative lengths, unsorted key barbs, an empty silhouette ...).
FeatherDesc read_feathers_section(const YAML::Node &node, const std::string &file, const std::string &folder);

/// Reads a template file: a YAML map with one key, `templates`, a map from names to templates.
std::vector<FeatherTemplate> read_template_file(const std::string &path);

/// A feather groom's dynamics defaults, set before its `dynamics` section is read: stems are stiffer
/// than hair (stiffness 10 at the root to 4 at the tip, damping 2).
void set_feather_dynamics_defaults(DynamicsSettings &r_dynamics);

/// Lines for `plume info` describing a feather groom: templates, key feathers, follicles, detail.
std::string describe_feathers(const FeatherDesc &feathers);

}  // namespace plume::io
