// Reading YAML nodes with errors that name the file, the key and the value:
// the one set of helpers the model, LCP and scene readers share (internal to
// src/io). Every failure throws io::InputError with one line
// "<source>: <key>: <what>".
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <map>
#include <string>
#include <vector>

namespace lcsim::io::yaml {

using Keys = std::map<std::string, YAML::Node>;

[[noreturn]] void fail(const std::string& source, const std::string& key, const std::string& what);

// What a node holds, for "(got ...)" in messages (scalars cut to 80 chars).
std::string describe(const YAML::Node& n);

// "a, b, c".
std::string join(const std::vector<std::string>& names);

// Parses `text`; malformed YAML names the line and column (1-based).
YAML::Node load(const std::string& text, const std::string& source);

// The entries of a mapping by key; keys outside `allowed` (unless it is
// empty: any key) and duplicate keys are errors, so that a typo
// ("restitutoin") never passes silently. `key` is the mapping's own key
// ("" for the top level).
Keys mapping(const YAML::Node& node, const std::string& source, const std::string& key,
             const std::vector<std::string>& allowed);

// A finite number.
double number(const YAML::Node& n, const std::string& source, const std::string& key);

// A list of finite numbers.
Eigen::VectorXd vector(const YAML::Node& n, const std::string& source, const std::string& key);

}  // namespace lcsim::io::yaml
