// Markov parameters (3.32) and leading row/column indices and coefficient
// matrices (3.39).
#include "lcs/lcs.hpp"

#include <Eigen/SVD>
#include <algorithm>

namespace lcsim::lcs {

namespace {
// max(dim) * 1e-12 * sigma_max (1 for sigma_max = 0), see lcs.hpp.
double tolerance_for(const MatrixXd& X, double sigma_max) {
  const double dim = static_cast<double>(std::max(X.rows(), X.cols()));
  return dim * 1e-12 * (sigma_max > 0.0 ? sigma_max : 1.0);
}
}  // namespace

double rank_tolerance(const MatrixXd& X) {
  if (X.size() == 0) return 0.0;
  return tolerance_for(X, Eigen::JacobiSVD<MatrixXd>(X).singularValues()(0));
}

int numerical_rank(const MatrixXd& X) {
  if (X.size() == 0) return 0;
  const VectorXd sv = Eigen::JacobiSVD<MatrixXd>(X).singularValues();
  return static_cast<int>((sv.array() > tolerance_for(X, sv(0))).count());
}

std::vector<MatrixXd> markov_parameters(const Lcs& sys, int count) {
  std::vector<MatrixXd> H;
  H.reserve(std::max(count, 0));
  if (count <= 0) return H;
  H.push_back(sys.D);
  MatrixXd AiB = sys.B;  // A^{i-1} B
  for (int i = 1; i < count; ++i) {
    H.push_back(sys.C * AiB);
    AiB = sys.A * AiB;
  }
  return H;
}

namespace {

// A row or column of H^i counts as nonzero when its largest entry exceeds a
// tolerance relative to the scale of the whole Markov sequence at that order,
// so that rounding in C A^{i-1} B is not mistaken for structure.
double markov_zero_tol(const std::vector<MatrixXd>& H, const Lcs& sys, int i) {
  double scale = H[i].cwiseAbs().maxCoeff();
  if (i > 0) {
    // ||C|| ||A||^{i-1} ||B|| bounds the size of the terms summed.
    const double a = std::max(sys.A.cwiseAbs().rowwise().sum().maxCoeff(), 1e-300);
    const double c = sys.C.cwiseAbs().rowwise().sum().maxCoeff();
    const double b = sys.B.cwiseAbs().colwise().sum().maxCoeff();
    scale = std::max(scale, c * std::pow(a, i - 1) * b);
  }
  return 1e-12 * scale;
}

// Markov parameters are computed one order at a time and the search stops
// once every row (column) has found its leading index: mechanical models need
// H^0..H^2 only, whatever n.
std::vector<int> leading_indices(const Lcs& sys, bool rows, MatrixXd* coefficients) {
  const int n = sys.n();
  const int k = sys.k();
  std::vector<int> idx(k, kInfiniteIndex);
  if (coefficients) *coefficients = MatrixXd::Zero(k, k);
  int found = 0;
  std::vector<MatrixXd> H;  // H^0..H^i so far (markov_zero_tol reads H[i])
  MatrixXd AiB = sys.B;
  for (int i = 0; i <= n && found < k; ++i) {
    if (i == 0) {
      H.push_back(sys.D);
    } else {
      H.push_back(sys.C * AiB);
      AiB = sys.A * AiB;
    }
    if (H[i].size() == 0) continue;
    const double tol = markov_zero_tol(H, sys, i);
    for (int j = 0; j < k; ++j) {
      if (idx[j] != kInfiniteIndex) continue;
      const double v = rows ? H[i].row(j).cwiseAbs().maxCoeff() : H[i].col(j).cwiseAbs().maxCoeff();
      if (v > tol) {
        idx[j] = i;
        ++found;
        if (coefficients) {
          if (rows)
            coefficients->row(j) = H[i].row(j);
          else
            coefficients->col(j) = H[i].col(j);
        }
      }
    }
  }
  return idx;
}

}  // namespace

std::vector<int> leading_row_indices(const Lcs& sys) { return leading_indices(sys, true, nullptr); }
std::vector<int> leading_column_indices(const Lcs& sys) {
  return leading_indices(sys, false, nullptr);
}

MatrixXd leading_row_coefficients(const Lcs& sys) {
  MatrixXd M;
  leading_indices(sys, true, &M);
  return M;
}

MatrixXd leading_column_coefficients(const Lcs& sys) {
  MatrixXd N;
  leading_indices(sys, false, &N);
  return N;
}

}  // namespace lcsim::lcs
