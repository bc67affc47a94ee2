// Internal helpers shared by the LCP solvers (not part of the public face).
#pragma once

#include <lcsim/lcp/lcp.hpp>
#include <string>

namespace lcsim::lcp::detail {

// Scaled acceptance threshold tolerance * (1 + ||q||_inf) (see Options::tolerance).
double acceptance(const VectorXd& q, const Options& opt);

// Principal pivoting treats z_i or w_i as zero (not infeasible) down to
// -kPivotZero * acceptance; the warm-started pivot (warm_pivot.cpp) measures
// its margin in the same unit.
constexpr double kPivotZero = 0.25;

// Validates (M, q) and the options; "" when fine.
std::string validate_all(const MatrixXd& M, const VectorXd& q, const Options& opt);

// A kInvalidInput result carrying `message`.
Result invalid(std::string message);

// Fills the diagnostics of z and decides the final status: a `claimed` kSolved
// is kept only if the residual check passes (residual <= acceptance, z >= -acc,
// w >= -acc); otherwise it becomes kNumericalFailure with an explanation.
Result finish(const MatrixXd& M, const VectorXd& q, VectorXd z, Status claimed, const Options& opt,
              std::string message);

}  // namespace lcsim::lcp::detail
