// The I/O layer: loaders (YAML models, LCP problems) and writers (CSV
// trajectories, JSON summaries). All input validation lives here: bad input
// throws InputError whose message names the file, the key and the value.
//
// Public face of src/io.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <vector>

#include "mech/mech.hpp"
#include "sim/sim.hpp"

namespace lcsim::io {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// One clear line: "<file>: <key>: <what is wrong> (got <value>)".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Loads a model file (format in README.md): `name`, then `mechanical:` with
// M, D, K, E, g, f, restitution, coordinates, constraints, or `lcs:` with
// A, B, C, D; optional `initial` and `t_end`. Validates dimensions,
// finiteness, M symmetric positive definite, restitution in [0, 1], t_end > 0,
// the initial state's size.
mech::Model load_model(const std::filesystem::path& path);
// The same from YAML text; `source` names it in messages.
mech::Model parse_model(const std::string& yaml_text, const std::string& source);

// Notes on a valid model that are not errors (e.g. dependent constraints:
// E without full row rank is legal, §4.6.1, and reported here).
std::vector<std::string> model_notes(const mech::Model& model);

struct LcpProblem {
  MatrixXd M;
  VectorXd q;
};
// `M` (list of rows) and `q` (list), square and matching, finite.
LcpProblem load_lcp(const std::filesystem::path& path);

// Parses "a,b,c" into a vector; InputError names `what` and the bad token.
VectorXd parse_vector(const std::string& text, const std::string& what);

// Writes text to a temporary file beside `path` and renames it into place, so
// a failure never leaves a half-written file. InputError if not writable.
void write_file_atomic(const std::filesystem::path& path, const std::string& content);

// CSV with header t, state (q names then v names for mechanical models, x1..
// otherwise), u1.., y1.., mode (active constraints joined by ';').
std::string trajectory_csv(const mech::Model& model, const sim::Trajectory& traj);

// JSON summary of a run (keys of the simulate command).
nlohmann::json trajectory_json(const mech::Model& model, const sim::Trajectory& traj);

nlohmann::json to_json(const VectorXd& v);
nlohmann::json to_json(const Eigen::MatrixXd& m);

}  // namespace lcsim::io
