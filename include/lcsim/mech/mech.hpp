// The mechanical layer: M q'' + D q' + K q = f + E' u, 0 <= y = E q + g ⟂ u >= 0.
//
// Public face of src/mech: the model value type, its LCS (3.65) with the affine
// terms f and g carried exactly by one extra constant state, energy and
// feasibility. Units are the user's (SI in the shipped models: m, kg, s, N).
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/mech/inputs.hpp>
#include <lcsim/mech/tolerances.hpp>  // the zero tests of a gap, for every user of a model
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim::mech {

using Eigen::MatrixXd;
using Eigen::VectorXd;
// Column-major; the storage of every model matrix.
using SparseMatrix = Eigen::SparseMatrix<double>;

// The model's matrices are held sparse whatever their size: a model stores
// only its non-zeros (a chain of N carts holds O(N) numbers, not 4 N^2), and a
// 2 x 2 model pays nothing for it. Algorithms that are dense by nature (the
// LCS theory, matrix exponentials, small Delassus matrices) take M.toDense()
// where they need it; the time-stepping layer chooses dense or sparse
// factorisations by size (sim::Options::sparse_dofs_threshold).
// A planar Coulomb frictional contact (issue 17; thesis §2.5.3, Lemma 2.5.1):
// the normal row E_c pairs with a tangent row t (relative sliding velocity
// u_T = t' v, m/s) and a coefficient mu >= 0 (dimensionless). The friction
// impulse P_T along t obeys |P_T| <= mu P_N and opposes sliding. The tangent
// is held sparse like E's rows: a contact stores the few coordinates it
// touches (a chain of 10^4 carts with a frictional contact each held 1.6 GB
// of dense tangents).
struct FrictionalContact {
  int contact = 0;                      // 0-based row of E
  Eigen::SparseVector<double> tangent;  // length N
  double mu = 0.0;                      // >= 0
  // Velocity of the surface along the tangent (m/s; a belt), finite: the
  // contact slides at tangent'v - velocity. 0 for a fixed surface.
  double velocity = 0.0;
  // The sliding velocity at generalised velocity v.
  double sliding(const VectorXd& v) const { return tangent.dot(v) - velocity; }
  // Coulomb friction in three dimensions (issue 27; docs/friction.md): a
  // second tangent row t2 (length N; empty for a planar contact, whose
  // friction acts along `tangent` alone) and the cone's edge count d: the
  // friction impulse lies in the polyhedral cone whose 2d edges are
  // mu P_N (cos(pi i/d) t + sin(pi i/d) t2), i = 0 .. 2d-1, inscribed in the
  // circular cone. t and t2 are orthogonal to the normal row and to each
  // other, of equal length (Euclidean, check_mechanical). d = 0 takes the
  // model's default (MechanicalModel::cone_edges). A planar contact is
  // the case d = 1 (edges +t and -t).
  Eigen::SparseVector<double> tangent2;
  int edges = 0;  // d >= 1, or 0 for the model's default
  // The tangents are t_k' J of an orthonormal world frame (t_1, t_2, n) at a
  // contact point with Jacobian J (a scene's contact, scene::ContactFrame):
  // the frame is orthonormal where it was built, and the rows in generalised
  // coordinates (rotations among them) need not be Euclidean-orthogonal, so
  // check_mechanical skips its orthogonality and equal-length tests.
  bool world_frame = false;
  bool is_3d() const { return tangent2.size() > 0; }

  FrictionalContact() = default;
  // A dense tangent is stored without its zeros.
  FrictionalContact(int contact_row, const VectorXd& tangent_row, double coefficient,
                    double surface_velocity = 0.0)
      : contact(contact_row),
        tangent(tangent_row.sparseView(0.0)),
        mu(coefficient),
        velocity(surface_velocity) {}
};

struct MechanicalModel {
  SparseMatrix M;                        // mass matrix, symmetric positive definite (N x N)
  SparseMatrix D;                        // damping (N x N), zero if omitted
  SparseMatrix K;                        // stiffness (N x N), zero if omitted
  SparseMatrix E;                        // constraint rows (k x N): E q + g >= 0
  VectorXd g;                            // gaps at q = 0 (k), zero if omitted
  VectorXd f;                            // constant generalised force (N), e.g. gravity
  VectorXd restitution;                  // per-constraint Newton coefficient in [0, 1] (k)
  std::vector<std::string> coordinates;  // names (N); "q1".. if omitted
  std::vector<std::string> constraints;  // names (k); "c1".. if omitted
  // Frictional contacts, at most one per row of E (empty: frictionless model).
  std::vector<FrictionalContact> friction;
  // The default d of three-dimensional contacts (FrictionalContact::edges =
  // 0): 2d = 8 edges, whose cone's worst-case deceleration is cos(pi/8) =
  // 0.924 of the circular cone's (docs/friction.md, "The cone's error").
  int cone_edges = kDefaultConeEdges;
  static constexpr int kDefaultConeEdges = 4;
  // Inputs that vary in time (issue 29, docs/inputs.md), empty by default so
  // that a model without them is what it always was: the signals, and where
  // they enter: f(t) = f + sum gain u(t) (gains of N entries) and
  // g(t) = g + sum gain u(t) (gains of k entries: a moving stop).
  std::vector<Input> inputs;
  std::vector<InputUse> force_inputs, gap_inputs;
  bool has_inputs() const { return !inputs.empty(); }
  bool has_friction() const { return !friction.empty(); }
  // Whether some frictional contact has two tangents (FrictionalContact::is_3d).
  bool has_friction_3d() const;
  // d of frictional contact f: 1 when planar, else its own or cone_edges.
  int edges_of(const FrictionalContact& c) const {
    return !c.is_3d() ? 1 : (c.edges > 0 ? c.edges : cone_edges);
  }
  int dofs() const { return static_cast<int>(M.rows()); }
  int num_constraints() const { return static_cast<int>(E.rows()); }
};

// Fills omitted (empty) D, K, g, f, restitution with zeros and names with
// defaults. Dimensions must already agree.
void fill_defaults(MechanicalModel& m);

// LCS of eq. (3.65) on the augmented state (q, v, 1) of size 2N + 1:
// A = [0 I 0; -M^{-1}K -M^{-1}D M^{-1}f; 0 0 0], B = [0; M^{-1}E'; 0],
// C = [E 0 g], D = 0. A model with inputs appends their exosystems'
// states w (input by input, exosystem_states): w' = S w, and the force and
// gap gains times each input's output row l in the v rows of A and in C.
lcs::Lcs to_lcs(const MechanicalModel& m);

// The exosystems' states at t (the right limits at a breakpoint), input by
// input: what the state w is re-initialised to at a scheduled event.
VectorXd exosystem_states(const MechanicalModel& m, double t);
// The first breakpoint of any input after t (strictly); +inf if none.
double next_breakpoint(const MechanicalModel& m, double t);
// The same for a list of inputs (a mechanical model's, or an `lcs:` model's
// Model::inputs): their exosystems' states at t, input by input, and their
// first breakpoint after t.
VectorXd exosystem_states(const std::vector<Input>& inputs, double t);
double next_breakpoint(const std::vector<Input>& inputs, double t);
// f(t) and g(t) with the inputs' values at t (the time-stepping methods).
VectorXd force_at(const MechanicalModel& m, double t);
VectorXd gap_at(const MechanicalModel& m, double t);

// Energies (J): T = ½ v'Mv, V = ½ q'Kq - f'q, total = T + V.
double kinetic_energy(const MechanicalModel& m, const VectorXd& v);
double potential_energy(const MechanicalModel& m, const VectorXd& q);
double total_energy(const MechanicalModel& m, const VectorXd& q, const VectorXd& v);

VectorXd gaps(const MechanicalModel& m, const VectorXd& q);  // E q + g
// Most negative gap (0 if all are >= 0).
double worst_violation(const MechanicalModel& m, const VectorXd& q);

// The configuration nearest to q in the kinetic metric that satisfies the
// constraints: argmin ½ (p - q)' M (p - q) subject to E p + g >= 0, i.e.
// p = q + M^{-1} E' lambda with 0 <= E q + g + E M^{-1} E' lambda ⟂ lambda >= 0
// (the KKT conditions: an LCP, solved over the rows that are violated, adding
// rows that the correction violates, at most k rounds). Velocities are the
// caller's. std::invalid_argument when the constraints admit no such p.
VectorXd project_feasible(const MechanicalModel& m, const VectorXd& q);

// Rank of E (numerical, lcs::rank_tolerance): by SVD up to 10^6 entries, by
// a sparse rank-revealing QR of E' above (its threshold the same tolerance
// with the Frobenius norm for the largest singular value, an upper bound).
int constraint_rank(const MechanicalModel& m);

// Delassus matrix E M^{-1} E' (the script M = script N of §3.8), dense (k x k).
MatrixXd delassus(const MechanicalModel& m);

// The LCS of a model is dense, n x n with n = 2N + 1 for N coordinates: the
// exact event-driven method, backward Euler and `lcsim analyze` work on it
// with O(n^2) memory and O(n^3) matrix functions. Beyond this many states they
// refuse the model with a message naming the limit (Moreau–Jean, which works
// on the sparse model, has no such limit). N = 500 coordinates fit.
inline constexpr int kMaxDenseLcsState = 1001;

// A model file holds either a mechanical model or a general LCS, with an
// optional default initial state and horizon.
struct Model {
  std::string name;
  std::string source;  // where it was loaded from (for messages)
  std::optional<MechanicalModel> mechanical;
  std::optional<lcs::Lcs> lcs;  // set for `lcs:` models
  VectorXd initial;             // full state (q then v for mechanical); empty if unset
  double t_end = std::numeric_limits<double>::quiet_NaN();  // NaN if unset
  // `lcs:` models only (issue 29, circuits; docs/model-format.md), each empty
  // or zero by default, so a model without them is what it always was:
  // - names of the states (n; default x1..xn) and of the complementarity
  //   pairs (k; default 1..k): CSV columns x, u_<pair>, y_<pair>, events;
  // - an exosystem: the last `exo_states` states are inputs w' = S w (S the
  //   lower-right block of A, no coupling from the other states), a constant
  //   (w' = 0) or a damped sine (a 2-state oscillator), so that each phase is
  //   still a matrix exponential. Their initial values are `exo_initial`,
  //   always: a user's initial state gives the other states (full_state);
  // - outputs z = output_x x + output_u u (output_names, one row each),
  //   written as CSV columns after y (a circuit's V(node) and I(element)).
  std::vector<std::string> state_names, pair_names;
  int exo_states = 0;
  VectorXd exo_initial;
  std::vector<std::string> output_names;
  MatrixXd output_x, output_u;
  // - inputs with breakpoints (a circuit's PULSE, PWL and delayed SIN
  //   sources; docs/inputs.md): their exosystems are the last states of the
  //   exosystem block, input by input (Input::exo_size() each, the tail of
  //   exo_initial their states at t = 0); the exact method re-initialises
  //   them at each breakpoint (a scheduled event), as a mechanical model's.
  std::vector<Input> inputs;
  // - switch configurations (a circuit's ideal switches; docs/circuits.md):
  //   the LCS and outputs of each configuration a run visits (the state is
  //   the same in every one), the times at which the one holding changes
  //   (increasing, known up to switch_horizon, s), and the configuration on
  //   each interval: switch_config[i] holds on [switch_times[i-1],
  //   switch_times[i]) (one more entry than switch_times). `lcs`, output_x
  //   and output_u are configuration switch_config[0]'s. The exact method
  //   swaps the matrices at each time, a scheduled event named by
  //   switch_notes[i] ("S1 on"). Empty: one configuration, as always.
  struct Configuration {
    lcs::Lcs lcs;
    MatrixXd output_x, output_u;
  };
  std::vector<Configuration> configurations;
  std::vector<double> switch_times;
  std::vector<int> switch_config;
  std::vector<std::string> switch_notes;
  double switch_horizon = std::numeric_limits<double>::infinity();
  bool is_switched() const { return !switch_times.empty(); }
  // The index into switch_times of the first time > t (switch_times.size()
  // when none): the configuration on the interval holding t is
  // switch_config[interval_at(t)] (src/mech/mech.cpp).
  std::size_t interval_at(double t) const;
  // The inputs whose breakpoints are scheduled events: mechanical->inputs
  // for a mechanical model, else `inputs`.
  const std::vector<Input>& scheduled_inputs() const;
  // The full state from `x`: `x` itself when of size state_size(), `x`
  // followed by exo_initial when of size state_size() - exo_states (> 0).
  VectorXd full_state(const VectorXd& x) const;
  bool is_mechanical() const { return mechanical.has_value(); }
  int state_size() const;  // 2N for mechanical, n for LCS
  int num_constraints() const;
  // Size of as_lcs(): 2N + 1 (plus the inputs' exosystems) for mechanical
  // models (augmented), n for LCS.
  int lcs_state_size() const;
  // The LCS to simulate: to_lcs(mechanical) (augmented) or the LCS itself.
  // Dense; std::invalid_argument beyond kMaxDenseLcsState (see there).
  lcs::Lcs as_lcs() const;
};

// What is wrong with a model: the field as the model file names it
// ("mechanical.M", "mechanical.E[1]", "lcs.B", "initial[2]") and what.
struct ModelProblem {
  std::string field;
  std::string what;
};
// The one check of a model, whether built in code or read from a file (the
// loaders put the file name in front): sizes that agree, finite entries, M
// symmetric (1e-12 relative) and positive definite (its smallest eigenvalue,
// or LDL' pivot above 64 coordinates, above N eps of the largest),
// restitution in [0, 1], no all-zero row of E, frictional contacts naming
// distinct rows of E with a finite tangent row of length N and a finite
// mu >= 0 (three-dimensional ones: t2 as t, d >= 0, cone_edges >= 1, no
// velocity, and t, t2 and the normal row pairwise orthogonal with |t| = |t2|
// to kTangentOrthogonality), an initial state of the right size and a finite t_end > 0 when
// set. nullopt when usable.
std::optional<ModelProblem> check_model(const Model& model);
// "" when A is symmetric to 1e-12 of its largest entry (the test check_model
// applies to M), else the first pair that is not, named with `name`:
// "K[0][1] = 2 but K[1][0] = 0".
std::string asymmetry(const SparseMatrix& A, std::string_view name);
// Relative tolerance of the orthogonality of a 3-D contact's rows: |a.b| <=
// this |a| |b| (Euclidean, in the model's coordinates), and ||t| - |t2|| <=
// this |t|. Rows typed with 16 digits pass; 0.7071 for 1/sqrt(2) does not
// (an angle of 1e-5 rad would let friction work on the normal at that order).
inline constexpr double kTangentOrthogonality = 1e-9;
std::optional<ModelProblem> check_mechanical(const MechanicalModel& m);
std::optional<ModelProblem> check_lcs(const lcs::Lcs& s);
std::optional<ModelProblem> check_mass_matrix(const SparseMatrix& M);

}  // namespace lcsim::mech

namespace lcsim::mech {

// Benchmark models built in memory (src/mech/benchmarks.cpp).

// A Model holding `m` (fill_defaults applied) under `name`, no initial state.
Model model_of(MechanicalModel m, const std::string& name);

// Unit mass on a spring of stiffness k (N/m) with a stop at q = -s (E = 1,
// g = s), restitution e: the extremes suite's stiff and soft springs.
Model spring_stop_model(double k, double s, double e = 0.0);

// Unit-mass ball over the ground q >= 0 under gravity g (f = -g), restitution e.
Model ball_model(double e, double g = 9.81);

// The two carts of thesis §3.7 (Figure 3.1): unit masses, K = [2 -1; -1 1]
// (a spring from cart 1 to the wall, one between the carts), the stop
// x1 >= 0 (eq. (3.1)) and, with `hook`, the hook x1 - x2 >= 0 of Example
// 3.8.3 (eq. (3.74)). No initial state or horizon (robots/two_carts*.yaml
// hold the thesis's).
Model two_carts_model(bool hook);
// The same two carts with the constraint rows E q + g >= 0 given instead (E
// with two columns; g empty for zero): the repeated, parallel and nearly
// dependent stops of the extremes suite. Constraints named by fill_defaults.
Model two_carts_model(const Eigen::MatrixXd& E, const Eigen::VectorXd& g = Eigen::VectorXd());

// The cart chain of the scaling benchmark (`lcsim generate chain`, issue 9):
// carts i = 0..n-1 (coordinate q_i, m), unit masses (kg), unit springs (N/m)
// between neighbours and, with `wall_spring`, from cart 0 to the wall, so
// K = tridiag(-1, 2, -1) with K(n-1, n-1) = 1 (K(0, 0) = 1 without the wall).
// `stops`: q_i + 1 >= 0 for every cart (rows 0..n-1 of E, g = 1).
// `hooks`: q_i - q_{i+1} + 0.5 >= 0 for every neighbouring pair (cart i+1 at
// most 0.5 m ahead of cart i; the rows after the stops).
// The model's initial state is the benchmark's, x_i = 0.1 (i mod 3) m,
// v_i = -1 m/s, and t_end = 10 s. O(n) storage.
struct ChainSpec {
  int n = 10;
  bool stops = true;
  bool hooks = false;
  bool wall_spring = true;
};
inline constexpr double kChainHookGap = 0.5;  // m
Model chain_model(const ChainSpec& spec);

}  // namespace lcsim::mech

namespace lcsim::mech {

// Index sets of constraints that can be active together (src/mech/coactive.cpp).
//
// A set J can be active together when some configuration closes all of J and
// violates nothing: { q : E_J q + g_J = 0, E q + g >= 0 } is non-empty. The
// two limits of one joint (rows e and -e with lower < upper) never can. Such
// rows make E rank deficient without being dependent constraints in the sense
// of §4.6.1 (an impulse split among rows that act together): they are never
// in one LCP. Decided exactly (up to the zero test of a gap) by a least-squares
// solve of the equalities and, on their solution set, Lemke's method on the
// PSD LCP of the inequalities (see coactive.cpp); not by a test of opposite
// parallel rows alone, which misses three or more rows that are pairwise but
// not jointly closable.
bool can_be_active_together(const MechanicalModel& m, std::vector<int> J);

// The maximal sets that can be active together, found as the maximal cliques
// of the pairwise graph (Bron-Kerbosch), each verified as a whole and split
// into its maximal feasible subsets if it fails. Pairs and singletons are
// tested exactly. At most `max_sets` sets (complete = false beyond: the
// verdicts below then do not cover every set; complete is false too when a
// feasibility LCP ends neither solved nor on a ray, undecided, counted as
// "not together"). Exponential in the worst case
// (2^j sets for j joints with two limits each; 128 for a 7-joint arm).
struct CoactiveSets {
  std::vector<std::vector<int>> maximal;             // sorted, 0-based constraint indices
  std::vector<std::pair<int, int>> exclusive_pairs;  // i < j never active together
  std::vector<int> never_active;                     // no admissible q closes it
  bool complete = true;
};
CoactiveSets coactive_sets(const MechanicalModel& m, size_t max_sets = 4096);

// Theorem 3.6.3 and the P-property of the Delassus matrix evaluated on each
// maximal set J that can be active together: the LCS (3.65) restricted to the
// constraints J (B_.J, C_J., D_JJ), its leading row and column coefficient
// matrices (3.39), and E_J M^{-1} E_J'. Near an admissible state only the
// constraints with zero gap can switch, and they form such a J (or a subset:
// principal submatrices of a P-matrix are P-matrices), so these verdicts are
// the ones that matter for admissible initial states; the theorem applied to
// all k rows at once asks for more (a state closing both limits of a joint)
// than any admissible state can reach.
struct CoactiveWellPosedness {
  struct Set {
    std::vector<int> indices;
    int rank = 0;  // numerical rank of E_J (lcs::numerical_rank)
    bool delassus_p_matrix = true, row_p_matrix = true, column_p_matrix = true;
  };
  std::vector<Set> sets;
  bool all_delassus_p = true;      // every E_J M^{-1} E_J' a P-matrix (unique impulses)
  bool locally_well_posed = true;  // Theorem 3.6.3 on every set (and the sets complete)
  bool dependent = false;          // some set has rank E_J < |J|: truly dependent rows
};
CoactiveWellPosedness coactive_well_posedness(const MechanicalModel& m, const CoactiveSets& s);

// `analyze` enumerates the sets only up to this many constraints (pairs are
// k^2 / 2 small LCPs; a 7-joint arm has 14 rows) and a summary lists at most
// kSummarySets maximal sets and exclusive pairs (their counts are given).
inline constexpr int kMaxCoactiveConstraints = 64;
inline constexpr std::size_t kSummarySets = 8;

// What was not judged, in plain sentences: `sets` null when the enumeration
// was skipped (k > kMaxCoactiveConstraints), else what its being cut short
// (sets->complete false) leaves open. `rank_E` (constraint_rank) says
// whether a rank deficit is left unexplained. Empty when all was judged.
std::vector<std::string> coactive_not_judged(const MechanicalModel& m, const CoactiveSets* sets,
                                             int rank_E);

}  // namespace lcsim::mech
