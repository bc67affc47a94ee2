// Projected Gauss–Seidel on a sparse symmetric LCP (include/lcsim/lcp/sparse.hpp):
// lcp::solve_pgs works on dense matrices only; this sweep reads the rows of a
// compressed row-major matrix, so a sweep costs O(nnz).
#include <algorithm>
#include <cmath>
#include <exception>
#include <lcsim/lcp/sparse.hpp>
#include <string>

#include "lcp/detail.hpp"

namespace lcsim::lcp {
namespace {

// The input errors of a sparse problem, "" when fine.
std::string validate_sparse(const SparseRowMatrix& M, const VectorXd& q, const Options& opt) {
  if (M.rows() != M.cols() || M.rows() != q.size())
    return "M is " + std::to_string(M.rows()) + " x " + std::to_string(M.cols()) + " and q has " +
           std::to_string(q.size()) + " entries: M must be square of q's size";
  if (!q.allFinite()) return "q has a non-finite entry";
  for (Eigen::Index i = 0; i < M.nonZeros(); ++i)
    if (!std::isfinite(M.valuePtr()[i])) return "M has a non-finite entry";
  if (!(opt.tolerance >= 0.0) || !std::isfinite(opt.tolerance))
    return "tolerance must be finite and >= 0, got " + std::to_string(opt.tolerance);
  if (opt.max_iterations < 1)
    return "max_iterations must be >= 1, got " + std::to_string(opt.max_iterations);
  if (opt.warm_start && opt.warm_start->size() != q.size())
    return "warm start has " + std::to_string(opt.warm_start->size()) + " entries, q has " +
           std::to_string(q.size());
  return "";
}

// z, w = M z + q and the diagnostics of z.
Result evaluated(const SparseRowMatrix& M, const VectorXd& q, VectorXd z, Status status) {
  Result r;
  r.status = status;
  r.w = M * z + q;
  r.residual = z.size() ? z.cwiseMin(r.w).cwiseAbs().maxCoeff() : 0.0;
  r.min_z = z.size() ? std::min(0.0, z.minCoeff()) : 0.0;
  r.min_w = z.size() ? std::min(0.0, r.w.minCoeff()) : 0.0;
  r.z = std::move(z);
  return r;
}

// One sweep in index order; returns the largest change M_aa |dz_a|.
double sweep(const SparseRowMatrix& M, const VectorXd& q, const VectorXd& diag, VectorXd& z) {
  double change = 0.0;
  for (Eigen::Index a = 0; a < q.size(); ++a) {
    double r = q(a);
    for (SparseRowMatrix::InnerIterator it(M, a); it; ++it) r += it.value() * z(it.col());
    const double za = std::max(0.0, z(a) - r / diag(a));
    change = std::max(change, std::abs(za - z(a)) * diag(a));
    z(a) = za;
  }
  return change;
}

Result sparse_pgs(const SparseRowMatrix& M, const VectorXd& q, const Options& opt) {
  const Eigen::Index n = q.size();
  VectorXd diag(n);
  for (Eigen::Index a = 0; a < n; ++a) {
    diag(a) = M.coeff(a, a);
    if (!(diag(a) > 0.0)) {
      Result r = evaluated(M, q, VectorXd::Zero(n), Status::kNumericalFailure);
      r.message = "PGS needs a positive diagonal; M(" + std::to_string(a) + "," +
                  std::to_string(a) + ") = " + std::to_string(diag(a));
      return r;
    }
  }
  VectorXd z = opt.warm_start ? VectorXd(opt.warm_start->cwiseMax(0.0)) : VectorXd::Zero(n);
  // The sweeps' own stopping rule, absolute in the units of q (as before the
  // row-scaled acceptance of the dense solvers; Moreau–Jean's steps depend
  // on it): tolerance (1 + ||q||_inf).
  const double tol = opt.tolerance * (1.0 + q.cwiseAbs().maxCoeff());
  for (int sweeps = 1; sweeps <= opt.max_iterations; ++sweeps) {
    if (sweep(M, q, diag, z) > tol) continue;
    const VectorXd w = M * z + q;
    if (z.cwiseMin(w).cwiseAbs().maxCoeff() <= tol) {
      Result r = evaluated(M, q, std::move(z), Status::kSolved);
      r.iterations = sweeps;
      return r;
    }
  }
  Result r = evaluated(M, q, std::move(z), Status::kIterationLimit);
  r.iterations = opt.max_iterations;
  r.message = "no convergence in " + std::to_string(opt.max_iterations) + " sweeps";
  return r;
}

}  // namespace

Result solve_sparse_pgs(const SparseRowMatrix& M, const VectorXd& q, const Options& opt) {
  const std::string bad = validate_sparse(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    return sparse_pgs(M, q, opt);
  } catch (const std::exception& e) {
    Result r;
    r.status = Status::kNumericalFailure;
    r.message = std::string("exception in sparse PGS: ") + e.what();
    return r;
  }
}

}  // namespace lcsim::lcp
