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

// One principal pivoting run on (M, q). MaxK: the largest k the storage holds
// without the heap (Eigen::Dynamic: any k). Small problems (k <= 16, the
// contacts of one impact or step) run allocation-free up to the result; at
// k = 4 the allocations had been half the time of a solve.
template <int MaxK>
class PrincipalPivoting {
  using Mat = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::ColMajor, MaxK, MaxK>;
  using Vec = Eigen::Matrix<double, Eigen::Dynamic, 1, Eigen::ColMajor, MaxK, 1>;
  using Idx = Eigen::Matrix<int, Eigen::Dynamic, 1, Eigen::ColMajor, MaxK, 1>;

 public:
  PrincipalPivoting(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block)
      : M_(M),
        q_(q),
        opt_(opt),
        block_(block),
        k_(static_cast<int>(q.size())),
        cap_(opt.max_pivots > 0 ? opt.max_pivots : (k_ <= 20 ? (1 << k_) + 10 : 50 * k_ + 1000)),
        eps_(detail::kPivotZero * opt.tolerance),
        symmetric_(is_symmetric(M)),
        in_(Idx::Zero(k_)),
        alpha_(k_),
        infeasible_(k_),
        z_(Vec::Zero(k_)),
        w_(q),
        s_(q.cwiseAbs()),
        qa_(k_),
        za_(k_),
        Maa_(k_, k_),
        llt_(k_),
        lu_(k_) {}

  // The driver: find the infeasible indices, flip, re-solve, until none is
  // left (or the cap, or a singular or non-finite step).
  Result run() {
    while (true) {
      const int n_inf = find_infeasible();
      if (n_inf == 0) return done(Status::kSolved, "");
      if (iterations_ >= cap_)
        return done(Status::kIterationLimit, "cap of " + std::to_string(cap_) + " pivots reached");
      flip(n_inf);
      ++iterations_;
      const int singular = solve_basic();
      if (singular > 0)
        return done(Status::kNumericalFailure, "singular principal submatrix of order " +
                                                   std::to_string(singular) +
                                                   ": M is not a P-matrix");
      update_w();
      if (!z_.allFinite() || !w_.allFinite())
        return done(Status::kNumericalFailure, "non-finite values in a principal pivot");
    }
  }

 private:
  // Fills infeasible_ with the infeasible indices, increasing; returns their
  // count. A quarter of the acceptance tolerance, each row against its own
  // scale (scaled_residual in lcp.hpp): row i is infeasible when
  // z_i < -eps ||z|| or w_i < -eps s_i, s_i = |q_i| + sum_j |M_ij| |z_j|. The
  // margin leaves room for rounding before the acceptance test of finish().
  int find_infeasible() {
    int n_inf = 0;
    const double zn = z_.cwiseAbs().maxCoeff();
    for (int i = 0; i < k_; ++i)
      if (in_(i) ? z_(i) < -eps_ * zn : w_(i) < -eps_ * s_(i)) infeasible_(n_inf++) = i;
    return n_inf;
  }

  // Block pivoting (Júdice & Pires) flips every infeasible index while their
  // count drops below its best, or for kBlockTries more tries; otherwise
  // Murty's least index.
  void flip(int n_inf) {
    if (block_ && n_inf < best_) {
      best_ = n_inf;
      tries_ = kBlockTries;
      flip_all(n_inf);
    } else if (block_ && tries_ > 0) {
      --tries_;
      flip_all(n_inf);
    } else {
      in_(infeasible_(0)) ^= 1;  // Murty: least index
      ++pivots_;
    }
  }
  void flip_all(int n_inf) {
    for (int j = 0; j < n_inf; ++j) in_(infeasible_(j)) ^= 1;
    pivots_ += n_inf;
  }

  // z_a = -M_aa^{-1} q_a on the basic set a = {i : in(i)}, z = 0 elsewhere.
  // Returns 0, or the order of M_aa when it is singular (z then stays 0).
  int solve_basic() {
    int na = 0;
    for (int i = 0; i < k_; ++i)
      if (in_(i)) alpha_(na++) = i;
    z_.setZero();
    if (na == 0) return 0;
    Maa_.resize(na, na);
    qa_.resize(na);
    for (int c = 0; c < na; ++c) {
      qa_(c) = q_(alpha_(c));
      for (int r = 0; r < na; ++r) Maa_(r, c) = M_(alpha_(r), alpha_(c));
    }
    if (!(symmetric_ && cholesky()) && !equilibrated_lu()) return na;
    for (int c = 0; c < na; ++c) z_(alpha_(c)) = za_(c);
    return 0;
  }
  // za = -M_aa^{-1} q_a by Cholesky; false when M_aa is not positive definite.
  bool cholesky() {
    llt_.compute(Maa_);
    if (llt_.info() != Eigen::Success) return false;
    za_ = -llt_.solve(qa_);
    return true;
  }
  // za = -M_aa^{-1} q_a by partial-pivoting LU, rows equilibrated by powers of
  // two (exact; lcp.hpp) so that the rank test sees rows of one size; false
  // when M_aa is singular.
  bool equilibrated_lu() {
    for (int r = 0; r < Maa_.rows(); ++r) {
      const double d = detail::row_scale(Maa_.row(r).cwiseAbs().maxCoeff());
      Maa_.row(r) *= d;
      qa_(r) *= d;
    }
    lu_.compute(Maa_);
    if (!(lu_.rcond() > 1e-14)) return false;
    za_ = -lu_.solve(qa_);
    return true;
  }

  // w = M z + q and the row scales s_i = |q_i| + sum_j |M_ij| |z_j|.
  void update_w() {
    w_.noalias() = M_ * z_;
    w_ += q_;
    for (int i = 0; i < k_; ++i) {
      double si = std::abs(q_(i));
      for (int j = 0; j < k_; ++j) si += std::abs(M_(i, j)) * std::abs(z_(j));
      s_(i) = si;
    }
  }

  Result done(Status status, std::string msg) const {
    Result r = detail::finish(M_, q_, VectorXd(z_), status, opt_, std::move(msg));
    r.pivots = pivots_;
    r.iterations = iterations_;
    return r;
  }

  const MatrixXd& M_;
  const VectorXd& q_;
  const Options& opt_;
  const bool block_;
  const int k_, cap_;
  const double eps_;
  const bool symmetric_;
  Idx in_;  // in(i): z_i basic (w_i = 0)
  Idx alpha_, infeasible_;
  Vec z_, w_, s_, qa_, za_;
  Mat Maa_;
  Eigen::LLT<Mat> llt_;
  Eigen::PartialPivLU<Mat> lu_;
  int best_ = k_ + 1, tries_ = kBlockTries, pivots_ = 0, iterations_ = 0;
};

Result guarded(const MatrixXd& M, const VectorXd& q, const Options& opt, bool block) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    constexpr int kSmall = 16;
    return q.size() <= kSmall ? PrincipalPivoting<kSmall>(M, q, opt, block).run()
                              : PrincipalPivoting<Eigen::Dynamic>(M, q, opt, block).run();
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
