// The impact laws' names say what they do (issue 24, item 8): "newton" is
// Newton's restitution per contact on Moreau's inelastic impulse,
// "inelastic" is Moreau's inelastic rule whatever the restitution, and
// "moreau" (the old name of "newton") is an alias that resolves to "newton"
// and says so.
//
// Tolerances: the examples are O(10) flops on small integers (1e-14, as
// examples_test.cpp); "moreau" and "newton" are one code path, so they agree
// exactly; the random friction cases compare one formula applied twice to the
// same data, also exact.
#include <gtest/gtest.h>

#include <algorithm>
#include <lcsim/impact/impact.hpp>
#include <random>
#include <stdexcept>

#include "impact/friction_test_util.hpp"
#include "impact_test_util.hpp"

namespace lcsim::impact {
namespace {

using testing::expect_near;
using testing::input;
using testing::run;
using testing::vec;

TEST(LawNames, MoreauIsAnAliasOfNewtonAndSaysSo) {
  const auto names = impact_law_names();
  EXPECT_EQ(std::count(names.begin(), names.end(), "moreau"), 0);  // not a law of its own
  EXPECT_EQ(std::count(names.begin(), names.end(), "newton"), 1);
  EXPECT_EQ(std::count(names.begin(), names.end(), "inelastic"), 1);
  ASSERT_TRUE(laws().contains("moreau"));
  EXPECT_EQ(make_impact_law("moreau")->name(), "newton");
  const std::string note = laws().alias_note("moreau");
  EXPECT_NE(note.find("'moreau' is an alias of 'newton'"), std::string::npos) << note;
  EXPECT_NE(note.find("'inelastic'"), std::string::npos) << note;
  EXPECT_EQ(laws().alias_note("newton"), "");
  try {
    make_impact_law("bogus");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("; alias moreau"), std::string::npos) << e.what();
  }
  // The alias runs newton's formula: Example 1.4.1 with e = 1/2 on both
  // contacts, v+ = (1 + e) u - e v with u = (1/3, 1/3, 1/3), v = (1, 0, 0).
  const auto m = testing::three_balls();
  const auto in = input(m, vec({1, 0, 0}), {0, 1}, vec({0.5, 0.5}));
  const ImpactResult mo = run("moreau", in), ne = run("newton", in);
  ASSERT_TRUE(mo.ok() && ne.ok()) << mo.message << ne.message;
  expect_near(ne.v_after, vec({0.0, 0.5, 0.5}), 1e-14);
  EXPECT_EQ(mo.v_after, ne.v_after);
  EXPECT_EQ(mo.impulse, ne.impulse);
}

// Example 1.4.1 (three balls, v = (1, 0, 0)): Moreau's inelastic rule moves
// all three at 1/3 with impulses (2/3, 1/3), whatever restitution the model
// or the input gives.
TEST(LawNames, InelasticIgnoresRestitutionOnExample141) {
  auto m = testing::three_balls();
  m.restitution = vec({0.5, 0.8});
  auto in = input(m, vec({1, 0, 0}), {0, 1});
  for (const bool from_model : {true, false}) {
    SCOPED_TRACE(from_model ? "the model's restitution" : "the input's restitution");
    in.restitution = from_model ? Eigen::VectorXd() : vec({0.9, 1.0});
    const ImpactResult r = run("inelastic", in);
    ASSERT_TRUE(r.ok()) << r.message;
    expect_near(r.v_after, vec({1.0 / 3, 1.0 / 3, 1.0 / 3}), 1e-14);
    expect_near(r.impulse, vec({2.0 / 3, 1.0 / 3}), 1e-14);
    EXPECT_EQ(r.mode, (IndexSet{0, 1}));
    EXPECT_NEAR(r.energy_after, 1.0 / 6, 1e-14);
    EXPECT_GT(run("newton", in).energy_after, 1.0 / 6 + 0.05);  // newton applies e
  }
}

// Example 3.8.3 at x0 = (0, 0, -1, 2): Moreau's rule selects the hook alone,
// lambda = (0, 3/2), v+ = (1/2, 1/2), with the model's restitution 1/2 ignored.
TEST(LawNames, InelasticSelectsTheHookAloneOnExample383) {
  auto m = testing::hook_model();
  m.restitution = vec({0.5, 0.5});
  auto in = input(m, vec({-1, 2}), {0, 1});
  in.restitution = Eigen::VectorXd();
  const ImpactResult r = run("inelastic", in);
  ASSERT_TRUE(r.ok()) << r.message;
  expect_near(r.v_after, vec({0.5, 0.5}), 1e-14);
  expect_near(r.impulse, vec({0.0, 1.5}), 1e-14);
  EXPECT_EQ(r.mode, (IndexSet{1}));
  EXPECT_NEAR(r.energy_after, 0.25, 1e-14);
}

// With friction "inelastic" is the friction LCP at e = 0: on random models
// with e = 1/2 it gives what "newton" gives with the restitution set to 0.
TEST(LawNames, InelasticWithFrictionIsNewtonAtZeroRestitution) {
  std::mt19937_64 rng(24);
  for (int trial = 0; trial < 20; ++trial) {
    SCOPED_TRACE(trial);
    const auto c = testing::random_friction(rng, 0.5);
    ImpactInput in;
    in.model = &c.model;
    in.q = Eigen::VectorXd::Zero(c.model.dofs());
    in.v = c.v;
    in.closed = c.closed;
    const ImpactResult a = run("inelastic", in);
    in.restitution = Eigen::VectorXd::Zero(c.model.num_constraints());
    const ImpactResult b = run("newton", in);
    ASSERT_EQ(a.ok(), b.ok()) << a.message << " / " << b.message;
    if (!a.ok()) continue;
    EXPECT_EQ(a.v_after, b.v_after);
    EXPECT_EQ(a.friction_impulse, b.friction_impulse);
  }
}

}  // namespace
}  // namespace lcsim::impact
