// LCP solvers against the enumeration oracle and against exact solutions.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <random>
#include <vector>

#include "lcp_test_util.hpp"

namespace lcsim::lcp {
namespace {

using test::random_nonsymmetric_pd;
using test::random_scaled_p;
using test::random_spd;

double max_abs_diff(const VectorXd& a, const VectorXd& b) { return (a - b).cwiseAbs().maxCoeff(); }

// Every status claim is checked against the problem itself, independently of
// the solver's own diagnostics: kSolved means z passes the row-scaled
// acceptance test at the default tolerance 1e-12 (recomputed here).
void expect_solution(const MatrixXd& M, const VectorXd& q, const Result& r, const char* who) {
  ASSERT_EQ(r.status, Status::kSolved) << who << ": " << r.message;
  EXPECT_LE(test::row_scaled_residual(M, q, r.z), 1e-12) << who;
  const VectorXd w = M * r.z + q;
  EXPECT_NEAR(r.residual, r.z.cwiseMin(w).cwiseAbs().maxCoeff(), 1e-15) << who;
}

// The generators keep cond(M) ~ 10 and ||q|| ~ 3, so a backward-stable
// solution of the final principal system is accurate to ~ cond * k * eps *
// ||z|| ~ 1e-13; 1e-9 leaves a wide margin for rounding while catching any
// wrong complementary basis (which moves z by O(1)).
constexpr double kOracleTol = 1e-9;

TEST(LcpOracle, SymmetricPMatricesAllSolversMatchEnumeration) {
  std::mt19937 rng(20240501);
  Options pgs_opt;
  pgs_opt.max_iterations = 200000;
  for (int k = 1; k <= 12; ++k) {
    for (int trial = 0; trial < 4; ++trial) {
      const MatrixXd M = random_spd(k, rng);
      const VectorXd q = test::gaussian(k, rng);
      const EnumerationResult oracle = enumerate_solutions(M, q);
      ASSERT_EQ(oracle.status, Status::kSolved);
      ASSERT_EQ(oracle.solutions.size(), 1u) << "P-matrix LCP has a unique solution";
      const VectorXd& z = oracle.solutions[0];
      const Result rl = solve_lemke(M, q), rp = solve_principal_pivoting(M, q),
                   rm = solve_murty(M, q), rg = solve_pgs(M, q, pgs_opt);
      expect_solution(M, q, rl, "lemke");
      expect_solution(M, q, rp, "pivot");
      expect_solution(M, q, rm, "murty");
      expect_solution(M, q, rg, "pgs");
      EXPECT_LE(max_abs_diff(rl.z, z), kOracleTol) << "k=" << k;
      EXPECT_LE(max_abs_diff(rp.z, z), kOracleTol) << "k=" << k;
      EXPECT_LE(max_abs_diff(rm.z, z), kOracleTol) << "k=" << k;
      // PGS stops at row-scaled residual <= 5e-13: |w_i| <= 5e-13 s_i with
      // s_i <= ||M|| ||z|| + ||q|| ~ 10, a natural residual ~ 5e-12; the error
      // bound for a P-matrix LCP, |z - z*| <= (1 + ||M||) / lambda_min(sym M)
      // * residual, is ~ 10 * 5e-12 here.
      EXPECT_LE(max_abs_diff(rg.z, z), kOracleTol) << "k=" << k;
    }
  }
}

TEST(LcpOracle, NonsymmetricPMatricesPivotingAndLemkeMatchEnumeration) {
  std::mt19937 rng(77);
  for (int k = 1; k <= 12; ++k) {
    for (int trial = 0; trial < 4; ++trial) {
      const MatrixXd M = trial % 2 ? random_nonsymmetric_pd(k, rng) : random_scaled_p(k, rng);
      if (k <= 10) {
        ASSERT_TRUE(is_p_matrix(M));
      }
      const VectorXd q = test::gaussian(k, rng);
      const EnumerationResult oracle = enumerate_solutions(M, q);
      ASSERT_EQ(oracle.solutions.size(), 1u);
      const VectorXd& z = oracle.solutions[0];
      const Result rl = solve_lemke(M, q), rp = solve_principal_pivoting(M, q),
                   rm = solve_murty(M, q);
      expect_solution(M, q, rl, "lemke");
      expect_solution(M, q, rp, "pivot");
      expect_solution(M, q, rm, "murty");
      EXPECT_LE(max_abs_diff(rl.z, z), kOracleTol) << "k=" << k;
      EXPECT_LE(max_abs_diff(rp.z, z), kOracleTol) << "k=" << k;
      EXPECT_LE(max_abs_diff(rm.z, z), kOracleTol) << "k=" << k;
    }
  }
}

TEST(LcpOracle, PsdMatricesLemkeAndPgsMatchEnumerationOnW) {
  // Rank-deficient symmetric PSD M: z need not be unique, but for any two
  // solutions (z1 - z2)'M(z1 - z2) <= 0, hence M z1 = M z2 and w is unique.
  std::mt19937 rng(4242);
  Options pgs_opt;
  pgs_opt.max_iterations = 200000;
  pgs_opt.tolerance = 1e-11;
  for (int k = 2; k <= 10; ++k) {
    for (int trial = 0; trial < 3; ++trial) {
      MatrixXd M;
      VectorXd q;
      test::random_psd_lcp(k, std::max(1, k / 2), rng, M, q);
      ASSERT_TRUE(is_positive_semidefinite(M));
      const EnumerationResult oracle = enumerate_solutions(M, q);
      ASSERT_EQ(oracle.status, Status::kSolved);
      const VectorXd w = M * oracle.solutions[0] + q;
      for (const VectorXd& z : oracle.solutions)  // uniqueness of w, as derived
        EXPECT_LE(max_abs_diff(M * z + q, w), 1e-10);
      const Result rl = solve_lemke(M, q);
      expect_solution(M, q, rl, "lemke");
      EXPECT_LE(max_abs_diff(rl.w, w), kOracleTol) << "k=" << k;
      // PGS on a singular M converges sublinearly; its accuracy on w is
      // bounded by the residual it reaches (1e-11 times the row scale s_i,
      // ~ 10 here) times ||M|| ~ 4, far inside 1e-8.
      const Result rg = solve_pgs(M, q, pgs_opt);
      ASSERT_EQ(rg.status, Status::kSolved) << rg.message;
      EXPECT_LE(max_abs_diff(rg.w, w), 1e-8) << "k=" << k;
      // Principal pivoting needs a P-matrix: it may fail here, never lie.
      const Result rp = solve_principal_pivoting(M, q);
      if (rp.ok()) expect_solution(M, q, rp, "pivot");
    }
  }
}

TEST(LcpLarge, SolversAgreeOnWUpToK300) {
  // cond(M) ~ 10 (see generators): w agrees to ~ cond * k * eps * ||z||
  // ~ 1e-12 at k = 300; 1e-9 is the bound asked of the solvers.
  std::mt19937 rng(99);
  Options pgs_opt;
  pgs_opt.max_iterations = 100000;
  for (int k : {30, 100, 300}) {
    const MatrixXd M = random_spd(k, rng);
    const VectorXd q = test::gaussian(k, rng);
    const Result rl = solve_lemke(M, q), rp = solve_principal_pivoting(M, q),
                 rg = solve_pgs(M, q, pgs_opt);
    expect_solution(M, q, rl, "lemke");
    expect_solution(M, q, rp, "pivot");
    expect_solution(M, q, rg, "pgs");
    EXPECT_LE(max_abs_diff(rl.w, rp.w), 1e-9) << "k=" << k;
    EXPECT_LE(max_abs_diff(rl.w, rg.w), 1e-9) << "k=" << k;

    const MatrixXd N = random_nonsymmetric_pd(k, rng);
    const Result nl = solve_lemke(N, q), np = solve_principal_pivoting(N, q);
    expect_solution(N, q, nl, "lemke nonsym");
    expect_solution(N, q, np, "pivot nonsym");
    EXPECT_LE(max_abs_diff(nl.w, np.w), 1e-9) << "k=" << k;
    EXPECT_LE(max_abs_diff(nl.z, np.z), 1e-9) << "k=" << k;
  }
}

// Naive Lemke on the dense tableau [I, -M, -e | q]: ratio-test ties go to the
// smallest row index, no lexicographic rule, no preference for z0. Used only
// to show that the degenerate examples below do make plain Lemke cycle.
int naive_lemke_pivots(const MatrixXd& M, const VectorXd& q, int cap) {
  const int k = static_cast<int>(q.size());
  MatrixXd T(k, 2 * k + 2);
  T << MatrixXd::Identity(k, k), -M, -VectorXd::Ones(k), q;
  std::vector<int> basis(k);
  for (int i = 0; i < k; ++i) basis[i] = i;
  int r = 0;
  for (int i = 0; i < k; ++i)
    if (q(i) < q(r)) r = i;
  int enter = 2 * k;
  for (int piv = 1; piv <= cap; ++piv) {
    T.row(r) /= T(r, enter);
    for (int i = 0; i < k; ++i)
      if (i != r) T.row(i) -= T(i, enter) * T.row(r);
    const int leave = basis[r];
    basis[r] = enter;
    if (leave == 2 * k) return piv;
    enter = leave < k ? leave + k : leave - k;
    double best = INFINITY;
    r = -1;
    for (int i = 0; i < k; ++i)
      if (T(i, enter) > 1e-12 && T(i, 2 * k + 1) / T(i, enter) < best - 1e-12) {
        best = T(i, 2 * k + 1) / T(i, enter);
        r = i;
      }
    if (r < 0) return -piv;
  }
  return cap + 1;  // cycled
}

TEST(LcpDegenerate, CyclingExampleSolvedByLexicographicLemke) {
  // Classic degenerate cyclic example (Cottle, Pang & Stone §4.9 style):
  // M = [[1,2,0],[0,1,2],[2,0,1]], q = -e. Every ratio test ties. The unique
  // solution (M is a P-matrix: minors 1, 1, 1, 9) is z = e/3, w = 0, since
  // each row reads z_i + 2 z_{i+1} - 1 = 0.
  MatrixXd M(3, 3);
  M << 1, 2, 0, 0, 1, 2, 2, 0, 1;
  const VectorXd q = -VectorXd::Ones(3);
  ASSERT_TRUE(is_p_matrix(M));
  EXPECT_GT(naive_lemke_pivots(M, q, 1000), 1000) << "the example must make naive Lemke cycle";
  const Result r = solve_lemke(M, q);
  expect_solution(M, q, r, "lemke");
  // z = 1/3 exactly up to a few roundings of O(1) numbers.
  EXPECT_LE(max_abs_diff(r.z, VectorXd::Constant(3, 1.0 / 3.0)), 1e-14);
  EXPECT_LE(r.pivots, 10);
}

TEST(LcpDegenerate, TiesAndZerosInQAgreeWithEnumeration) {
  // q with exact zeros and repeated values: degenerate bases everywhere.
  std::mt19937 rng(5);
  for (int k = 2; k <= 10; ++k) {
    for (int trial = 0; trial < 3; ++trial) {
      const MatrixXd M = trial == 2 ? random_scaled_p(k, rng) : random_spd(k, rng);
      VectorXd q(k);
      for (int i = 0; i < k; ++i) q(i) = (i % 3 == 0) ? 0.0 : (i % 3 == 1 ? -1.0 : -2.0);
      // Integer-valued M with exact ties as well.
      const MatrixXd Mi = (2.0 * M).array().round().matrix() + 3.0 * k * MatrixXd::Identity(k, k);
      for (const MatrixXd* A : {&M, &Mi}) {
        const EnumerationResult oracle = enumerate_solutions(*A, q);
        ASSERT_EQ(oracle.solutions.size(), 1u);
        for (const Result& r : {solve_lemke(*A, q), solve_principal_pivoting(*A, q)}) {
          expect_solution(*A, q, r, "degenerate");
          EXPECT_LE(max_abs_diff(r.z, oracle.solutions[0]), kOracleTol);
        }
      }
    }
  }
  // q = 0: z = 0 is the solution, no pivot needed.
  const Result r0 = solve_lemke(MatrixXd::Identity(3, 3), VectorXd::Zero(3));
  EXPECT_EQ(r0.pivots, 0);
  EXPECT_EQ(r0.z, VectorXd::Zero(3));
}

TEST(LcpDelassus, DependentConstraintsGiveUniqueWAndImpulse) {
  // Two identical contact rows E = [[1,0],[1,0]] (thesis Theorem 4.6.5: the
  // impulse E'z is unique though z is not). M = E E' = [[1,1],[1,1]], and with
  // q = (-1,-1) every solution has z1 + z2 = 1, w = 0, E'z = (1, 0).
  MatrixXd E(2, 2);
  E << 1, 0, 1, 0;
  const MatrixXd M = E * E.transpose();
  const VectorXd q = -VectorXd::Ones(2);
  const Eigen::Vector2d impulse(1.0, 0.0);
  // Inputs are small integers: results are exact up to one or two roundings.
  constexpr double kTol = 1e-14;
  const EnumerationResult oracle = enumerate_solutions(M, q);
  ASSERT_EQ(oracle.solutions.size(), 2u) << "vertices (1,0) and (0,1)";
  for (const VectorXd& z : oracle.solutions) {
    EXPECT_LE(max_abs_diff(E.transpose() * z, impulse), kTol);
    EXPECT_LE((M * z + q).cwiseAbs().maxCoeff(), kTol);
  }
  Options pgs_opt;
  for (const Result& r : {solve_lemke(M, q), solve_pgs(M, q, pgs_opt), solve_enumeration(M, q)}) {
    expect_solution(M, q, r, "delassus");
    EXPECT_LE(max_abs_diff(E.transpose() * r.z, impulse), kTol);
    EXPECT_LE(r.w.cwiseAbs().maxCoeff(), kTol);
  }
  const Result rp = solve_principal_pivoting(M, q);  // not a P-matrix
  if (rp.ok()) {
    EXPECT_LE(max_abs_diff(E.transpose() * rp.z, impulse), kTol);
  }
}

TEST(LcpInfeasible, LemkeReportsRayTermination) {
  // M = [[1,-1],[-1,1]] is PSD (copositive-plus), q = (-1,-1): w1 + w2 = -2 for
  // every z, so no z gives w >= 0. For copositive-plus M a secondary ray
  // proves infeasibility (Cottle, Pang & Stone Thm 4.4.13).
  MatrixXd M(2, 2);
  M << 1, -1, -1, 1;
  const VectorXd q = -VectorXd::Ones(2);
  const Result r = solve_lemke(M, q);
  EXPECT_EQ(r.status, Status::kRayTermination) << r.message;
  EXPECT_FALSE(r.message.empty());
  EXPECT_TRUE(enumerate_solutions(M, q).solutions.empty());
  EXPECT_EQ(solve_enumeration(M, q).status, Status::kNumericalFailure);
  Options opt;
  opt.max_iterations = 500;
  EXPECT_EQ(solve_pgs(M, q, opt).status, Status::kIterationLimit);
  EXPECT_FALSE(solve_principal_pivoting(M, q).ok());
}

TEST(LcpMurty, ExponentialExampleTakes2PowKMinus1Pivots) {
  // Murty (1978): M = upper triangular, 1 on the diagonal, 2 above; q = -e.
  // The unique solution is z = e_k (row i: z_i + 2 sum_{j>i} z_j - 1 = 0 holds
  // for i = k, and w_i = 2 - 1 = 1 > 0 for i < k). Rows k-1.. do not involve
  // z_1, so the least-index rule solves the trailing problem of order k-1 with
  // index 1 toggled in between: P(k) = 2 P(k-1) + 1, P(1) = 1, so P(k) = 2^k - 1.
  for (int k = 1; k <= 10; ++k) {
    MatrixXd M = MatrixXd::Identity(k, k);
    for (int i = 0; i < k; ++i)
      for (int j = i + 1; j < k; ++j) M(i, j) = 2.0;
    const VectorXd q = -VectorXd::Ones(k);
    const Result r = solve_murty(M, q);
    expect_solution(M, q, r, "murty");
    EXPECT_EQ(r.pivots, (1 << k) - 1) << "k=" << k;
    // Integer data, triangular systems: exact.
    EXPECT_EQ(r.z, VectorXd::Unit(k, k - 1));
    // The block method and Lemke are not fooled.
    const Result rb = solve_principal_pivoting(M, q);
    expect_solution(M, q, rb, "pivot");
    EXPECT_LE(rb.iterations, 2 * k);
    EXPECT_EQ(rb.z, VectorXd::Unit(k, k - 1));
    expect_solution(M, q, solve_lemke(M, q), "lemke");
  }
}

TEST(LcpPgs, WarmStartRelaxationAndIterationCap) {
  std::mt19937 rng(11);
  const MatrixXd M = random_spd(20, rng);
  const VectorXd q = test::gaussian(20, rng);
  const Result base = solve_pgs(M, q);
  expect_solution(M, q, base, "pgs");
  EXPECT_GT(base.iterations, 1);

  Options warm;
  warm.warm_start = &base.z;
  const Result again = solve_pgs(M, q, warm);
  expect_solution(M, q, again, "pgs warm");
  EXPECT_EQ(again.iterations, 0) << "the warm start already satisfies the tolerance";

  Options sor;
  sor.relaxation = 1.3;
  const Result rs = solve_pgs(M, q, sor);
  expect_solution(M, q, rs, "sor");
  EXPECT_LE(max_abs_diff(rs.z, base.z), kOracleTol);

  Options capped;
  capped.max_iterations = 2;
  const Result rc = solve_pgs(M, q, capped);
  EXPECT_EQ(rc.status, Status::kIterationLimit);
  EXPECT_EQ(rc.iterations, 2);
  EXPECT_GT(rc.residual, 0.0);

  MatrixXd Z = M;
  Z(3, 3) = 0.0;  // zero diagonal: PGS undefined
  EXPECT_EQ(solve_pgs(Z, q).status, Status::kNumericalFailure);
}

TEST(LcpHonesty, NonPMatrixNeverReportedSolvedWrongly) {
  // M = [[0,1],[1,0]] (not P: zero diagonal), q = (-1,-1): z = (1,1) solves
  // (w = (0,0)), but principal submatrices of order 1 are singular.
  MatrixXd M(2, 2);
  M << 0, 1, 1, 0;
  const VectorXd q = -VectorXd::Ones(2);
  for (const Result& r : {solve_principal_pivoting(M, q), solve_murty(M, q), solve_lemke(M, q)})
    if (r.ok()) expect_solution(M, q, r, "non-P");
  const Result rp = solve_principal_pivoting(M, q);
  EXPECT_TRUE(rp.ok() || rp.status == Status::kNumericalFailure ||
              rp.status == Status::kIterationLimit);
  // A tolerance no solver can meet forces an honest failure.
  std::mt19937 rng(3);
  const MatrixXd S = random_spd(8, rng);
  const VectorXd qs = test::gaussian(8, rng);
  Options impossible;
  impossible.tolerance = 0.0;
  impossible.max_iterations = 50;
  const Result rg = solve_pgs(S, qs, impossible);
  EXPECT_NE(rg.status, Status::kSolved);
}

}  // namespace
}  // namespace lcsim::lcp
