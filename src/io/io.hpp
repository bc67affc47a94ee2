// The I/O layer: loaders (YAML models, LCP problems) and writers (CSV
// trajectories, JSON summaries). All input validation lives here: bad input
// throws InputError whose message names the file, the key and the value.
//
// Public face of src/io.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
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

// The YAML text of a mechanical model (docs/model-format.md), read back
// exactly by parse_model (numbers round-trip). Each matrix is written in the
// spelling that stores least: a list of rows when small (at most 64 entries),
// {diagonal: [...]} when diagonal, else {rows, cols, entries} with its
// non-zeros, so a chain of N carts takes O(N) bytes. `header` lines are
// written first as comments. std::invalid_argument for an `lcs:` model.
std::string model_yaml(const mech::Model& model, const std::string& header = "");

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

// ---- URDF models and scenes (docs/model-format.md, section "Scenes") ----

namespace urdf {
class ModelInterface;
}

namespace lcsim::io {

// Parses a URDF file with urdfdom and checks what lcsim relies on: finite
// numbers in every <origin>, <axis>, <inertial>, <limit> and <dynamics>;
// masses >= 0; non-zero axes on revolute and prismatic joints; lower <= upper.
// InputError names the file, the element and the value.
std::shared_ptr<urdf::ModelInterface> load_urdf(const std::filesystem::path& path);
// The same from URDF text; `source` names it in messages.
std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source);

// The rigid-body part of a scene linearised about a reference configuration.
// Coordinates are the joint positions themselves (rad for revolute, m for
// prismatic joints), in the order of `joints`.
struct UrdfLinearisation {
  std::vector<std::string> joints;  // the simulated joints
  MatrixXd M;        // joint-space mass matrix at q0 (composite-rigid-body algorithm)
  VectorXd tau_g;    // gravity generalised force at q0 (N or N m)
  MatrixXd K_g;      // gravity stiffness -d tau_g / dq at q0 (symmetric)
  VectorXd damping;  // <dynamics damping> of each simulated joint (N s/m or N m s/rad)
};

// Linearises `model` about q0 (positions by joint name; joints not named sit
// at 0). Every joint not in `joints` is frozen at its q0; fixed joints are
// merged. `gravity` in the URDF root frame (m/s^2). `source` names the URDF in
// messages. K_g by central differences of tau_g, step 6e-6 (see urdf_model.cpp).
UrdfLinearisation linearise_urdf(const urdf::ModelInterface& model,
                                 const std::vector<std::string>& joints,
                                 const std::map<std::string, double>& q0,
                                 const Eigen::Vector3d& gravity, const std::string& source);

// Scenes: a YAML file with a top-level `urdf:` key. `load_model` and
// `parse_model` dispatch to these, so every command accepts a scene. The URDF
// path is relative to the directory of `source` (the scene's path). The
// coordinates are the joint positions (not deviations from q0); format and
// linearisation in docs/model-format.md, "Scenes".
mech::Model load_scene(const std::filesystem::path& path);
mech::Model parse_scene(const std::string& yaml_text, const std::string& source);

// What a scene's model keeps only in linearised form, for building the scene
// again from its URDF (src/bullet): the URDF and its path, the q0 of every
// joint the scene names (frozen joints sit there), gravity (m/s^2, URDF root
// frame), and the linearisation whose tau_g and K_g went into f and K (the
// rest of K and f, and all of D, are the springs' and the joints' dampers).
struct SceneSetup {
  std::shared_ptr<urdf::ModelInterface> urdf;
  std::string urdf_path;
  std::map<std::string, double> q0;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  UrdfLinearisation linearisation;
};
// The setup of the scene `model` was loaded from (model.source, read again);
// std::nullopt when model.source is not a readable, valid scene file or when
// `model` is not what that file gives (changed after loading: M, D, K, E, g,
// f, restitution or the names differ).
std::optional<SceneSetup> scene_setup(const mech::Model& model);

}  // namespace lcsim::io
