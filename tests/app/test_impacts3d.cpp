// Impacts at a state on a model with a 3-D contact (issue 27): the JSON
// gives the impulse along the second tangent and the mode with its cone
// facet, as the closed form of a point mass hitting a rough floor.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/app/impacts.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::app {
namespace {

using nlohmann::json;

// A unit point mass (x, y, z) on the floor z >= 0, mu = 0.5, d = 4, and a
// planar wall contact x >= 0 that stays open.
mech::Model point3d() {
  return scene::parse_model(
      "name: p3\nmechanical:\n  M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n"
      "  E: [[0, 0, 1], [1, 0, 0]]\n  g: [0, 1]\n  constraints: [floor, wall]\n"
      "  friction:\n    - {contact: floor, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.5}\n"
      "    - {contact: wall, tangent: [0, 1, 0], mu: 0.2}\n",
      "p3.yaml");
}

// v- = (3 cos(pi/8), 3 sin(pi/8), -2): the tangential velocity on the
// bisector of edges 0 and 1 (d = 4), P_N = 2. It slides on, so the impulse
// is on the opposite face (edges 4 and 5), of size mu P_N cos(pi/8)
// against the velocity: |u+| = 3 - 0.5 * 2 * cos(pi/8).
TEST(ImpactsAtState3d, JsonGivesBothTangentialImpulsesAndTheFacet) {
  const double a = std::acos(-1.0) / 8, c = std::cos(a);
  ImpactsRequest req;
  req.x0 = (Eigen::VectorXd(6) << 0, 0, 0, 3 * std::cos(a), 3 * std::sin(a), -2).finished();
  req.rules = {"inelastic"};
  const mech::Model model = point3d();
  const json j = impacts_json(model, impacts_at_state(model, req));
  const json& r = j["rules"]["inelastic"];
  ASSERT_EQ(r["ok"], true) << r.dump();
  EXPECT_EQ(r["friction_mode"], json::parse(R"({"floor": "slip-face-4", "wall": "open"})"));
  // Closed form to rounding of a 12-unknown LCP on unit data (1e-12).
  const double P = 0.5 * 2 * c;
  EXPECT_NEAR(r["friction_impulse"][0].get<double>(), -P * std::cos(a), 1e-12);
  EXPECT_NEAR(r["friction_impulse2"][0].get<double>(), -P * std::sin(a), 1e-12);
  EXPECT_EQ(r["friction_impulse2"][1].get<double>(), 0.0);
  EXPECT_NEAR(r["state_after"][3].get<double>(), (3 - P) * std::cos(a), 1e-12);
  EXPECT_NEAR(r["state_after"][4].get<double>(), (3 - P) * std::sin(a), 1e-12);
  EXPECT_EQ(r["friction_outcome"]["floor"], "slip");
}

// A planar model's JSON has neither key (its output is unchanged).
TEST(ImpactsAtState3d, PlanarModelsHaveNoThreeDimensionalKeys) {
  const mech::Model model =
      scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/block_on_floor_friction.yaml");
  const json j = impacts_json(model, impacts_at_state(model, {}));
  for (const auto& [name, r] : j["rules"].items()) {
    EXPECT_FALSE(r.contains("friction_impulse2")) << name;
    EXPECT_FALSE(r.contains("friction_mode")) << name;
    EXPECT_TRUE(r.contains("friction_outcome")) << name;
  }
}

}  // namespace
}  // namespace lcsim::app
