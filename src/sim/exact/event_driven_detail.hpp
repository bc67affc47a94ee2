// Private to src/sim: the event-driven method's types, shared by its files.
//   event_driven.cpp      the main loop (EventDriven::run: its stages, phase
//                         by phase and event by event) and the entry point
//   monitors.cpp          a phase's monitors: how each starts, and their
//                         first root on a sampling interval
//   brent.hpp             roots of the monitored Bohl functions (Brent's method)
//   phase.cpp             a phase: closed loop of a mode, balancing, spectral
//                         bound, exponentials, the monitors (EventDriven::make_phase)
//   reinitialisation.cpp  what happens at an event: impact law and mode
//                         selection (mechanical), LDCP jumps (general LCS)
//   accumulation.cpp      accumulations of impacts and their limit
//   livelock.cpp          the guard against events that make no progress
//   sampler.cpp           output samples on the dt_out grid (GridSampler)
//   friction_phase.cpp    a phase with closed frictional contacts: stick rows
//                         and slip columns in the feedback, the cone and
//                         sliding monitors (issue 17)
//   friction_modes.cpp    stick / slip selection at an event (the
//                         acceleration-level friction LCP, thesis (4.44))
//   cone_phase.cpp        3-D contacts on a polyhedral cone (issue 27): the
//                         rows and columns of stick, edge and face slip,
//                         their monitors and forces
//   cone_modes.cpp        mode selection at an event for models with such
//                         contacts (candidates checked on the phase's monitors)
//   cone_boundary.cpp     the same where stick forces reach their polygons
//                         together (the modes that keep the forces there)
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <functional>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace lcsim::sim::detail {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;

constexpr double kEps = std::numeric_limits<double>::epsilon();
constexpr double kSqrtEps = 0x1p-26;  // sqrt(kEps), exactly

// The modes of a 3-D contact with d >= 2 edge pairs (cone_phase.cpp), kept in
// the phase's FrictionMode vector past the public values: slip with the
// force on edge i (0 <= i < 2d: the velocity within pi/(2d) of edge
// direction i, the force mu u_N against it) or on face j (the velocity along
// the bisector of edges j and j+1, the force on the opposite face), coded
// 16 + 2i and 16 + 2j + 1. Samples and events carry kSlip (FrictionMode's
// public values); event notes name the facet (friction_mode_name).
// 16 + 4d <= 127 bounds d.
constexpr int kConeCodeBase = 16;
constexpr int kMaxEventConeEdges = (127 - kConeCodeBase) / 4;  // 27
inline FrictionMode cone_edge(int i) { return static_cast<FrictionMode>(kConeCodeBase + 2 * i); }
inline FrictionMode cone_face(int j) {
  return static_cast<FrictionMode>(kConeCodeBase + 2 * j + 1);
}
inline bool cone_slip(FrictionMode m) { return static_cast<int>(m) >= kConeCodeBase; }
inline bool cone_on_face(FrictionMode m) { return (static_cast<int>(m) - kConeCodeBase) % 2 == 1; }
inline int cone_index(FrictionMode m) { return (static_cast<int>(m) - kConeCodeBase) / 2; }
// A cone mode's facet as the impact laws and Moreau–Jean name it: the facet
// holding the friction force (opposite the velocity's, i + d mod 2d) for a
// contact with d edge pairs; edge -1 for a mode that is not a cone slip.
impact::ConeFacet force_facet(FrictionMode m, int d);
// "slip-edge-i", "slip-face-j" (force_facet's) for a cone mode, else to_string(m).
std::string friction_mode_name(FrictionMode m, int d);

// An upper bound on the spectral radius, ||B^16||^(1/16) ||A|| with
// B = A/||A|| (Gelfand's formula; 4 squarings, no eigen-decomposition).
double spectral_radius_bound(const MatrixXd& A);
// Whether A's nonzero pattern (an edge i -> j where A(i, j) != 0, NaN
// included) has no path of `len` edges: then every product of `len`
// factors A, formed in any order, is exactly zero (phase.cpp).
bool no_path_of(const MatrixXd& A, int len);
// The smallest k such that A's nonzero pattern has no path of k edges (then
// A^k = 0 exactly, and e^{A tau} is its finite series), or 0 when the
// pattern has a cycle; at most n. No products (phase.cpp).
int nilpotency_index(const MatrixXd& A);

struct Monitor {
  RowVectorXd w;            // phi(t) = w x(t)
  RowVectorXd wA;           // phi'(t) = w Acl x(t)
  double scale = 0.0;       // |w| |x| scale for tolerances
  int constraint = -1;      // which constraint
  bool multiplier = false;  // true: u_i of an active constraint; false: free output y_i
  int friction = -1;        // entry of mechanical.friction for a cone or sliding monitor
};

// A free pair of a mode (free_pairs.cpp): a pair r of the mode whose
// multiplier u_r moves neither the state (B_r = 0) nor any held output
// (D_{S r} = 0 on the mode and its undetermined rows S) and whose own
// output vanishes identically: u_r is not unique (an ideal bridge's load
// floating while its four diodes block: D1's reverse voltage), only bounded
// by the outputs it moves. Its admissible values at x are the z with
// z >= 0, z >= l x (l in lower) and z <= h x (h in upper); the phase's
// monitors are the differences h - l (Fourier–Motzkin), and a sample's u_r
// is the least admissible value, max(0, l x) (unbalanced coordinates).
struct FreePair {
  int column = -1;
  std::vector<RowVectorXd> lower, upper;
};

struct Phase {
  lcs::IndexSet mode;
  MatrixXd Acl;                // closed-loop matrix
  MatrixXd F;                  // u_I = F x (|I| x n); a free pair's row is zero
  std::vector<FreePair> free;  // general LCS only (free_pairs.cpp)
  // Models with friction: the mode of each entry of mechanical.friction and
  // its tangential multiplier u_T = Ft x (n_F x n); both empty otherwise.
  std::vector<FrictionMode> friction;
  MatrixXd Ft;
  // Models with 3-D contacts on a cone (d >= 2): the friction force along
  // each contact's second tangent, u_T2 = Ft2 x (n_F x n); empty otherwise.
  MatrixXd Ft2;
  // Balanced coordinates z = x ./ D with Ab = D^{-1} Acl D (powers of 2):
  // a stiff spring k makes Acl's entries span k and 1 while its frequencies
  // are sqrt(k); exponentials of the balanced matrix keep the relative
  // accuracy that the unbalanced one loses (gap errors of 1e-8 at k = 1e9).
  VectorXd D;
  MatrixXd Ab;
  std::vector<Monitor> monitors;  // w, wA in balanced coordinates
  double Ab_norm1 = 0.0;          // ||Ab||_1
  // Above kDenseExpMax states, Ab by rows when at most a tenth of it is
  // non-zero (a chain's closed loop is banded): products with vectors then
  // cost O(nnz), not O(n^2).
  Eigen::SparseMatrix<double, Eigen::RowMajor> Ab_sparse;
  bool use_sparse = false;
  VectorXd times(const VectorXd& x) const {
    return use_sparse ? VectorXd(Ab_sparse * x) : VectorXd(Ab * x);
  }
  RowVectorXd row_times(const RowVectorXd& w) const {
    return use_sparse ? RowVectorXd(w * Ab_sparse) : RowVectorXd(w * Ab);
  }
  double rho = 0.0;  // spectral_radius_bound(Ab)
  // nilpotency_index(Ab) when Ab is finite, else 0: with nil = k > 0
  // (a body without springs: x' = v, v' = const, k = 3), e^{Ab tau} is the
  // finite series sum_{j<k} (Ab tau)^j / j!, exactly (no truncation: each
  // entry of (Ab tau)^k is a sum of products with a factor exactly zero).
  int nil = 0;

  // Up to this many states e^{Ab tau} is formed (Padé with scaling and
  // squaring, O(n^3)) and, on a sampling grid, reused; above it only its
  // action on a vector is computed (O(n^2) per term): a chain of 100 carts
  // (n = 201) spent 70% of its run in dense exponentials.
  static constexpr int kDenseExpMax = 64;
  bool dense_exp() const { return Ab.rows() <= kDenseExpMax; }

  // e^{Ab tau} z in balanced coordinates. Above kDenseExpMax: the Taylor
  // series of the action in s = ceil(||Ab tau||_1) substeps, so each substep
  // has ||Ab tau/s||_1 <= 1 and its series, truncated once two consecutive
  // terms are below eps/4 of the partial sum, converges like 1/k! (at most
  // ~20 terms); the error is that of the dense exponential's (both are
  // backward stable for ||Ab tau/s|| <= 1; Al-Mohy & Higham 2011 choose s
  // and the degree more finely).
  // With nil > 0, at any size: the finite series by nil - 1 products with
  // Ab (exact up to rounding, which is below Pade's with its scaling and
  // squaring).
  VectorXd expv(double tau, const VectorXd& z) const;  // phase.cpp
  // e^{Ab tau} formed: the finite series when nil > 0, else Pade with
  // scaling and squaring (Eigen's MatrixExponential). The one way the
  // exact method forms a phase's exponential (phase.cpp).
  MatrixXd expm(double tau) const;
  VectorXd exp_apply(double tau, const VectorXd& x) const {
    return D.cwiseProduct(expv(tau, x.cwiseQuotient(D)));
  }
};

// The step exponential e^{Ab dt} of a mode's balanced closed loop, kept
// per mode (EventDriven::step_cache_): valid for the Ab and dt it was made
// for. Above Phase::kDenseExpMax it is formed only once the actions
// e^{Ab dt} z spent on this mode's samples have cost as much as forming it
// (`action_flops`, an estimate), and never when a matrix-vector product with
// it costs more than the action (a sparse chain's closed loop).
struct StepExp {
  MatrixXd Ab;
  double dt = 0.0;
  MatrixXd E;  // empty until formed
  double action_flops = 0.0;
};

// Output samples of one phase on the dt_out grid, in increasing time: the
// first from the phase start by e^{Ab (t - t0)}, each later one from the one
// before by the step exponential e^{Ab dt} (one matrix-vector product), so a
// sample's cost does not grow with the phase's length (issue 24: 15 ms a
// sample on Talos, each evaluated from the phase start). Grid times k dt
// differ from the previous one by dt up to an ulp of t, the time resolution
// of the states evaluated from the start too. Event and end states are still
// evaluated from the phase start (state_at in event_driven.cpp).
class GridSampler {
 public:
  // fetch: the mode's StepExp, asked for at the phase's second sample (a
  // phase sampled once, or not at all, never copies Ab into the cache).
  GridSampler(const Phase& ph, double t0, const VectorXd& z0, double dt,
              std::function<StepExp&()> fetch)
      : ph_(ph), t0_(t0), z0_(z0), dt_(dt), fetch_(std::move(fetch)) {}
  // The state (unbalanced, augmented) at grid time t: stepped from the last
  // sample when t is the grid point after it, else from the phase start.
  VectorXd at(double t);

 private:
  VectorXd step(const VectorXd& z);
  const Phase& ph_;
  double t0_;
  const VectorXd& z0_;
  double dt_;
  std::function<StepExp&()> fetch_;
  StepExp* step_ = nullptr;
  VectorXd z_;      // the last sample (balanced); empty before the first
  double t_ = 0.0;  // its time
};

// An impact of an event-driven run: its time and the resolution of that
// time (the gap's rounding over the approach rate, plus a few ulp of t).
struct ImpactTime {
  double t = 0.0;
  double noise = 0.0;
};

// A geometric tail found in a sequence of impacts (accumulation.cpp).
struct GeometricTail {
  double t_star = -1.0;  // the limit; < 0: none
  double ratio = 0.0;    // per period; 0 when the limit is taken without one
  int period = 1;        // impacts per period
  double since = 0.0;    // the first impact of the evidence
};

// kOk when computed; the message says why not.
struct EventResult : OutcomeStartingAs<Status::kNumericalFailure> {
  VectorXd x_plus;
  lcs::IndexSet mode;
  std::vector<FrictionMode> friction;  // models with friction: the selected stick / slip modes
  VectorXd impulse;                    // sum of the impulses applied (size k)
  // Models with friction: the sum of the tangential impulses applied, per
  // entry of mechanical.friction (empty otherwise).
  VectorXd friction_impulse;
  // Models with 3-D friction (has_cone_): the same along each entry's second
  // tangent (empty otherwise; Event::friction_impulse2).
  VectorXd friction_impulse2;
  bool jumped = false;
  bool accumulation = false;
  double t_star = 0.0;  // extrapolated accumulation time (accumulation only)
  std::string note;     // how an accumulation's limit was taken (Event::note)
  // An accumulation's limit (sensitivities only): the contacts projected
  // onto E_J q + g_J = 0, E_J v = 0, after the first limit_round rounds,
  // from the state limit_x (take_accumulation_limit).
  lcs::IndexSet limit_rows;
  size_t limit_round = 0;
  VectorXd limit_x;
  long lcp_solves = 0;
  std::vector<WarningCount> warnings;  // counted into Trajectory::warnings
  // Forward sensitivities only (sensitivity.cpp): each round of the impact
  // law, its closed contacts, velocity before, impulses and restitution,
  // and with friction each contact's outcome (stick, slip+, slip-).
  struct ImpactRound {
    lcs::IndexSet closed;
    VectorXd v_before, impulse, restitution;
    std::vector<impact::ContactOutcome> outcome;
  };
  std::vector<ImpactRound> rounds;
  // A general LCS's jumps (sensitivities only): each jump's mode I (x+ =
  // P_I x, thesis §3.4.2) and the state before it.
  struct LcsJump {
    lcs::IndexSet mode;
    VectorXd x_before;
  };
  std::vector<LcsJump> lcs_jumps;
};

// Ends a run that cannot make progress: `limit` consecutive events, each
// less than 1e-4 of the fastest time scale (1/rho) after the one before and
// each changing the state by less than 1e-6 of its size, are a livelock, not
// physics: modes that alternate with impulses at the level of the gaps'
// rounding (on the NAO legs before accumulations were taken: every 2e-9 s,
// jumps of 8e-8 in a state of size 1.5, for ever). A real accumulation has
// geometrically shrinking intervals and is taken as a limit long before.
constexpr double kIdleJump = 1e-6;

class LivelockGuard {
 public:
  // friction_contacts: the row of E of each entry of mechanical.friction
  // (a stick / slip change there involves that contact).
  LivelockGuard(int limit, double rho, std::vector<std::string> names,
                std::vector<int> friction_contacts = {})
      : limit_(limit),
        rho_(rho),
        names_(std::move(names)),
        friction_contacts_(std::move(friction_contacts)) {}
  // "" while the run makes progress, else the failure message. `trigger`:
  // the constraint whose monitor ended the phase (-1 if none), named with
  // the contacts whose modes or impulses changed.
  std::string after_event(double t, const VectorXd& x_minus, const VectorXd& x_plus,
                          const lcs::IndexSet& old_mode, const EventResult& ev,
                          const std::vector<FrictionMode>& old_friction = {}, int trigger = -1);

 private:
  int limit_;
  double rho_;
  std::vector<std::string> names_;
  std::vector<int> friction_contacts_;
  int streak_ = 0;
  double since_ = 0.0, last_t_ = -std::numeric_limits<double>::infinity();
  std::set<int> involved_;
};

class IntervalSeries;  // monitors.cpp
class Sensitivity;     // sensitivity.hpp

class EventDriven {
 public:
  // `model` fits the dense LCS (Integrator::run checks).
  EventDriven(const mech::Model& model, const Options& opt)
      : model_(model), opt_(opt), sys_(model.as_lcs()) {
    n_ = sys_.n();
    k_ = sys_.k();
    if (model.is_mechanical()) {
      N_ = model.mechanical->dofs();
      restitution_ = model.mechanical->restitution;
    }
    solver_ = lcp::make_solver(opt.lcp_solver);
    impact_ = impact::make_impact_law(opt.impact);
    impact_times_.assign(k_, {});
    ldcp_.solver = solver_.get();
    ldcp_data_ = lcs::ldcp_data(sys_);
    rho_A_ = spectral_radius_bound(sys_.A);
    ldcp_.data = &ldcp_data_;
    if (model.is_mechanical() && model.mechanical->has_friction()) init_friction();
    if (!opt.sensitivity.empty()) init_sensitivity();
  }

  Trajectory run(const VectorXd& x0_user);

 private:
  VectorXd augment(const VectorXd& x) const {
    if (!model_.is_mechanical()) return x;
    VectorXd xa(n_);
    if (model_.mechanical->has_inputs())  // the inputs' exosystems (schedule.cpp)
      xa << x, 1.0, mech::exosystem_states(*model_.mechanical, 0.0);
    else
      xa << x, 1.0;
    return xa;
  }
  VectorXd user(const VectorXd& xa) const {
    return model_.is_mechanical() ? VectorXd(xa.head(2 * N_)) : xa;
  }
  // The resolution of an event time t: a few ulp of t, plus the root
  // tolerance the user allows (Options::event_time_tol). A monitor crossing
  // zero at rate r is located within r times this of zero, on either side.
  double time_resolution(double t) const {
    return 16.0 * kEps * std::max(1.0, std::abs(t)) + opt_.event_time_tol;
  }
  bool is_zero(double value, double scale) const {
    return std::abs(value) <= mech::zero_tolerance(scale, ldcp_);
  }

  // `friction`: the mode of each entry of mechanical.friction (empty for
  // frictionless models). The phase returned is the memo's (phase_memo_),
  // or on error the failed one: valid until the next call.
  const Phase& make_phase(const lcs::IndexSet& mode, const std::vector<FrictionMode>& friction,
                          const lcs::IndexSet& undetermined, const VectorXd& xa,
                          std::string& err) const;
  Phase build_phase(const lcs::IndexSet& mode, const std::vector<FrictionMode>& friction,
                    const lcs::IndexSet& undetermined, const VectorXd& xa, std::string& err) const;
  // Friction (friction_phase.cpp, friction_modes.cpp).
  void init_friction();
  bool friction_feedback(Phase& ph, const VectorXd& xa, std::string& err) const;
  void indeterminate_split(const Phase& ph, const MatrixXd& S, const std::vector<int>& stick,
                           const VectorXd& xa, MatrixXd& F_all) const;
  void add_friction_monitors(Phase& ph) const;
  std::string painleve_phase(const Phase& ph, const MatrixXd& S, int n_stick) const;
  std::string select_friction(double t, const lcs::IndexSet& undetermined, VectorXd& xa,
                              EventResult& out);
  // The normal mode and friction modes at a regular state after the LDCP's
  // selection `sel` (friction_modes.cpp): sel.mode, or sel.mode with its
  // undetermined constraints held too where friction presses them shut.
  // "" or the failure message; undetermined gets the K the phase keeps.
  // held: the ending phase's mode (I ∪ K is tried first when it held them).
  std::string select_friction_releasing(double t, const lcs::ModeSelection& sel, VectorXd& xa,
                                        EventResult& out, lcs::IndexSet& undetermined);
  bool spans_row(const lcs::IndexSet& mode, int j) const;
  std::string select_friction_and_normals(double t, const lcs::ModeSelection& sel,
                                          const lcs::IndexSet& held, VectorXd& xa, EventResult& out,
                                          lcs::IndexSet& undetermined);
  // True when some constraint of `which` (outside ph.mode) has its gap leave
  // zero downwards at the phase start (its first nonzero derivative < 0).
  bool presses_shut(const Phase& ph, const lcs::IndexSet& which, const VectorXd& xa,
                    double t) const;
  // The constraints of ph.mode whose normal force leaves zero downwards at
  // the phase start (friction_modes.cpp).
  lcs::IndexSet lifting_normals(const Phase& ph, const VectorXd& xa, double t) const;
  // I ∪ K (then I) less one constraint of `lifting`, when that phase starts
  // consistently (friction_modes.cpp): true and out, undetermined set, else
  // false.
  bool release_normal(double t, const lcs::ModeSelection& sel, const lcs::IndexSet& lifting,
                      VectorXd& xa, EventResult& out, lcs::IndexSet& undetermined);
  // True when every monitor of `ph` (normals and friction) starts positive or
  // leaves zero upwards.
  bool all_consistent(const Phase& ph, const VectorXd& xa, double t) const;
  // The normal rows of ph.mode are dependent (rank of E_I below |I|).
  bool redundant_normals(const Phase& ph) const;
  std::vector<int> zero_sliding(const lcs::IndexSet& mode, const VectorXd& xa,
                                std::vector<FrictionMode>& fm) const;
  void project_sliding(const lcs::IndexSet& mode, const std::vector<int>& zero, VectorXd& xa) const;
  std::vector<FrictionMode> friction_lcp_modes(const lcs::IndexSet& mode,
                                               const std::vector<FrictionMode>& fixed,
                                               const std::vector<int>& zero, const VectorXd& xa,
                                               long& solves) const;
  bool consistent(const Phase& ph, const VectorXd& xa, double t) const;
  // 3-D contacts on a polyhedral cone (cone_phase.cpp, cone_modes.cpp).
  bool is_cone(size_t f) const { return f < cone_d_.size() && cone_d_[f] >= 2; }
  // The rows entry f holds at acceleration level in `mode` (also force
  // columns) and what its friction adds to its normal's force column
  // (empty when nothing).
  void cone_rows(size_t f, FrictionMode mode, std::vector<RowVectorXd>& held,
                 RowVectorXd& column) const;
  // Ft, Ft2 rows of entry f from its normal's row uN and its held rows'
  // multipliers (the rows of F_all from `first`).
  void cone_forces(Phase& ph, size_t f, const RowVectorXd& uN, const MatrixXd& F_all,
                   Eigen::Index first) const;
  void add_cone_monitors(Phase& ph, size_t f) const;
  // A singular H M^-1 G' with slip (several contacts of one body holding the
  // same tangent rows): true, with the minimum-norm forces in F_all, when
  // S F = -HAv is consistent and every force in S's null space Z acts on
  // nothing (M^-1 G' Z = 0), so the motion is determined though the split of
  // the forces between the contacts is not.
  static bool resultant_determined(const MatrixXd& S, const MatrixXd& MinvGt, const MatrixXd& HAv,
                                   MatrixXd& F_all);
  // The sliding velocity (along t, t2) of entry f as rows on the augmented state.
  std::pair<RowVectorXd, RowVectorXd> cone_sliding_rows(size_t f) const;
  std::string select_cone_friction(double t, const lcs::IndexSet& undetermined, VectorXd& xa,
                                   EventResult& out);
  // The modes each entry of mechanical.friction may take at state xa, in
  // the order tried, and the velocity rows that vanish (rows over v and
  // their values: zero, or the belt's velocity).
  std::vector<std::vector<FrictionMode>> cone_candidates(const lcs::IndexSet& mode,
                                                         const VectorXd& xa,
                                                         std::vector<RowVectorXd>& zero_rows,
                                                         std::vector<double>& zero_target) const;
  void project_rows(const lcs::IndexSet& mode, const std::vector<RowVectorXd>& rows,
                    const std::vector<double>& target, VectorXd& xa) const;
  // Stick forces reaching their polygons at an event (cone_boundary.cpp):
  // fm (the first candidate, whose phase failed) with the contacts whose
  // friction monitors start at zero given the modes that keep their forces
  // where they are; found when exactly one combination of those is
  // consistent; a message when several are; "" and not found otherwise.
  std::string select_cone_boundary(double t, const lcs::IndexSet& mode,
                                   const lcs::IndexSet& undetermined,
                                   const std::vector<std::vector<FrictionMode>>& cand,
                                   const VectorXd& xa, std::vector<FrictionMode>& fm, bool& found);
  // The acceleration-level cone LCP's guess moved to the front of each 3-D
  // contact's candidates (cone_guess.cpp).
  void cone_lcp_guess(const lcs::IndexSet& mode, const VectorXd& xa,
                      std::vector<std::vector<FrictionMode>>& cand, long& solves) const;
  // held: the constraints the ending phase kept closed (empty at the start).
  EventResult process_event(double t, const VectorXd& xa, const lcs::IndexSet& held = {});
  // The accumulation that an impact of contact r at t (time resolution
  // `noise`) ends, if any: r's own impacts, or every contact's.
  GeometricTail accumulation_time(int r, double t, double noise) const;
  // Records the impacts of `contacts` (impulse > 0) at t.
  void record_impacts(const std::vector<int>& contacts, const VectorXd& impulse, double t,
                      const VectorXd& noise);
  void project_onto(const std::vector<int>& rows, VectorXd& xa, bool positions) const;
  EventResult process_mechanical(double t, const VectorXd& xa, const lcs::IndexSet& held);
  // What the contacts show at an event state: one round of
  // process_mechanical (reinitialisation.cpp).
  struct ContactScan {
    VectorXd gap, gap_scale, rate;  // E q + g, the scale of its terms, E v
    impact::ImpactInput in;         // q, v and the closed contacts (zero gap)
    std::vector<int> resting;       // closed, with a zero rate
    bool approaching = false;       // a closed contact with a negative rate
    int accumulating = -1;          // a contact whose impacts accumulate at tail.t_star
    GeometricTail tail;
    std::string violation;  // a gap below zero beyond rounding: the message
  };
  // time_noise: the resolution of each approaching contact's impact time.
  ContactScan scan_contacts(double t, const VectorXd& xa, const lcs::IndexSet& held,
                            bool limit_taken, VectorXd& time_noise) const;
  bool impact_round(double t, ContactScan& scan, bool limit_taken, const VectorXd& time_noise,
                    VectorXd& xa, EventResult& out);
  bool select_regular_mode(double t, const ContactScan& scan, const lcs::IndexSet& held,
                           VectorXd& xa, EventResult& out);
  std::string take_accumulation_limit(int r, double t, const GeometricTail& tail,
                                      const VectorXd& gap, const VectorXd& gap_scale,
                                      const VectorXd& rate, VectorXd& xa,
                                      lcs::IndexSet& joined) const;
  EventResult process_lcs(double t, const VectorXd& xa);
  // Free pairs (free_pairs.cpp). The pairs of `mode` that are free (FreePair)
  // with `undetermined` held too; empty for mechanical models.
  lcs::IndexSet free_columns(const lcs::IndexSet& mode, const lcs::IndexSet& undetermined) const;
  // Column c could be a free pair of a mode holding `held` (c among them):
  // B_c = 0, D_{held c} = 0, and some output outside `held` moves with u_c.
  bool free_shape(int c, const lcs::IndexSet& held) const;
  // The phase's feedback and monitors when ph.mode has free pairs; false
  // with err set when refused.
  bool free_feedback(Phase& ph, const lcs::IndexSet& free, std::string& err) const;
  bool add_free_monitors(Phase& ph, const lcs::IndexSet& free, const lcs::IndexSet& undetermined,
                         std::string& err) const;
  // Moves into `mode` the pairs that are free there (undetermined ones, and
  // inactive ones whose output vanishes identically): one phase per motion.
  void normalise_free(lcs::IndexSet& mode, lcs::IndexSet& undetermined) const;
  // Mode selection when the LDCP's levels fail (a singular script M_II):
  // every mode whose phase starts consistently at xa; true with out.mode
  // set when one motion continues the state, else false with why.
  bool select_by_enumeration(double t, const VectorXd& xa, EventResult& out, std::string& why);
  // " (active: D1; undecided: D2, D3)": a failed selection's sets by the
  // pairs' names (a circuit's diodes), "" when both are empty.
  std::string pair_sets(const lcs::IndexSet& active, const lcs::IndexSet& undecided) const;
  std::string pair_list(const lcs::IndexSet& s) const;  // "D1, D2" ("none" when empty)
  // y_r vanishes identically on the phase from xa, for every held pair r.
  bool held_outputs_vanish(const Phase& ph, const VectorXd& xa) const;
  void record(Trajectory& tr, double t, const VectorXd& xa, const Phase& ph) const;
  // A phase's start, per monitor: the noise level of its value, the order m0
  // of its first nonzero derivative (0 = the value; -1 = none up to n) and
  // that derivative d0; and the first sampling step.
  struct MonitorStart {
    std::vector<double> noise;
    std::vector<int> m0;
    std::vector<double> d0;
    // A value above the noise band but within mode selection's zero test
    // (LdcpOptions::tol_rel of its terms) whose next nonzero derivative is
    // positive: the LDCP took it for zero and the monitor opens from it.
    std::vector<char> small_opening;
    double h_first = 0.0;
  };
  // `monitors`: these monitors (over phase's state) in place of phase's own;
  // each monitor's start is its own, whatever the others are.
  MonitorStart monitor_start(const Phase& phase, const VectorXd& xstart, double t, double h_max,
                             const std::vector<Monitor>* monitors = nullptr) const;
  // Noise level of each monitor at the phase start (monitors.cpp).
  std::vector<double> monitor_noise(const std::vector<Monitor>& monitors, const VectorXd& xstart,
                                    double t) const;
  // st.m0, st.d0 and st.h_first from st.noise.
  void first_derivatives(const Phase& phase, const std::vector<Monitor>& monitors,
                         const VectorXd& xstart, MonitorStart& st) const;

  // One run's state between the stages of run() (event_driven.cpp).
  struct RunState {
    Trajectory tr;
    double t = 0.0;
    VectorXd xa;  // the augmented state at t
    Phase phase;  // the phase from t
    // The Zeno guard: events since window_start (at most a unit of time ago).
    long events_in_window = 0;
    double window_start = 0.0;
  };
  // The march over one phase from its start t0 (event_driven.cpp,
  // monitors.cpp): the monitors' start and arming, the output grid, and the
  // first event found. It refers to itself (the sampler to xstart): built in
  // place, never copied.
  struct PhaseMarch {
    PhaseMarch(const Phase& ph, double t, const VectorXd& xa, double dt_out,
               std::function<StepExp&()> fetch)
        : phase(ph),
          t0(t),
          xstart(xa.cwiseQuotient(ph.D)),
          // Output grid k dt_out (not a running sum, whose rounding accumulates).
          k_out(dt_out > 0 ? std::floor(t / dt_out + 1e-9) + 1 : 0.0),
          next_out(dt_out > 0 ? k_out * dt_out : std::numeric_limits<double>::infinity()),
          dt_out_(dt_out),
          sampler(ph, t, xstart, dt_out, std::move(fetch)) {}
    PhaseMarch(const PhaseMarch&) = delete;
    PhaseMarch& operator=(const PhaseMarch&) = delete;
    void advance_out() { next_out = ++k_out * dt_out_; }
    // The state (augmented, unbalanced) at tt, from the phase start.
    VectorXd state_at(double tt) const { return phase.D.cwiseProduct(phase.expv(tt - t0, xstart)); }
    const Phase& phase;
    double t0;
    VectorXd xstart;  // balanced
    MonitorStart start;
    std::vector<char> armed;
    std::vector<char> opening;  // armed by a positive derivative
    std::vector<double> offset;
    double k_out, next_out;
    double dt_out_;
    GridSampler sampler;
    double t_event = std::numeric_limits<double>::infinity();
    int trigger = -1;          // the constraint whose monitor gave t_event
    int trigger_monitor = -1;  // that monitor's index in phase.monitors
  };
  void arm_monitors(PhaseMarch& pm) const;
  double monitor_root(PhaseMarch& pm, size_t j, double ta, double tb, const VectorXd& xa_a,
                      const VectorXd& xa_b, IntervalSeries& series) const;
  void first_root(PhaseMarch& pm, double ta, double tb, const VectorXd& xa_a,
                  const VectorXd& xa_b) const;
  // The stages of run() (event_driven.cpp).
  bool start_run(RunState& r, const VectorXd& x0_user);
  void record_initial_jump(RunState& r, const EventResult& ev) const;
  bool next_phase(RunState& r, LivelockGuard& livelock);
  // t_stop: the horizon or the next scheduled event, whichever is first.
  void march_phase(PhaseMarch& pm, double h_first, double h_max, double t_stop,
                   Trajectory& tr) const;
  // Scheduled events (schedule.cpp): the first breakpoint of an input after
  // t (+inf for a model without inputs), and the event there.
  double next_scheduled(double t) const;
  bool take_scheduled(RunState& r, PhaseMarch& pm, double t_b);
  // A switched model (mech::Model::configurations): at a switch time t_b
  // (the first after t0), the configuration after it replaces sys_ and the
  // caches built on it; its note ("S1 on"), or "" when t_b is no switch time.
  std::string swap_configuration(double t0, double t_b);
  int config_ = 0;  // the configuration holding (index into model_.configurations)
  // Per configuration, the caches built on its matrices while it does not
  // hold (a switched circuit alternates between a few: each is built once).
  struct ConfigCaches {
    bool built = false;
    lcs::LdcpData ldcp;
    double rho_A = 0.0;
    std::map<lcs::IndexSet, lcs::ModeFeedback> feedback;
    std::map<std::pair<lcs::IndexSet, std::vector<FrictionMode>>, double> rho;
    std::map<std::pair<lcs::IndexSet, std::vector<FrictionMode>>, StepExp> step;
  };
  std::vector<ConfigCaches> config_caches_;
  void swap_caches(ConfigCaches& c);
  // Moving stops (mechanical.gap_inputs; schedule.cpp): the part of each gap
  // (G_w w) and of its rate (G_w S w) that the inputs give at xa, and the
  // velocity shift delta with E_J delta = that rate on the closed rows J, so
  // that the impact law sees the velocities relative to the stops.
  bool moving_stops() const {
    return model_.is_mechanical() && !model_.mechanical->gap_inputs.empty();
  }
  VectorXd stop_offset(const VectorXd& xa) const;
  VectorXd stop_rate(const VectorXd& xa) const;
  VectorXd stop_shift(const std::vector<int>& closed, const VectorXd& xa) const;
  bool take_event(RunState& r, PhaseMarch& pm, LivelockGuard& livelock);
  bool zeno_guard(RunState& r, long events_seen) const;
  bool reinitialise(RunState& r, const VectorXd& x_minus, EventResult& ev);
  bool classify_event(Event& e, const EventResult& ev, const lcs::IndexSet& old_mode,
                      const std::vector<FrictionMode>& old_friction) const;
  void end_run(RunState& r) const;
  void fill_friction(Sample& s, const Phase& ph, const VectorXd& xa) const;
  // Contact f's d (1 when planar or frictionless).
  int cone_d(size_t f) const { return f < cone_d_.size() ? cone_d_[f] : 1; }
  // An event's tangential impulses and friction modes after (models with
  // friction only).
  void set_friction(Event& e, const EventResult& ev) const;
  VectorXd multipliers(const Phase& ph, const VectorXd& xa) const {
    VectorXd u = VectorXd::Zero(k_);
    if (!ph.mode.empty()) {
      const VectorXd uI = ph.F * xa;
      for (size_t i = 0; i < ph.mode.size(); ++i) u(ph.mode[i]) = uI(i);
    }
    for (const FreePair& f : ph.free) {  // the least admissible value
      double z = 0.0;
      for (const RowVectorXd& l : f.lower) z = std::max(z, l.dot(xa));
      u(f.column) = z;
    }
    return u;
  }
  // Keeps the first gap of a mechanical model below -(sqrt(eps) |C_r|_1
  // max|x| + tol_abs) in infeasible_: far beyond the rounding the exact
  // method leaves (1e-13 relative), far below any missed contact. `gaps`:
  // C xa (k_ > 0).
  void check_feasible(double t, const VectorXd& xa, const VectorXd& gaps) const;
  double energy(const VectorXd& xa) const {
    if (!model_.is_mechanical()) return 0.0;
    return mech::total_energy(*model_.mechanical, xa.head(N_), xa.segment(N_, N_));
  }

  const mech::Model& model_;
  const Options& opt_;
  lcs::Lcs sys_;
  int n_ = 0, k_ = 0, N_ = 0;
  VectorXd restitution_;
  std::unique_ptr<lcp::Solver> solver_;
  std::unique_ptr<impact::ImpactLaw> impact_;
  lcs::LdcpOptions ldcp_;
  std::vector<std::vector<ImpactTime>> impact_times_;  // last few impacts per contact
  std::vector<ImpactTime> impact_seq_;                 // last few impacts of any contact
  // The first recorded state whose gap is negative beyond rounding (a
  // missed event: the run cannot say "completed"), as a message; "" if none.
  mutable std::string infeasible_;
  lcs::IndexSet ldcp_undetermined_;  // K of the last mode selection
  lcs::LdcpData ldcp_data_;
  double rho_A_ = 0.0;  // bound on the spectral radius of the free dynamics
  mutable std::map<lcs::IndexSet, lcs::ModeFeedback> feedback_cache_;
  mutable std::map<std::pair<lcs::IndexSet, std::vector<FrictionMode>>, double> rho_cache_;
  // The last phase built without error and its arguments (make_phase): a
  // selection at an event builds its chosen phase to check it, and the
  // caller then asks for the same one (the same mode, friction modes,
  // undetermined set and state, bit for bit), which is returned as built.
  struct PhaseMemo {
    lcs::IndexSet mode, undetermined;
    std::vector<FrictionMode> friction;
    VectorXd xa;
    Phase phase;
    // The monitors' start of `phase` from xa at start_t (h_max = 1), once a
    // selection check asked for it (selection_start).
    std::optional<MonitorStart> start;
    double start_t = 0.0;
  };
  mutable std::optional<PhaseMemo> phase_memo_;
  mutable Phase failed_phase_;  // make_phase's result when it fails
  // The Cholesky factor of the mechanical model's M (project_onto), built
  // at its first use: M is the same throughout a run.
  mutable std::optional<Eigen::LLT<MatrixXd>> M_llt_;
  // project_onto's factors for the last row set J it projected on (the
  // closed gaps, then the resting rates: at an event of a body resting on
  // its contacts the same set, event after event): M^-1 E_J' and the
  // decomposition of E_J M^-1 E_J', functions of J alone, so a projection
  // on the same set solves with the very same numbers.
  struct ProjectionFactors {
    std::vector<int> rows;
    MatrixXd MinvEt;
    Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod;
  };
  mutable std::optional<ProjectionFactors> projection_;
  // The regular-only LDCP at an event (select_regular_mode) reads the state
  // only through the free response C A^m x and its scales |C| |A|^m |x|
  // (src/lcs/ldcp.cpp, FreeResponse): a selection whose free response equals
  // the last one's, order by order (ldcp_free_response), is the last one's.
  // Kept only while the free dynamics' |A| is nilpotent (no_path_of: then
  // the response ends, and the LDCP's retry in scaled time returns its first
  // result), for the configuration it was made in (reinitialisation.cpp).
  struct LdcpMemo {
    int config = -1;
    std::vector<VectorXd> response;  // C A^m x, |C| |A|^m |x| for m = 0, 1, ...
    lcs::ModeSelection sel;
  };
  std::optional<LdcpMemo> ldcp_memo_;
  lcs::ModeSelection ldcp_scratch_;  // a selection not kept in the memo
  int ldcp_nilpotent_config_ = -1;   // the configuration ldcp_nilpotent_ was found for
  bool ldcp_nilpotent_ = false;
  // lcs::select_mode(sys_, xa, ldcp_ regular only), or the memo's; its
  // callers read mode, undetermined, status, message and lcp_solves (a
  // repeated selection counts its solves again, so a run's lcp_solves read
  // as before).
  const lcs::ModeSelection& select_regular_ldcp(const VectorXd& xa);
  // The free response the LDCP would read at xa (every order up to the last
  // nonzero one; false when it does not end by order n or is not finite).
  bool ldcp_free_response(const VectorXd& xa, std::vector<VectorXd>& response) const;
  // monitor_start(ph, xa ./ ph.D, t, 1.0) for a selection's checks (its m0
  // and d0): kept with the memo when ph is the memo's phase at its state, so
  // the checks of one chosen phase (consistent, lifting_normals) start its
  // monitors once. Valid until the next make_phase.
  const MonitorStart& selection_start(const Phase& ph, const VectorXd& xa, double t) const;
  // monitor_start(ph, xstart = xa ./ ph.D, t, h_max) for the phase a run
  // marches, the selection's start reused when it is the same (phase.cpp).
  MonitorStart march_start(const Phase& ph, const VectorXd& xa, const VectorXd& xstart, double t,
                           double h_max) const;
  mutable MonitorStart scratch_start_;
  std::map<std::pair<lcs::IndexSet, std::vector<FrictionMode>>, StepExp> step_cache_;
  // The cache entry for `phase`'s samples on a grid of step dt, reset when
  // its Ab or dt differ (a frictional mode's feedback depends on the state).
  StepExp& step_exp(const Phase& phase, double dt);
  // Friction (empty for frictionless models): M^{-1} (dense), the row of E
  // of each frictional contact, and the impact law's outcome per constraint
  // at the current event (kNone where no impact).
  MatrixXd Minv_;
  std::vector<int> friction_contacts_;
  std::vector<impact::ContactOutcome> outcome_;
  // d of each entry of mechanical.friction (1 for a planar one); some >= 2
  // (has_cone_): the cone's modes and selection (cone_modes.cpp).
  std::vector<int> cone_d_;
  bool has_cone_ = false;
  // Forward sensitivities (Options::sensitivity; null otherwise).
  void init_sensitivity();
  std::shared_ptr<Sensitivity> sens_;
};

}  // namespace lcsim::sim::detail
