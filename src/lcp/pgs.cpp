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
  const double acc = detail::acceptance(q, opt);
  VectorXd z = opt.warm_start ? VectorXd(opt.warm_start->cwiseMax(0.0)) : VectorXd::Zero(k);
  VectorXd w = M * z + q;
  const VectorXd inv_diag = M.diagonal().cwiseInverse();
  const double omega = opt.relaxation;
  int it = 0;
  auto residual = [&] { return z.cwiseMin(w).cwiseAbs().maxCoeff(); };
  bool converged = residual() <= 0.5 * acc;
  while (!converged && it < opt.max_iterations) {
    for (int i = 0; i < k; ++i) {
      const double zi = std::max(0.0, z(i) - omega * w(i) * inv_diag(i));
      const double dz = zi - z(i);
      if (dz != 0.0) {
        z(i) = zi;
        w.noalias() += dz * M.col(i);
      }
    }
    ++it;
    if (residual() <= 0.5 * acc) {
      // Confirm against a fresh w (the running update drifts by rounding).
      w.noalias() = M * z;
      w += q;
      converged = residual() <= 0.5 * acc;
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
