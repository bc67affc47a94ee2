// The open question of §8.2.2: does per-contact Newton restitution on the
// inelastic impulse, v+ = v + sum_i (1 + e_i) M^{-1} E_i' lambda_i, ever gain
// kinetic energy when the e_i differ?
//
// Answer: yes. With lambda the inelastic impulse (w = E_J v + W lambda,
// 0 <= w ⟂ lambda >= 0, W = E_J M^{-1} E_J') and d = e∘lambda,
//     2 (T+ - T-) = d'W d - lambda'W lambda            (w'd = 0 by complementarity)
// which is positive e.g. for three unit balls v = (4, 0, -1), e = (1, 0):
// lambda = (3, 2), d = (3, 0), d'Wd = 18 > lambda'W lambda = 14, so the energy
// rises by 2 J, from 8.5 to 10.5. The same jump leaves balls 2 and 3
// approaching (E_2 v+ = -3): the rule is not even admissible there. Writing
// r = lambda - d >= 0, T- - T+ = ½ sum_i r_i (E_i v+ - E_i v) over the contacts
// with lambda_i > 0: if v+ is admissible (E_J v+ >= 0) and every impulsed
// contact was approaching or resting (E_i v <= 0), each term is >= 0 and the
// energy cannot rise. A gain with an admissible v+ needs a contact that
// separates (E_i v > 0), is pushed through the coupling (lambda_i > 0) and has
// e_i < 1; the random search below finds none (see docs/impact-rules.md).
#include <gtest/gtest.h>

#include <cstdio>
#include <lcsim/impact/impact.hpp>
#include <random>

#include "impact_test_util.hpp"

namespace lcsim::impact {
namespace {

using testing::pivot;
using testing::vec;

TEST(Section822, NewtonWithDifferentCoefficientsGainsEnergy) {
  const auto m = testing::three_balls();
  const ImpactResult r =
      moreau_newton(testing::input(m, vec({4, 0, -1}), {0, 1}, vec({1, 0})), pivot());
  ASSERT_TRUE(r.ok()) << r.message;
  // Small integers throughout: exact up to rounding of a few flops.
  EXPECT_NEAR(r.impulse(0), 6.0, 1e-14);  // (1 + 1) * 3
  EXPECT_NEAR(r.impulse(1), 2.0, 1e-14);  // (1 + 0) * 2
  EXPECT_NEAR(r.v_after(0), -2.0, 1e-14);
  EXPECT_NEAR(r.v_after(1), 4.0, 1e-14);
  EXPECT_NEAR(r.v_after(2), 1.0, 1e-14);
  EXPECT_NEAR(r.energy_before, 8.5, 1e-14);
  EXPECT_NEAR(r.energy_after, 10.5, 1e-13);  // +2 J
  EXPECT_NEAR(r.worst_rate, -3.0, 1e-14);    // balls 2 and 3 still approach
  EXPECT_FALSE(r.admissible);
  // The rules that never gain energy, on the same state.
  for (const char* name : {"moreau-restitution", "sequential"}) {
    const ImpactResult s = make_impact_law(name)->apply(
        testing::input(m, vec({4, 0, -1}), {0, 1}, vec({1, 0})), pivot());
    ASSERT_TRUE(s.ok()) << name << ": " << s.message;
    EXPECT_LE(s.energy_after, s.energy_before) << name;
  }
}

// With dependent constraints the inelastic impulse is not unique (only
// E_J' lambda is, Theorem 4.6.5), so per-contact coefficients make Newton's
// v+ depend on which lambda the LCP solver returns: two identical stops
// x >= 0 with e = (0, 1) at v = -1 admit lambda = (1, 0) -> v+ = 0 and
// lambda = (0, 1) -> v+ = 1, and every convex combination in between.
TEST(Section822, NewtonIsNotWellDefinedForDependentConstraints) {
  Eigen::MatrixXd E(2, 1);
  E << 1, 1;
  const auto m = testing::make_model(Eigen::MatrixXd::Identity(1, 1), E);
  const auto in = testing::input(m, vec({-1}), {0, 1}, vec({0, 1}));
  for (const char* s : {"lemke", "pivot", "pgs"}) {
    const ImpactResult r = moreau_newton(in, *lcp::make_solver(s));
    ASSERT_TRUE(r.ok()) << s << ": " << r.message;
    // lambda1 + lambda2 = 1 (the inelastic jump to 0) whatever the solver...
    EXPECT_NEAR(r.impulse(0) + r.impulse(1) / 2.0, 1.0, 1e-9) << s;
    // ...but v+ = lambda2 anywhere in [0, 1].
    EXPECT_GE(r.v_after(0), -1e-9) << s;
    EXPECT_LE(r.v_after(0), 1.0 + 1e-9) << s;
    std::printf("solver %-6s: impulse (%g, %g), v+ = %g\n", s, r.impulse(0), r.impulse(1),
                r.v_after(0));
  }
}

// Random search over full-rank models (dependent ones are excluded: there the
// rule is not well defined, see above) with per-contact e_i in [0, 1], half of
// them drawn from {0, 1}: the largest energy gain overall, and the largest
// with an admissible v+. The identity 2 dT = d'Wd - lambda'W lambda is
// checked on every sample.
TEST(Section822, RandomSearchFindsGainsOnlyWithInadmissibleJumps) {
  std::mt19937_64 rng(822);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  double gain_any = 0.0, gain_admissible = 0.0, identity = 0.0;
  int admissible = 0, gaining = 0;
  const int samples = 20000;
  for (int c = 0; c < samples; ++c) {
    const testing::RandomImpact ri = testing::random_impact(rng, false);
    const int k = ri.model.num_constraints();
    Eigen::VectorXd e(k);
    const bool binary = u01(rng) < 0.5;
    for (int i = 0; i < k; ++i) e(i) = binary ? std::round(u01(rng)) : u01(rng);
    const ImpactInput in = testing::input(ri.model, ri.v, ri.closed, e);
    const ImpactResult r = moreau_newton(in, pivot());
    ASSERT_TRUE(r.ok()) << r.message;
    if (r.energy_before <= 0.0) continue;
    const double rel = (r.energy_after - r.energy_before) / r.energy_before;
    // The identity, on the closed set.
    Eigen::VectorXd lam(k), d(k);
    for (int i = 0; i < k; ++i) {
      lam(i) = r.impulse(i) / (1.0 + e(i));
      d(i) = e(i) * lam(i);
    }
    const Eigen::MatrixXd W =
        ri.model.E * ri.model.M.toDense().llt().solve(ri.model.E.transpose().toDense());
    // w'lambda = w'd = 0 by complementarity up to the LCP's acceptance; kept
    // in the sum so that the check is pure algebra, exact up to rounding of
    // terms of size lambda'W lambda (hence that scale).
    const Eigen::VectorXd w = ri.model.E * ri.v + W * lam;
    const double predicted =
        0.5 * (2.0 * w.dot(lam) + 2.0 * w.dot(d) + d.dot(W * d) - lam.dot(W * lam));
    const double size =
        r.energy_before + r.energy_after + lam.cwiseAbs().dot(W.cwiseAbs() * lam.cwiseAbs());
    identity = std::max(identity, std::abs(predicted - (r.energy_after - r.energy_before)) / size);
    gain_any = std::max(gain_any, rel);
    if (rel > 1e-9) ++gaining;
    if (r.admissible) {
      ++admissible;
      gain_admissible = std::max(gain_admissible, rel);
    }
  }
  std::printf(
      "newton, per-contact e: %d samples, %d gain energy (largest %.3g of T-), %d "
      "admissible, largest admissible gain %.3g, identity error %.2e\n",
      samples, gaining, gain_any, admissible, gain_admissible, identity);
  EXPECT_GT(gain_any, 0.01);  // gains exist, and are not rounding
  EXPECT_GT(gaining, 100);
  EXPECT_LE(gain_admissible, 1e-9);  // rounding only (see the tolerances of properties_test)
  EXPECT_LE(identity, 1e-9);
}

}  // namespace
}  // namespace lcsim::impact
