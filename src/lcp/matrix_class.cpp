// Matrix classes used by the LCP theory (Cottle, Pang & Stone §3.3; thesis
// §4.5): P-matrices (unique solution for every q), positive (semi)definite.
#include <algorithm>
#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcp/redundant.hpp>
#include <vector>

namespace lcsim::lcp {
namespace {

constexpr int kMaxPMatrixOrder = 20;

// Eigenvalues of the symmetric part (M + M')/2: x'Mx = x'((M + M')/2)x.
Eigen::VectorXd symmetric_part_eigenvalues(const MatrixXd& M) {
  const MatrixXd S = 0.5 * (M + M.transpose());
  return Eigen::SelfAdjointEigenSolver<MatrixXd>(S, Eigen::EigenvaluesOnly).eigenvalues();
}

bool square_nonempty_finite(const MatrixXd& M) {
  return M.rows() == M.cols() && M.rows() > 0 && M.allFinite();
}

}  // namespace

bool is_symmetric(const MatrixXd& M, double rel_tol) {
  if (!square_nonempty_finite(M)) return false;
  const double scale = M.cwiseAbs().maxCoeff();
  return (M - M.transpose()).cwiseAbs().maxCoeff() <= rel_tol * scale;
}

bool is_positive_definite(const MatrixXd& M, double rel_tol) {
  if (!square_nonempty_finite(M)) return false;
  const Eigen::VectorXd ev = symmetric_part_eigenvalues(M);
  // Smallest eigenvalue positive relative to the largest magnitude.
  return ev(0) > rel_tol * ev.cwiseAbs().maxCoeff();
}

bool is_positive_semidefinite(const MatrixXd& M, double rel_tol) {
  if (!square_nonempty_finite(M)) return false;
  const Eigen::VectorXd ev = symmetric_part_eigenvalues(M);
  return ev(0) >= -rel_tol * ev.cwiseAbs().maxCoeff();
}

// All 2^k - 1 principal minors positive. Scale-aware: a minor counts as
// positive when det(M_aa) > rel_tol * prod_i ||row_i(M_aa)||_2, the Hadamard
// bound on |det(M_aa)|, so the test is invariant under positive row scaling.
// Above k = 20 the enumeration is too costly; a sufficient condition is used
// instead (symmetric part positive definite), so the answer is conservative.
bool is_p_matrix(const MatrixXd& M, double rel_tol) {
  if (!square_nonempty_finite(M)) return false;
  const int k = static_cast<int>(M.rows());
  if (k > kMaxPMatrixOrder) return is_positive_definite(M, rel_tol);
  std::vector<int> alpha;
  for (unsigned mask = 1; mask < (1u << k); ++mask) {
    alpha.clear();
    for (int i = 0; i < k; ++i)
      if (mask & (1u << i)) alpha.push_back(i);
    const MatrixXd Maa = M(alpha, alpha);
    const double hadamard = Maa.rowwise().norm().prod();
    const double det = alpha.size() == 1 ? Maa(0, 0) : Maa.partialPivLu().determinant();
    if (!(det > rel_tol * hadamard)) return false;
  }
  return true;
}

}  // namespace lcsim::lcp

namespace lcsim::lcp {

// redundant.hpp. Enumerates the 2^k - 1 sets as is_p_matrix does.
bool is_p_matrix_on_independent_rows(const MatrixXd& Ns, const MatrixXd& W, double rel_tol) {
  if (!square_nonempty_finite(Ns) || W.rows() != Ns.rows() || W.cols() != Ns.cols() ||
      Ns.rows() > kMaxPMatrixOrder)
    return false;
  const int k = static_cast<int>(Ns.rows());
  std::vector<int> a;
  const auto positive = [rel_tol](const MatrixXd& A) {
    const double det = A.rows() == 1 ? A(0, 0) : A.partialPivLu().determinant();
    return det > rel_tol * A.rowwise().norm().prod();
  };
  for (unsigned mask = 1; mask < (1u << k); ++mask) {
    a.clear();
    for (int i = 0; i < k; ++i)
      if (mask & (1u << i)) a.push_back(i);
    if (!positive(W(a, a))) continue;  // dependent rows: a redundant set
    if (!positive(Ns(a, a))) return false;
  }
  return true;
}

}  // namespace lcsim::lcp
