// Lemke's complementary pivoting method with lexicographic degeneracy
// resolution (Cottle, Pang & Stone, "The Linear Complementarity Problem",
// §4.4 and §4.9).
//
// Tableau: w - M z - e z0 = q with basic variables x_B and basis matrix B.
// We keep B^{-1} (k x k) and x_B = B^{-1} q and update both by a rank-one
// (product-form) pivot update, O(k^2) per pivot; B^{-1} is refactorised from
// scratch only every max(64, k) pivots to bound the growth of rounding errors.
// Lexicographic rule: the rows of [x_B, B^{-1}] stay lexicographically
// positive, so the minimum ratio row is unique and no basis repeats.
#include <algorithm>
#include <cmath>
#include <exception>
#include <lcsim/lcp/lcp.hpp>
#include <string>
#include <vector>

#include "lcp/detail.hpp"

namespace lcsim::lcp {
namespace {

class LemkeTableau {
 public:
  // Variable ids: 0..k-1 are w_j, k..2k-1 are z_j, 2k is z0.
  LemkeTableau(const MatrixXd& M, const VectorXd& q)
      : M_(M), q_(q), k_(static_cast<int>(q.size())) {
    binv_.setIdentity(k_, k_);
    x_ = q;
    basis_.resize(k_);
    for (int i = 0; i < k_; ++i) basis_[i] = i;
    d_.resize(k_);
  }

  int k() const { return k_; }
  int z0() const { return 2 * k_; }
  int basic(int row) const { return basis_[row]; }

  // d = B^{-1} a_var, the entering column in the current tableau.
  const VectorXd& column(int var) {
    if (var < k_) {
      d_ = binv_.col(var);
    } else if (var < 2 * k_) {
      d_.noalias() = binv_ * M_.col(var - k_);
      d_ = -d_;
    } else {
      d_ = -binv_.rowwise().sum();
    }
    return d_;
  }

  // Pivot the entering variable (whose column is d_) into row r.
  void pivot(int r, int entering) {
    const double piv = d_(r);
    row_ = binv_.row(r) / piv;
    const double xr = x_(r) / piv;
    binv_.noalias() -= d_ * row_.transpose();
    binv_.row(r) = row_;
    x_ -= xr * d_;
    x_(r) = xr;
    basis_[r] = entering;
  }

  // Minimum ratio row among rows with d_i > 0 with lexicographic tie-breaking;
  // -1 if no row qualifies (secondary ray).
  int ratio_test() {
    const double dmax = d_.cwiseAbs().maxCoeff();
    const double piv_tol = 1e-12 * std::max(1.0, dmax);
    const double xmax = x_.cwiseAbs().maxCoeff();
    const double zero_tol = 1e-14 * xmax;  // basic values below this are rounding noise
    double theta_min = std::numeric_limits<double>::infinity();
    for (int i = 0; i < k_; ++i) {
      if (d_(i) > piv_tol) {
        const double xi = x_(i) > zero_tol ? x_(i) : 0.0;
        theta_min = std::min(theta_min, xi / d_(i));
      }
    }
    if (!std::isfinite(theta_min)) return -1;
    ties_.clear();
    for (int i = 0; i < k_; ++i) {
      if (d_(i) > piv_tol) {
        const double xi = x_(i) > zero_tol ? x_(i) : 0.0;
        if (xi / d_(i) <= theta_min * (1.0 + 1e-12)) ties_.push_back(i);
      }
    }
    if (ties_.size() == 1) return ties_[0];
    // z0 leaving ends the method at a solution: prefer it among ties.
    for (int i : ties_)
      if (basis_[i] == z0()) return i;
    // Lexicographic minimum of the rows B^{-1}_{i,:} / d_i, column by column.
    for (int j = 0; j < k_ && ties_.size() > 1; ++j) {
      double vmin = std::numeric_limits<double>::infinity();
      double scale = 0.0;
      for (int i : ties_) {
        const double v = binv_(i, j) / d_(i);
        vmin = std::min(vmin, v);
        scale = std::max(scale, std::abs(v));
      }
      const double tie_tol = 1e-11 * scale;
      std::erase_if(ties_, [&](int i) { return binv_(i, j) / d_(i) > vmin + tie_tol; });
    }
    return ties_[0];
  }

  // Rebuild B^{-1} and x_B from the basis (bounds accumulated rounding).
  bool refactor() {
    MatrixXd B(k_, k_);
    for (int i = 0; i < k_; ++i) B.col(i) = basis_column(basis_[i]);
    Eigen::PartialPivLU<MatrixXd> lu(B);
    if (!(lu.rcond() > 1e-14)) return false;
    binv_ = lu.inverse();
    x_.noalias() = binv_ * q_;
    return binv_.allFinite();
  }

  // Iterative refinement of x_B = B^{-1} q with the maintained inverse.
  void refine(int steps) {
    for (int s = 0; s < steps; ++s) {
      VectorXd r = q_;
      for (int i = 0; i < k_; ++i) {
        const int v = basis_[i];
        if (v < k_) {
          r(v) -= x_(i);
        } else if (v < 2 * k_) {
          r.noalias() += x_(i) * M_.col(v - k_);
        } else {
          r.array() += x_(i);
        }
      }
      x_.noalias() += binv_ * r;
    }
  }

  VectorXd z() const {
    VectorXd z = VectorXd::Zero(k_);
    for (int i = 0; i < k_; ++i)
      if (basis_[i] >= k_ && basis_[i] < 2 * k_) z(basis_[i] - k_) = std::max(0.0, x_(i));
    return z;
  }

  bool finite() const { return x_.allFinite() && d_.allFinite(); }

 private:
  VectorXd basis_column(int v) const {
    if (v < k_) return VectorXd::Unit(k_, v);
    if (v < 2 * k_) return -M_.col(v - k_);
    return -VectorXd::Ones(k_);
  }

  const MatrixXd& M_;
  const VectorXd& q_;
  int k_;
  MatrixXd binv_;
  VectorXd x_, d_, row_;
  std::vector<int> basis_;
  std::vector<int> ties_;
};

// Pivots on the row-equilibrated (Ms, qs) (lcp.hpp), judges z on (M, q).
Result lemke(const MatrixXd& M, const VectorXd& q, const MatrixXd& Ms, const VectorXd& qs,
             const Options& opt) {
  const int k = static_cast<int>(q.size());
  if (q.minCoeff() >= 0.0) return detail::finish(M, q, VectorXd::Zero(k), Status::kSolved, opt, "");
  const int cap = opt.max_pivots > 0 ? opt.max_pivots : 50 * k + 1000;
  const int refactor_every = std::max(64, k);

  LemkeTableau t(Ms, qs);
  // Initial pivot: z0 enters in the row of the most negative q_i. Among exact
  // ties the largest index keeps every row of [x_B, B^{-1}] lexicographically
  // positive: row i becomes (q_i - q_r, e_i - e_r), positive iff i < r on a tie.
  int r = 0;
  for (int i = 1; i < k; ++i)
    if (qs(i) <= qs(r)) r = i;
  t.column(t.z0());
  int leaving = t.basic(r);
  t.pivot(r, t.z0());
  int pivots = 1;
  int entering = leaving + k;  // complement of w_r is z_r
  while (true) {
    if (pivots >= cap) {
      Result res = detail::finish(M, q, t.z(), Status::kIterationLimit, opt,
                                  "pivot cap " + std::to_string(cap) + " reached");
      res.pivots = pivots;
      return res;
    }
    t.column(entering);
    if (!t.finite()) {
      Result res = detail::finish(M, q, VectorXd::Zero(k), Status::kNumericalFailure, opt,
                                  "non-finite tableau entries");
      res.pivots = pivots;
      return res;
    }
    r = t.ratio_test();
    if (r < 0) {
      Result res = detail::finish(M, q, t.z(), Status::kRayTermination, opt,
                                  "secondary ray: the entering variable is unbounded");
      res.pivots = pivots;
      return res;
    }
    leaving = t.basic(r);
    t.pivot(r, entering);
    ++pivots;
    if (leaving == t.z0()) break;
    entering = leaving < k ? leaving + k : leaving - k;
    if (pivots % refactor_every == 0 && !t.refactor()) {
      Result res = detail::finish(M, q, t.z(), Status::kNumericalFailure, opt,
                                  "singular basis on refactorisation");
      res.pivots = pivots;
      return res;
    }
  }
  t.refine(2);
  Result res = detail::finish(M, q, t.z(), Status::kSolved, opt, "");
  res.pivots = pivots;
  return res;
}

}  // namespace

Result solve_lemke(const MatrixXd& M, const VectorXd& q, const Options& opt) {
  const std::string bad = detail::validate_all(M, q, opt);
  if (!bad.empty()) return detail::invalid(bad);
  try {
    const detail::Scaling eq = detail::equilibrate_rows(M, q);
    return lemke(M, q, eq.M, eq.q, opt);
  } catch (const std::exception& e) {
    Result r;
    r.status = Status::kNumericalFailure;
    r.message = std::string("exception in Lemke: ") + e.what();
    return r;
  }
}

}  // namespace lcsim::lcp
