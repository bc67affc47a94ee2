// Impact rules on the thesis's exact examples: Example 3.8.3 (two carts with a
// hook, the counter-example to the rule of ref. [177]), Example 1.4.1 (three
// balls, sequential pairwise impacts) and Newton's cradle.
//
// Tolerances: the pivoting rules and "sequential"/"flip" do O(10) flops on
// small integers, so 1e-14 covers rounding; the sequential limit is reached to
// the stopping test 1e-12 |E_i||v| (impact.hpp), so its limit is checked to
// 1e-11; Ipopt ("moreau-qp") stops at tol 1e-12 on the scaled problem, so its
// velocities are checked to 1e-8 (the barrier leaves O(sqrt(mu)) errors).
#include <gtest/gtest.h>

#include <lcsim/impact/impact.hpp>
#include <stdexcept>
#include <tuple>

#include "impact_test_util.hpp"

namespace lcsim::impact {
namespace {

using testing::expect_near;
using testing::input;
using testing::pivot;
using testing::run;
using testing::vec;

TEST(ImpactRegistry, ListsAllRulesAndRejectsUnknownNames) {
  const std::vector<std::string> names = impact_law_names();
  for (const char* n :
       {"inelastic", "moreau-qp", "newton", "moreau-restitution", "sequential", "flip"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_EQ(make_impact_law(n)->name(), n);
  }
  try {
    make_impact_law("bogus");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("bogus"), std::string::npos);
    EXPECT_NE(msg.find("moreau-qp"), std::string::npos);
    EXPECT_NE(msg.find("sequential"), std::string::npos);
  }
}

// Example 3.8.3 at x0 = (0, 0, -1, 2): both gaps close (E v = (-1, -3)).
// Minimisation 3.8.1 selects the hook alone: lambda = (0, 3/2), v+ = (1/2, 1/2).
TEST(Example383, MoreauAndItsMinimisationSelectTheHookAlone) {
  const auto m = testing::hook_model();
  const auto in = input(m, vec({-1, 2}), {0, 1});
  for (const char* rule : {"moreau", "moreau-qp"}) {
    SCOPED_TRACE(rule);
    const ImpactResult r = run(rule, in);
    ASSERT_TRUE(r.ok()) << r.message;
    const double tol = std::string(rule) == "moreau" ? 1e-14 : 1e-8;
    expect_near(r.v_after, vec({0.5, 0.5}), tol);
    expect_near(r.impulse, vec({0.0, 1.5}), tol);
    EXPECT_EQ(r.mode, (IndexSet{1}));
    EXPECT_TRUE(r.admissible);
    EXPECT_NEAR(r.energy_before, 2.5, 1e-14);
    EXPECT_NEAR(r.energy_after, 0.25, tol);
  }
}

// Rule [177]: both constraints would be violated, so both become active;
// E w = 0 gives w = 0 and lambda = (-1, 2): the stop pulls. Not admissible.
TEST(Example383, RuleOf177SelectsBothAndNeedsAPullingStop) {
  const auto m = testing::hook_model();
  const ImpactResult r = run("flip", input(m, vec({-1, 2}), {0, 1}));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_EQ(r.mode, (IndexSet{0, 1}));
  expect_near(r.impulse, vec({-1.0, 2.0}), 1e-14);
  expect_near(r.v_after, vec({0.0, 0.0}), 1e-14);
  EXPECT_FALSE(r.admissible);
  EXPECT_NE(r.message.find("not an admissible solution"), std::string::npos) << r.message;
}

// Where the flip impulse is nonnegative the two rules give the same jump:
// at x0 = (0, 0, -1, 0), E v = (-1, -1); Moreau stops the left cart alone,
// lambda = (1, 0), v+ = 0, and [177] picks both with the same lambda = (1, 0).
TEST(Example383, RulesAgreeWhenTheFlipImpulseIsNonnegative) {
  const auto m = testing::hook_model();
  const auto in = input(m, vec({-1, 0}), {0, 1});
  const ImpactResult mo = run("moreau", in), fl = run("flip", in);
  ASSERT_TRUE(mo.ok() && fl.ok());
  expect_near(mo.v_after, vec({0, 0}), 1e-14);
  expect_near(fl.v_after, mo.v_after, 1e-14);
  expect_near(fl.impulse, mo.impulse, 1e-14);
  EXPECT_TRUE(fl.admissible);
}

// Example 1.4.1: three unit balls touching, v = (1, 0, 0). Moreau: all three
// move together at 1/3 with impulses (2/3, 1/3).
TEST(Example141, MoreauGivesOneThirdEach) {
  const auto m = testing::three_balls();
  const ImpactResult r = run("moreau", input(m, vec({1, 0, 0}), {0, 1}));
  ASSERT_TRUE(r.ok()) << r.message;
  expect_near(r.v_after, vec({1.0 / 3, 1.0 / 3, 1.0 / 3}), 1e-14);
  expect_near(r.impulse, vec({2.0 / 3, 1.0 / 3}), 1e-14);
  EXPECT_EQ(r.mode, (IndexSet{0, 1}));
  EXPECT_NEAR(r.energy_after, 1.0 / 6, 1e-14);
}

// The thesis prints the sequence v1: 1 1/2 1/2 3/8 3/8 11/32,
// v2: 0 1/2 1/4 3/8 5/16 11/32, v3: 0 0 1/4 1/4 5/16 5/16.
TEST(Example141, SequentialReproducesThePrintedIteratesAndConverges) {
  const auto m = testing::three_balls();
  auto in = input(m, vec({1, 0, 0}), {0, 1});
  in.record_iterates = true;
  const ImpactResult r = run("sequential", in);
  ASSERT_TRUE(r.ok()) << r.message;
  const std::vector<Eigen::VectorXd> printed = {vec({1, 0, 0}),
                                                vec({0.5, 0.5, 0}),
                                                vec({0.5, 0.25, 0.25}),
                                                vec({3. / 8, 3. / 8, 0.25}),
                                                vec({3. / 8, 5. / 16, 5. / 16}),
                                                vec({11. / 32, 11. / 32, 5. / 16})};
  ASSERT_GE(r.iterates.size(), printed.size());
  for (size_t i = 0; i < printed.size(); ++i) {
    SCOPED_TRACE("iterate " + std::to_string(i));
    expect_near(r.iterates[i], printed[i], 1e-15);  // dyadic rationals: exact
  }
  EXPECT_EQ(static_cast<int>(r.iterates.size()), r.iterations + 1);
  expect_near(r.v_after, vec({1.0 / 3, 1.0 / 3, 1.0 / 3}), 1e-11);
  expect_near(r.impulse, vec({2.0 / 3, 1.0 / 3}), 1e-11);
  EXPECT_NE(r.message.find("converged after"), std::string::npos) << r.message;
  EXPECT_LE(r.energy_after, r.energy_before);
}

TEST(Example141, SequentialReportsTheCap) {
  const auto m = testing::three_balls();
  auto in = input(m, vec({1, 0, 0}), {0, 1});
  in.max_iterations = 5;
  const ImpactResult r = run("sequential", in);
  EXPECT_FALSE(r.ok());
  EXPECT_EQ(r.iterations, 5);
  EXPECT_NE(r.message.find("not converged"), std::string::npos) << r.message;
}

// Newton's cradle, e = 1: the simultaneous rule gives (-1/3, 2/3, 2/3), the
// sequential one passes the momentum along: (0, 0, 1). Both keep energy 1/2.
TEST(NewtonsCradle, SimultaneousAndSequentialPartButKeepEnergy) {
  const auto m = testing::three_balls();
  const auto in = input(m, vec({1, 0, 0}), {0, 1}, vec({1, 1}));
  const ImpactResult nw = run("newton", in);
  ASSERT_TRUE(nw.ok()) << nw.message;
  expect_near(nw.v_after, vec({-1.0 / 3, 2.0 / 3, 2.0 / 3}), 1e-14);
  expect_near(nw.impulse, vec({4.0 / 3, 2.0 / 3}), 1e-14);
  EXPECT_NEAR(nw.energy_after, 0.5, 1e-14);
  const ImpactResult sq = run("sequential", in);
  ASSERT_TRUE(sq.ok()) << sq.message;
  expect_near(sq.v_after, vec({0, 0, 1}), 1e-15);
  EXPECT_EQ(sq.iterations, 2);
  EXPECT_NEAR(sq.energy_after, 0.5, 1e-15);
  // With one coefficient for all contacts, restitution inside the LCP
  // (Moreau–Jean) is the same map as Newton's on the inelastic impulse.
  const ImpactResult mj = run("moreau-restitution", in);
  ASSERT_TRUE(mj.ok()) << mj.message;
  expect_near(mj.v_after, nw.v_after, 1e-14);
}

TEST(ImpactRules, NoClosedContactMeansNoImpact) {
  const auto m = testing::three_balls();
  for (const auto& name : impact_law_names()) {
    const ImpactResult r = run(name, input(m, vec({1, 0, 0}), {}));
    EXPECT_TRUE(r.ok()) << name;
    expect_near(r.v_after, vec({1, 0, 0}), 0.0);
    EXPECT_EQ(r.impulse.size(), 2);
  }
}

// Nearly dependent rows: x1 >= 0 and x1 + d x2 >= 0 (angle d), both closed,
// M = diag(4, 1/100), v = (-1, 0). Moreau's rule gives v+ = (0, 0) with the
// impulse 4 on the first row: the vertex of the cone, M (v+ - v) = (4, 0) =
// E'(4, 0). Newton with e = 1/2 on both rows and the Moreau–Jean law with
// e = 1/2 both give v+ = (1/2, 0), impulse 6. The Delassus matrix [[1/4,
// 1/4], [1/4, 1/4 + 100 d^2]] rounds to singular once 400 d^2 < eps (d =
// 1e-8 here): the LCP alone then split the impulse as (0, 4) and left v+ =
// (0, 400 d) (found by the extremes suite). The rules refine the LCP's
// answer on E (detail::refine_on_active_set), where the two rows span the
// plane whatever d: v+ to rounding, 1e-14. The impulse through E' (its
// first component, the sum of the two) to 1e-12; each one is >= 0.
TEST(ImpactRules, NearlyDependentRowsGiveTheExactVelocity) {
  for (double d : {1e-6, 1e-8, 1e-10, 1e-13}) {
    Eigen::MatrixXd E(2, 2);
    E << 1, 0, 1, d;
    const auto m = testing::make_model(Eigen::Vector2d(4, 0.01).asDiagonal().toDenseMatrix(), E);
    for (const auto& [rule, e, v_after] :
         {std::tuple{"moreau", 0.0, vec({0, 0})}, std::tuple{"newton", 0.5, vec({0.5, 0})},
          std::tuple{"moreau-restitution", 0.5, vec({0.5, 0})}}) {
      SCOPED_TRACE(std::string(rule) + " d " + std::to_string(d));
      const ImpactResult r = run(rule, input(m, vec({-1, 0}), {0, 1}, vec({e, e})));
      ASSERT_TRUE(r.ok()) << rule << " d " << d << ": " << r.message;
      expect_near(r.v_after, v_after, 1e-14);
      EXPECT_NEAR(r.impulse.sum(), 4 * (1 + e), 1e-12) << rule << " d " << d;
      EXPECT_GE(r.impulse.minCoeff(), 0.0) << rule << " d " << d;
      EXPECT_TRUE(r.admissible) << rule << " d " << d;
    }
  }
}

TEST(ImpactRules, BadInputIsAResultNotAnException) {
  const auto m = testing::three_balls();
  for (const auto& name : impact_law_names()) {
    const ImpactResult r = run(name, input(m, vec({1, 0}), {0}));
    EXPECT_FALSE(r.ok()) << name;
    EXPECT_NE(r.message.find("velocity"), std::string::npos) << r.message;
  }
}

}  // namespace
}  // namespace lcsim::impact
