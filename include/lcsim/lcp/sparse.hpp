// LCP solvers for the step problems of time-stepping on large or repeated
// problems: projected Gauss–Seidel on a sparse matrix, and principal pivoting
// warm-started on a previous basis. Both return a Result like the dense
// solvers of lcp.hpp (src/lcp/sparse_pgs.cpp, src/lcp/warm_pivot.cpp).
#pragma once

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <lcsim/lcp/lcp.hpp>
#include <vector>

namespace lcsim::lcp {

using SparseRowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Projected Gauss–Seidel on w = M z + q, 0 <= z ⟂ w >= 0, for a symmetric M
// held sparse by rows (compressed), from opt.warm_start (projected onto
// z >= 0; zero without one). A sweep updates z_i <- max(0, z_i - w_i / M_ii)
// in index order with w_i from the current z; after a sweep whose largest
// change M_ii |dz_i| is at most acceptance = opt.tolerance (1 + ||q||_inf),
// the natural residual ||min(z, M z + q)||_inf is computed and the solve ends
// kSolved when it is at most acceptance too. opt.max_iterations caps the
// sweeps (kIterationLimit: z is the last iterate). opt.relaxation is not
// used. A non-positive diagonal entry is kNumericalFailure (z zero).
Result solve_sparse_pgs(const SparseRowMatrix& M, const VectorXd& q, const Options& opt = {});

// solve_principal_pivoting's answer on a guessed basis, for a sequence of
// LCPs with a symmetric M that change little (the step LCPs of a contact
// phase). The basis J is where the previous solution is positive; the
// candidate z_J = -M_JJ^{-1} q_J (LLT of M_JJ, zero off J) is accepted when it
// passes the pivoting solver's own acceptance test with a margin: z_J > m,
// w_a > m off J, |w_J| <= acceptance, with m = kMargin times the pivoting
// solver's zero threshold (src/lcp/detail.hpp). With the margin, the pivoting
// solver from scratch ends on the same basis J for any reasonably
// conditioned M (the LCP solution moves by O(cond(M) tol) under the
// tolerance's perturbations, far less than m), and on the same basis it
// computes the same numbers (the same LLT of the same M_JJ and the same
// solve), so an accepted z is bitwise the solver's. Problems near a change of
// basis (an entry of z or w within m of zero) are rejected: the caller then
// solves from scratch. The factor of M_JJ is kept while M (by `version`) and
// J stay. No heap allocation once sizes have been seen.
class WarmPivot {
 public:
  static constexpr double kMargin = 1e3;
  // z_prev: the previous solution (sized like q); `version` changes whenever M
  // does. Returns the result: kSolved with z, w, residual, min_w filled
  // (pivots = iterations = 0), or kNumericalFailure when the guessed basis is
  // rejected (then only the status and message are meaningful). The
  // reference stays valid until the next call.
  const Result& solve(const MatrixXd& M, long version, const VectorXd& q, const VectorXd& z_prev,
                      const Options& opt);

 private:
  const Result& reject();
  std::vector<int> J_, J_factored_;
  long version_ = -1;
  MatrixXd Mjj_;
  Eigen::LLT<MatrixXd> llt_;
  VectorXd zj_;
  Result result_;
};

}  // namespace lcsim::lcp
