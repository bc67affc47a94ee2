// The well-posedness report: Markov parameters (3.32), leading indices and
// coefficient matrices (3.39), Theorem 3.6.3, the backward Euler guard of
// Example 7.3.3, the passivity checks of §7.2 and the summary of a report.
//
// Tolerances: the data are small integers and the Markov parameters are
// products of at most n + 1 = 7 such matrices, exact in floating point; the
// comparisons use 1e-12 only to avoid asserting bitwise equality.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <lcsim/lcs/lcs.hpp>

namespace lcsim::lcs {
namespace {

constexpr double kExact = 1e-12;

Lcs two_carts() {  // eq. (3.1)
  Lcs s;
  s.A.resize(4, 4);
  s.A << 0, 0, 1, 0,  //
      0, 0, 0, 1,     //
      -2, 1, 0, 0,    //
      1, -1, 0, 0;
  s.B = (MatrixXd(4, 1) << 0, 0, 1, 0).finished();
  s.C = (MatrixXd(1, 4) << 1, 0, 0, 0).finished();
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

Lcs triple_integrator() {  // Example 7.3.3
  Lcs s;
  s.A = (MatrixXd(3, 3) << 0, 1, 0, 0, 0, 1, 0, 0, 0).finished();
  s.B = (MatrixXd(3, 1) << 0, 0, 1).finished();
  s.C = (MatrixXd(1, 3) << 1, 0, 0).finished();
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

Lcs scalar(double a, double b, double c, double d) {
  Lcs s;
  s.A = MatrixXd::Constant(1, 1, a);
  s.B = MatrixXd::Constant(1, 1, b);
  s.C = MatrixXd::Constant(1, 1, c);
  s.D = MatrixXd::Constant(1, 1, d);
  return s;
}

TEST(WellPosedness, TwoCartsMarkovParametersAndIndices) {
  const Lcs s = two_carts();
  // DESIGN.md (misprint note on §3.7): 0, 0, 1, 0, -2, 0, 5, ...
  const auto H = markov_parameters(s, 7);
  const double expected[] = {0, 0, 1, 0, -2, 0, 5};
  for (int i = 0; i < 7; ++i) EXPECT_NEAR(H[i](0, 0), expected[i], kExact) << "H^" << i;

  const auto r = analyze_well_posedness(s);
  EXPECT_EQ(r.n, 4);
  EXPECT_EQ(r.k, 1);
  ASSERT_EQ(r.markov.size(), 5u);  // H^0..H^n
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(r.markov[i](0, 0), expected[i], kExact);
  EXPECT_EQ(r.rho, std::vector<int>{2});
  EXPECT_EQ(r.eta, std::vector<int>{2});
  EXPECT_NEAR(r.row_coefficients(0, 0), 1.0, kExact);  // script M = 1 (§3.7)
  EXPECT_NEAR(r.column_coefficients(0, 0), 1.0, kExact);
  EXPECT_TRUE(r.row_p_matrix);
  EXPECT_TRUE(r.column_p_matrix);
  EXPECT_TRUE(r.locally_well_posed);
  EXPECT_FALSE(r.backward_euler_risky);
  // Position output of a mechanical system: CB = 0 with B != 0, so no K > 0
  // can satisfy the KYP LMI (lcs.hpp, N2).
  EXPECT_EQ(r.passive, "no");
  EXPECT_NE(r.passivity_reason.find("CB"), std::string::npos) << r.passivity_reason;
}

TEST(WellPosedness, TripleIntegratorIsRiskyForBackwardEuler) {
  const auto r = analyze_well_posedness(triple_integrator());
  EXPECT_EQ(r.rho, std::vector<int>{3});
  EXPECT_TRUE(r.backward_euler_risky);  // Example 7.3.3
  EXPECT_TRUE(r.locally_well_posed);    // script M = script N = 1
  EXPECT_EQ(r.passive, "no");
}

// Stiff oscillators, omega = 1e3 ... 1e12 rad/s: x = (q, v), q'' = -w^2 q + u,
// y = q. H^1 = 0 and H^2 = 1 exactly at every omega, so rho = 2 and script
// M = 1 (a P-matrix). A zero test scaled by ||C|| ||A|| ||B|| = w^2 called
// H^2 zero from omega ~ 1e6 on; the terms of C A B are |C| |A| |B| = 1.
// Also with the mass scaled (M = 1e-6, K = 1e6: the same omega = 1e6).
TEST(WellPosedness, StiffOscillatorsKeepTheirIndex) {
  for (const double mass : {1.0, 1e-6})
    for (const double w : {1e3, 1e6, 1e9, 1e12}) {
      Lcs sys;
      sys.A = (Eigen::Matrix2d() << 0, 1, -w * w, 0).finished();
      sys.B = Eigen::Vector2d(0, 1 / mass);
      sys.C = Eigen::RowVector2d(1, 0);
      sys.D = Eigen::MatrixXd::Zero(1, 1);
      const auto r = analyze_well_posedness(sys);
      EXPECT_EQ(r.rho, std::vector<int>{2}) << "omega " << w << ", mass " << mass;
      EXPECT_DOUBLE_EQ(r.row_coefficients(0, 0), 1 / mass);
      EXPECT_TRUE(r.locally_well_posed) << "omega " << w;
    }
}

TEST(WellPosedness, NonPMatrixAndInfiniteIndex) {
  // script M = -1: not a P-matrix, Theorem 3.6.3 does not apply.
  auto r = analyze_well_posedness(scalar(-1, 1, -1, 0));
  EXPECT_EQ(r.rho, std::vector<int>{1});
  EXPECT_FALSE(r.row_p_matrix);
  EXPECT_FALSE(r.locally_well_posed);
  // B = 0, D = 0: every Markov parameter vanishes, the index is infinite.
  r = analyze_well_posedness(scalar(-1, 0, 1, 0));
  EXPECT_EQ(r.rho, std::vector<int>{kInfiniteIndex});
  EXPECT_FALSE(r.row_p_matrix);
  EXPECT_FALSE(r.column_p_matrix);
  EXPECT_FALSE(r.locally_well_posed);
}

TEST(Passivity, NegativeFeedthroughIsNotPassive) {
  const auto r = analyze_well_posedness(scalar(-1, 1, 1, -1));
  EXPECT_EQ(r.passive, "no");
  EXPECT_NE(r.passivity_reason.find("D + D'"), std::string::npos) << r.passivity_reason;
}

TEST(Passivity, UnstablePoleFailsOnTheImaginaryAxis) {
  // G(s) = 1/(s - 1): CB = 1 > 0 passes N2, but Re G(jw) = -1/(w^2 + 1) < 0.
  const auto r = analyze_well_posedness(scalar(1, 1, 1, 0));
  EXPECT_EQ(r.passive, "no");
  EXPECT_NE(r.passivity_reason.find("G(l)"), std::string::npos) << r.passivity_reason;
}

TEST(Passivity, RcCircuitHasIdentityCertificate) {
  // G(s) = 1/(s + 1): A + A' = -2 <= 0 and B = C', so K = I works.
  const auto r = analyze_well_posedness(scalar(-1, 1, 1, 0));
  EXPECT_EQ(r.passive, "yes");
  EXPECT_NE(r.passivity_reason.find("K = I"), std::string::npos) << r.passivity_reason;
}

TEST(Passivity, LosslessLcCircuitIsNotFlaggedByRounding) {
  // G(s) = s/(s^2 + 1): G(jw) + G(jw)^* = 0 exactly on the imaginary axis
  // (lossless), so the frequency test sees only rounding there and must not
  // call it a violation; K = I is a certificate (A + A' = 0, B = C').
  Lcs s;
  s.A = (MatrixXd(2, 2) << 0, 1, -1, 0).finished();
  s.B = (MatrixXd(2, 1) << 0, 1).finished();
  s.C = (MatrixXd(1, 2) << 0, 1).finished();
  s.D = MatrixXd::Zero(1, 1);
  const auto r = analyze_well_posedness(s);
  EXPECT_EQ(r.passive, "yes") << r.passivity_reason;
}

TEST(Passivity, VelocityOutputMassSpringNeedsItsEnergyCertificate) {
  // m v' = -k q - d v + u, y = v (collocated velocity output): passive with
  // storage = energy, K = blockdiag(k, m), which the report cannot guess from
  // (A, B, C) when m != 1, so it says "unknown" and the certificate checks.
  const double m = 2.0, k = 3.0, d = 0.5;
  Lcs s;
  s.A = (MatrixXd(2, 2) << 0, 1, -k / m, -d / m).finished();
  s.B = (MatrixXd(2, 1) << 0, 1 / m).finished();
  s.C = (MatrixXd(1, 2) << 0, 1).finished();
  s.D = MatrixXd::Zero(1, 1);
  const auto r = analyze_well_posedness(s);
  EXPECT_EQ(r.passive, "unknown") << r.passivity_reason;
  const MatrixXd K = (MatrixXd(2, 2) << k, 0, 0, m).finished();
  const auto cert = verify_passivity_certificate(s, K);
  EXPECT_TRUE(cert.ok()) << cert.message;
  // LMI = diag(0, -2d) exactly: largest eigenvalue 0.
  EXPECT_NEAR(cert.lmi_max_eigenvalue, 0.0, kExact);
  EXPECT_FALSE(verify_passivity_certificate(s, MatrixXd::Identity(2, 2)).ok());
  EXPECT_FALSE(verify_passivity_certificate(s, -K).ok());
}

TEST(Passivity, ReasonIsAlwaysStated) {
  for (const Lcs& s : {two_carts(), triple_integrator(), scalar(-1, 1, 1, 0)}) {
    const auto r = analyze_well_posedness(s);
    EXPECT_FALSE(r.passivity_reason.empty());
  }
}

// Issue 24 (items 7 and 8): the passivity reasons speak of the LCS's
// feedthrough D (y = C x + D u), which `analyze` prints beside a mechanical
// model's damping D; the two carts' position output has relative degree 2,
// so the check fails at N2 (CB = 0 with B != 0).
TEST(ReportWords, PassivityReasonNamesTheFeedthrough) {
  const WellPosednessReport r = analyze_well_posedness(two_carts());
  EXPECT_EQ(r.passive, "no");
  EXPECT_NE(r.passivity_reason.find("feedthrough"), std::string::npos) << r.passivity_reason;
  EXPECT_NE(r.passivity_reason.find("y = C x + D u"), std::string::npos) << r.passivity_reason;
  // D + D' < 0: the first necessary condition, same words.
  Lcs s = two_carts();
  s.D(0, 0) = -1.0;
  const WellPosednessReport n = analyze_well_posedness(s);
  EXPECT_NE(n.passivity_reason.find("not a mechanical damping"), std::string::npos)
      << n.passivity_reason;
}

// Sizes: the two carts' report (5 Markov parameters of 1 x 1) is shown
// whole; a report whose matrices exceed 400 numbers is summarised by name.
TEST(ReportWords, SummaryLeavesOutOnlyLargeMatrices) {
  WellPosednessReport r = analyze_well_posedness(two_carts());
  EXPECT_TRUE(summary_left_out(r).empty());
  r.markov.assign(5, MatrixXd::Zero(9, 9));     // 405 numbers together
  r.row_coefficients = MatrixXd::Zero(20, 20);  // 400: shown
  r.column_coefficients = MatrixXd::Zero(21, 20);
  EXPECT_EQ(summary_left_out(r), (std::vector<std::string>{"markov", "column_coefficients"}));
}

}  // namespace
}  // namespace lcsim::lcs
