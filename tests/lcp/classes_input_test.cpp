// Matrix-class checks on known matrices, input validation and the registry.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <limits>
#include <stdexcept>

namespace lcsim::lcp {
namespace {

MatrixXd mat2(double a, double b, double c, double d) {
  MatrixXd M(2, 2);
  M << a, b, c, d;
  return M;
}

TEST(LcpMatrixClass, KnownMatrices) {
  const MatrixXd I = MatrixXd::Identity(3, 3);
  EXPECT_TRUE(is_p_matrix(I));
  EXPECT_TRUE(is_positive_definite(I));
  EXPECT_TRUE(is_positive_semidefinite(I));
  EXPECT_TRUE(is_symmetric(I));

  // Delassus matrix of two identical constraints: PSD, singular, not P.
  const MatrixXd D = mat2(1, 1, 1, 1);
  EXPECT_FALSE(is_p_matrix(D));
  EXPECT_FALSE(is_positive_definite(D));
  EXPECT_TRUE(is_positive_semidefinite(D));
  EXPECT_TRUE(is_symmetric(D));

  // Skew-symmetric: x'Mx = 0 for all x, so PSD but not PD; zero diagonal, not P.
  const MatrixXd K = mat2(0, 1, -1, 0);
  EXPECT_TRUE(is_positive_semidefinite(K));
  EXPECT_FALSE(is_positive_definite(K));
  EXPECT_FALSE(is_p_matrix(K));
  EXPECT_FALSE(is_symmetric(K));

  // Triangular with unit diagonal: every principal minor is 1 (P), but the
  // symmetric part [[1,-1.5],[-1.5,1]] has eigenvalue 1 - 1.5 < 0 (not PSD).
  const MatrixXd T = mat2(1, -3, 0, 1);
  EXPECT_TRUE(is_p_matrix(T));
  EXPECT_FALSE(is_positive_definite(T));
  EXPECT_FALSE(is_positive_semidefinite(T));

  // Nonsymmetric PD: symmetric part is the identity.
  const MatrixXd N = mat2(1, 5, -5, 1);
  EXPECT_TRUE(is_positive_definite(N));
  EXPECT_TRUE(is_p_matrix(N));  // minors 1, 1, 26

  // det = -2 < 0: not P.
  EXPECT_FALSE(is_p_matrix(mat2(1, 2, 3, 4)));
  EXPECT_FALSE(is_p_matrix(mat2(-1, 0, 0, 1)));

  // Scale awareness: the tests are invariant under positive scaling.
  EXPECT_TRUE(is_p_matrix(1e-20 * I));
  EXPECT_TRUE(is_positive_definite(1e-20 * I));
  EXPECT_TRUE(is_p_matrix(1e20 * T));
  EXPECT_TRUE(is_symmetric(1e-30 * D));
  // A minor at rounding level relative to the entries counts as zero:
  // det [[1,1],[1,1+1e-15]] = 1e-15 < 1e-12 * Hadamard bound (~2).
  EXPECT_FALSE(is_p_matrix(mat2(1, 1, 1, 1 + 1e-15)));
  EXPECT_TRUE(is_p_matrix(mat2(1, 1, 1, 1 + 1e-15), 1e-16));

  // Murty's matrix (upper triangular, 1 diag, 2 above) is P at k = 10.
  MatrixXd Mu = MatrixXd::Identity(10, 10);
  for (int i = 0; i < 10; ++i)
    for (int j = i + 1; j < 10; ++j) Mu(i, j) = 2.0;
  EXPECT_TRUE(is_p_matrix(Mu));
  // Its symmetric part is the all-ones matrix J: x'Jx = (sum x)^2 >= 0, with
  // J singular for k >= 2, so PSD but not PD.
  EXPECT_TRUE(is_positive_semidefinite(Mu));
  EXPECT_FALSE(is_positive_definite(Mu));

  // Non-square and non-finite matrices are in no class.
  EXPECT_FALSE(is_p_matrix(MatrixXd::Ones(2, 3)));
  EXPECT_FALSE(is_symmetric(MatrixXd::Ones(2, 3)));
  EXPECT_FALSE(is_positive_definite(mat2(1, 0, 0, std::nan(""))));
}

TEST(LcpInput, InvalidInputIsReportedNotThrown) {
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q = -VectorXd::Ones(2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  MatrixXd Mnan = M;
  Mnan(1, 0) = nan;
  VectorXd qinf = q;
  qinf(1) = inf;
  struct Case {
    MatrixXd M;
    VectorXd q;
    const char* what;
  };
  const Case cases[] = {
      {M, VectorXd::Ones(3), "has size 3"},
      {MatrixXd::Ones(2, 3), q, "square"},
      {MatrixXd(0, 0), VectorXd(0), "empty"},
      {Mnan, q, "M(1,0)"},
      {M, qinf, "q(1)"},
  };
  for (const std::string& name : solver_names()) {
    const auto solver = make_solver(name);
    for (const Case& c : cases) {
      Result r;
      EXPECT_NO_THROW(r = solver->solve(c.M, c.q, Options{})) << name;
      EXPECT_EQ(r.status, Status::kInvalidInput) << name << " " << c.what;
      EXPECT_NE(r.message.find(c.what), std::string::npos) << name << ": " << r.message;
      EXPECT_EQ(r.z.size(), 0);
    }
  }
  EXPECT_EQ(solve_murty(Mnan, q).status, Status::kInvalidInput);
  EXPECT_EQ(enumerate_solutions(Mnan, q).status, Status::kInvalidInput);
  EXPECT_NE(validate(M, VectorXd::Ones(3)), "");
  EXPECT_EQ(validate(M, q), "");

  Options bad;
  bad.relaxation = 2.5;
  EXPECT_EQ(solve_pgs(M, q, bad).status, Status::kInvalidInput);
  const VectorXd wrong(3);
  Options warm;
  warm.warm_start = &wrong;
  EXPECT_EQ(solve_pgs(M, q, warm).status, Status::kInvalidInput);
  Options neg;
  neg.tolerance = -1.0;
  EXPECT_EQ(solve_lemke(M, q, neg).status, Status::kInvalidInput);

  // Enumeration refuses k > 16 (2^17 bases).
  const Result big = solve_enumeration(MatrixXd::Identity(17, 17), -VectorXd::Ones(17));
  EXPECT_EQ(big.status, Status::kInvalidInput);
  EXPECT_NE(big.message.find("16"), std::string::npos);
}

TEST(LcpRegistry, NamesAndUnknownSolver) {
  EXPECT_EQ(solver_names(), (std::vector<std::string>{"lemke", "pivot", "pgs", "enum"}));
  for (const std::string& name : solver_names()) EXPECT_EQ(make_solver(name)->name(), name);
  try {
    make_solver("dantzig");
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("dantzig"), std::string::npos);
    for (const std::string& name : solver_names()) EXPECT_NE(msg.find(name), std::string::npos);
  }
  // Through the interface, solutions are the same as the free functions'.
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q(Eigen::Vector2d(-1.0, 2.0));
  for (const std::string& name : solver_names()) {
    const Result r = make_solver(name)->solve(M, q, Options{});
    ASSERT_TRUE(r.ok()) << name;
    EXPECT_EQ(r.z, Eigen::Vector2d(1.0, 0.0)) << name;  // exact: w = z - 1 = 0
  }
}

TEST(LcpEvaluate, DiagnosticsOfACandidate) {
  const MatrixXd M = MatrixXd::Identity(2, 2);
  const VectorXd q(Eigen::Vector2d(-1.0, 2.0));
  const Result good = evaluate(M, q, Eigen::Vector2d(1.0, 0.0));
  EXPECT_EQ(good.status, Status::kSolved);
  EXPECT_EQ(good.residual, 0.0);
  // z = (0.5, -0.25): w = (-0.5, 1.75), min(z, w) = (-0.5, -0.25).
  const Result bad = evaluate(M, q, Eigen::Vector2d(0.5, -0.25));
  EXPECT_EQ(bad.status, Status::kNumericalFailure);
  EXPECT_EQ(bad.residual, 0.5);
  EXPECT_EQ(bad.min_z, -0.25);
  EXPECT_EQ(bad.min_w, -0.5);
  EXPECT_EQ(natural_residual(M, q, Eigen::Vector2d(0.5, -0.25)), 0.5);
  EXPECT_EQ(evaluate(M, q, VectorXd(3)).status, Status::kInvalidInput);
  EXPECT_EQ(to_string(Status::kRayTermination), "ray termination");
}

}  // namespace
}  // namespace lcsim::lcp
