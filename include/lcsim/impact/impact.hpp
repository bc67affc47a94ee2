// The impact layer: impact laws behind one interface.
//
// Public face of src/impact. An impact law maps a pre-impact velocity and the
// closed contacts (zero gap) to a post-impact velocity and an impulse.
#pragma once

#include <Eigen/Dense>
#include <lcsim/core/outcome.hpp>
#include <lcsim/core/registry.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace lcsim::impact {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using IndexSet = std::vector<int>;

// What an impact did at a frictional contact (ImpactResult::outcome).
enum class ContactOutcome {
  kNone,          // frictionless, or not closed
  kNoImpulse,     // closed frictional contact that received no normal impulse
  kStick,         // tangential velocity zero after the impact, |P_T| <= mu P_N
  kSlipPositive,  // slides along +t after the impact, P_T = -mu P_N
  kSlipNegative,  // slides along -t after the impact, P_T = +mu P_N
  // A 3-D contact (mech::FrictionalContact::is_3d) slides after the impact;
  // its friction impulse lies on the cone's boundary at ImpactResult::facet.
  kSlip,
};
// "none", "no-impulse", "stick", "slip+", "slip-", "slip"
const char* to_string(ContactOutcome o);

// Where a sliding 3-D contact's friction acts on its polyhedral cone of 2d
// edges (edge i at the angle pi i/d from the first tangent): on edge i, or
// on the face between edges i and i+1 (mod 2d), the one of maximal
// dissipation (the force F of the polygon minimising F.u for the sliding
// velocity u). edge = -1: none (not sliding, or planar).
struct ConeFacet {
  int edge = -1;
  bool face = false;
};
// The facet of maximal dissipation for the sliding velocity u = (u1, u2)
// along (t, t2), u != 0: the edge i minimising D_i.u, D_i = (cos, sin)(pi i/d);
// the face (i, i+1) when its neighbour ties to 1e-9 |u| (u within about
// 1e-9 / sin(pi/d) rad of the face's bisector, rounding of a velocity that
// is on it).
ConeFacet cone_facet(double u1, double u2, int d);
// A 3-D contact's mode as outputs write it: "open" (kNone, kNoImpulse),
// "stick", "slip-edge-<i>" or "slip-face-<i>" (between edges i and i+1).
std::string cone_mode_text(ContactOutcome o, ConeFacet facet);
// The direction (cos, sin)(pi i/d) of edge i, exact where it is a multiple
// of pi/2 (cos(pi) = -1, sin(pi) = 0, not 1.2e-16).
std::pair<double, double> cone_edge(int i, int d);

// kOk when computed; the message says why not.
struct ImpactResult : OutcomeStartingAs<Status::kNumericalFailure> {
  VectorXd v_after;  // post-impact velocity (N)
  VectorXd impulse;  // per constraint (k, zero outside the closed set)
  IndexSet mode;     // constraints with positive impulse
  double energy_before = 0.0, energy_after = 0.0;  // kinetic energy (J)
  double worst_rate = 0.0;  // most negative E_J v+ (0 if none): admissibility
  int lcp_solves = 0;
  lcp::Status lcp_status = lcp::Status::kSolved;
  // Appended fields (the integrator uses only those above).
  // false when the result is computed but not an admissible impact: a negative
  // impulse entry (rule [177], "flip") or E_J v+ < 0 beyond rounding.
  bool admissible = true;
  int iterations = 0;  // sequential: pairwise impacts done; moreau-qp: Ipopt iterations
  // Sequential: v before the first pairwise impact, then after each one (only
  // filled when ImpactInput::record_iterates is set).
  std::vector<VectorXd> iterates;
  // Friction (models with mechanical.friction; both empty otherwise):
  // tangential impulse P_T per constraint (k, N s, along the contact's
  // tangent row; 0 without friction) and the outcome per constraint (k).
  VectorXd friction_impulse;
  std::vector<ContactOutcome> outcome;
  // Models with 3-D friction (mech::MechanicalModel::has_friction_3d; empty
  // otherwise): the friction impulse along the second tangent (k, N s) and
  // the cone's facet of each sliding 3-D contact (k).
  VectorXd friction_impulse2;
  std::vector<ConeFacet> facet;
  // Painlevé-type case: some closed frictional contact has W_NN - mu |W_NT|
  // <= 0; the impact LCP then may have no solution or several, so no
  // result is computed (ok = false, message names the contact).
  bool painleve = false;
  // Kinetic energy rose through the impact (beyond rounding): with e > 0 and
  // W_NT != 0 Newton's law can do that (Kane's paradox); message says so.
  bool energy_gain = false;
};

struct ImpactInput {
  const mech::MechanicalModel* model = nullptr;
  VectorXd q, v;         // configuration and pre-impact velocity
  IndexSet closed;       // constraints with zero gap (0-based, sorted)
  VectorXd restitution;  // per constraint (k); empty = the model's
  // Appended fields.
  int max_iterations = 0;        // sequential: cap on pairwise impacts (0 = 100000)
  bool record_iterates = false;  // sequential: fill ImpactResult::iterates
};

class ImpactLaw {
 public:
  virtual ~ImpactLaw() = default;
  virtual std::string name() const = 0;
  virtual ImpactResult apply(const ImpactInput& in, const lcp::Solver& solver) const = 0;
  // Whether apply handles mechanical.friction; a law that does not refuses a
  // model with friction (ok = false, message says so).
  virtual bool handles_friction() const { return false; }
};
// The laws by name: those below, and "moreau-qp" in programs that link the
// component lcsim::ipopt (include/lcsim/ipopt/moreau_qp.hpp). "moreau" is an
// alias of "newton" (its old name; laws().alias_note("moreau") says so): a
// law made by it is named "newton".
Registry<ImpactLaw>& laws();
// Throws std::invalid_argument naming the unknown law and the known ones.
std::unique_ptr<ImpactLaw> make_impact_law(std::string_view name);
std::vector<std::string> impact_law_names();

// The rules, by name (docs/impact-rules.md). All work on the closed set J
// (constraints with zero gap), velocities in the model's units (m/s), impulses
// per constraint (N s), energies in J. e_i is ImpactInput::restitution or the
// model's.
//
// "newton" (alias "moreau"): Moreau's inelastic impact LCP (3.69)-(3.70) on
// J, with per-contact Newton restitution applied to the inelastic impulse
// (§8.2.2): v+ = v + sum_i (1 + e_i) M^{-1} E_i' lambda_i. e = 0 is Moreau's
// rule. "inelastic": the same with e = 0 whatever the restitution.
ImpactResult moreau_newton(const ImpactInput& in, const lcp::Solver& solver);
// "newton", "inelastic" and "moreau-restitution" on a model with friction: the
// planar Coulomb impact as one LCP (thesis §2.5.3, Lemma 2.5.1; Glocker's
// planar formulation, Siconos's fc2d_tolcp) with unknowns per frictional
// closed contact (lambda_N, lambda_R, xi): the normal impulse, the split
// lambda_R = lambda_T + mu lambda_N >= 0 of the tangential impulse, and the
// reserve xi >= 0 (the negative part of the post-impact sliding velocity);
// a frictionless contact keeps lambda_N alone:
//   0 <= u_N+ + e u_N-           ⟂ lambda_N >= 0
//   0 <= u_T+ + xi               ⟂ lambda_R >= 0
//   0 <= 2 mu lambda_N - lambda_R ⟂ xi >= 0
// with u+ = u- + W (lambda_N, lambda_T), W = G M^{-1} G', G = [E_J; T_F].
// Newton's restitution acts on approaching contacts (u_N- < 0) only. Refuses
// Painlevé-type cases (ImpactResult::painleve) and flags a gain of energy
// (ImpactResult::energy_gain; impossible for e = 0).
ImpactResult moreau_friction(const ImpactInput& in, const lcp::Solver& solver);

// The same law on a model with 3-D friction (has_friction_3d; moreau_friction
// comes here for one): one LCP in Stewart and Trinkle's form with, per closed
// frictional contact f with d edges-pairs (planar: d = 1, edges +t and -t),
// the normal impulse lambda_N, an impulse beta_i >= 0 on each of the 2d
// edges D_i = cos(pi i/d) t + sin(pi i/d) t2, and the slack xi (the sliding
// speed in the polygon's dual norm, max_i -D_i.u+):
//   0 <= u_N+ + e u_N-                  ⟂ lambda_N >= 0
//   0 <= D_i.v+ - velocity_i + xi       ⟂ beta_i >= 0
//   0 <= mu lambda_N - sum_i beta_i     ⟂ xi >= 0
// with v+ = v + M^{-1} (E_J' lambda_N + sum D_i' beta_i). The friction impulse
// sum beta_i D_i lies in the cone and, when the contact slides, on the edges
// most opposed to the sliding (maximal dissipation over the polygon); it
// does work -xi mu lambda_N <= 0. On a planar model it is the planar law
// with four unknowns in place of three (the same numbers to rounding,
// tests/impact/friction3d_test.cpp). Painlevé: the single-contact test
// W_NN - mu max_i |W_N D_i| <= 0, and the P-matrix test over one edge per
// contact while there are at most 256 such choices.
ImpactResult moreau_friction_cone(const ImpactInput& in, const lcp::Solver& solver);

// The friction LCP above from its data, for the impact law and the
// time-stepping methods: Wg = G M^{-1} G' (n_N + n_F square, normal rows
// first), rate_N (n_N, restitution included), rate_T (n_F), normal_of[f] the
// normal row (0..n_N) of frictional contact f, mu (n_F). Unknowns
// z = (lambda_N, lambda_R, xi), size n_N + 2 n_F.
struct FrictionLcp {
  MatrixXd M;
  VectorXd q;
};
FrictionLcp friction_lcp(const MatrixXd& Wg, const VectorXd& rate_N, const VectorXd& rate_T,
                         const std::vector<int>& normal_of, const VectorXd& mu);
// Solves a friction_lcp: lcp::solve_scaled with `solver` and its fallbacks
// (1e-12, then 1e-10), then Lemke's and (size <= 12) the enumeration's z
// with entries below rounding (64 eps |z|_inf) set to zero (a lambda_R of
// 1e-33 left by a pivot where the cone row is formed of zeros) by the same
// row-scaled test; each z kept only when its impulses and rates obey the
// law to 1e-8 of their units, never relative to the slack xi, which a
// failing pivot inflates (friction_cone.cpp, check_cone_lcp). `solves`
// counts the LCP solves, `tried` lists the solvers.
lcp::Result solve_friction_lcp(const FrictionLcp& p, const lcp::Solver& solver, int* solves,
                               std::string* tried);
// The impulses (lambda_N, lambda_T) of a solution z of friction_lcp.
void friction_impulses(const VectorXd& z, int n_normal, const std::vector<int>& normal_of,
                       const VectorXd& mu, VectorXd& lambda_N, VectorXd& lambda_T);

// The cone's LCP above from its data, for the impact law and Moreau–Jean's
// step with 3-D friction: Wb = B W^{-1} B' over B = [E_J; D] (normal rows,
// then each frictional contact's 2 d_f edge rows from row first[f] of D),
// rate_N (n_N, restitution included), rate_D (n_E, the surfaces' velocity
// removed), normal_of[f] the normal row (0..n_N) of frictional contact f.
// Unknowns z = (lambda_N, beta (n_E), xi (n_F)).
FrictionLcp friction_cone_lcp(const MatrixXd& Wb, const VectorXd& rate_N, const VectorXd& rate_D,
                              const std::vector<int>& normal_of, const std::vector<int>& first,
                              const std::vector<int>& d, const VectorXd& mu);
// Solves a friction_cone_lcp: solve_friction_lcp, then Lemke's z, accepted
// on its impulses and rates, never relative to the slack (friction_cone.cpp).
lcp::Result solve_friction_cone_lcp(const FrictionLcp& p, const lcp::Solver& solver, int* solves,
                                    std::string* tried);

// "moreau-restitution": the Moreau–Jean law, restitution inside the LCP:
// 0 <= E_J v+ + e∘E_J v ⟂ lambda >= 0, v+ = v + M^{-1} E_J' lambda.
ImpactResult moreau_restitution(const ImpactInput& in, const lcp::Solver& solver);
// "sequential": pairwise impacts in turn (Example 1.4.1): sweep over J in
// index order, resolve each approaching contact alone with its restitution,
// lambda_i = -(1 + e_i) E_i v / (E_i M^{-1} E_i'), until a sweep finds no
// approaching contact. ok = false if the cap is reached first.
ImpactResult sequential(const ImpactInput& in);
// "flip": the mode rule of ref. [177] recalled in Example 3.8.3: I = the closed
// constraints with E_i v < 0; solve E_I w = 0, w = v + M^{-1} E_I' lambda
// (least-squares lambda of minimal norm if E_I is rank deficient), then apply
// restitution Newton-style. admissible = false if some lambda_i < 0 or
// E_J v+ < 0: the rule then yields no admissible impact.
ImpactResult flip_rule(const ImpactInput& in);

// Tolerances shared by the rules: |x| <= kRelTol * scale + kAbsTol counts as
// zero, where scale is |E_i||v| for a rate (as the integrator's is_zero).
inline constexpr double kRelTol = 1e-12;
inline constexpr double kAbsTol = 1e-13;

}  // namespace lcsim::impact
