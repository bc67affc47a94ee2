// The step-LCP solvers of include/lcsim/lcp/sparse.hpp against the dense
// solvers: solve_sparse_pgs against the enumeration oracle and principal
// pivoting, WarmPivot against principal pivoting from scratch.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcp/sparse.hpp>
#include <random>
#include <vector>

#include "lcp_test_util.hpp"

namespace lcsim::lcp {
namespace {

using test::random_spd;

double max_abs_diff(const VectorXd& a, const VectorXd& b) { return (a - b).cwiseAbs().maxCoeff(); }

SparseRowMatrix sparse(const MatrixXd& M) {
  SparseRowMatrix S = M.sparseView();
  S.makeCompressed();
  return S;
}

// A banded SPD matrix like a chain's Delassus matrix: tridiagonal with
// diagonal 2 + d_i (d_i in [0, 1]) and off-diagonal -1, so diagonally
// dominant with eigenvalues in [min d_i, 5].
MatrixXd random_tridiagonal_spd(int k, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.1, 1.0);
  MatrixXd M = MatrixXd::Zero(k, k);
  for (int i = 0; i < k; ++i) {
    M(i, i) = 2.0 + u(rng);
    if (i + 1 < k) M(i, i + 1) = M(i + 1, i) = -1.0;
  }
  return M;
}

// A status "solved" is checked against the problem itself: a complementary z
// within the acceptance tol (1 + ||q||_inf) that the solve was given.
void expect_solution(const MatrixXd& M, const VectorXd& q, const Result& r, double tol) {
  ASSERT_EQ(r.status, Status::kSolved) << r.message;
  const double acc = tol * (1.0 + q.cwiseAbs().maxCoeff());
  const VectorXd w = M * r.z + q;
  EXPECT_LE(r.z.cwiseMin(w).cwiseAbs().maxCoeff(), acc);
  EXPECT_GE(r.z.minCoeff(), -acc);
  EXPECT_GE(w.minCoeff(), -acc);
  // The reported diagnostics are those of z (same products, rounding only).
  EXPECT_LE(max_abs_diff(r.w, w), 1e-14 * (1.0 + w.cwiseAbs().maxCoeff()));
  EXPECT_NEAR(r.residual, r.z.cwiseMin(w).cwiseAbs().maxCoeff(), 1e-14);
}

// random_spd keeps eigenvalues in [0.5, ~4.5] and ||q||_inf ~ 3, the
// tridiagonal ones in [0.1, 5]: the error bound of a P-matrix LCP,
// |z - z*| <= (1 + ||M||) / lambda_min(M) * residual, is at most
// ~ 60 * 1e-12 * 4 ~ 2.4e-10 for PGS stopped at residual 1e-12 (1 + ||q||),
// and the pivoting solutions are exact up to cond * k * eps ~ 1e-13. 1e-9
// leaves a margin for rounding while catching a wrong basis (an O(1) change).
constexpr double kOracleTol = 1e-9;

TEST(SparsePgs, MatchesEnumerationOnRandomSpd) {
  std::mt19937 rng(314159);
  Options opt;
  opt.max_iterations = 200000;
  for (int k = 1; k <= 12; ++k) {
    for (int trial = 0; trial < 4; ++trial) {
      const MatrixXd M = random_spd(k, rng);
      const VectorXd q = test::gaussian(k, rng);
      const EnumerationResult oracle = enumerate_solutions(M, q);
      ASSERT_EQ(oracle.status, Status::kSolved);
      ASSERT_EQ(oracle.solutions.size(), 1u) << "P-matrix LCP has a unique solution";
      const Result r = solve_sparse_pgs(sparse(M), q, opt);
      expect_solution(M, q, r, opt.tolerance);
      EXPECT_LE(max_abs_diff(r.z, oracle.solutions[0]), kOracleTol) << "k=" << k;
      EXPECT_GE(r.iterations, 1);
    }
  }
}

TEST(SparsePgs, MatchesPrincipalPivotingOnBandedProblems) {
  std::mt19937 rng(2718);
  Options opt;
  opt.max_iterations = 200000;
  for (int k : {20, 100, 300}) {
    const MatrixXd M = random_tridiagonal_spd(k, rng);
    const VectorXd q = test::gaussian(k, rng);
    const Result exact = solve_principal_pivoting(M, q);
    ASSERT_EQ(exact.status, Status::kSolved) << exact.message;
    const Result r = solve_sparse_pgs(sparse(M), q, opt);
    expect_solution(M, q, r, opt.tolerance);
    EXPECT_LE(max_abs_diff(r.z, exact.z), kOracleTol) << "k=" << k;
  }
}

TEST(SparsePgs, WarmStartAtTheSolutionEndsAfterOneSweep) {
  std::mt19937 rng(11);
  const MatrixXd M = random_tridiagonal_spd(50, rng);
  const VectorXd q = test::gaussian(50, rng);
  const Result exact = solve_principal_pivoting(M, q);
  ASSERT_TRUE(exact.ok());
  Options opt;
  opt.warm_start = &exact.z;
  const Result r = solve_sparse_pgs(sparse(M), q, opt);
  expect_solution(M, q, r, opt.tolerance);
  // A sweep at the exact solution changes z by rounding only (<< tolerance).
  EXPECT_EQ(r.iterations, 1);
}

TEST(SparsePgs, ReportsIterationLimitAndBadInput) {
  std::mt19937 rng(12);
  const MatrixXd M = random_spd(12, rng);
  const VectorXd q = -VectorXd::Ones(12);  // z = M^{-1} 1 > 0 is not reached in one sweep
  Options opt;
  opt.max_iterations = 1;
  const Result r = solve_sparse_pgs(sparse(M), q, opt);
  EXPECT_EQ(r.status, Status::kIterationLimit);
  EXPECT_EQ(r.iterations, 1);
  EXPECT_EQ(r.z.size(), 12);

  EXPECT_EQ(solve_sparse_pgs(sparse(M), VectorXd::Ones(3)).status, Status::kInvalidInput);
  MatrixXd Z = M;
  Z(4, 4) = 0.0;
  const Result rz = solve_sparse_pgs(sparse(Z), q);
  EXPECT_EQ(rz.status, Status::kNumericalFailure);
  EXPECT_NE(rz.message.find("M(4,4)"), std::string::npos) << rz.message;
}

// WarmPivot on the basis of principal pivoting's own solution computes the
// same LLT of the same M_JJ and the same solve: bitwise the same z.
TEST(WarmPivot, OnTheSolversBasisGivesTheSolversSolution) {
  std::mt19937 rng(2024);
  const Options opt;
  WarmPivot warm;
  long version = 0;
  for (int k = 1; k <= 16; ++k) {
    const MatrixXd M = random_spd(k, rng);
    ++version;
    VectorXd q = test::gaussian(k, rng);
    VectorXd z_prev = solve_principal_pivoting(M, q).z;
    // A sequence of nearby problems, as in consecutive time steps.
    for (int step = 0; step < 3; ++step) {
      const Result exact = solve_principal_pivoting(M, q);
      ASSERT_TRUE(exact.ok());
      const Result& r = warm.solve(M, version, q, z_prev, opt);
      bool same_basis = true;
      for (int i = 0; i < k; ++i) same_basis &= (z_prev(i) > 0.0) == (exact.z(i) > 0.0);
      if (r.ok()) {
        EXPECT_TRUE(same_basis) << "k=" << k;
        expect_solution(M, q, r, opt.tolerance);
        for (int i = 0; i < k; ++i) EXPECT_EQ(r.z(i), exact.z(i)) << "k=" << k << " i=" << i;
        EXPECT_EQ(r.pivots, 0);
      }
      if (step == 0) {
        EXPECT_TRUE(r.ok()) << "the solver's own basis, k=" << k << ": " << r.message;
      }
      z_prev = exact.z;
      q += 1e-3 * test::gaussian(k, rng);
    }
  }
}

TEST(WarmPivot, RejectsAWrongBasis) {
  // M = I, q = (-1, 2): the solution is z = (1, 0), w = (0, 2).
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q{{-1.0, 2.0}};
  WarmPivot warm;
  const VectorXd wrong{{0.0, 1.0}};  // basis {1}: z_1 = -2 < 0
  EXPECT_FALSE(warm.solve(M, 1, q, wrong, Options{}).ok());
  const VectorXd right{{0.5, 0.0}};
  const Result& r = warm.solve(M, 1, q, right, Options{});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.z(0), 1.0);
  EXPECT_EQ(r.z(1), 0.0);
  EXPECT_EQ(r.w(1), 2.0);
}

TEST(WarmPivot, RejectsAnEntryWithinItsMarginOfZero) {
  // M = I, q = (-1, -1e-13): z = (1, 1e-13) solves it, but z_2 is below the
  // margin kMargin * 0.25 * 1e-12 * (1 + 1) = 5e-10, where the pivoting
  // solver's zero test could end on another basis: the caller must solve.
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q{{-1.0, -1e-13}};
  WarmPivot warm;
  const VectorXd prev{{1.0, 1.0}};
  EXPECT_FALSE(warm.solve(M, 1, q, prev, Options{}).ok());
  const VectorXd q2{{-1.0, -1e-6}};  // z_2 = 1e-6 is well above the margin
  const Result& r = warm.solve(M, 1, q2, prev, Options{});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r.z(1), 1e-6);
}

}  // namespace
}  // namespace lcsim::lcp
