// Matrix model files (docs/model-format.md): reading and writing the YAML of
// a mechanical model or an LCS. Scenes (URDF) are read by the scene layer,
// whose scene::load_model reads either kind.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/io/input_error.hpp>
#include <lcsim/mech/mech.hpp>
#include <string>
#include <vector>

namespace lcsim::io {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Loads a model file (format in README.md): `name`, then `mechanical:` with
// M, D, K, E, g, f, restitution, coordinates, constraints, or `lcs:` with
// A, B, C, D; optional `initial` and `t_end`. Validates dimensions,
// finiteness, M symmetric positive definite, restitution in [0, 1], t_end > 0,
// the initial state's size. A scene (a top-level `urdf:` key) is not a
// matrix model: scene::load_model reads both kinds.
mech::Model load_matrix_model(const std::filesystem::path& path);
// The same from YAML text; `source` names it in messages.
mech::Model parse_matrix_model(const std::string& yaml_text, const std::string& source);

// Notes on a valid model that are not errors (e.g. dependent constraints:
// E without full row rank is legal, §4.6.1, and reported here).
std::vector<std::string> model_notes(const mech::Model& model);

// The YAML text of a mechanical model (docs/model-format.md), read back
// exactly by parse_matrix_model (numbers round-trip). Each matrix is written in the
// spelling that stores least: a list of rows when small (at most 64 entries),
// {diagonal: [...]} when diagonal, else {rows, cols, entries} with its
// non-zeros, so a chain of N carts takes O(N) bytes. `header` lines are
// written first as comments. std::invalid_argument for an `lcs:` model or a
// model with inputs (docs/inputs.md).
std::string model_yaml(const mech::Model& model, const std::string& header = "");

}  // namespace lcsim::io
