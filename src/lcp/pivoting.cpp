// Principal pivoting for P-matrix LCPs (Cottle, Pang & Stone §4.2):
//  - Murty's least-index method ("Murty's Bard-type scheme"): flip the least
//    infeasible index; finite for every P-matrix, nonsymmetric included, but
//    2^k - 1 pivots in the worst case (Murty 1978).
//  - block principal pivoting (Júdice & Pires 1994): flip every infeasible
//    index at once; when the number of infeasibilities has not dropped below
//    its best value for kBlockTries iterations, take single least-index steps
//    (Murty) until it does. Finite on P-matrices because Murty's method is
//    finite and the best count strictly decreases between block phases.
//
// Each iteration solves M_aa z_a = -q_a from scratch (Cholesky when M is
// symmetric, partial-pivoting LU otherwise) and sets w = M z + q.
#include <algorithm>
#include <cmath>
#include <exception>
#include <string>
#include <vector>

#include "lcp/detail.hpp"
#include "lcp/lcp.hpp"

namespace lcsim::lcp {
namespace {

constexpr int kBlockTries = 3;

Result principal_pivoting(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block) {
  const int k = static_cast<int>(q.size());
  const int cap = opt.max_pivots > 0 ? opt.max_pivots : (k <= 20 ? (1 << k) + 10 : 50 * k + 1000);
  const double eps = 0.25 * detail::acceptance(q, opt);
  const bool symmetric = is_symmetric(M);

  std::vector<char> in(k, 0);  // in[i]: z_i basic (w_i = 0)
  std::vector<int> alpha, infeasible;
  VectorXd z = VectorXd::Zero(k), w = q;
  MatrixXd Maa;
  VectorXd za;
  Eigen::LLT<MatrixXd> llt;
  Eigen::PartialPivLU<MatrixXd> lu;

  int best = k + 1, tries = kBlockTries, pivots = 0, iterations = 0;
  auto done = [&](Status s, std::string msg) {
    Result r = detail::finish(M, q, z, s, opt, std::move(msg));
    r.pivots = pivots;
    r.iterations = iterations;
    return r;
  };
  while (true) {
    infeasible.clear();
    for (int i = 0; i < k; ++i)
      if (in[i] ? z(i) < -eps : w(i) < -eps) infeasible.push_back(i);
    if (infeasible.empty()) return done(Status::kSolved, "");
    if (iterations >= cap)
      return done(Status::kIterationLimit, "cap of " + std::to_string(cap) + " pivots reached");
    const int n_inf = static_cast<int>(infeasible.size());
    if (block && n_inf < best) {
      best = n_inf;
      tries = kBlockTries;
      for (int i : infeasible) in[i] ^= 1;
      pivots += n_inf;
    } else if (block && tries > 0) {
      --tries;
      for (int i : infeasible) in[i] ^= 1;
      pivots += n_inf;
    } else {
      in[infeasible.front()] ^= 1;  // Murty: least index
      ++pivots;
    }
    ++iterations;

    alpha.clear();
    for (int i = 0; i < k; ++i)
      if (in[i]) alpha.push_back(i);
    z.setZero();
    if (!alpha.empty()) {
      Maa = M(alpha, alpha);
      bool solved = false;
      if (symmetric) {
        llt.compute(Maa);
        if (llt.info() == Eigen::Success) {
          za = -llt.solve(q(alpha));
          solved = true;
        }
      }
      if (!solved) {
        lu.compute(Maa);
        if (!(lu.rcond() > 1e-14))
          return done(Status::kNumericalFailure, "singular principal submatrix of order " +
                                                     std::to_string(alpha.size()) +
                                                     ": M is not a P-matrix");
        za = -lu.solve(q(alpha));
      }
      z(alpha) = za;
    }
    w.noalias() = M * z;
    w += q;
    if (!z.allFinite() || !w.allFinite())
      return done(Status::kNumericalFailure, "non-finite values in a principal pivot");
  }
}

Result guarded(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    return principal_pivoting(M, q, opt, block);
  } catch (const std::exception& e) {
    Result r;
    r.status = Status::kNumericalFailure;
    r.message = std::string("exception in principal pivoting: ") + e.what();
    return r;
  }
}

}  // namespace

Result solve_principal_pivoting(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  return guarded(M, q, opt, /*block=*/true);
}

Result solve_murty(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  return guarded(M, q, opt, /*block=*/false);
}

}  // namespace lcsim::lcp
