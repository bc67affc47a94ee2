// Reading YAML files and nodes with errors that name the file, the key and
// the value: the one set of helpers the model, LCP, scene and study readers
// share. Every failure throws io::InputError with one line
// "<source>: <key>: <what>".
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/io/input_error.hpp>
#include <lcsim/mech/mech.hpp>
#include <map>
#include <string>
#include <vector>

namespace lcsim::io {

// The whole text of a file; InputError "<path>: cannot open: no such file"
// (or "is a directory", "permission denied or unreadable").
std::string read_file(const std::filesystem::path& path);

// A model file's YAML root (InputError for an empty file), whether it is a
// scene (a top-level `urdf:` key), and the matrix model of a root that is not.
YAML::Node load_model_root(const std::string& yaml_text, const std::string& source);
bool is_scene(const YAML::Node& root);
mech::Model parse_matrix_model(const YAML::Node& root, const std::string& source);

}  // namespace lcsim::io

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

// A dense matrix as a list of rows of finite numbers, all of one length.
// `cols_if_empty` gives the column count of `[]` (0 rows).
Eigen::MatrixXd matrix(const YAML::Node& n, const std::string& source, const std::string& key,
                       Eigen::Index cols_if_empty);

// "R x C", a matrix's dimensions for "(got ...)" in messages.
template <class Mat>
std::string dims(const Mat& m) {
  return std::to_string(m.rows()) + " x " + std::to_string(m.cols());
}

// That `v` has `size` entries; else "expected <size> entries <why> (got
// <v.size()>)" at `key`.
void expect_size(const Eigen::VectorXd& v, Eigen::Index size, const std::string& source,
                 const std::string& key, const std::string& why);

// A model file's `inputs:` list (src/io/model_inputs.cpp, docs/inputs.md),
// each checked (mech::check_input).
std::vector<mech::Input> inputs(const YAML::Node& n, const std::string& source);
// A list of {input: name, gain: [size numbers]} at `key`
// (mechanical.force_inputs, mechanical.gap_inputs); `why` says where size
// comes from.
std::vector<mech::InputUse> input_uses(const YAML::Node& n, const std::vector<mech::Input>& inputs,
                                       Eigen::Index size, const std::string& source,
                                       const std::string& key, const std::string& why);

}  // namespace lcsim::io::yaml
