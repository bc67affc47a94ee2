// The LCS layer: x' = A x + B u, y = C x + D u, 0 <= y ⟂ u >= 0 (eq. (3.13)).
//
// Public face of src/lcs: Markov parameters (3.32), leading row/column indices
// and coefficient matrices (3.39), the consistent subspace V_I (3.4), the jump
// space T_I (3.7), the projection P_I onto V_I along T_I (§3.4.2), the mode
// feedback F_I (§3.4.1), the well-posedness report (Theorem 3.6.3, (3.40),
// passivity of §7.2) and mode selection by the LDCP (§3.5.2, Theorems
// 3.6.7/3.6.8/3.6.12).
//
// Index sets are sorted vectors of 0-based constraint indices.
#pragma once

#include <Eigen/Dense>
#include <lcsim/core/outcome.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <string>
#include <vector>

namespace lcsim::lcs {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using IndexSet = std::vector<int>;

struct Lcs {
  MatrixXd A;  // n x n
  MatrixXd B;  // n x k
  MatrixXd C;  // k x n
  MatrixXd D;  // k x k
  int n() const { return static_cast<int>(A.rows()); }
  int k() const { return static_cast<int>(B.cols()); }
};

// Rank decisions use singular values: sigma is "zero" when
// sigma <= rank_tolerance(scale) = max(dim) * 1e-12 * scale, where scale is
// the largest singular value of the matrix being factored (or 1 if it is 0).
// The 1e-12 (not eps) leaves room for errors accumulated in products like A^i B.
double rank_tolerance(const MatrixXd& X);
// The number of singular values of X above rank_tolerance(X), from one SVD.
int numerical_rank(const MatrixXd& X);

// H^0 = D, H^i = C A^{i-1} B, i = 1..count-1 (eq. (3.32)).
std::vector<MatrixXd> markov_parameters(const Lcs& sys, int count);

// Leading indices (Definition 3.6.2); kInfiniteIndex when a row/column of all
// H^0..H^n vanishes (the mode is then not autonomous, Lemma 3.6.5). An entry
// of H^i counts as nonzero when above 1e-12 |C| |A|^{i-1} |B| (the magnitudes
// of its terms), so stiff models (omega up to 1e9 and beyond) get the index of
// the unscaled theory.
inline constexpr int kInfiniteIndex = -1;
std::vector<int> leading_row_indices(const Lcs& sys);     // rho_i
std::vector<int> leading_column_indices(const Lcs& sys);  // eta_j
MatrixXd leading_row_coefficients(const Lcs& sys);        // script M in (3.39)
MatrixXd leading_column_coefficients(const Lcs& sys);     // script N in (3.39)

// V_I = V(A, B_.I, C_I., D_II) (eq. (3.4)) and T_I = T(...) (eq. (3.7)),
// as orthonormal bases (n x dim) computed by SVD with rank_tolerance.
struct ConsistentSubspace {
  MatrixXd basis;
};
struct JumpSpace {
  MatrixXd basis;
};
ConsistentSubspace consistent_subspace(const Lcs& sys, const IndexSet& I);
JumpSpace jump_space(const Lcs& sys, const IndexSet& I);

// P_I: projection onto V_I along T_I. ok = false (with a message) when
// V_I ⊕ T_I != R^n, i.e. mode I is not autonomous (Lemma 3.3.3).
// kOk when computed; the message says why not.
struct Projection : OutcomeStartingAs<Status::kNumericalFailure> {
  MatrixXd P;
};
Projection projection(const Lcs& sys, const IndexSet& I);

// F_I (|I| x n): u_I = F_I x keeps y_I = 0 on V_I and makes V_I invariant for
// x' = (A + B_.I F_I) x. Built from leading rows: y_i^(rho_i) = C_i A^rho_i x
// + (script M)_i u = 0 for i in I, so F_I = -(script M_II)^{-1} (C A^rho)_I.
// ok = false when script M_II is singular.
// kOk when computed; the message says why not.
struct ModeFeedback : OutcomeStartingAs<Status::kNumericalFailure> {
  MatrixXd F;
};
ModeFeedback mode_feedback(const Lcs& sys, const IndexSet& I);

// x is regular (admits a smooth continuation) iff for all i
// (C_i x, C_i A x, ..., C_i A^{rho_i - 1} x) is lexicographically >= 0 (3.40),
// valid when script M is a P-matrix (Theorem 3.6.7).
bool is_regular_state(const Lcs& sys, const VectorXd& x, double tol);

struct WellPosednessReport {
  int n = 0, k = 0;
  std::vector<MatrixXd> markov;  // H^0..H^n
  std::vector<int> rho, eta;
  MatrixXd row_coefficients, column_coefficients;
  bool row_p_matrix = false, column_p_matrix = false;
  bool locally_well_posed = false;  // Theorem 3.6.3 applies
  // Passivity (§7.2): exists K = K' > 0 with [A'K+KA, KB-C'; B'K-C, -(D+D')] <= 0.
  // "yes" with a certificate, "no" when a necessary condition fails, or "unknown".
  std::string passive = "unknown";
  std::string passivity_reason;
  // Backward Euler consistency guard (§7.3, Example 7.3.3): some rho_i >= 3.
  bool backward_euler_risky = false;
};
WellPosednessReport analyze_well_posedness(const Lcs& sys);

// A summary of a report (what `lcsim analyze` prints unless asked for the
// full report): the verdicts, and of the matrices only those of at most
// kSummaryEntries numbers. The report's matrices grow as k^2 n: 66 stops on
// a 33-cart chain give 135 Markov parameters of 66 x 66, 3.7 MB of text.
// 400 numbers (a 20 x 20 matrix, a screen) keep every matrix of the thesis's
// examples and of a 7-joint arm's Delassus matrix (14 x 14).
inline constexpr Eigen::Index kSummaryEntries = 400;
inline bool summary_shows(Eigen::Index entries) { return entries <= kSummaryEntries; }
// The parts of `r` a summary leaves out, by their JSON names: "markov" (all
// of H^0..H^n, counted together), "row_coefficients", "column_coefficients".
std::vector<std::string> summary_left_out(const WellPosednessReport& r);

// Mode selection by LDCP (§3.5.2) solved level by level as a series of LCPs
// with Schur complements of the leading row coefficient matrix (proof of
// Theorem 3.6.7, extended to the impulsive levels -n+1..0). Requires script M
// to be a P-matrix for uniqueness; a failing LCP is reported, not hidden.
// kOk when computed; the message says why not.
struct ModeSelection : OutcomeStartingAs<Status::kNumericalFailure> {
  IndexSet mode;          // I: constraints with lexicographically positive u
  IndexSet undetermined;  // K: u and y identically zero so far (Remark 3.4.8)
  // Impulsive coefficients u^{-n+1..0}: impulse[j] multiplies delta^{(j)}.
  std::vector<VectorXd> impulse;
  VectorXd x_plus;  // re-initialised state x0 + sum_j A^j B u^{-j} (eq. (3.10))
  int lcp_solves = 0;
};
// What the LDCP needs of the system alone: leading row indices, script M,
// and the Markov parameters H^i, computed on first use (a mode selection
// rarely needs more than a few orders; mechanical models with n = 2N+1 would
// otherwise pay for 3n products). Compute once per system and pass it in
// LdcpOptions::data when selecting modes repeatedly. Keeps a pointer to sys,
// which must outlive it.
struct LdcpData {
  std::vector<int> rho;
  MatrixXd Mlead;
  const MatrixXd& markov(int i) const;  // H^i
  const Lcs* sys = nullptr;
  mutable std::vector<MatrixXd> H;
  mutable MatrixXd AiB;  // A^{i} B for the next order
};
LdcpData ldcp_data(const Lcs& sys);

struct LdcpOptions {
  // A coefficient is treated as zero when |value| <= tol_rel * (sum of the
  // absolute values of the terms that formed it) + tol_abs.
  double tol_rel = 1e-9;
  double tol_abs = 1e-13;
  // true: the state is known to be regular; impulsive levels are not solved
  // (u = 0 there) and a negative free coefficient is reported (Theorem 3.6.7).
  bool regular_only = false;
  const lcp::Solver* solver = nullptr;  // nullptr = principal pivoting
  const LdcpData* data = nullptr;       // nullptr = computed here
};
ModeSelection select_mode(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt = {});

}  // namespace lcsim::lcs

// ---------------------------------------------------------------------------
// Details of the subspace and well-posedness part (src/lcs/subspaces.cpp,
// src/lcs/wellposedness.cpp), appended to the declarations above.
//
// - consistent_subspace, jump_space, projection, mode_feedback and
//   is_regular_state throw std::invalid_argument when the Lcs dimensions
//   disagree or I is not a sorted set of distinct indices in [0, k).
// - V_I and T_I: before the recursions (3.4)/(3.7) the mode quadruple
//   (A, B_.I, C_I., D_II) is balanced by exact equivalences that do not change
//   V or T (time scaling of (A, B_.I), scaling of each output row and each
//   input column); rank decisions use rank_tolerance of the balanced
//   [A B_.I; C_I. D_II] (an a-priori scale), so they do not depend on units.
// - projection: ok = false also when Ker [B_.I; D_II] != {0} (the other half
//   of Lemma 3.3.3 (3)); P is still filled whenever V_I ⊕ T_I = R^n.
// - mode_feedback uses the leading rows of the mode's own system
//   (A, B_.I, C_I., D_II); they coincide with rho_i and script M_II of the full
//   system whenever H^{rho_i}_{iI} != 0.
// - is_regular_state: tol is relative. C_i A^j x counts as zero when
//   |C_i A^j x| <= tol * || |C_i| |A|^j ||_1 * ||x||_inf (entrywise
//   magnitudes of the row's terms, so a stiff spring elsewhere in A does not
//   inflate it as ||A||^j did). An infinite rho_i uses n terms.
//   1e-9 is a sensible value for data accurate to ~1e-12.
// - analyze_well_posedness, passivity (§7.2; K = K' > 0 with
//   L(K) = [A'K+KA, KB-C'; B'K-C, -(D+D')] <= 0). Each necessary condition
//   below follows from L(K) <= 0 with K > 0 for ANY realisation (minimality is
//   not needed); the first that fails gives passive = "no":
//     N1  D + D' >= 0 (lower-right block of L(K)).
//     N2  on Z = Ker(D + D'): (KB - C') Z = 0 (a PSD matrix with a zero
//         diagonal block has zero off-diagonal blocks), hence Z'CBZ = Z'B'KBZ
//         is symmetric positive semidefinite and Ker(Z'CBZ) = Ker(BZ).
//         (This is what fails for every mechanical LCS (3.65) with position
//         output y = E q + g and E != 0: CB = 0, B != 0.)
//     N3  G(l) + G(l)^* >= 0 at sample points l with Re l >= 0 that are not
//         near eigenvalues of A (x = (lI - A)^{-1} B u turns L(K) <= 0 into
//         u^*(G + G^*)u >= 2 Re(l) x^*Kx >= 0): a log grid of |l| over
//         [1e-4, 1e4] * max(||A||_2, 1) at arg l = 0, 30, 60, 90 degrees.
//   Sufficient: passive = "yes" when the candidate K = I is verified by
//   verify_passivity_certificate (e.g. circuits in port-Hamiltonian form with
//   A + A' <= 0, B = C'). A mechanical model with velocity output y = E v is
//   passive with K = blockdiag(stiffness, mass) (plus a constant-state block),
//   but M is not recoverable from (A, B, C) alone, so that certificate must
//   be checked by the caller that knows M through verify_passivity_certificate.
//   Otherwise passive = "unknown"; passivity_reason says what was checked.
namespace lcsim::lcs {

// kOk when computed; the message says why not.
struct PassivityCertificateCheck : OutcomeStartingAs<Status::kNumericalFailure> {
  double lmi_max_eigenvalue = 0.0;  // largest eigenvalue of L(K) (must be <= ~0)
  double k_min_eigenvalue = 0.0;    // smallest eigenvalue of K (must be > 0)
};
// Verifies K = K' > 0 and L(K) <= 0 up to 1e-10 relative to the scale
// ||K|| (||A|| + ||B||) + ||C|| + ||D|| of the entries of L(K).
PassivityCertificateCheck verify_passivity_certificate(const Lcs& sys, const MatrixXd& K);

}  // namespace lcsim::lcs
