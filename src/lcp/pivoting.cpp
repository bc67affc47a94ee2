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
// Storage is fixed-capacity (no heap) up to k = 16.
#include <algorithm>
#include <cmath>
#include <exception>
#include <lcsim/lcp/lcp.hpp>
#include <string>
#include <vector>

#include "lcp/detail.hpp"

namespace lcsim::lcp {
namespace {

constexpr int kBlockTries = 3;

// MaxK: the largest k the storage holds without the heap (Eigen::Dynamic: any
// k). Small problems (k <= 16, the contacts of one impact or step) run
// allocation-free up to the result; at k = 4 the allocations had been half
// the time of a solve.
template <int MaxK>
Result principal_pivoting(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block) {
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, MaxK, MaxK>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxK, 1>;
  using Idx = Eigen::Matrix<int, Eigen::Dynamic, 1, Eigen::ColMajor, MaxK, 1>;
  const int k = static_cast<int>(q.size());
  const int cap = opt.max_pivots > 0 ? opt.max_pivots : (k <= 20 ? (1 << k) + 10 : 50 * k + 1000);
  // A quarter of the acceptance tolerance, each row against its own scale
  // (scaled_residual in lcp.hpp): row i is infeasible when z_i < -eps ||z||
  // or w_i < -eps s_i, s_i = |q_i| + sum_j |M_ij| |z_j|. The margin leaves
  // room for rounding before the acceptance test of finish().
  const double eps = detail::kPivotZero * opt.tolerance;
  const bool symmetric = is_symmetric(M);

  Idx in = Idx::Zero(k);  // in(i): z_i basic (w_i = 0)
  Idx alpha(k), infeasible(k);
  Vec z = Vec::Zero(k), w = q, s = q.cwiseAbs(), qa(k), za(k);
  Mat Maa(k, k);
  Eigen::LLT<Mat> llt(k);
  Eigen::PartialPivLU<Mat> lu(k);

  int best = k + 1, tries = kBlockTries, pivots = 0, iterations = 0;
  auto done = [&](Status s, std::string msg) {
    Result r = detail::finish(M, q, VectorXd(z), s, opt, std::move(msg));
    r.pivots = pivots;
    r.iterations = iterations;
    return r;
  };
  while (true) {
    int n_inf = 0;
    const double zn = z.cwiseAbs().maxCoeff();
    for (int i = 0; i < k; ++i)
      if (in(i) ? z(i) < -eps * zn : w(i) < -eps * s(i)) infeasible(n_inf++) = i;
    if (n_inf == 0) return done(Status::kSolved, "");
    if (iterations >= cap)
      return done(Status::kIterationLimit, "cap of " + std::to_string(cap) + " pivots reached");
    if (block && n_inf < best) {
      best = n_inf;
      tries = kBlockTries;
      for (int j = 0; j < n_inf; ++j) in(infeasible(j)) ^= 1;
      pivots += n_inf;
    } else if (block && tries > 0) {
      --tries;
      for (int j = 0; j < n_inf; ++j) in(infeasible(j)) ^= 1;
      pivots += n_inf;
    } else {
      in(infeasible(0)) ^= 1;  // Murty: least index
      ++pivots;
    }
    ++iterations;

    int na = 0;
    for (int i = 0; i < k; ++i)
      if (in(i)) alpha(na++) = i;
    z.setZero();
    if (na > 0) {
      Maa.resize(na, na);
      qa.resize(na);
      for (int c = 0; c < na; ++c) {
        qa(c) = q(alpha(c));
        for (int r = 0; r < na; ++r) Maa(r, c) = M(alpha(r), alpha(c));
      }
      bool solved = false;
      if (symmetric) {
        llt.compute(Maa);
        if (llt.info() == Eigen::Success) {
          za = -llt.solve(qa);
          solved = true;
        }
      }
      if (!solved) {
        // Rows equilibrated by powers of two (exact; lcp.hpp) so that the
        // rank test below sees rows of one size.
        for (int r = 0; r < na; ++r) {
          const double d = detail::row_scale(Maa.row(r).cwiseAbs().maxCoeff());
          Maa.row(r) *= d;
          qa(r) *= d;
        }
        lu.compute(Maa);
        if (!(lu.rcond() > 1e-14))
          return done(Status::kNumericalFailure, "singular principal submatrix of order " +
                                                     std::to_string(na) + ": M is not a P-matrix");
        za = -lu.solve(qa);
      }
      for (int c = 0; c < na; ++c) z(alpha(c)) = za(c);
    }
    w.noalias() = M * z;
    w += q;
    for (int i = 0; i < k; ++i) {
      double si = std::abs(q(i));
      for (int j = 0; j < k; ++j) si += std::abs(M(i, j)) * std::abs(z(j));
      s(i) = si;
    }
    if (!z.allFinite() || !w.allFinite())
      return done(Status::kNumericalFailure, "non-finite values in a principal pivot");
  }
}

Result guarded(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    constexpr int kSmall = 16;
    return q.size() <= kSmall ? principal_pivoting<kSmall>(M, q, opt, block)
                              : principal_pivoting<Eigen::Dynamic>(M, q, opt, block);
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
