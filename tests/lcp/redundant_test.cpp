// lcp::is_p_matrix_on_independent_rows (redundant.hpp): the P-matrix test of
// a normal matrix Ns = E M^-1 G' judged only on sets of independent rows of E.
#include <gtest/gtest.h>

#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcp/redundant.hpp>
#include <random>

namespace lcsim::lcp {
namespace {

using Eigen::MatrixXd;

// Four coplanar corners of a box (half-sides a, b) of unit mass and inertia
// diag(Ix, Iy) acting on (z, rx, ry): E has rank 3, so W = E M^-1 E' and
// every Ns = E M^-1 (E + F)' have a zero 4 x 4 minor (not P-matrices), while
// with F = 0 every set of three corners is independent and positive.
TEST(PMatrixOnIndependentRows, RedundantCornersAreNotPainleve) {
  const double a = 0.15, b = 0.1;
  MatrixXd E(4, 3);
  E << 1, b, -a, 1, b, a, 1, -b, -a, 1, -b, a;
  const MatrixXd Minv = Eigen::Vector3d(1.0, 1 / 0.004, 1 / 0.01).asDiagonal();
  const MatrixXd W = E * Minv * E.transpose();
  EXPECT_FALSE(is_p_matrix(W));
  EXPECT_TRUE(is_p_matrix_on_independent_rows(W, W));
  // Friction of mu = 0.3 at the corners, 0.05 m below the centre, all along
  // +x: a column 0.3 * 0.05 on ry (the pitch) from each corner. The 3 x 3
  // and smaller minors stay positive (one corner: W_ii - mu c a/Iy > 0).
  MatrixXd G = E;
  G.col(2).array() += 0.3 * 0.05;
  const MatrixXd Ns = E * Minv * G.transpose();
  EXPECT_FALSE(is_p_matrix(Ns));
  EXPECT_TRUE(is_p_matrix_on_independent_rows(Ns, W));
  // A friction column that presses the first corner shut on its own
  // (W_00 + its column < 0): refused on that single independent row.
  MatrixXd Gp = E;
  Gp(0, 2) += 60.0;  // Ns_00 = 5.75 - 0.15 * 100 * 60 < 0
  EXPECT_FALSE(is_p_matrix_on_independent_rows(E * Minv * Gp.transpose(), W));
}

// Without dependent rows the test is is_p_matrix's, on random pairs.
TEST(PMatrixOnIndependentRows, EqualsIsPMatrixWhenRowsAreIndependent) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  int p = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const int k = 1 + trial % 5;
    MatrixXd E(k, k + 2), F(k, k + 2);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < k + 2; ++j) E(i, j) = n(rng), F(i, j) = 0.4 * n(rng);
    const MatrixXd W = E * E.transpose(), Ns = E * (E + F).transpose();
    ASSERT_TRUE(is_p_matrix(W));
    EXPECT_EQ(is_p_matrix_on_independent_rows(Ns, W), is_p_matrix(Ns)) << "trial " << trial;
    p += is_p_matrix(Ns);
  }
  EXPECT_GT(p, 0);
  EXPECT_LT(p, 300);  // both answers occur
}

}  // namespace
}  // namespace lcsim::lcp
