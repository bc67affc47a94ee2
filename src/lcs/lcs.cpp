// Markov parameters (3.32) and leading row/column indices and coefficient
// matrices (3.39).
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <lcsim/lcs/lcs.hpp>
#include <limits>

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

// Leading indices are decided entry by entry: H^i_jl counts as nonzero when
// it exceeds 1e-12 of the magnitudes of the terms that formed it,
// T^i = |C| |A|^{i-1} |B| (T^0 = |D|), so that rounding in C A^{i-1} B is not
// mistaken for structure. T^i is invariant under diagonal scalings of the
// state (|C S| |S^-1 A S|^{i-1} |S^-1 B| = |C| |A|^{i-1} |B|) and scales with
// time like H^i, so the decision does not depend on units: a stiff spring
// (omega = 1e9) on another row of A does not drown E M^-1 E' (a bound
// ||C|| ||A||^{i-1} ||B|| did, from omega ~ 1e6 on). tol_abs keeps exact zeros
// zero when the terms vanish too.
constexpr double kMarkovRel = 1e-12;

// Markov parameters are computed one order at a time and the search stops
// once every row (column) has found its leading index: mechanical models need
// H^0..H^2 only, whatever n.
std::vector<int> leading_indices(const Lcs& sys, bool rows, MatrixXd* coefficients) {
  const int n = sys.n();
  const int k = sys.k();
  std::vector<int> idx(k, kInfiniteIndex);
  if (coefficients) *coefficients = MatrixXd::Zero(k, k);
  int found = 0;
  MatrixXd AiB = sys.B;  // A^{i-1} B for the next order
  // T^i is needed only for entries that are nonzero but below the cheap
  // bound 1e-12 c a^{i-1} b >= 1e-12 T^i_jl (c, a, b: largest absolute row
  // sums of C and A, column sum of B), which every entry above it passes
  // either way; mechanical models never need it (H^1 = 0 exactly, H^2 =
  // E M^-1 E'), so its O(n^2 k) products are spent only where they decide.
  const double a = sys.A.size() ? sys.A.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
  const double c = sys.C.size() ? sys.C.cwiseAbs().rowwise().sum().maxCoeff() : 0.0;
  const double b = sys.B.size() ? sys.B.cwiseAbs().colwise().sum().maxCoeff() : 0.0;
  for (int i = 0; i <= n && found < k; ++i) {
    MatrixXd H;
    if (i == 0) {
      H = sys.D;
    } else {
      H = sys.C * AiB;
      AiB = sys.A * AiB;
    }
    if (H.size() == 0) continue;
    const double cheap =
        kMarkovRel * (i == 0 ? H.cwiseAbs().maxCoeff() : c * std::pow(a, i - 1) * b);
    MatrixXd T;  // |C| |A|^{i-1} |B| (|D| for i = 0), on first need
    const auto term_scale = [&]() -> const MatrixXd& {
      if (T.size() == 0) {
        if (i == 0) {
          T = sys.D.cwiseAbs();
        } else {
          MatrixXd P = sys.B.cwiseAbs();
          const MatrixXd A_abs = sys.A.cwiseAbs();
          for (int m = 1; m < i; ++m) P = A_abs * P;
          T = sys.C.cwiseAbs() * P;
        }
      }
      return T;
    };
    const auto nonzero = [&](int r, int l) {
      const double h = std::abs(H(r, l));
      if (h > cheap) return true;
      if (h == 0.0) return false;
      return h > kMarkovRel * term_scale()(r, l) + std::numeric_limits<double>::min();
    };
    for (int j = 0; j < k; ++j) {
      if (idx[j] != kInfiniteIndex) continue;
      bool any = false;
      for (int l = 0; l < k && !any; ++l) any = rows ? nonzero(j, l) : nonzero(l, j);
      if (any) {
        idx[j] = i;
        ++found;
        if (coefficients) {
          if (rows)
            coefficients->row(j) = H.row(j);
          else
            coefficients->col(j) = H.col(j);
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
