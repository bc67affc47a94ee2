// Impacts at a state (app::impacts_at_state, `lcsim impacts` and Python's
// `lcsim.impacts`): Example 3.8.3 by hand, the JSON's fields, the laws chosen
// on a model with friction, and every refused input named by its field.
#include <gtest/gtest.h>

#include <functional>
#include <lcsim/app/impacts.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::app {
namespace {

using nlohmann::json;

// Example 3.8.3 / 1.4.1: a few flops on small integers, exact to rounding.
constexpr double kTol = 1e-14;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

mech::Model robot(const std::string& file) { return scene::load_model(kRobots + file); }

Eigen::VectorXd vec(std::initializer_list<double> v) {
  Eigen::VectorXd x(v.size());
  int i = 0;
  for (double d : v) x(i++) = d;
  return x;
}

// The hook's state of Example 3.8.3: both gaps zero, v = (-1, 2).
ImpactsRequest hook_state() {
  ImpactsRequest r;
  r.x0 = vec({0, 0, -1, 2});
  return r;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

// Moreau's law (restitution 0) at the hook's state: the hook alone closes,
// impulse 1.5 on it, v+ = (1/2, 1/2); T = |v|^2 / 2 falls from 5/2 to 1/4.
TEST(ImpactsAtState, ExampleThreeEightThreeByHand) {
  ImpactsRequest req = hook_state();
  req.rules = {"moreau"};  // the alias: newton's row, once, and a note
  const ImpactsAtState r = impacts_at_state(robot("two_carts_hook.yaml"), req);
  EXPECT_EQ(r.closed, (impact::IndexSet{0, 1}));
  ASSERT_EQ(r.results.size(), 1u);
  EXPECT_EQ(r.results[0].first, "newton");
  ASSERT_EQ(r.notes.size(), 1u);
  const impact::ImpactResult& n = r.results[0].second;
  ASSERT_TRUE(n.ok()) << n.message;
  EXPECT_TRUE(n.v_after.isApprox(vec({0.5, 0.5}), kTol)) << n.v_after.transpose();
  EXPECT_NEAR(n.impulse(0), 0.0, kTol);
  EXPECT_NEAR(n.impulse(1), 1.5, kTol);
  EXPECT_NEAR(n.energy_before, 2.5, kTol);
  EXPECT_NEAR(n.energy_after, 0.25, kTol);
  EXPECT_EQ(r.failures(), "");
}

TEST(ImpactsAtState, JsonNamesTheConstraints) {
  const mech::Model model = robot("two_carts_hook.yaml");
  ImpactsRequest req = hook_state();
  req.rules = {"newton", "moreau"};  // the alias adds no second row
  const json j = impacts_json(model, impacts_at_state(model, req));
  EXPECT_EQ(j["model"], "two_carts_hook");
  EXPECT_EQ(j["closed"], json::parse(R"(["stop", "hook"])"));
  EXPECT_EQ(j["state_before"], json::parse("[0.0, 0.0, -1.0, 2.0]"));
  EXPECT_EQ(j["restitution"], json::parse("[0.0, 0.0]"));  // the model's
  ASSERT_EQ(j["rules"].size(), 1u);
  const json& n = j["rules"]["newton"];
  EXPECT_EQ(n["mode"], json::parse(R"(["hook"])"));
  EXPECT_EQ(n["ok"], true);
  EXPECT_FALSE(n.contains("friction_outcome"));  // frictionless model
  const json after = n["state_after"];
  ASSERT_EQ(after.size(), 4u);
  EXPECT_NEAR(after[2].get<double>(), 0.5, kTol);
  EXPECT_NEAR(after[3].get<double>(), 0.5, kTol);
}

// Every law, on a model with friction: those that handle it, and only those.
TEST(ImpactsAtState, WithFrictionEveryLawIsThoseThatHandleIt) {
  const ImpactsAtState r = impacts_at_state(robot("block_on_floor_friction.yaml"), {});
  std::vector<std::string> expected;
  for (const auto& n : impact::impact_law_names())
    if (impact::make_impact_law(n)->handles_friction()) expected.push_back(n);
  std::vector<std::string> got;
  for (const auto& [name, res] : r.results) got.push_back(name);
  EXPECT_EQ(got, expected);
  EXPECT_FALSE(expected.empty());
}

TEST(ImpactsAtState, RefusedInputsNameTheirField) {
  const mech::Model hook = robot("two_carts_hook.yaml");
  const auto starts = [](const std::string& s, const std::string& p) { return s.rfind(p, 0) == 0; };
  ImpactsRequest req = hook_state();
  req.x0 = vec({0, 0, 1});
  EXPECT_EQ(error_of([&] { impacts_at_state(hook, req); }),
            "x0: expected 4 entries (q then v) (got 3)");
  req.x0 = vec({-5, 0, -1, 2});  // the stop's gap is -5
  EXPECT_TRUE(starts(error_of([&] { impacts_at_state(hook, req); }),
                     "x0: constraint 'stop' (0) is violated"));
  req = hook_state();
  req.restitution = vec({2.0, 0.0});
  EXPECT_EQ(error_of([&] { impacts_at_state(hook, req); }),
            "restitution (mechanical.restitution[0]): outside [0, 1] (got 2)");
  req.restitution = vec({0.5});
  EXPECT_TRUE(starts(error_of([&] { impacts_at_state(hook, req); }),
                     "restitution (mechanical.restitution): expected 2 entries"));
  ImpactsRequest friction;
  friction.rules = {"sequential"};
  EXPECT_EQ(error_of([&] { impacts_at_state(robot("block_on_floor_friction.yaml"), friction); }),
            "rules: impact law 'sequential' does not handle friction, and the model has friction");
  EXPECT_EQ(error_of([&] { impacts_at_state(robot("triple_integrator.yaml"), {}); }),
            "model 'triple_integrator': impact rules need a mechanical model (M, E), not `lcs:`");
}

}  // namespace
}  // namespace lcsim::app
