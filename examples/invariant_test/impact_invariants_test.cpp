// A test a user of lcsim would write: on random mechanical models (seeded,
// so every run checks the same ones), Moreau's inelastic impact (law
// "inelastic": e = 0 whatever the model's restitution; "moreau" is an alias
// of "newton", which applies the restitution) must
//  - never raise the kinetic energy,
//  - leave no closed contact approaching: E_J v+ >= 0 (feasibility),
//  - give impulses >= 0 complementary to the post-impact rates:
//    lambda_i (E_i v+) = 0,
//  - move v by exactly M^{-1} E' lambda.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <random>

namespace {
using Eigen::MatrixXd;
using Eigen::VectorXd;

// N coordinates, k <= N contacts, all closed at q = 0 (g = 0). M = B B' + I
// is symmetric positive definite with eigenvalues >= 1; E has full row rank
// with probability one; entries are O(1).
lcsim::mech::MechanicalModel random_model(std::mt19937& rng, int n, int k) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  auto random = [&](int r, int c) {
    return MatrixXd(MatrixXd::NullaryExpr(r, c, [&] { return u(rng); }));
  };
  const MatrixXd B = random(n, n);
  lcsim::mech::MechanicalModel m;
  m.M = (B * B.transpose() + MatrixXd::Identity(n, n)).sparseView();
  m.E = random(k, n).sparseView();
  m.restitution = VectorXd::Zero(k);  // inelastic
  lcsim::mech::fill_defaults(m);
  return m;
}

TEST(MoreauImpact, InelasticInvariantsOnRandomModels) {
  std::mt19937 rng(20240611);  // fixed seed: the same 500 models each run
  std::uniform_int_distribution<int> dofs(1, 6);
  std::normal_distribution<double> normal(0.0, 1.0);
  auto law = lcsim::impact::make_impact_law("inelastic");
  auto solver = lcsim::lcp::make_solver("pivot");
  int checked = 0;
  for (int trial = 0; trial < 500; ++trial) {
    const int n = dofs(rng);
    const int k = std::uniform_int_distribution<int>(1, n)(rng);
    const lcsim::mech::MechanicalModel m = random_model(rng, n, k);
    lcsim::impact::ImpactInput in;
    in.model = &m;
    in.q = VectorXd::Zero(n);
    in.v = VectorXd::NullaryExpr(n, [&] { return normal(rng); });
    for (int i = 0; i < k; ++i) in.closed.push_back(i);  // every gap is 0 at q = 0
    // Tolerance: a pivoting LCP solve in double precision has relative
    // error <= ~k cond(W) eps for the Delassus matrix W = E M^{-1} E'; the
    // models kept have cond(W) <= 1e6, so <= ~6e-10: 1e-8 leaves a margin
    // and still catches any wrong impulse. The scale of a rate is |E_i| |v|,
    // of an energy T(v), of an impulse |M| |v| / |E_i|.
    const MatrixXd M(m.M), E(m.E);
    const MatrixXd W = E * M.ldlt().solve(E.transpose());
    const Eigen::JacobiSVD<MatrixXd> svd(W);
    if (svd.singularValues()(0) > 1e6 * svd.singularValues()(k - 1))
      continue;  // nearly dependent contacts: not this test's subject
    ++checked;
    const double tol = 1e-8;
    const lcsim::impact::ImpactResult r = law->apply(in, *solver);
    ASSERT_TRUE(r.ok()) << "trial " << trial << ": " << r.message;
    const VectorXd rate = E * r.v_after;  // E_J v+
    const double vnorm = in.v.norm();
    EXPECT_LE(r.energy_after, r.energy_before * (1.0 + tol)) << "trial " << trial;
    EXPECT_NEAR(r.energy_before, 0.5 * in.v.dot(M * in.v), tol * r.energy_before);
    for (int i = 0; i < k; ++i) {
      const double rate_scale = E.row(i).norm() * vnorm;
      const double impulse_scale = M.norm() * vnorm / E.row(i).norm();
      EXPECT_GE(rate[i], -tol * rate_scale) << "trial " << trial << ", contact " << i;
      EXPECT_GE(r.impulse[i], -tol * impulse_scale) << "trial " << trial << ", contact " << i;
      EXPECT_LE(std::abs(r.impulse[i] * rate[i]), tol * impulse_scale * rate_scale)
          << "trial " << trial << ", contact " << i;
    }
    const VectorXd jump = M.ldlt().solve(E.transpose() * r.impulse);
    EXPECT_LE((r.v_after - in.v - jump).norm(), tol * vnorm) << "trial " << trial;
  }
  EXPECT_GE(checked, 400);  // the conditioning filter left most models in
}

}  // namespace
