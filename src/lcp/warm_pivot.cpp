// WarmPivot: principal pivoting's answer on the previous solution's basis
// (include/lcsim/lcp/sparse.hpp), accepted by the pivoting solver's own test
// (pivoting.cpp: tolerance and zero threshold from detail.hpp) with a margin.
#include <algorithm>
#include <cmath>
#include <lcsim/lcp/sparse.hpp>

#include "lcp/detail.hpp"

namespace lcsim::lcp {

const Result& WarmPivot::reject() {
  result_.status = Status::kNumericalFailure;
  result_.message = "the guessed basis fails the acceptance test with its margin";
  return result_;
}

const Result& WarmPivot::solve(const MatrixXd& M, long version, const VectorXd& q,
                               const VectorXd& z_prev, const Options& opt) {
  const int na = static_cast<int>(q.size());
  J_.clear();
  for (int a = 0; a < na; ++a)
    if (z_prev(a) > 0.0) J_.push_back(a);
  const int nj = static_cast<int>(J_.size());
  if (nj > 0) {
    if (version != version_ || J_ != J_factored_) {
      Mjj_.resize(nj, nj);
      for (int c = 0; c < nj; ++c)
        for (int r = 0; r < nj; ++r) Mjj_(r, c) = M(J_[r], J_[c]);
      llt_.compute(Mjj_);
      version_ = version;
      J_factored_ = J_;
    }
    if (llt_.info() != Eigen::Success) return reject();
    // zj = -M_JJ^{-1} q_J, as the pivoting solver computes it (-llt.solve(q_J)).
    zj_.resize(nj);
    for (int c = 0; c < nj; ++c) zj_(c) = q(J_[c]);
    llt_.solveInPlace(zj_);
    zj_ = -zj_;
  }
  // The pivoting solver's test, row by row (pivoting.cpp), with a margin;
  // w = M z + q with z zero off J.
  const double zn = nj > 0 ? zj_.cwiseAbs().maxCoeff() : 0.0;
  const double eps = kMargin * detail::kPivotZero * opt.tolerance;
  for (int c = 0; c < nj; ++c)
    if (!(zj_(c) > eps * zn)) return reject();  // also refuses NaN
  Result& r = result_;
  r.w.resize(na);
  r.residual = 0.0;
  r.min_w = 0.0;
  int next = 0;  // J_ is sorted
  for (int a = 0; a < na; ++a) {
    double w = q(a), scale = std::abs(q(a));  // scale: |q_a| + sum_c |M_ac| |z_c|
    for (int c = 0; c < nj; ++c) {
      w += M(a, J_[c]) * zj_(c);
      scale += std::abs(M(a, J_[c]) * zj_(c));
    }
    r.w(a) = w;
    const double margin = eps * scale;
    if (next < nj && J_[next] == a) {
      ++next;
      if (!(std::abs(w) <= opt.tolerance * scale)) return reject();
      r.residual = std::max(r.residual, std::abs(w));  // min(z_a, w_a) = w_a: z_a > margin
      r.min_w = std::min(r.min_w, w);
    } else if (!(w > margin)) {
      return reject();
    }
  }
  r.z.setZero(na);
  for (int c = 0; c < nj; ++c) r.z(J_[c]) = zj_(c);
  r.status = Status::kSolved;
  r.message.clear();
  r.pivots = 0;
  r.iterations = 0;
  r.min_z = 0.0;
  return r;
}

}  // namespace lcsim::lcp
