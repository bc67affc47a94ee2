// MuJoCo (src/mujoco) on the contact scenes, beside the exact run.
//
// Tolerances from MuJoCo's soft contact (docs/contacts.md, "Peers on contact
// scenes"). With margin 0 a MuJoCo contact exists only once a geom
// penetrates, at the start of a step: the first contact force is in the
// step after the crossing, so its step ends within 2 h of the exact impact.
// At rest each contact row i carries f_i with a steady penetration
// delta_i = f_i R_i / k, where k = 1 / (dmax^2 tc^2 zeta^2) is solref's
// stiffness (tc = 2 h = 2 ms, zeta = 1, dmax = 0.95: k = 2.77e5 1/s^2) and
// R_i = (1 - d) / d A_ii the regulariser (d >= dmin = 0.9 on the first
// millimetre, A_ii the row's inverse inertia). For the box (1.2 kg,
// corners at (+-0.15, +-0.1) m, inertia 0.005 / 0.01 kg m^2 about x / y):
// A_ii = 1 / 1.2 + 0.1^2 / 0.005 + 0.15^2 / 0.01 = 5.08 1/kg, and f_i <=
// m g = 11.8 N, so delta <= 11.8 * (0.1 / 0.9) * 5.08 / 2.77e5 = 2.4e-5 m,
// asserted; measured 1.09e-6 m.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>

namespace lcsim::mujoco {
namespace {

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

sim::Options options(const mech::Model& m, double h) {
  sim::Options o;
  o.t_end = m.t_end;
  o.h = h;
  o.dt_out = h;
  return o;
}

double first_contact(const sim::Trajectory& tr) {
  for (const auto& e : tr.events)
    if (!e.mode_after.empty()) return e.t;
  return NAN;
}

TEST(MujocoContacts, BoxDropLandsWithinTwoStepsAndSinksLessThanItsSoftContactBound) {
  const mech::Model m = scene::load_model(kRobots + "box_drop_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.2 / 9.81);
  const double t_mj = first_contact(tr);
  std::printf("[ mujoco   ] box drop: first contact %.6g (exact %.6g), rest z %.9g\n", t_mj, t_star,
              tr.final_state(2));
  EXPECT_GT(t_mj, t_star);
  EXPECT_LE(t_mj, t_star + 2 * h);
  const double sink = 0.05 - tr.final_state(2);
  EXPECT_GT(sink, 0.0);  // soft: it rests in the floor, never above it
  EXPECT_LE(sink, 2.4e-5);
  // Flat and still: the rotation and velocities of the linear model's rest.
  for (int i = 3; i < 12; ++i) EXPECT_NEAR(tr.final_state(i), 0.0, 1e-6) << "entry " << i;
}

TEST(MujocoContacts, BoxDropFinalStateAgreesWithTheExactRunToTheSink) {
  const mech::Model m = scene::load_model(kRobots + "box_drop_scene.yaml");
  sim::Options o = options(m, 1e-3);
  const auto event = sim::make_integrator("event");
  const sim::Trajectory ex = event->run(m, m.initial, sim::keep_used(o, event->options_used()));
  const sim::Trajectory mj = simulate_mujoco(m, m.initial, o);
  const bullet::Comparison c = bullet::compare_trajectories(ex, mj, 1e-12);
  EXPECT_LE(c.error_final, 2.4e-5);  // the sink bound above
}

TEST(MujocoContacts, QuadrupedLandsOnItsFeetAndSettles) {
  const mech::Model m = scene::load_model(kRobots + "quadruped_drop_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.03 / 9.81);
  EXPECT_GT(first_contact(tr), t_star);
  EXPECT_LE(first_contact(tr), t_star + 2 * h);
  // Sink of the 6 kg robot on four feet: the bound above with f <= m g =
  // 58.9 N and a foot's A_ii <= 1 / 0.2 + 1 / 6 + leg rotations (< 40
  // 1/kg) is 58.9 * 0.111 * 40 / 2.77e5 = 9.4e-4 m; measured 1.2e-5 m.
  const double sink = 0.35 - tr.final_state(2);
  std::printf("[ mujoco   ] quadruped: sink %.3e m\n", sink);
  EXPECT_GT(sink, 0.0);
  EXPECT_LE(sink, 9.4e-4);
}

TEST(MujocoContacts, RefusesWhatItCannotRun) {
  const mech::Model carts = scene::load_model(kRobots + "two_carts_scene.yaml");
  try {
    check_expressible(carts);
    FAIL() << "two carts' stops are not contacts";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("not a contact"), std::string::npos) << e.what();
  }
  const mech::Model matrix = scene::load_model(kRobots + "ball.yaml");
  EXPECT_THROW(check_expressible(matrix), std::invalid_argument);
}

TEST(MujocoContacts, StiffSpringsDivergeAndAreReportedAsSuch) {
  // The quadruped with joint springs of 1e9 N m/rad: explicit torques at
  // h = 1e-3 (omega h >> 2) grow without bound; the run must end with a
  // numerical failure, never "completed".
  namespace fs = std::filesystem;
  std::ifstream in(kRobots + "quadruped_drop_scene.yaml");
  std::string yaml((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (std::size_t p; (p = yaml.find("stiffness: 20")) != std::string::npos;)
    yaml.replace(p, 13, "stiffness: 1e9");
  yaml.replace(yaml.find("urdf: quadruped.urdf"), 20, "urdf: " + kRobots + "quadruped.urdf");
  const fs::path path = fs::path(::testing::TempDir()) / "stiff_quadruped.yaml";
  std::ofstream(path) << yaml;
  const mech::Model m = scene::load_model(path);
  sim::Options o = options(m, 1e-3);
  Eigen::VectorXd x0 = m.initial;
  x0(m.mechanical->dofs() + 6) = 1.0;  // fl_hip moving at 1 rad/s
  const sim::Trajectory tr = simulate_mujoco(m, x0, o);
  EXPECT_EQ(tr.status, sim::RunStatus::kNumericalFailure) << tr.message;
  EXPECT_NE(tr.message.find("mujoco"), std::string::npos) << tr.message;
}

}  // namespace
}  // namespace lcsim::mujoco
