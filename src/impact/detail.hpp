// Internal helpers shared by the impact rules (not part of the public face).
#pragma once

#include <functional>
#include <lcsim/impact/impact.hpp>
#include <optional>
#include <string>
#include <vector>

namespace lcsim::impact::detail {

// The data every rule needs on the closed set J.
struct Setup {
  int k = 0;        // constraints in the model
  VectorXd e;       // restitution (k)
  MatrixXd EJ;      // rows of E on J (|J| x N)
  MatrixXd MinvEt;  // M^{-1} E_J' (N x |J|)
  MatrixXd W;       // Delassus matrix E_J M^{-1} E_J' (|J| x |J|)
  VectorXd a;       // pre-impact rates E_J v (|J|)
  VectorXd e_J;     // restitution on J (|J|)
  MatrixXd L;       // Cholesky factor of M (M = L L')
};

// Validates the input and fills `out` with the no-impact defaults (v_after = v,
// zero impulse, energy_before = energy_after). Returns nullopt when there is
// nothing more to do: out.ok() says whether the input was valid (an empty J is a
// valid input with no impact). A model with friction is refused (kInvalidInput,
// message says so) unless the caller handles friction (moreau_friction): a
// law must not ignore it silently.
std::optional<Setup> prepare(const ImpactInput& in, ImpactResult& out,
                             bool handles_friction = false);

// Fills impulse (per constraint, from the impulse on J), mode (impulse_J(i) >
// mode_threshold), v_after, energy_after, worst_rate and admissible
// (E_J v+ >= -1e-9 scale-relative and impulse >= -1e-9 relative: rounding and
// the interior-point solver stay far inside that).
void finish(const ImpactInput& in, const Setup& s, const VectorXd& impulse_J,
            const VectorXd& v_after, double mode_threshold, ImpactResult& out);

// Solves the impact LCP w = W z + q, 0 <= z ⟂ w >= 0 with `solver` after
// scaling it to a unit diagonal and |q| = 1, falling back to Lemke and then
// projected Gauss–Seidel (dependent constraints make W singular, PSD but not
// P). On failure sets out.message and returns nullopt.
std::optional<VectorXd> solve_impact_lcp(const MatrixXd& W, const VectorXd& q,
                                         const lcp::Solver& solver, ImpactResult& out);

// Refines an impact LCP solution z (impulse on J, post-impact velocity
// v + M^{-1} E_J' z, rates E_J v+ + e_target∘(E_J v) >= 0 complementary to
// z; e_target = 0 for Moreau's rule, the restitution for the Moreau–Jean
// law) on its active set A = {z > 0 or rate within rounding of 0}, without
// forming W: the M-nearest velocity to v with E_A v+ = -e_A∘(E_A v), from a
// column-pivoted QR of L^{-1} E_A' (condition cond(E_A); W has its square).
// Nearly dependent rows (angle d between them) leave W singular to rounding
// once d^2 < eps, and the LCP may then split the impulse wrongly, moving v+
// by d; the refinement is exact there. Returns the refined (impulse_J,
// v_after) when it moves v+ by more than rounding (kRelTol) and is still a
// solution (impulse >= 0, every closed rate >= 0, to the tolerances of
// finish); nullopt otherwise (keep z).
struct Refined {
  VectorXd impulse_J;
  VectorXd v_after;
};
std::optional<Refined> refine_on_active_set(const Setup& s, const VectorXd& v,
                                            const VectorXd& e_target, const VectorXd& z);

// Shared by the friction laws (friction.cpp, friction_cone.cpp): the
// threshold of a positive normal impulse (rounding of the largest approach
// rate through the diagonal of W), and the flag and message of an impact
// that raised the kinetic energy beyond `surface_work`, the work of moving
// surfaces (J; Kane's paradox, only restitution can cause it).
double friction_mode_threshold(const Setup& s);
void flag_friction_energy_gain(double surface_work, ImpactResult& out);
// The Painlevé test on a solved friction impact (issue 27; friction.cpp).
// Wf: the Delassus matrix over [E_J; friction rows]; its first nj rows are
// the closed normals. stick_rows: the friction rows held by the contacts
// that stick after the impact (index into Wf); slip_cols (Wf.rows() x nj):
// column j the friction of normal j's contact frozen in its sliding's
// direction, mu W_f D(w) (zero for a sticking or frictionless contact).
// True when the normal impulses are unique for these modes: the normal
// matrix with the slips' columns, the sticking rows eliminated (Schur
// complement over an independent subset of them, which holds them all), is
// a P-matrix on the sets of contacts of independent normal rows; always
// true when nothing slips. nj <= 12 (2^nj minors), else not judged (true).
bool no_painleve_after_solve(const MatrixXd& Wf, Eigen::Index nj,
                             const std::vector<Eigen::Index>& stick_rows,
                             const MatrixXd& slip_cols);
// Issue 27 (painleve.cpp): when no_painleve_after_solve fails (a
// sufficient condition), the impact is decided by enumerating the closed
// contacts' modes of the planar Coulomb impact problem u = Wg lambda + b
// (Wg over the nj closed normals, then the frictional rows; normal_of[f]
// the normal of frictional row f; per frictional contact open, stick,
// slip+, slip-, per frictionless one open or closed: 4 or 2 square systems
// per contact, each solution kept when the mode's inequalities hold to 1e-9
// of their terms; a singular system judged by solve_singular_mode, as the
// cone's). unique: exactly one motion (Wg lambda, equal to 1e-8 of its
// terms), that of lambda_law (the LCP's solution in the same coordinates);
// else `message` says why (two motions and the modes of both, a singular
// mode system that leaves the velocity free or is not decided, naming its
// modes, or more than kPainleveModeBound combinations: not enumerated).
// labels: each normal's name in messages.
constexpr long kPainleveModeBound = 4096;
struct PainleveVerdict {
  bool unique = false;
  bool enumerated = false;  // false: above the bound, not decided
  std::string message;
};
// Each closed normal's name in messages: "row ('name')".
std::vector<std::string> closed_labels(const ImpactInput& in);
PainleveVerdict decide_painleve_by_modes(const MatrixXd& Wg, const VectorXd& b, Eigen::Index nj,
                                         const std::vector<int>& normal_of, const VectorXd& mu,
                                         const VectorXd& lambda_law,
                                         const std::vector<std::string>& labels);
// Issue 27 for cones with d >= 2 (painleve_cone.cpp): the same decision
// for the polyhedral cone law. Wg, b over the nj closed normals, then per
// frictional contact f its tangent rows t1 (and t2 when d[f] >= 2) from
// first_t[f]; normal_of[f] its normal. Per contact open, stick, slip on edge
// i (2d), slip on face k (2d) (d = 1: open, stick, edges 0 and 1; no
// friction: open, closed), each a square system; a singular one is judged
// by velocity uniqueness (solve_mode_system, painleve_modes.cpp). Above
// kConePainleveModeBound combinations (18^4 = 104976 for four contacts at
// d = 4), not enumerated.
constexpr long kConePainleveModeBound = 200000;
struct ConeModesProblem {
  MatrixXd Wg;
  VectorXd b;
  Eigen::Index nj = 0;
  std::vector<int> normal_of, d;
  std::vector<Eigen::Index> first_t;
  VectorXd mu;
};
PainleveVerdict decide_cone_painleve_by_modes(const ConeModesProblem& p, const VectorXd& lambda_law,
                                              const std::vector<std::string>& labels);
// What both enumerations share (painleve_modes.cpp). A mode's square
// system: the impulses lambda = P x over its unknowns x, the equations
// A x = rhs (A = R Wg P, rhs = -R b: the rates R u that the mode holds at
// zero), its inequalities F x + h >= 0, each row's tolerance 1e-9 of the
// terms of u (a rate row, on_rates) or of lambda (an impulse row).
struct ModeInequalities {
  MatrixXd F;
  VectorXd h;
  std::vector<bool> on_rates;
  // The row a_u u + a_l lambda >= 0 (a_u, a_l: 1 x n), u = WP x + b.
  void add(const MatrixXd& a_u, const MatrixXd& a_l, const MatrixXd& P, const MatrixXd& WP,
           const VectorXd& b, bool rate);
};
struct ModeOutcome {
  enum Kind { kNone, kMotion, kContinuum, kUndecided } kind = kNone;
  VectorXd lambda;  // a motion's impulse (Wg lambda + b: the rates after)
};
// One mode's motion, its system solved with pivots below 1e-12 of the
// largest taken as rounding. A regular system: its solution when the
// inequalities hold. A singular one (dependent rows: a box's four coplanar
// corners leave the normal block of rank 3) is judged by velocity, not
// impulse, uniqueness: an inconsistent system is no motion; a consistent
// one's impulses are x0 + K y (K its kernel) over the polyhedron of y where
// the inequalities hold (see the .cpp): the law's motion when Wg P K = 0
// and its velocity is the law's; no motion when the polyhedron is empty;
// one motion when every vertex gives one velocity and no ray moves it;
// else a continuum (kContinuum). A kernel above 3 or an inequality matrix
// of lower rank: kUndecided.
ModeOutcome solve_mode_system(const MatrixXd& Wg, const VectorXd& b, const MatrixXd& P,
                              const MatrixXd& A, const VectorXd& rhs, const ModeInequalities& q,
                              const VectorXd& lambda_law);
// Equal motions: Wg (a - c) zero to 1e-8 of its terms (Wg = G M^-1 G' is
// positive semidefinite, so Wg d = 0 is G' d = 0: the same velocity after).
bool same_velocity(const MatrixXd& Wg, const VectorXd& b, const VectorXd& a, const VectorXd& c);
// The motions an enumeration found, distinct by velocity, with the text of
// each one's modes, and the verdict they give.
struct MotionTally {
  const MatrixXd& Wg;
  const VectorXd& b;
  std::vector<VectorXd> motions;
  std::vector<std::string> modes;
  // Takes a mode's outcome; false (message set, naming the modes by
  // modes_text(), called only for a new motion or a refusal) when it ends
  // the enumeration: a continuum, or a singular system not decided.
  bool add(const ModeOutcome& o, const std::function<std::string()>& modes_text,
           PainleveVerdict& out);
  // unique when the one motion found is lambda_law's; else the message.
  void decide(const VectorXd& lambda_law, PainleveVerdict& out) const;
};
// The acceptance of a solution z of friction_cone_lcp, or of the planar
// friction_lcp (its impulses lambda_N, lambda_R; its cone row 2 mu lambda_N
// - lambda_R), on the quantities that matter (friction_cone.cpp; applied by
// solve_friction_lcp and solve_friction_cone_lcp to every z they accept),
// in the form of lcp::scaled_residual,
// |min(z_i / its scale, w_i / its scale)| per row, with a scale per unit:
// an impulse (lambda_N, beta; N s) against P = the largest impulse and its
// rate (m/s) against V = |q|_inf + max_i sum_j |M_ij| |z_j| over the
// impulses' rows and columns (the rates before the impact and the change
// the impulses make); a slack xi (a sliding speed, m/s) against V and its
// cone row mu lambda_N - sum beta (N s) against P. So: impulses >= 0, rates
// >= 0, every contact's edge impulses within mu lambda_N, complementarity
// of the rates and of the slack, each to kConeLcpTolerance of its own unit
// and none relative to the slack, which the physics leaves free (any xi
// with zero impulses on an open contact). Tolerance: the solvers accept a
// row at 1e-10 of its own terms (solve_friction_lcp's second pass); a
// solution's cone row has terms <= 2 mu lambda_N <= 2 mu P and a rate row
// terms <= V + xi <= 2 V (xi <= |u+| <= V), so 1e-8 holds what they
// accept for mu up to 50; a violation that matters (the cube's: 1 of P)
// is far above it.
constexpr double kConeLcpTolerance = 1e-8;
struct ConeLcpCheck {
  double worst = 0.0;      // the worst row's measure (infinity: not finite, wrong size)
  Eigen::Index row = -1;   // that row of the LCP
  Eigen::Index cone = -1;  // its frictional contact (0 .. n_F - 1), -1 if none
  double impulse_scale = 0.0, rate_scale = 0.0;  // P (N s), V (m/s)
  std::string what;                              // the row's numbers
  bool ok() const { return worst <= kConeLcpTolerance; }
  std::string text() const;
};
// n_F of a friction_cone_lcp, read from its M: the largest trailing square
// block of zeros (the slacks' columns and cone rows; an edge's or a
// normal's diagonal entry, a Delassus diagonal, is positive). 0 for an LCP
// of another form.
Eigen::Index cone_slack_count(const MatrixXd& M);
ConeLcpCheck check_cone_lcp(const FrictionLcp& p, const VectorXd& z);
// The message of a friction impact whose LCP no solver solved (`tried`: the
// solvers, in the order tried).
std::string friction_lcp_failure(const std::string& tried, const lcp::Result& res);

}  // namespace lcsim::impact::detail
