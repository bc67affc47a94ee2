// Private to src/sim: the kernels of the Moreau–Jean step (moreau_jean.cpp).
// Sparse-times-dense products without Eigen's per-call set-up, the products
// with the model's matrices (MjOperators) and the factored iteration matrix
// W = M + h theta D + h^2 theta^2 K with its cached columns W^{-1} E_i'
// (MjIteration, mj_iteration.cpp).
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim::sim::detail {

using Eigen::MatrixXd;
using SparseCol = Eigen::SparseMatrix<double, Eigen::ColMajor>;
using SparseRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Sparse times dense on compressed matrices, by the loops of Eigen 3.4's
// sparse_time_dense_product_impl in the same order (so the same rounding: a
// row sum from 0 in storage order; a column sweep adding A_ij (alpha x_j)),
// without its per-call set-up (resize, zeroing, evaluators), which costs more
// than the arithmetic on the 2 x 2 models of the thesis.
// out = A x, A by rows.
inline void times(const SparseRow& A, const VectorXd& x, VectorXd& out) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    double s = 0.0;
    for (int p = outer[i]; p < outer[i + 1]; ++p) s += val[p] * x[inner[p]];
    out[i] = s;
  }
}
// out += alpha A x, A by columns.
inline void add_times(const SparseCol& A, double alpha, const VectorXd& x, VectorXd& out) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    const double xj = alpha * x[j];
    for (int p = outer[j]; p < outer[j + 1]; ++p) out[inner[p]] += val[p] * xj;
  }
}

// x.allFinite() without its two subtractions per entry.
inline bool all_finite(const VectorXd& x) {
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i])) return false;
  return true;
}

// Products with the model's matrices (held sparse, mech::MechanicalModel).
// `sparse` chooses how W is factored, nothing else.
class MjOperators {
 public:
  MjOperators(const mech::MechanicalModel& m, bool sparse)
      : m_(m),
        sparse_(sparse),
        Ec_(m.E),
        Er_(m.E),
        Er_abs_(m.E.cwiseAbs()),
        g_abs_(m.g.cwiseAbs()),
        K_(m.K),
        D_(m.D),
        f_(m.f) {
    Ec_.makeCompressed();
    Er_.makeCompressed();
    Er_abs_.makeCompressed();
    K_.makeCompressed();
    D_.makeCompressed();
    Gt_ = contact_rows_transposed(m);
  }
  bool sparse() const { return sparse_; }
  int dofs() const { return m_.dofs(); }
  int constraints() const { return m_.num_constraints(); }
  const SparseCol& E_by_columns() const { return Ec_; }
  // [E; T]' (N x (k + n_F)): column i < k is E_i', column k + f the tangent
  // row of m.friction[f] (the rows whose W^{-1} columns MjIteration caches).
  // Models with 3-D friction: n_F more columns, k + n_F + f the second
  // tangent of m.friction[f] (empty for a planar contact).
  const SparseCol& rows_transposed() const { return Gt_; }
  static SparseCol contact_rows_transposed(const mech::MechanicalModel& m) {
    SparseCol Gt = m.E.transpose();
    const int k = m.num_constraints(), nf = static_cast<int>(m.friction.size());
    Gt.conservativeResize(m.dofs(), k + (m.has_friction_3d() ? 2 : 1) * nf);
    auto put = [&Gt](const Eigen::SparseVector<double>& t, int col) {
      for (Eigen::SparseVector<double>::InnerIterator it(t); it; ++it)
        if (it.value() != 0.0) Gt.insert(it.index(), col) = it.value();
    };
    for (int f = 0; f < nf; ++f) {
      put(m.friction[static_cast<size_t>(f)].tangent, k + f);
      if (m.friction[static_cast<size_t>(f)].is_3d())
        put(m.friction[static_cast<size_t>(f)].tangent2, k + nf + f);
    }
    Gt.makeCompressed();
    return Gt;
  }
  // A model with inputs (docs/inputs.md): the step's force from t0 to
  // t0 + h, theta f(t0 + h) + (1 - theta) f(t0) (f alone without inputs).
  void set_step(double t0, double h, double theta) const {
    if (m_.has_inputs())
      f_ = theta * mech::force_at(m_, t0 + h) + (1.0 - theta) * mech::force_at(m_, t0);
  }
  // f - D v - K (q + h theta v): the smooth force of the step. No allocation
  // after the first call (the scratch vector is kept).
  void step_force(const VectorXd& q, const VectorXd& v, double h, double theta,
                  VectorXd& out) const {
    qt_ = q + (h * theta) * v;
    out.setZero();
    add_times(K_, 1.0, qt_, out);  // = K qt
    out = f_ - out;
    add_times(D_, -1.0, v, out);
  }
  // out = E x (out sized k).
  void E_times(const VectorXd& x, VectorXd& out) const { times(Er_, x, out); }
  // out = |E| x + |g| (x >= 0): the magnitude of the terms a gap is formed
  // from, for a test that must not read rounding as a sign.
  void abs_E_times(const VectorXd& x, VectorXd& out) const {
    times(Er_abs_, x, out);
    out += g_abs_;
  }
  // W = M + h theta D + h^2 theta^2 K.
  SparseCol W_sparse(double h, double theta) const {
    SparseCol W = m_.M + (h * theta) * m_.D + (h * h * theta * theta) * m_.K;
    W.makeCompressed();
    return W;
  }
  MatrixXd W_dense(double h, double theta) const { return W_sparse(h, theta).toDense(); }
  // T + V = ½ v'Mv + ½ q'Kq - f'q (J).
  double energy(const VectorXd& q, const VectorXd& v) const { return mech::total_energy(m_, q, v); }

 private:
  const mech::MechanicalModel& m_;
  bool sparse_;
  SparseCol Ec_;      // E by columns: assembles the active Delassus matrix
  SparseRow Er_;      // E by rows: the gap rates E v
  SparseRow Er_abs_;  // |E| by rows, and |g|: the gaps' scales (abs_E_times)
  VectorXd g_abs_;
  SparseCol K_, D_;      // compressed copies for add_times
  SparseCol Gt_;         // [E; T]': normal and tangent rows as columns
  mutable VectorXd f_;   // the step's force: f, or f(t) with inputs (set_step)
  mutable VectorXd qt_;  // step_force scratch: q + h theta v
};

// The factored iteration matrix W for one step length, and the cached columns
// W^{-1} E_i' and, for models with friction, W^{-1} t_f' (column k + f;
// MjOperators::rows_transposed), computed on first use, pruned of entries
// below kPruneRelative times the largest.
class MjIteration {
 public:
  static constexpr double kPruneRelative = 1e-17;  // columns keep |x| > this * max|x|
  static constexpr size_t kLocalColumnMax = 256;   // largest neighbourhood of a local solve

  // Factors W at step h; false (and message()) if W is not positive definite.
  bool factor(const MjOperators& ops, double h, double theta);
  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }
  VectorXd solve(const VectorXd& rhs) const {
    if (sparse_) return ldlt_.solve(rhs);
    return llt_.solve(rhs);
  }
  // out = W^{-1} rhs into a vector of the right size (no allocation).
  void solve(const VectorXd& rhs, VectorXd& out) const {
    if (sparse_)
      out = ldlt_.solve(rhs);
    else
      out = llt_.solve(rhs);
  }
  // W^{-1} E_i' (i < k) or W^{-1} t_{i-k}' as an N x 1 sparse column; false
  // if not finite.
  bool column(int i, const SparseCol*& out) {
    if (!have_[i] && !compute_column(i)) return false;
    out = &cols_[i];
    return true;
  }

 private:
  bool compute_column(int i);
  bool local_column(int i, std::vector<int>& nodes, VectorXd& c);

  bool sparse_ = false, ok_ = false;
  std::string message_;
  Eigen::LLT<MatrixXd> llt_;
  Eigen::SimplicialLDLT<SparseCol> ldlt_;
  SparseCol Et_, W_;
  std::vector<SparseCol> cols_;
  std::vector<int> stamp_, local_;  // local_column: visit marks and local indices
  std::vector<char> have_;
};

}  // namespace lcsim::sim::detail
