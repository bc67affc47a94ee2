// The impact map with named closed contacts (`lcsim impacts --map --closed`,
// src/app/impact_map.cpp): velocities built by hand, impacts computed directly
// with the law, and every refused input named in its message.
#include <gtest/gtest.h>

#include <lcsim/app/impact_map.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::app {
namespace {

using io::InputError;
using scene::load_model;
using scene::parse_model;

// Three unit carts: a stop q1 >= 0 (row 0, "stop"), a hook q1 - q2 >= 0
// (row 1, "hook") and a far stop q3 + 5 >= 0 (row 2, "far"). M = I.
mech::MechanicalModel three_carts() {
  return *parse_model(
              "name: three\nmechanical:\n  M: [[1,0,0],[0,1,0],[0,0,1]]\n"
              "  E: [[1,0,0],[1,-1,0],[0,0,1]]\n  g: [0, 0, 5]\n"
              "  restitution: [0.5, 0.25, 0]\n  constraints: [stop, hook, far]\n",
              "three.yaml")
              .mechanical;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Cell velocities: with M = I and E_J = [1 0 0; 1 -1 0] the v nearest to v0
// with E_J v = w keeps v3 and has v1 = w1, v2 = w1 - w2. Each cell's mode and
// post-impact rates must equal Moreau's law applied to that v directly.
// Tolerance 1e-13: both sides solve the same 2x2 LCP on entries of size <= 2
// (a few roundings of numbers of size <= 3).
TEST(ImpactMap, ClosedMapCellsAreTheLawAppliedToTheHandBuiltVelocity) {
  const mech::MechanicalModel m = three_carts();
  ImpactMapSpec spec;
  spec.q = Eigen::Vector3d(0, 0, 1);
  spec.v0 = Eigen::Vector3d(0.3, -0.2, 0.7);
  spec.closed = parse_constraint_list(m, "stop,1", "--closed");
  ASSERT_EQ(spec.closed, (std::vector<int>{0, 1}));
  spec.axis1 = parse_map_range("-1:1:5", "--map");
  spec.axis2 = parse_map_range("-1:1:3", "--map");
  const ImpactMap map = impact_map(m, spec);
  ASSERT_EQ(map.failure, "");
  ASSERT_EQ(map.cells.size(), 15u);
  EXPECT_EQ(map.axes, (std::vector<std::string>{"stop", "hook"}));
  const auto law = impact::make_impact_law("moreau");
  const auto solver = lcp::make_solver("enum");
  Eigen::MatrixXd EJ(2, 3);
  EJ << 1, 0, 0, 1, -1, 0;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 3; ++j) {
      const ImpactMapCell& c = map.cells[i * 3 + j];
      const double w1 = -1 + 0.5 * i, w2 = -1 + 1.0 * j;
      EXPECT_DOUBLE_EQ(c.before(0), w1);
      EXPECT_DOUBLE_EQ(c.before(1), w2);
      impact::ImpactInput in;
      in.model = &m;
      in.q = spec.q;
      in.v = Eigen::Vector3d(w1, w1 - w2, 0.7);
      in.closed = {0, 1};
      const impact::ImpactResult r = law->apply(in, *solver);
      ASSERT_TRUE(r.ok()) << r.message;
      EXPECT_EQ(c.mode, r.mode) << "w = " << w1 << ", " << w2;
      const Eigen::Vector2d after = EJ * r.v_after;
      EXPECT_NEAR(c.after(0), after(0), 1e-13);
      EXPECT_NEAR(c.after(1), after(1), 1e-13);
    }
  // Header by 0-based index, then one line per cell.
  const std::string csv = impact_map_csv(m, map);
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "rate_0,rate_1,mode,rate_0+,rate_1+");
}

// With M = I the q nearest to (0.4, 0.1, 1) closing stop and hook is
// (0, 0, 1): q1 = 0 and q1 - q2 = 0, q3 untouched.
TEST(ImpactMap, CloseContactsPlacesQOnTheNamedContacts) {
  const mech::MechanicalModel m = three_carts();
  const Eigen::VectorXd q = close_contacts(m, Eigen::Vector3d(0.4, 0.1, 1), {0, 1}, "--closed");
  EXPECT_NEAR(q(0), 0.0, 1e-15);
  EXPECT_NEAR(q(1), 0.0, 1e-15);
  EXPECT_EQ(q(2), 1.0);
}

TEST(ImpactMap, RefusesWithAMessageNamingTheValue) {
  const mech::MechanicalModel m = three_carts();
  EXPECT_TRUE(contains(error_of([&] { parse_constraint_list(m, "stop,wall", "--closed"); }),
                       "--closed: unknown constraint 'wall' (known: stop, hook, far)"));
  EXPECT_TRUE(contains(error_of([&] { parse_constraint_list(m, "3", "--closed"); }),
                       "--closed: constraint index 3 out of range"));
  EXPECT_TRUE(contains(error_of([&] { parse_constraint_list(m, "stop,0", "--closed"); }),
                       "'stop' named twice"));
  ImpactMapSpec spec;
  spec.v0 = Eigen::Vector3d::Zero();
  spec.axis1 = spec.axis2 = parse_map_range("-1:1:3", "--map");
  // q1 = 0.3: the stop is open with gap 0.3.
  spec.q = Eigen::Vector3d(0.3, 0.3, 0);
  spec.closed = {0, 1};
  EXPECT_TRUE(contains(
      error_of([&] { impact_map(m, spec); }),
      "closed constraints: constraint 'stop' (0) is open at q = (0.3, 0.3, 0) (gap = 0.3)"));
  // q3 = -5 closes 'far' too, which is not named.
  spec.q = Eigen::Vector3d(0, 0, -5);
  EXPECT_TRUE(
      contains(error_of([&] { impact_map(m, spec); }), "constraint 'far' (2) is also closed"));
  // q3 = -6 violates 'far'.
  spec.q = Eigen::Vector3d(0, 0, -6);
  EXPECT_TRUE(contains(error_of([&] { impact_map(m, spec); }),
                       "constraint 'far' (2) is violated at q = (0, 0, -6) (gap = -1)"));
  // One name is not a map.
  spec.q = Eigen::Vector3d(0, 0, 0);
  spec.closed = {0};
  EXPECT_TRUE(contains(error_of([&] { impact_map(m, spec); }), "name two constraints"));
  // Without --closed a three-coordinate model has no velocity map.
  spec.closed = {};
  EXPECT_TRUE(contains(error_of([&] { impact_map(m, spec); }), "needs a model with two"));
}

// Two copies of one stop cannot have their approach velocities set apart.
TEST(ImpactMap, DependentRowsAreRefused) {
  const mech::MechanicalModel m =
      *parse_model("name: dup\nmechanical:\n  M: [[1,0],[0,1]]\n  E: [[1,0],[2,0]]\n", "dup.yaml")
           .mechanical;
  ImpactMapSpec spec;
  spec.q = spec.v0 = Eigen::Vector2d::Zero();
  spec.closed = {0, 1};
  spec.axis1 = spec.axis2 = parse_map_range("-1:1:3", "--map");
  EXPECT_TRUE(contains(error_of([&] { impact_map(m, spec); }), "'c1', 'c2' are dependent"));
}

}  // namespace
}  // namespace lcsim::app
