// Projected Gauss–Seidel / SOR (Cottle, Pang & Stone §5.2):
//   z_i <- max(0, z_i - omega * w_i / M_ii),  w = M z + q,
// sweeping i = 0..k-1. w is kept current by a column update after each change
// (w += dz_i M_:,i), so a sweep costs one pass over M in storage order and the
// natural residual is available after every sweep; it is recomputed from
// scratch before a solution is reported.
#include <algorithm>
#include <cmath>
#include <exception>
#include <lcsim/lcp/lcp.hpp>
#include <string>

#include "lcp/detail.hpp"

namespace lcsim::lcp {
namespace {

Result pgs(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  const int k = static_cast<int>(q.size());
  for (int i = 0; i < k; ++i)
    if (!(M(i, i) > 0.0))
      return detail::finish(M, q, VectorXd::Zero(k), Status::kNumericalFailure, opt,
                            "PGS needs a positive diagonal; M(" + std::to_string(i) + "," +
                                std::to_string(i) + ") = " + std::to_string(M(i, i)));
  // Half the acceptance tolerance: the running w and s drift by rounding
  // before the fresh confirmation below.
  const double acc = 0.5 * opt.tolerance;
  VectorXd z = opt.warm_start ? VectorXd(opt.warm_start->cwiseMax(0.0)) : VectorXd::Zero(k);
  VectorXd w = M * z + q;
  const MatrixXd absM = M.cwiseAbs();
  VectorXd s = absM * z + q.cwiseAbs();  // row magnitudes s_i of scaled_residual (z >= 0)
  const VectorXd inv_diag = M.diagonal().cwiseInverse();
  const double omega = opt.relaxation;
  int it = 0;
  // The row-scaled residual (lcp.hpp) from the running w and s, O(k).
  auto residual = [&] {
    const double zn = z.maxCoeff();
    double worst = 0.0;
    for (int i = 0; i < k; ++i) {
      const double a = zn > 0.0 ? z(i) / zn : 0.0, b = s(i) > 0.0 ? w(i) / s(i) : 0.0;
      worst = std::max(worst, std::abs(std::min(a, b)));
    }
    return worst;
  };
  bool converged = residual() <= acc;
  while (!converged && it < opt.max_iterations) {
    for (int i = 0; i < k; ++i) {
      const double zi = std::max(0.0, z(i) - omega * w(i) * inv_diag(i));
      const double dz = zi - z(i);
      if (dz != 0.0) {
        z(i) = zi;
        w.noalias() += dz * M.col(i);
        s.noalias() += dz * absM.col(i);  // z_i, zi >= 0: |zi| - |z_i| = dz
      }
    }
    ++it;
    if (residual() <= acc) {
      // Confirm against a fresh w and s (the running updates drift by rounding).
      w.noalias() = M * z;
      w += q;
      s.noalias() = absM * z;
      s += q.cwiseAbs();
      converged = residual() <= acc;
    }
  }
  Result r = detail::finish(
      M, q, z, converged ? Status::kSolved : Status::kIterationLimit, opt,
      converged ? "" : "no convergence in " + std::to_string(opt.max_iterations) + " sweeps");
  r.iterations = it;
  return r;
}

}  // namespace

Result solve_pgs(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    return pgs(M, q, opt);
  } catch (const std::exception& e) {
    Result r;
    r.status = Status::kNumericalFailure;
    r.message = std::string("exception in PGS: ") + e.what();
    return r;
  }
}

}  // namespace lcsim::lcp
