// Random LCP generators for the LCP tests (fixed seeds, reproducible).
#pragma once

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

}  // namespace lcsim::lcp::test
