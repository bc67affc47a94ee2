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
#include <string>
#include <vector>

#include "lcp/lcp.hpp"

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

// H^0 = D, H^i = C A^{i-1} B, i = 1..count-1 (eq. (3.32)).
std::vector<MatrixXd> markov_parameters(const Lcs& sys, int count);

// Leading indices (Definition 3.6.2); kInfiniteIndex when a row/column of all
// H^0..H^n vanishes (the mode is then not autonomous, Lemma 3.6.5).
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
struct Projection {
  MatrixXd P;
  bool ok = false;
  std::string message;
};
Projection projection(const Lcs& sys, const IndexSet& I);

// F_I (|I| x n): u_I = F_I x keeps y_I = 0 on V_I and makes V_I invariant for
// x' = (A + B_.I F_I) x. Built from leading rows: y_i^(rho_i) = C_i A^rho_i x
// + (script M)_i u = 0 for i in I, so F_I = -(script M_II)^{-1} (C A^rho)_I.
// ok = false when script M_II is singular.
struct ModeFeedback {
  MatrixXd F;
  bool ok = false;
  std::string message;
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

// Mode selection by LDCP (§3.5.2) solved level by level as a series of LCPs
// with Schur complements of the leading row coefficient matrix (proof of
// Theorem 3.6.7, extended to the impulsive levels -n+1..0). Requires script M
// to be a P-matrix for uniqueness; a failing LCP is reported, not hidden.
struct ModeSelection {
  bool ok = false;
  std::string message;
  IndexSet mode;          // I: constraints with lexicographically positive u
  IndexSet undetermined;  // K: u and y identically zero so far (Remark 3.4.8)
  // Impulsive coefficients u^{-n+1..0}: impulse[j] multiplies delta^{(j)}.
  std::vector<VectorXd> impulse;
  VectorXd x_plus;  // re-initialised state x0 + sum_j A^j B u^{-j} (eq. (3.10))
  int lcp_solves = 0;
};
struct LdcpOptions {
  // A coefficient is treated as zero when |value| <= tol_rel * (sum of the
  // absolute values of the terms that formed it) + tol_abs.
  double tol_rel = 1e-9;
  double tol_abs = 1e-13;
  int first_level = 0;  // 0 = start at -n+1 (impulsive levels); 1 = regular part only
  const lcp::Solver* solver = nullptr;  // nullptr = principal pivoting
};
ModeSelection select_mode(const Lcs& sys, const VectorXd& x0, const LdcpOptions& opt = {});

}  // namespace lcsim::lcs
