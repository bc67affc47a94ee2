// Bullet's MLCP solvers as LCP back-ends (src/bullet/mlcp.cpp), checked
// against lcsim's principal pivoting on problems with a unique solution.
#include <gtest/gtest.h>

#include <lcsim/bullet/bullet.hpp>
#include <random>

namespace lcsim::bullet {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

MatrixXd random_matrix(int k, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  MatrixXd A(k, k);
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) A(i, j) = n(rng);
  return A;
}

VectorXd random_vector(int k, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  VectorXd v(k);
  for (int i = 0; i < k; ++i) v(i) = n(rng);
  return v;
}

// SPD M = A A' + k I (condition number ~ 5): the solution is unique and every
// back-end must find it. Tolerance: the residual check runs at
// lcp::Options{}.tolerance = 1e-12 (1 + |q|); with eigenvalues >= k the
// solution error is at most that residual over k, so 1e-9 is loose.
TEST(BulletMlcp, SolvesSpdLcp) {
  std::mt19937 rng(7);
  for (int trial = 0; trial < 10; ++trial) {
    const int k = 8;
    const MatrixXd A = random_matrix(k, rng);
    const MatrixXd M = A * A.transpose() + k * MatrixXd::Identity(k, k);
    const VectorXd q = random_vector(k, rng);
    const lcp::Result ref = lcp::solve_principal_pivoting(M, q);
    ASSERT_TRUE(ref.ok());
    for (MlcpSolver s : {MlcpSolver::kDantzig, MlcpSolver::kLemke, MlcpSolver::kPgs}) {
      const lcp::Result r = solve_bullet_mlcp(s, M, q);
      EXPECT_TRUE(r.ok()) << static_cast<int>(s) << ": " << r.message;
      EXPECT_LE((r.z - ref.z).cwiseAbs().maxCoeff(), 1e-9) << static_cast<int>(s);
    }
  }
}

// Nonsymmetric P-matrices (M + M' positive definite, so M is P, the LCP has a
// unique solution): btDantzigSolver assumes symmetry and reports success on
// wrong answers (notes/bullet.md: 0 of 50 right at k = 16). lcsim's residual
// check must turn every wrong answer into kNumericalFailure, and what it lets
// through must be the unique solution.
TEST(BulletMlcp, DantzigOnNonsymmetricPMatrixIsCaught) {
  std::mt19937 rng(11);
  int caught = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const int k = 16;
    const MatrixXd A = random_matrix(k, rng), S = random_matrix(k, rng);
    const MatrixXd M = A * A.transpose() / k + MatrixXd::Identity(k, k) + (S - S.transpose());
    const VectorXd q = random_vector(k, rng);
    const lcp::Result ref = lcp::solve_principal_pivoting(M, q);
    ASSERT_TRUE(ref.ok()) << ref.message;
    const lcp::Result r = solve_bullet_mlcp(MlcpSolver::kDantzig, M, q);
    if (r.ok()) {
      EXPECT_LE((r.z - ref.z).cwiseAbs().maxCoeff(), 1e-8);
    } else {
      EXPECT_EQ(r.status, lcp::Status::kNumericalFailure);
      EXPECT_NE(r.message.find("residual check failed"), std::string::npos) << r.message;
      ++caught;
    }
  }
  EXPECT_GT(caught, 0);
}

TEST(BulletMlcp, InvalidInputIsReported) {
  const lcp::Result r =
      solve_bullet_mlcp(MlcpSolver::kLemke, MatrixXd::Identity(2, 2), VectorXd::Zero(3));
  EXPECT_EQ(r.status, lcp::Status::kInvalidInput);
}

}  // namespace
}  // namespace lcsim::bullet
