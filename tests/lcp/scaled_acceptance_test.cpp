// The row-scaled acceptance test and badly scaled rows (issue #14): a row of
// size 1 next to a row of size 1e12 is judged against its own scale, and every
// solver either solves a badly scaled LCP or says it did not.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <lcsim/lcp/lcp.hpp>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "lcp_test_util.hpp"

namespace lcsim::lcp {
namespace {

using Named = std::pair<std::string, std::function<Result(const MatrixXd&, const VectorXd&)>>;

// Every way the layer solves an LCP: the registry's solvers (only the
// built-in lemke, pivot, pgs, enum are linked into this test), Murty, and
// the fallback chains.
std::vector<Named> every_solver() {
  std::vector<Named> out;
  for (const std::string& name : solver_names())
    out.emplace_back(name, [name](const MatrixXd& M, const VectorXd& q) {
      return make_solver(name)->solve(M, q, Options{});
    });
  out.emplace_back("murty", [](const MatrixXd& M, const VectorXd& q) { return solve_murty(M, q); });
  out.emplace_back("fallbacks(pivot)", [](const MatrixXd& M, const VectorXd& q) {
    return solve_with_fallbacks(*make_solver("pivot"), M, q, Options{});
  });
  out.emplace_back("scaled(pivot)", [](const MatrixXd& M, const VectorXd& q) {
    return solve_scaled(*make_solver("pivot"), M, q, Options{});
  });
  return out;
}

// The issue's example: M = diag(1e12, 1), q = (-1e12, -1), unique solution
// z = (1, 1), w = 0.
void issue_example(MatrixXd& M, VectorXd& q) {
  M = MatrixXd::Zero(2, 2);
  M(0, 0) = 1e12;
  M(1, 1) = 1.0;
  q = VectorXd(2);
  q << -1e12, -1.0;
}

TEST(LcpScaledAcceptance, DiagonalOneE12SolvedByEverySolver) {
  MatrixXd M;
  VectorXd q;
  issue_example(M, q);
  const std::vector<Named> all = every_solver();
  ASSERT_GE(all.size(), 7u);  // lemke, pivot, pgs, enum, murty, two chains
  for (const auto& [name, solve] : all) {
    const Result r = solve(M, q);
    ASSERT_EQ(r.status, Status::kSolved) << name << ": " << r.message;
    ASSERT_EQ(r.z.size(), 2) << name;
    // z_i = -q_i / M_ii: one division each, exact here (1e12 / 1e12 and 1 / 1)
    // up to the power-of-two row scaling, which is exact; 4 ulps of 1 allow
    // for a pivot update or a refinement step.
    EXPECT_NEAR(r.z(0), 1.0, 1e-15) << name;
    EXPECT_NEAR(r.z(1), 1.0, 1e-15) << name;
    EXPECT_LE(test::row_scaled_residual(M, q, r.z), 1e-12) << name;
    EXPECT_LE(r.scaled_residual, 1e-12) << name;
  }
}

TEST(LcpScaledAcceptance, OldAcceptanceSaidSolvedNewOneRefuses) {
  MatrixXd M;
  VectorXd q;
  issue_example(M, q);
  VectorXd z(2);
  z << 1.0, 0.0;  // what Lemke and enumeration used to return: w = (0, -1)
  const Result r = evaluate(M, q, z);
  // The old test, residual <= 1e-12 (1 + ||q||_inf) = 1.000000000001, passed:
  ASSERT_DOUBLE_EQ(r.residual, 1.0);
  EXPECT_LE(r.residual, 1e-12 * (1.0 + 1e12));
  EXPECT_GE(r.min_w, -1e-12 * (1.0 + 1e12));
  // The row-scaled one refuses, at row 1: w_1 = -1 against s_1 = |q_1| = 1.
  EXPECT_EQ(r.status, Status::kNumericalFailure);
  EXPECT_DOUBLE_EQ(r.scaled_residual, 1.0);
  EXPECT_EQ(r.worst_row, 1);
  EXPECT_NE(r.message.find("row 1"), std::string::npos) << r.message;
  int worst = -1;
  EXPECT_DOUBLE_EQ(scaled_residual(M, q, z, &worst), 1.0);
  EXPECT_EQ(worst, 1);
}

TEST(LcpScaledAcceptance, ScaledResidualIsInvariantUnderRowScaling) {
  // Hand example: M = [[2, 1], [1, 3]], q = (-3, 1), z = (1.5, 0): w = (0, 2.5),
  // row 0: min(1.5/1.5, 0/(3 + 3)) = 0; row 1: min(0, 2.5/(1 + 1.5)) = 0.
  // Perturb z_0 by 1e-6: w_0 = 2e-6, s_0 = 3 + 2 (1.5 + 1e-6), so row 0 reads
  // min(1, 2e-6 / 6.000002); rescaling row 0 by 1e9 must not change it.
  MatrixXd M(2, 2);
  M << 2, 1, 1, 3;
  VectorXd q(2);
  q << -3, 1;
  VectorXd z(2);
  z << 1.5 + 1e-6, 0.0;
  const double expected = 2e-6 / (3.0 + 2.0 * (1.5 + 1e-6));
  // Rounding: w_0 = 2 (1.5 + 1e-6) - 3 loses ~ eps * 3 absolute to
  // cancellation, 1e-16 / 2e-6 ~ 1e-10 relative; 1e-9 relative covers it.
  EXPECT_NEAR(scaled_residual(M, q, z), expected, 1e-9 * expected);
  MatrixXd Ms = M;
  VectorXd qs = q;
  Ms.row(0) *= 1e9;
  qs(0) *= 1e9;
  EXPECT_NEAR(scaled_residual(Ms, qs, z), expected, 1e-9 * expected);
}

// Random P-matrix LCPs with a known solution: z*, w* complementary, q = w* -
// M z*, then rows scaled by 10^U(-12, 12). Row scaling keeps the solution
// (unique for a P-matrix). Every solver must either solve to the row-scaled
// tolerance (recomputed here) with z = z*, or report failure.
TEST(LcpScaledAcceptance, BadlyScaledRowsSolvedOrRefusedNeverWrong) {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const std::vector<Named> all = every_solver();
  std::vector<int> solved(all.size(), 0), refused(all.size(), 0);
  constexpr int kProblems = 200;
  for (int p = 0; p < kProblems; ++p) {
    const int k = 2 + p % 7;
    const MatrixXd M0 = p % 2 ? test::random_nonsymmetric_pd(k, rng) : test::random_spd(k, rng);
    VectorXd z_star = VectorXd::Zero(k), w_star = VectorXd::Zero(k);
    for (int i = 0; i < k; ++i) (u(rng) < 0.5 ? z_star(i) : w_star(i)) = 0.1 + u(rng);
    const VectorXd d = test::random_row_scales(k, -12.0, 12.0, rng);
    const MatrixXd M = d.asDiagonal() * M0;
    const VectorXd q = d.cwiseProduct(w_star - M0 * z_star);
    for (std::size_t s = 0; s < all.size(); ++s) {
      const Result r = all[s].second(M, q);
      if (r.status != Status::kSolved) {
        ++refused[s];
        continue;
      }
      ++solved[s];
      EXPECT_LE(test::row_scaled_residual(M, q, r.z), 1e-12) << all[s].first << " problem " << p;
      // The unscaled M0 has cond ~ 10 (lcp_test_util.hpp) and entries of z*
      // in [0.1, 1.1]: an accepted z (backward error 1e-12 per row) lies
      // within ~ cond * k * 1e-12 ~ 1e-10 of z*; 1e-8 leaves margin and still
      // catches a wrong complementary basis (which moves z by >= 0.1).
      EXPECT_LE((r.z - z_star).cwiseAbs().maxCoeff(), 1e-8) << all[s].first << " problem " << p;
    }
  }
  for (std::size_t s = 0; s < all.size(); ++s)
    std::printf("%-18s solved %3d refused %3d of %d\n", all[s].first.c_str(), solved[s], refused[s],
                kProblems);
  // The chains end with enumeration (k <= 8 here), which solves every one of
  // these; a chain that refuses a P-matrix LCP would be a regression.
  EXPECT_EQ(solved[all.size() - 2], kProblems);
  EXPECT_EQ(solved[all.size() - 1], kProblems);
}

TEST(LcpScaledAcceptance, SubnormalDiagonalIsNotInvalidInputInSolveScaled) {
  // Found by fuzz_lcp: M_11 = 1.36e-312 (subnormal) gives 1 / sqrt(M_11)
  // ~ 8.6e155 in solve_scaled's diagonal scaling and an overflowing scaled
  // problem, which was then reported as kInvalidInput on well-formed data.
  MatrixXd M(2, 2);
  M << 2, 7.02445990853128e-251, 1.35144606937101e-312, 1.35675105884842e-312;
  VectorXd q(2);
  q << 8.29195511698081e-317, 0;
  ASSERT_TRUE(validate(M, q).empty());
  const Result r = solve_scaled(*make_solver("pivot"), M, q, Options{});
  EXPECT_NE(r.status, Status::kInvalidInput) << r.message;
  // q >= 0: z = 0 solves it (w = q >= 0); the accepted z must pass the test.
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_LE(test::row_scaled_residual(M, q, r.z), 1e-12);
}

}  // namespace
}  // namespace lcsim::lcp
