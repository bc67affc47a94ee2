// Internal helpers shared by the LCP solvers (not part of the public face).
#pragma once

#include <lcsim/lcp/lcp.hpp>
#include <string>

namespace lcsim::lcp::detail {

// Principal pivoting treats a row as infeasible only beyond kPivotZero times
// the acceptance tolerance, each row against its own scale (z_i against
// ||z||_inf, w_i against s_i = |q_i| + sum_j |M_ij| |z_j|, as
// scaled_residual); the warm-started pivot (warm_pivot.cpp) measures its
// margin in the same unit.
constexpr double kPivotZero = 0.25;

// Validates (M, q) and the options; "" when fine.
std::string validate_all(const MatrixXd& M, const VectorXd& q, const Options& opt);

// A kInvalidInput result carrying `message`.
Result invalid(std::string message);

// Fills the diagnostics of z and decides the final status: a `claimed` kSolved
// is kept only if the acceptance test passes (scaled_residual <= opt.tolerance,
// the one test of every solver); otherwise it becomes kNumericalFailure with a
// message naming the worst row.
Result finish(const MatrixXd& M, const VectorXd& q, VectorXd z, Status claimed, const Options& opt,
              std::string message);

// The one way the LCP layer rescales an LCP: rows by r > 0 and the unknowns
// by c > 0, M' = diag(r) M diag(c), q' = diag(r) q, z = diag(c) z'. The
// solution sets correspond exactly (0 <= z' ⟂ diag(r) w >= 0 iff
// 0 <= z ⟂ w >= 0). Solvers equilibrate rows (equilibrate_rows); solve_scaled
// scales symmetrically (symmetric_scaling).
struct Scaling {
  VectorXd r, c;
  MatrixXd M;  // the scaled M'
  VectorXd q;  // the scaled q'
  VectorXd unscale(const VectorXd& z_scaled) const { return c.cwiseProduct(z_scaled); }
};
Scaling scale(const MatrixXd& M, const VectorXd& q, VectorXd r, VectorXd c);
// 2^-e with 2^(e - 1) <= m < 2^e (1 if m is 0 or not finite, e clamped to
// [-1000, 1000]): the power of two that brings a row of largest magnitude m
// to [0.5, 1), exactly.
double row_scale(double m);
// r_i = 2^-e_i with 2^(e_i - 1) <= max_j |M_ij| < 2^e_i (|q_i| for a zero row,
// 1 if both vanish), c = 1: powers of two, so M' and q' are exact.
Scaling equilibrate_rows(const MatrixXd& M, const VectorXd& q);
// r = D / s, c = s D with D = diag(1 / sqrt(M_ii)) (1 where M_ii <= 0) and
// s = max |D q| (1 if 0): M' = D M D, q' = D q / s (see solve_scaled).
Scaling symmetric_scaling(const MatrixXd& M, const VectorXd& q);

}  // namespace lcsim::lcp::detail
