// Random LCP generators for the LCP tests (fixed seeds, reproducible).
#pragma once

#include <algorithm>
#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <random>

namespace lcsim::lcp::test {

inline MatrixXd gaussian(int rows, int cols, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  MatrixXd A(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) A(i, j) = n(rng);
  return A;
}

inline VectorXd gaussian(int k, std::mt19937& rng) { return gaussian(k, 1, rng); }

// Symmetric positive definite, eigenvalues in [0.5, ~4.5]: A A'/k + I/2 with
// A k x k standard normal (Marchenko–Pastur: spectrum of A A'/k in [0, 4]).
inline MatrixXd random_spd(int k, std::mt19937& rng) {
  const MatrixXd A = gaussian(k, k, rng);
  return A * A.transpose() / k + 0.5 * MatrixXd::Identity(k, k);
}

// Nonsymmetric positive definite (hence P): SPD plus a skew-symmetric part.
// x'Mx = x'Sx >= 0.5 |x|^2; the skew part has norm ~ 2, so cond(M) stays ~ 10.
inline MatrixXd random_nonsymmetric_pd(int k, std::mt19937& rng) {
  const MatrixXd B = gaussian(k, k, rng) / std::sqrt(static_cast<double>(k));
  return random_spd(k, rng) + (B - B.transpose());
}

// Nonsymmetric P-matrix that is not positive definite in general: a positive
// row scaling D (entries in [0.2, 5]) of a positive definite matrix; principal
// minors are det(D_aa) det(S_aa) > 0.
inline MatrixXd random_scaled_p(int k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(std::log(0.2), std::log(5.0));
  VectorXd d(k);
  for (int i = 0; i < k; ++i) d(i) = std::exp(u(rng));
  return d.asDiagonal() * random_nonsymmetric_pd(k, rng);
}

// Symmetric positive semidefinite of rank m < k (dependent constraints) with a
// q that makes the LCP solvable: q = w* - M z* for complementary z*, w* >= 0.
inline void random_psd_lcp(int k, int m, std::mt19937& rng, MatrixXd& M, VectorXd& q) {
  const MatrixXd A = gaussian(k, m, rng);
  M = A * A.transpose() / m;
  std::uniform_real_distribution<double> u(0.0, 1.0);
  VectorXd z = VectorXd::Zero(k), w = VectorXd::Zero(k);
  for (int i = 0; i < k; ++i) (u(rng) < 0.5 ? z(i) : w(i)) = u(rng);
  q = w - M * z;
}

// The row-scaled residual recomputed here, independently of the library's
// scaled_residual (lcp.hpp): per row, z_i against ||z||_inf and w_i against
// s_i = |q_i| + sum_j |M_ij| |z_j|, worst |min| over the rows.
inline double row_scaled_residual(const MatrixXd& M, const VectorXd& q, const VectorXd& z) {
  const VectorXd w = M * z + q;
  const VectorXd s = M.cwiseAbs() * z.cwiseAbs() + q.cwiseAbs();
  const double zn = z.lpNorm<Eigen::Infinity>();
  double worst = 0.0;
  for (Eigen::Index i = 0; i < z.size(); ++i) {
    const double a = zn == 0.0 ? 0.0 : z(i) / zn;
    const double b = s(i) == 0.0 ? 0.0 : w(i) / s(i);
    worst = std::max(worst, std::abs(std::min(a, b)));
  }
  return worst;
}

// Positive row scales 10^U(lo, hi): D M, D q has the same solutions as M, q.
inline VectorXd random_row_scales(int k, double lo, double hi, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(lo, hi);
  VectorXd d(k);
  for (int i = 0; i < k; ++i) d(i) = std::pow(10.0, u(rng));
  return d;
}

}  // namespace lcsim::lcp::test
