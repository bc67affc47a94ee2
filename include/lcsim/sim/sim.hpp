// The simulation layer: integrators behind one interface, each producing the
// same Trajectory (samples + events) for a Model.
//
// Public face of src/sim. Nothing throws inside the integration loop: trouble
// ends the run with a status and a message, and warnings are counted.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <lcsim/core/format.hpp>
#include <lcsim/core/outcome.hpp>
#include <lcsim/core/status.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/mech/mech.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::sim {

using Eigen::VectorXd;
using IndexSet = std::vector<int>;

// kStick: a frictional contact's sliding velocity reached zero and it
// sticks; kSlip: a frictional contact starts to slide (its stick force
// reached the edge of the friction cone, or it reverses). kSchedule: a
// breakpoint of an input (a step, a pulse's edge, a PWL point; docs/inputs.md),
// where the exact method re-initialises the input's exosystem.
enum class EventType {
  kImpact,
  kRelease,
  kContact,
  kAccumulation,
  kStart,
  kStick,
  kSlip,
  kSchedule
};
std::string_view to_string(EventType t);

// What a closed frictional contact does in a sample (Sample::friction_mode):
// kOpen when its normal constraint is not closed; kStick, tangential
// velocity zero (relative to its surface) and |u_T| <= mu u_N; kSlipPositive
// / kSlipNegative, sliding along +t / -t with u_T = -/+ mu u_N; kSlip, a 3-D
// contact (two tangents) sliding, its friction on the cone's boundary.
enum class FrictionMode : signed char { kOpen, kStick, kSlipPositive, kSlipNegative, kSlip };
std::string_view to_string(FrictionMode m);  // "open", "stick", "slip+", "slip-", "slip"
// A contact's mode as the outputs write it: to_string(m), except a 3-D slip
// on a known facet (facet.edge >= 0): "slip-edge-<i>" or "slip-face-<i>"
// (impact::cone_mode_text's names).
std::string friction_mode_text(FrictionMode m, impact::ConeFacet facet);

struct Sample {
  double t = 0.0;
  VectorXd x;  // state: q then v for mechanical models
  VectorXd u;  // multipliers (regular part)
  VectorXd y;  // gaps / outputs
  IndexSet mode;
  // The switch configuration holding (an index into mech::Model::
  // configurations, whose outputs the CSV writes; a switched circuit's, set
  // by the exact method); 0 for every other model.
  int configuration = 0;
  // Tangential multipliers (mean friction force over the step, N), one per
  // entry of mechanical.friction in its order; empty for frictionless models.
  VectorXd u_t;
  // The mode of each entry of mechanical.friction, in its order; empty for
  // frictionless models and for methods that do not determine it.
  std::vector<FrictionMode> friction_mode;
  // Models with 3-D friction (mech::MechanicalModel::has_friction_3d; both
  // empty otherwise, so planar outputs stay as they were): the multiplier
  // along each entry's second tangent (mean force over the step, N; 0 for a
  // planar entry), and the cone facet holding the friction force of each
  // entry in mode kSlip (edge -1 elsewhere; empty when the method does not
  // determine it).
  VectorXd u_t2;
  std::vector<impact::ConeFacet> friction_facet;
  // Forward sensitivities (Options::sensitivity; both empty otherwise,
  // docs/sensitivities.md): dx(:, c) = dx/dtheta_c, the derivative of x with
  // respect to column c of Trajectory::sensitivity_columns (rows as x; units
  // of x per unit of the column's quantity), and dx_exists[c] = 1 when that
  // derivative exists here, 0 when it does not (its entries are then 0 and
  // are not a value: Trajectory::sensitivity_losses says why).
  Eigen::MatrixXd dx;
  std::vector<char> dx_exists;
};

struct Event {
  double t = 0.0;
  EventType type = EventType::kContact;
  VectorXd state_before, state_after;
  IndexSet mode_after;
  VectorXd impulse;  // u^0 (size k); zero when no jump
  // Models with friction (empty otherwise): the tangential impulse of each
  // entry of mechanical.friction (N s, zero when no jump) and its mode after.
  VectorXd friction_impulse;
  std::vector<FrictionMode> friction_mode_after;
  // Models with 3-D friction (empty otherwise): the impulse along each
  // entry's second tangent (N s) and the cone facet after, as Sample's.
  VectorXd friction_impulse2;
  std::vector<impact::ConeFacet> friction_facet_after;
  // How the event was resolved when that is not plain: for an accumulation,
  // the contacts, the impacts seen and how the limit time and state were
  // extrapolated; for a kStick / kSlip event, each contact whose mode
  // changed ("'floor': slip+ -> stick"). Empty otherwise.
  std::string note;
  // Forward sensitivities (Options::sensitivity; empty otherwise): dt(c) =
  // dt_event/dtheta_c (s per unit of column c), dt_exists[c] as
  // Sample::dx_exists. An event at t = 0 has dt = 0 (its time is fixed).
  Eigen::RowVectorXd dt;
  std::vector<char> dt_exists;
};

// Where a forward sensitivity stops existing (docs/sensitivities.md): the
// time t (s), the constraint involved (its name, "" if none), why ("grazing
// contact", ...), and the columns of Trajectory::sensitivity_columns that it
// ends (from t on, dx_exists is 0 for them).
struct SensitivityLoss {
  double t = 0.0;
  std::string contact;
  std::string reason;
  std::vector<int> columns;
};

struct Options;

// A run ends kCompleted, kInvalidInput (nothing was integrated),
// kNumericalFailure, kEventLimit or kInterrupted, with Trajectory::message
// saying why ("" when completed) and Trajectory::t_end the time reached.
using RunStatus = lcsim::Status;

struct Trajectory : Outcome {
  std::string method;
  double t_end = 0.0;            // the time reached (the horizon when completed)
  std::vector<Sample> samples;   // at a jump two samples share t (before, after)
  std::vector<Event> events;     // the first Options::max_recorded_events of them
  long events_not_recorded = 0;  // events past that cap: counted, not kept
  // The impact law the run applied ("moreau-restitution", ...), as each
  // method applies it: the event-driven method its Options::impact,
  // Moreau–Jean the law inside its LCP, backward Euler the inelastic one.
  std::string impact_law;
  VectorXd final_state;
  double energy_initial = 0.0, energy_final = 0.0;  // mechanical models only
  double max_violation = 0.0;                       // most negative gap over the run (0 if none)
  long lcp_solves = 0;
  long steps = 0;  // time-stepping steps, or continuous phases
  // Warnings counted per kind ("pgs-not-converged", "restitution-ignored",
  // ...), in order of first appearance, each with its first time and message:
  // a run that warns a million times stays small and still says what and when.
  std::vector<WarningCount> warnings;
  double wall_time_s = 0.0;  // of the whole call, set by the checked entry (Integrator::run)
  // "" when the method integrates the model; else what it integrates instead
  // ("the URDF's nonlinear multibody (Bullet)"): its error against an exact
  // run of the model has that difference as a floor.
  std::string dynamics;
  // Forward sensitivities (Options::sensitivity; all empty otherwise): the
  // columns, "x0[i]" for each entry i of the initial state then each named
  // parameter as asked ("f[1]", "e[stop]"); dx/dtheta at t_end (state size x
  // columns) with its dx_exists; and where derivatives stopped existing.
  std::vector<std::string> sensitivity_columns;
  Eigen::MatrixXd dx_final;
  std::vector<char> dx_final_exists;
  std::vector<SensitivityLoss> sensitivity_losses;
  // Hands a recorded sample to opt.sample_sink when set (it is then not
  // kept), else appends it to samples.
  void record_sample(Sample s, const Options& opt);
  // Counts a warning of `kind` at time t (see lcsim::count_warning).
  void warn(std::string_view kind, double t, std::string message);
  long warning_count() const;                       // over all kinds
  long warning_count(std::string_view kind) const;  // of one kind (0 if none)
  // The first message of the first warning, or "" when there is none.
  std::string first_warning() const;
};

struct Options {
  // Horizon (s). Unset: the model's t_end (its scenario); a run with
  // neither is invalid input.
  std::optional<double> t_end;
  double dt_out = 0.0;  // output grid (s); 0 = events only (plus start and end)
  double h = 1e-3;      // time step of time-stepping methods (s)
  double theta = 0.5;   // Moreau–Jean theta
  // Impact law name (src/impact). The default is Moreau–Jean's law,
  // restitution inside the impact LCP: admissible by construction with several
  // closed contacts (a resting contact never rebounds), and the same as
  // "newton" (Newton's (1+e) per contact) with one contact or e = 0
  // (docs/impact-rules.md gives the evidence).
  std::string impact = "moreau-restitution";
  std::string lcp_solver = "pivot";
  // Event-driven: extra root tolerance in time (s) and the cap on events per unit
  // time that ends a run that would loop forever (Zeno without limit).
  // 0 = to machine precision (Brent's 2 ulp(t)), the default.
  double event_time_tol = 0.0;
  double max_events_per_unit_time = 1e6;
  long max_events = 1000000;
  // Events kept in Trajectory::events; later ones are counted in
  // Trajectory::events_not_recorded (with one warning), and their samples are
  // not recorded, so output stays bounded whatever the run does.
  long max_recorded_events = 100000;
  // Event-driven livelock guard: this many consecutive events that each
  // change the state by less than 1e-6 of its size, less than 1e-4 of the
  // fastest time scale apart, end the run with a failure naming the contacts
  // (a run that cannot make progress is never "completed").
  int livelock_events = 64;
  // Accumulation (right-Zeno, Remark 3.4.11), whatever the restitution:
  // when the impacts of a contact come this close, or their intervals shrink
  // geometrically with a tail (the time the remaining impacts take) below
  // accumulation_tail * max(1, t), the limit is taken and the run continues.
  double accumulation_dt = 1e-10;
  double accumulation_tail = 1e-6;
  bool record_samples = true;
  // A run whose recorded samples would take more than this many bytes (an
  // estimate from the horizon, dt_out or h, and the state and constraint
  // sizes) is refused before it starts (kInvalidInput), naming dt_out or h;
  // a sample_sink that streams to disk counts too.
  double max_output_bytes = 1e9;
  // When set, every recorded sample is passed here instead of being kept in
  // Trajectory::samples, in time order (a writer streams them to disk, so a
  // long run's output never has to fit in memory). Called on the thread that
  // runs the integrator; it must not throw.
  std::function<void(const Sample&)> sample_sink;
  // Progress of a long run: when set, called with the time reached, every
  // kProgressSteps steps of a time-stepping method and once per sampling step
  // of the event-driven method's event search (at least once per phase;
  // cheap enough for a wall-clock check in the callee).
  std::function<void(double t)> progress;
  static constexpr long kProgressSteps = 1024;
  // Time-stepping: run backward Euler even where the consistency guard
  // refuses it (some leading row index rho_i >= 3, §7.3, Example 7.3.3).
  bool force = false;
  // Moreau–Jean, how its linear algebra scales (src/sim/stepping/time_stepping.cpp):
  // models with more than `sparse_dofs_threshold` coordinates factor
  // W = M + h theta D + h^2 theta^2 K by sparse LDL'; smaller ones a dense
  // copy by LLT (the model's matrices are sparse either way). 0 forces the sparse path, a huge
  // value the dense one (the tests run both on one model).
  int sparse_dofs_threshold = 64;
  // Moreau–Jean: a step's LCP over at most this many active constraints is
  // solved by `lcp_solver` (pivoting, exact); a larger one by projected
  // Gauss–Seidel on the sparse Delassus matrix, warm-started from the
  // previous step's impulses.
  int pivot_max_active = 32;
  // Forward sensitivities of the exact method (docs/sensitivities.md): "x0"
  // (every entry of the initial state) and named parameters of a
  // frictionless mechanical model: "f[i]", "g[c]", "e[c]", "K[i][j]",
  // "D[i][j]", "M[i][j]" (i, j a coordinate's index or name, c a
  // constraint's; M[i][j] moves M(i,j) and M(j,i) together). Empty: none
  // (the run is unchanged). Refused (kInvalidInput) by methods other than
  // "event", for models with friction and impact laws whose map is not
  // differentiable at a fixed active set (check_sensitivity).
  std::vector<std::string> sensitivity;
};

// What a method reads from Options besides what every method reads (t_end,
// dt_out, record_samples, sample_sink, progress, max_output_bytes). An
// option a method does not read must stay at its default: Integrator::run
// refuses a changed one rather than ignore it silently.
struct OptionsUsed {
  bool h = false;               // the time step
  bool theta = false;           // Moreau–Jean's theta
  bool impact = false;          // the impact law
  bool lcp_solver = false;      // the LCP solver
  bool event_search = false;    // event_time_tol, max_events*, livelock_events, accumulation_*
  bool force = false;           // backward Euler's consistency override
  bool linear_algebra = false;  // sparse_dofs_threshold, pivot_max_active
  // Not options, what the method needs of the model: a mechanical one
  // (Moreau–Jean, Bullet), or an LCS small enough to be dense (the exact
  // method and backward Euler: mech::kMaxDenseLcsState).
  bool needs_mechanical = false;
  bool dense_lcs = false;
  // The method handles mechanical.friction (planar Coulomb, issue 17); a
  // method without it refuses a model with friction (check_run).
  bool friction = false;
  // The method computes Options::sensitivity (the exact method; the
  // derivative of the discrete map for backward Euler and Moreau–Jean).
  bool sensitivity = false;
  // The method also handles 3-D contacts (two tangents, a polyhedral cone:
  // mech::FrictionalContact::is_3d, issue 27); a method with friction but
  // not this refuses a model that has one (check_run).
  bool friction_3d = false;
  // The method factors W = M + h theta D + h^2 theta^2 K by Cholesky (it
  // reads one triangle), so it needs D and K symmetric: check_run refuses a
  // model whose D or K is not (mech::asymmetry) rather than symmetrise it.
  bool symmetric_dk = false;
  // The method evaluates a mechanical model's inputs (docs/inputs.md); a
  // method without it refuses a model that has some (check_run).
  bool inputs = false;
};

// "" when `opt.sensitivity` is empty or asks what the model and the method
// (`used`, its impact law opt.impact) can give; else one line naming the
// entry and why (src/sim/exact/sensitivity_names.cpp).
std::string check_sensitivity(const mech::Model& model, const Options& opt, std::string_view method,
                              const OptionsUsed& used);

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual std::string name() const = 0;
  // The options this method reads (see OptionsUsed).
  virtual OptionsUsed options_used() const = 0;
  // Checks the model, x0 and opt (check_run), then integrates. Invalid input
  // never reaches the method: it gives a trajectory with status kInvalidInput
  // and a message naming the field and the value. An unset opt.t_end is the
  // model's.
  Trajectory run(const mech::Model& model, const VectorXd& x0, const Options& opt) const;
  // What run() would refuse, without running: the refused trajectory
  // (kInvalidInput, the message) from check_run or from the method's own
  // refusal(), else nullopt. A sweep checks every row with it before it runs
  // any.
  std::optional<Trajectory> refuse(const mech::Model& model, const VectorXd& x0,
                                   const Options& opt) const;

 protected:
  // What this method cannot take beyond check_run (Bullet: a model it
  // cannot express): "" or one line naming the part of the model.
  virtual std::string refusal(const mech::Model& model) const {
    (void)model;
    return "";
  }
  // The method itself, on input that run() has checked.
  virtual Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                               const Options& opt) const = 0;

 private:
  // refuse() with `opt` resolved for the method (t_end filled in).
  std::optional<Trajectory> refuse_resolved(const mech::Model& model, const VectorXd& x0,
                                            Options& opt) const;
};
// The integrators by name: "event", "euler", "moreau-jean", and "bullet" in
// programs that link the component lcsim::bullet.
Registry<Integrator>& integrators();
// Throws std::invalid_argument naming the unknown method and the known ones.
std::unique_ptr<Integrator> make_integrator(std::string_view name);
std::vector<std::string> integrator_names();

// The one check of a run's input, used by Integrator::run (and so by the
// CLI and the Python module): the model (mech::check_model), x0 (size,
// finite), opt.t_end (finite > 0; run() fills it from the model), dt_out,
// the options `used` reads (h > 0 and at most 1e9 steps, theta in (0, 1],
// known impact law and LCP solver, event-search limits) and those it does
// not (each at its default), an admissible start (infeasible_start) and the
// output limit (max_output_bytes, from an estimate of the samples recorded).
// "" when usable, else one line naming the field and the value.
std::string check_run(const mech::Model& model, const VectorXd& x0, const Options& opt,
                      std::string_view method, const OptionsUsed& used);

// What every checked entry does before its method (Integrator::run, and
// bullet::simulate_bullet, which takes more than an Integrator): fills an
// unset opt.t_end with the model's, then check_run. A refused trajectory
// (status kInvalidInput, the message, nothing integrated) when the input is
// bad, else nullopt and `opt` is ready for the method.
std::optional<Trajectory> refuse_invalid_run(const mech::Model& model, const VectorXd& x0,
                                             Options& opt, std::string_view method,
                                             const OptionsUsed& used);

// `opt` with the options that `used` does not read reset to their defaults:
// one set of options applied to several methods (a sweep, a study) keeps for
// each what it reads.
Options keep_used(const Options& opt, const OptionsUsed& used);

// The run of `method` ("event" by default) from x0, or from the model's
// initial state when x0 is empty; unknown names and a missing initial state
// give status kInvalidInput like any other bad input.
Trajectory simulate(const mech::Model& model, const VectorXd& x0, const Options& opt = {},
                    std::string_view method = "event");
Trajectory simulate(const mech::Model& model, const Options& opt = {},
                    std::string_view method = "event");

// Empty if the initial state x0 (q then v) satisfies E q0 + g >= 0 up to
// rounding (a gap below -(1e-9 (|E| |q0| + |g|) + 1e-13) counts, the zero test
// of mode selection); else the message every integrator fails with, naming
// the first violated constraint and its gap (thesis §3.8: a mechanical state
// must be admissible). LCS models and wrongly sized x0 give "".
std::string infeasible_start(const mech::Model& model, const VectorXd& x0);

// What every time-stepping method shares (Moreau–Jean, backward Euler, and
// the Bullet scene in src/bullet):
// - the step grid: n steps of h, the last shortened so that t_n = t_end
//   (h "divides" t_end when t_end / h is an integer to 1e-9 relative);
// - the output sampler on the grid dt_out (every step when dt_out = 0);
struct StepGrid {
  long n = 0;
  double h = 0.0;
  double h_last = 0.0;
  static StepGrid of(double t_end, double h);
};
class OutputSampler {
 public:
  explicit OutputSampler(double dt_out) : dt_out_(dt_out), next_(dt_out) {}
  // True if the state at step time t (steps of h) is to be recorded.
  bool want(double t, double h, bool last);

 private:
  double dt_out_;
  double next_;
};

// Divergence (src/sim/divergence.cpp): a run is never "completed" once its
// numbers have left the model's scales. Every time-stepping method (and
// Bullet's scenes) passes each step's state here and ends with
// kNumericalFailure and the message on the first "" it does not get back;
// Integrator::run checks every method's final state and worst gap the same
// way. Diverged means: a non-finite entry of the state (named); the model's
// total energy risen above its start by more than kAmplitude^2 times the
// energy scale of the model and the start (the model has no input but a
// moving belt, which the scale counts); a gap below -kAmplitude times the
// length scale the energy scale allows over the horizon (far past any
// stop). LCS models (no energy): non-finite entries only.
class DivergenceGuard {
 public:
  static constexpr double kAmplitude =
      1e3;                             // three orders of magnitude in amplitude, six in energy
  static constexpr long kStride = 16;  // steps between energy and gap tests
  // x0: the start (q then v, or the LCS state); t_end: the horizon (s).
  DivergenceGuard(const mech::Model& model, const VectorXd& x0, double t_end);
  // The state x (q then v; extra trailing entries are tested for finiteness
  // only) at time t: "" when sane, else "diverged at t = ...: <what>". The
  // finiteness test runs on every call, the energy and gap tests every
  // kStride calls and whenever `full`.
  std::string check(double t, const VectorXd& x, bool full = false);
  // The same for a mechanical state given as q and v.
  std::string check(double t, Eigen::Ref<const VectorXd> q, Eigen::Ref<const VectorXd> v,
                    bool full = false);
  // The run's most negative gap (Trajectory::max_violation): "" or the message.
  std::string check_worst_gap(double worst_gap) const;
  double energy_scale() const { return energy_scale_; }  // J (0 for LCS models)
  double length_scale() const { return length_scale_; }  // model units of the gaps

 private:
  std::string violation_message(const std::string& where, double gap) const;
  std::string non_finite(double t, Eigen::Ref<const VectorXd> x, Eigen::Index offset) const;
  const mech::Model* model_;
  bool mechanical_ = false;
  double e0_ = 0.0, energy_scale_ = 0.0, length_scale_ = 0.0;
  long calls_ = 0;
};

// What Integrator::run does after every method (and bullet::simulate_bullet
// after its scenes): a completed run whose final state or worst gap the
// guard finds diverged becomes kNumericalFailure, "<method>: <why>".
void check_diverged(const mech::Model& model, const VectorXd& x0, Trajectory& tr);

// A number with six significant digits, as the integrators' messages print it
// ("0.001", "3.16228e+04"): lcsim::short_number (core/format.hpp).
using lcsim::short_number;

// Event-driven integration (Algorithm 3.7.1): exact matrix-exponential phases,
// events as roots of Bohl functions, re-initialisation by the impact law
// (mechanical models) or by the LDCP and P_I (general LCS).
Trajectory simulate_event_driven(const mech::Model& model, const VectorXd& x0, const Options& opt);

}  // namespace lcsim::sim
