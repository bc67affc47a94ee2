// The outputs of 3-D friction (issue 27): the CSV's ut2_<contact> columns
// and fm_<contact> cells naming the cone's facet, the JSON events'
// friction_impulse2 and facet modes; planar models keep their columns.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <sstream>
#include <string>
#include <vector>

namespace lcsim::io {
namespace {

// A point mass (x, y, z) on the floor z >= 0 sliding at the heading pi/8
// (the bisector of edges 0 and 1 at d = 4), and a frictionless wall.
const char* kModel3d = R"(name: p3
mechanical:
  M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]
  E: [[0, 0, 1], [1, 0, 0]]
  g: [0, 5]
  f: [0, 0, -9.81]
  constraints: [floor, wall]
  friction:
    - {contact: floor, tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.3, d: 4}
initial: [0, 0, 0, 0.9238795325112867, 0.3826834323650898, 0]
)";

std::vector<std::string> split(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream s(line);
  std::string cell;
  while (std::getline(s, cell, ',')) out.push_back(cell);
  return out;
}

std::vector<std::string> csv_line(const std::string& csv, int n) {
  std::stringstream s(csv);
  std::string line;
  for (int i = 0; i <= n; ++i) std::getline(s, line);
  return split(line);
}

TEST(Friction3dOutputs, CsvHasTheSecondTangentAndTheFacet) {
  const mech::Model model = scene::parse_model(kModel3d, "p3.yaml");
  sim::Options o;
  o.t_end = 0.05;
  o.h = 1e-3;
  o.dt_out = 0.01;
  const sim::Trajectory tr = sim::make_integrator("moreau-jean")->run(model, model.initial, o);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  const std::string csv = trajectory_csv(model, tr);
  const std::vector<std::string> head = csv_line(csv, 0);
  const std::vector<std::string> want{"t",      "x",        "y",         "z",        "v_x",
                                      "v_y",    "v_z",      "u_floor",   "u_wall",   "y_floor",
                                      "y_wall", "ut_floor", "ut2_floor", "fm_floor", "mode"};
  // Coordinates are named q1.. when the file gives none.
  ASSERT_EQ(head.size(), want.size());
  for (size_t i = 7; i < want.size(); ++i) EXPECT_EQ(head[i], want[i]) << i;
  // A sliding row: the force on face 4, mu g cos(pi/8) against the
  // velocity (N per kg; 17 digits of the step's value, 1e-12 relative).
  const std::vector<std::string> row = csv_line(csv, 3);
  ASSERT_EQ(row.size(), want.size());
  const double a = std::acos(-1.0) / 8, F = 0.3 * 9.81 * std::cos(a);
  EXPECT_NEAR(std::stod(row[11]), -F * std::cos(a), 1e-12 * F);
  EXPECT_NEAR(std::stod(row[12]), -F * std::sin(a), 1e-12 * F);
  EXPECT_EQ(row[13], "slip-face-4");
}

TEST(Friction3dOutputs, PlanarModelsKeepTheirColumns) {
  std::string planar = kModel3d;
  planar.replace(planar.find("tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.3, d: 4"),
                 std::string("tangents: [[1, 0, 0], [0, 1, 0]], mu: 0.3, d: 4").size(),
                 "tangent: [1, 0, 0], mu: 0.3");
  const mech::Model model = scene::parse_model(planar, "p2.yaml");
  const std::string csv = trajectory_csv(model, sim::Trajectory{});
  EXPECT_EQ(csv.find("ut2_"), std::string::npos);
  EXPECT_NE(csv.find("ut_floor,fm_floor,mode"), std::string::npos);
  sim::Trajectory tr;
  sim::Event e;
  e.state_before = e.state_after = Eigen::VectorXd::Zero(6);
  e.impulse = Eigen::VectorXd::Zero(2);
  e.friction_impulse = Eigen::VectorXd::Zero(1);
  e.friction_mode_after = {sim::FrictionMode::kSlipPositive};
  tr.events.push_back(e);
  const nlohmann::json j = trajectory_json(model, tr);
  EXPECT_FALSE(j["events"][0].contains("friction_impulse2"));
  EXPECT_EQ(j["events"][0]["friction_mode_after"][0], "slip+");
}

// An event of a 3-D model (as the exact method records one): its impulse
// along t2 and the facet in the mode's text.
TEST(Friction3dOutputs, JsonEventsNameTheFacet) {
  const mech::Model model = scene::parse_model(kModel3d, "p3.yaml");
  sim::Trajectory tr;
  sim::Event e;
  e.state_before = e.state_after = Eigen::VectorXd::Zero(6);
  e.impulse = Eigen::VectorXd::Zero(2);
  e.friction_impulse = Eigen::VectorXd::Constant(1, -0.25);
  e.friction_impulse2 = Eigen::VectorXd::Constant(1, 0.5);
  e.friction_mode_after = {sim::FrictionMode::kSlip};
  e.friction_facet_after = {impact::ConeFacet{2, false}};
  tr.events.push_back(e);
  e.friction_facet_after = {impact::ConeFacet{5, true}};
  tr.events.push_back(e);
  e.friction_facet_after.clear();  // a method that does not name the facet
  tr.events.push_back(e);
  const nlohmann::json j = trajectory_json(model, tr);
  EXPECT_EQ(j["events"][0]["friction_impulse2"][0], 0.5);
  EXPECT_EQ(j["events"][0]["friction_mode_after"][0], "slip-edge-2");
  EXPECT_EQ(j["events"][1]["friction_mode_after"][0], "slip-face-5");
  EXPECT_EQ(j["events"][2]["friction_mode_after"][0], "slip");
}

}  // namespace
}  // namespace lcsim::io
