// The I/O layer: loaders (YAML models, LCP problems) and writers (CSV
// trajectories, JSON summaries). All input validation lives here: bad input
// throws InputError whose message names the file, the key and the value.
//
// Public face of src/io.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

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

// The same CSV streamed to disk as a run goes (sim::Options::sample_sink), so
// a long run's output never has to fit in memory: rows go to a temporary
// file beside `path` (".<name>.tmp-XXXXXX"), which commit() renames into
// place; a writer destroyed without commit() (a failed or refused run, an
// exception) removes it. So `path` appears whole or not at all.
// The constructor throws InputError when no file can be created beside
// `path`; write() never throws (a sink must not): a write error is kept and
// thrown by commit() as InputError "<path>: cannot write: <reason>".
class TrajectoryCsvWriter {
 public:
  TrajectoryCsvWriter(const std::filesystem::path& path, const mech::Model& model);
  ~TrajectoryCsvWriter();
  TrajectoryCsvWriter(const TrajectoryCsvWriter&) = delete;
  TrajectoryCsvWriter& operator=(const TrajectoryCsvWriter&) = delete;
  void write(const sim::Sample& sample) noexcept;
  void commit();
  const std::string& temporary_path() const { return temporary_; }

 private:
  void flush() noexcept;
  static constexpr std::size_t kBufferBytes = 1 << 20;
  std::string path_, temporary_, buffer_, logic_error_;
  int n_ = 0, k_ = 0, nf_ = 0, fd_ = -1, error_ = 0;  // nf_: frictional contacts
  std::size_t rows_ = 0;
};

// The temporary files of the writers above (and of any caller that tracks
// its own) are kept in a fixed table, so that a signal handler can remove
// them: remove_temporary_files() is async-signal-safe (unlink(2) over a
// table of char buffers; at most 32 files, paths under 4096 bytes).
void track_temporary_file(const std::string& path);
void untrack_temporary_file(const std::string& path);
void remove_temporary_files() noexcept;

// `text` cut at every `sep` ("a,,b" gives "a", "", "b"; "" gives none): the
// comma lists of names and ranges the commands take.
std::vector<std::string> split(const std::string& text, char sep);

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
// masses >= 0; inertia tensors positive semi-definite with I1 + I2 >= I3
// (refused, or repaired: UrdfRepairs); non-zero axes on revolute,
// continuous and prismatic joints.
// <visual>, <collision> and <material> are dropped unread (no geometry is
// used). A <limit> with lower > upper is no limit; a scene refuses it only
// where it would become a stop. InputError names the file, the element and
// the value.
std::shared_ptr<urdf::ModelInterface> load_urdf(const std::filesystem::path& path);
// The same from URDF text; `source` names it in messages.
std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source);

// What parse_urdf repairs instead of refusing (a scene's `balance_inertia:
// true`), and what it repaired. An inertia tensor that is not positive
// semi-definite or breaks the triangle inequality I1 + I2 >= I3 (beyond the
// check's 1e-4 of the largest moment) is refused unless balance_inertia;
// then it is replaced, in its principal frame, by the moments with each
// negative one set to 0 and, if still I1 + I2 < I3, I1 and I2 each raised by
// half the deficit (I3, the principal axes and the mass kept; the result is
// positive semi-definite with I1 + I2 = I3). Valid tensors are never
// changed. Each repair adds a note naming the URDF, the link and the
// moments before and after.
struct UrdfRepairs {
  bool balance_inertia = false;
  std::vector<std::string> notes;
};
std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source,
                                                 UrdfRepairs& repairs);

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

// <mimic joint="J" multiplier="a" offset="b"> on joint m: q_m = a q_J + b
// (urdfdom's defaults a = 1, b = 0). Chains are followed to the first joint
// that mimics nothing, composing the maps: the result's `leader` is never a
// mimic itself. Returns every revolute, continuous or prismatic joint that
// carries a <mimic> (a <mimic> on a fixed joint means nothing and is
// skipped). InputError naming the joint when a leader is missing or has no
// position (fixed, floating, planar), and for a cycle of mimics.
struct Mimic {
  std::string leader;
  double multiplier = 1.0;
  double offset = 0.0;
};
// `simulated`: joints a scene simulates. Such a joint is its own coordinate
// even if it carries a <mimic> (the scene's explicit choice wins: the NAO
// legs of issue 12 simulate RHipYawPitch, which the URDF ties to
// LHipYawPitch), so it is not returned, and a chain stops at it.
std::map<std::string, Mimic> mimic_joints(const urdf::ModelInterface& model,
                                          const std::string& source,
                                          const std::vector<std::string>& simulated = {});

// The exact (nonlinear) joint-space dynamics of a scene's URDF as functions
// of the coordinates q (the simulated joints, in the order of `joints`):
// every other joint sits at its `q0` (0 if not named), fixed joints are
// merged, and a mimic joint follows its leader (q_m = a q_J + b; when J is
// frozen, m is frozen there too). A mimic of a simulated joint moves with it:
// its motion enters the Jacobian of every body below it, so its mass,
// gravity and damping act through J. A simulated joint that is itself a
// mimic is refused (InputError naming both joints). `model` must outlive
// this object. Errors as linearise_urdf.
class UrdfDynamics {
 public:
  UrdfDynamics(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
               const std::map<std::string, double>& q0, const Eigen::Vector3d& gravity,
               const std::string& source);
  const std::vector<std::string>& joints() const { return joints_; }
  VectorXd reference() const;                       // q0 of the simulated joints
  MatrixXd mass_matrix(const VectorXd& q) const;    // M(q), composite-rigid-body algorithm
  VectorXd gravity_force(const VectorXd& q) const;  // tau_g(q) (N or N m)
  VectorXd damping() const;                         // diagonal of T' diag(<dynamics damping>) T
  struct Impl;

 private:
  std::vector<std::string> joints_;
  std::shared_ptr<const Impl> impl_;
};

// Linearises `model` about q0 (positions by joint name; joints not named sit
// at 0) through UrdfDynamics: every joint not in `joints` is frozen at its
// q0, fixed joints are merged, mimics follow their leaders. `gravity` in the URDF root frame
// (m/s^2). `source` names the URDF in messages. K_g by central differences of tau_g, step 6e-6 (see
// urdf_model.cpp).
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

// A scene's model with what it was linearised from, so that the exact
// dynamics can be evaluated away from q0 (check_linearisation).
struct Scene {
  mech::Model model;
  std::shared_ptr<urdf::ModelInterface> urdf;
  std::string urdf_source;           // the URDF's path, for messages
  std::map<std::string, double> q0;  // as the scene gives it (joints not named: 0)
  Eigen::Vector3d gravity;           // m/s^2, URDF root frame
  UrdfLinearisation lin;             // M, tau_g, K_g, damping at q0 (coordinates: lin.joints)
  std::vector<std::string> notes;    // what loading repaired (UrdfRepairs::notes)
};
Scene read_scene(const std::string& yaml_text, const std::string& source);
// The scene in `path`, or nullopt when the file is a model, not a scene (no
// top-level `urdf:` key). Errors as load_model.
std::optional<Scene> load_scene_details(const std::filesystem::path& path);
// The model in `path` (as load_model) and, for a scene, the Scene: the file
// is read and parsed once (a 10000-cart model's YAML tree is 75 MB).
struct LoadedModel {
  mech::Model model;
  std::optional<Scene> scene;
};
LoadedModel load_model_and_scene(const std::filesystem::path& path);
// model_notes of the model, after the scene's notes (what loading repaired):
// the notes `analyze` prints.
std::vector<std::string> model_notes(const LoadedModel& loaded);

// ---- How far the linear model holds (src/io/linearisation.cpp) ----
//
// At coordinates q the exact model has the mass matrix M(q) and the force
// F(q) = tau_g(q) + springs(q) (springs are linear in q, so exact in the
// model); the linear model has M0 = M(q0) and L(q) = f - K q. Velocity
// terms (Coriolis and centrifugal forces, quadratic in v) are not measured.
//   mass error   e_M(q) = ||M(q) - M0||_F / ||M0||_F
//   force error  e_F(q) = ||F(q) - L(q)||_2 / max(||F(q)||_2, ||L(q)||_2, ||K (q - q0)||_2)
//                (0 where all vanish), F(q) - L(q) = tau_g(q) - tau_g(q0) + K_g (q - q0);
//                the last term of the scale, the linear model's change of force
//                since q0, keeps rounding noise from counting where both forces
//                vanish (a spring at its rest length, gravity along no joint)
//   error        e(q) = max(e_M(q), e_F(q))
// For a pendulum about its hanging equilibrium, e_F = |theta - sin theta| / |theta| ~ theta^2/6.
struct LinearisationCheck {
  double error = 0.0;        // max over the states of e(q)
  double mass_error = 0.0;   // max of e_M
  double force_error = 0.0;  // max of e_F
  VectorXd worst_q;          // the state where e(q) was largest
  std::size_t states = 0;    // how many states were evaluated
};
constexpr std::size_t kLinearisationStates = 200;  // states evaluated at most
constexpr double kLinearisationThreshold = 0.01;   // default warning threshold (1 %)

// e(q) at the given coordinates (size N each; the first N entries of a full
// state are used, so trajectory states (q, v) may be passed as they are).
// More than kLinearisationStates states are subsampled evenly, first and last
// kept. std::invalid_argument for a wrong size.
LinearisationCheck check_linearisation(const Scene& scene, const std::vector<VectorXd>& states);

// The states of a run as they stream by (sim::Options::sample_sink), thinned
// so that at most 2 * kLinearisationStates are kept, evenly spaced, plus the
// last: what check_linearisation evaluates, in bounded memory however long
// the run. The command line and the Python module check a scene's run with
// it, so both report the same check.
class LinearisationStates {
 public:
  void add(const VectorXd& x);
  std::vector<VectorXd> states() const;

 private:
  std::vector<VectorXd> kept_;
  VectorXd last_;
  long seen_ = 0, stride_ = 1;
};

// "" when check.error <= threshold, else the warning line. InputError
// ("--linearisation-threshold: ...") unless threshold is finite and > 0.
std::string linearisation_warning(const LinearisationCheck& check, double threshold);
void check_linearisation_threshold(double threshold);

// Per simulated joint, the interval of q about q0 (other joints at q0) in
// which e(q) <= threshold: from q0 outwards in 64 steps to the joint's limit
// (or pi rad / 1 m when it has none), then 50 bisections where e first
// exceeds the threshold (each coordinate alone; e need not be monotone, the
// scan stops at the first crossing it sees).
struct LinearRange {
  std::string joint;
  std::string unit;  // "rad" (revolute) or "m" (prismatic)
  double q0 = 0.0;
  double lower = 0.0, upper = 0.0;  // rad or m, absolute joint positions
  // What ends each side: "threshold" (e crosses it there), "limit" (the
  // joint's limit, no crossing before it) or "search" (no limit on that
  // side: the scan stopped at pi rad or 1 m without a crossing).
  std::string lower_end, upper_end;
};
std::vector<LinearRange> linear_ranges(const Scene& scene, double threshold);

// JSON of the two: {error, mass_error, force_error, worst_q, states} and
// [{joint, unit, q0, lower, upper, lower_end, upper_end}, ...].
nlohmann::json to_json(const LinearisationCheck& check);
nlohmann::json to_json(const std::vector<LinearRange>& ranges);
// The scene `model` was loaded from (model.source, read again), for building
// it again from its URDF (src/bullet); std::nullopt when model.source is not
// a readable, valid scene file or when `model` is not what that file gives
// (changed after loading: M, D, K, E, g, f or the names differ). The
// restitution may differ: the returned scene's model carries `model`'s (a
// study's restitution axis changes a parameter, not the kind of model).
std::optional<Scene> scene_setup(const mech::Model& model);

}  // namespace lcsim::io
