// MuJoCo (src/mujoco/mjcf_bodies.cpp) on scenes of several bodies, and the
// friction multipliers of its samples, against closed forms.
//
// Tolerances from MuJoCo's soft contact, as tests/mujoco/test_mujoco_contacts.cpp
// derives them: with margin 0 a contact exists only once its geoms overlap
// at the start of a step, so the first contact force is in the step after
// the crossing, within 2 h of the exact impact. At rest a contact carrying
// f sinks by r = R f / k with R = (1 - d) / d A_ii (A_ii the row's inverse
// inertia) and MuJoCo's stiffness k = d / (dmax^2 tc^2 zeta^2): r = f (1 -
// d) A_ii dmax^2 tc^2 zeta^2 / d^2, tc = 2 h = 2 ms, zeta = 1, dmax = 0.95,
// and d = dmin = 0.9 at a penetration of microns (solimp's width is 1 mm:
// d rises above dmin by 2 (dmax - dmin) (r / width)^2 < 1e-6).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>

namespace lcsim::mujoco {
namespace {

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
const std::string kData = std::string(LCSIM_SOURCE_DIR) + "/tests/bullet/data/";
constexpr double kG = 9.81;

sim::Options options(const mech::Model& m, double h) {
  sim::Options o;
  o.t_end = m.t_end;
  o.h = h;
  o.dt_out = h;
  return o;
}

double first_contact(const sim::Trajectory& tr, int row) {
  for (const auto& e : tr.events)
    if (std::find(e.mode_after.begin(), e.mode_after.end(), row) != e.mode_after.end()) return e.t;
  return NAN;
}

TEST(MujocoBodies, BallDroppedOntoATableMeetsItAtTheFreeFallTime) {
  const mech::Model m = scene::load_model(kData + "ball_table_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.25 / kG);
  const double t_mj = first_contact(tr, 0);
  std::printf("[ mujoco   ] ball on table: first contact %.6g (exact %.6g), rest z %.9g\n", t_mj,
              t_star, tr.final_state(2));
  EXPECT_GT(t_mj, t_star);
  EXPECT_LE(t_mj, t_star + 2 * h);
  // Rests on the table top: f = m g = 9.81 N, the ball's A_ii = 1 / m = 1
  // 1/kg (its centre on the normal: no lever): r = 9.81 * 0.1 * 0.9025 *
  // 4e-6 / 0.81 = 4.37211e-6 m, d's rise above dmin making it smaller by a
  // relative 1e-6 at most; 1e-9 m is MuJoCo's rest to its solver's
  // tolerance (1e-8 of the force) and more.
  const double sink = 0.65 - tr.final_state(2);
  EXPECT_NEAR(sink, 9.81 * 0.1 * 0.9025 * 4e-6 / 0.81, 1e-9);
  EXPECT_NEAR(tr.final_state(0), 0.0, 1e-12);  // falls straight: no lateral force
  EXPECT_NEAR(tr.final_state(1), 0.0, 1e-12);
}

TEST(MujocoBodies, GripperClosesOnTheBoxWithinTwoStepsOfTheExactRun) {
  const mech::Model m = scene::load_model(kRobots + "gripper_box_scene.yaml");
  const double h = 1e-3;
  sim::Options o = options(m, h);
  const auto event = sim::make_integrator("event");
  const sim::Trajectory ex = event->run(m, m.initial, sim::keep_used(o, event->options_used()));
  ASSERT_EQ(ex.status, sim::RunStatus::kCompleted) << ex.message;
  const sim::Trajectory mj = simulate_mujoco(m, m.initial, o);
  ASSERT_EQ(mj.status, sim::RunStatus::kCompleted) << mj.message;
  // Each finger (q = 0.05 + 0.1 cos(20 t)) meets the box's face at q = 0.11 m.
  const double t_star = std::acos(0.6) / 20.0;
  const auto& c = m.mechanical->constraints;
  for (const char* tip : {"left_tip.sphere0", "right_tip.sphere0"}) {
    const int row = static_cast<int>(std::find(c.begin(), c.end(), tip) - c.begin());
    ASSERT_LT(row, static_cast<int>(c.size())) << tip;
    EXPECT_GT(first_contact(mj, row), t_star) << tip;
    EXPECT_LE(first_contact(mj, row), t_star + 2 * h) << tip;
  }
  // Both settle squeezing the box: the final states differ by the soft
  // contacts' sinks (above): the fingers' f = 2.4 N with A_ii = 1 / 0.1 +
  // 1 / 1.2 = 10.8 1/kg (the tips at the box's centre height: no lever),
  // r = 2.4 * 0.1 * 10.8 * 3.61e-6 / 0.81 = 1.2e-5 m; the box's corners on
  // the floor, f <= m g = 11.8 N, A_ii <= 5.08 1/kg
  // (test_mujoco_contacts.cpp): r <= 2.7e-5 m.
  const bullet::Comparison cmp = bullet::compare_trajectories(ex, mj, 1e-12);
  std::printf("[ mujoco   ] gripper: final difference %.3e\n", cmp.error_final);
  EXPECT_LE(cmp.error_final, 2.7e-5);
}

// The legged robot (robots/vision60_drop_scene.yaml, a one-body `bodies:`
// scene) dropped 0.03 m: its four toes land together at sqrt(2 h / g) =
// 0.0782 s, MuJoCo's within 2 h (above). Its dampers are explicit applied
// forces here, unstable at h = 1e-3 (tests/bullet/test_bodies_scenes.cpp):
// a numerical failure there, never a completed run; at h = 1e-4 it lands.
TEST(MujocoBodies, LeggedRobotLandsOnItsFourToesAtTheFreeFallTime) {
  const mech::Model m = scene::load_model(kRobots + "vision60_drop_scene.yaml");
  sim::Options o = options(m, 1e-3);
  o.t_end = 0.15;
  const sim::Trajectory coarse = simulate_mujoco(m, m.initial, o);
  EXPECT_EQ(coarse.status, sim::RunStatus::kNumericalFailure) << coarse.message;
  o.h = o.dt_out = 1e-4;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, o);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.03 / kG);
  for (int toe = 0; toe < 4; ++toe) {
    EXPECT_GT(first_contact(tr, toe), t_star) << "toe " << toe;
    EXPECT_LE(first_contact(tr, toe), t_star + 2 * o.h) << "toe " << toe;
  }
}

// Both peers on the legged robot to T = 1 s (h = 1e-4): two independent
// nonlinear simulators of the same URDF settle it to the same state up to
// MuJoCo's resting sink on its toes (64 N each, a toe's A_ii < 40 1/kg as
// test_mujoco_contacts.cpp bounds the quadruped's, tc = 2 h:
// r <= 64 * 0.1 * 40 * 0.9025 * 4e-8 / 0.81 = 1.2e-5 m; measured 6.3e-7),
// so their common difference to the exact run of the linear model (2.9e-4,
// the same in both to that sink) is lcsim's linearisation, not a peer's
// error.
TEST(MujocoBodies, BothPeersSettleTheLeggedRobotAlikeAwayFromTheLinearModel) {
  const mech::Model m = scene::load_model(kRobots + "vision60_drop_scene.yaml");
  sim::Options o = options(m, 1e-4);
  const auto event = sim::make_integrator("event");
  sim::Options oe = o;
  oe.h = 1e-3;
  const sim::Trajectory ex = event->run(m, m.initial, sim::keep_used(oe, event->options_used()));
  ASSERT_EQ(ex.status, sim::RunStatus::kCompleted) << ex.message;
  const sim::Trajectory mj = simulate_mujoco(m, m.initial, o);
  ASSERT_EQ(mj.status, sim::RunStatus::kCompleted) << mj.message;
  const sim::Trajectory bt = bullet::simulate_bullet(m, m.initial, o);
  ASSERT_EQ(bt.status, sim::RunStatus::kCompleted) << bt.message;
  const double peers = (mj.final_state - bt.final_state).cwiseAbs().maxCoeff();
  const double e_mj = (mj.final_state - ex.final_state).cwiseAbs().maxCoeff();
  const double e_bt = (bt.final_state - ex.final_state).cwiseAbs().maxCoeff();
  std::printf("[ mujoco   ] vision60: |mujoco - bullet| %.3e, to the exact run %.3e / %.3e\n",
              peers, e_mj, e_bt);
  EXPECT_LE(peers, 1.2e-5);
  EXPECT_LE(std::abs(e_mj - e_bt), 1.2e-5);
  EXPECT_GT(e_bt, 10 * peers);  // the linear model's difference, well above the peers'
}

// Sums of the friction entries' multipliers along t1 and t2, and of the
// normal multipliers, at sample s.
struct Totals {
  double t1 = 0.0, t2 = 0.0, n = 0.0;
};
Totals totals(const sim::Sample& s) {
  Totals out;
  if (s.u_t.size() > 0) out.t1 = s.u_t.sum();
  if (s.u_t2.size() > 0) out.t2 = s.u_t2.sum();
  out.n = s.u.sum();
  return out;
}

// The box sliding on the floor (tests/bullet/data/box_slide_bodies_scene.yaml):
// the floor's friction on it is along +t2 = -x, against the velocity, and
// on the cone's boundary while it slides, so each step's u_t2 is mu times
// its u_n (MuJoCo's pyramidal and elliptic cones agree along a tangent);
// u_t1 is zero (nothing pushes across). The multipliers are the whole
// horizontal force on the box, so their impulse is its momentum change,
// sum h u_t2 = m (v0 - v_x(T)), to rounding (500 steps of O(1) N: 1e-12
// N s). The closed form -mu m g holds on average: MuJoCo's soft contacts
// let the box hop, so u_n is m g only on average, and the box sticks when
// the impulse reaches m v0, at v0 / (mu g) = 0.33979 s, which MuJoCo's
// run meets to its step and the hop's (measured 0.340; 2e-3 s asserted).
TEST(MujocoBodies, SlidingBoxFeelsMuMgAgainstItsVelocity) {
  const mech::Model m = scene::load_model(kData + "box_slide_bodies_scene.yaml");
  const double h = 1e-3, mu = 0.3, mass = 1.2, v0 = 1.0;
  for (Settings::Cone cone : {Settings::Cone::kPyramidal, Settings::Cone::kElliptic}) {
    Settings s;
    s.cone = cone;
    const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h), s);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_EQ(tr.samples.back().u_t.size(), 8);  // the box's eight corners
    ASSERT_EQ(tr.samples.back().u_t2.size(), 8);
    double coulomb = 0.0, across = 0.0, impulse = 0.0, t_stop = NAN;
    int sliding = 0;
    for (std::size_t j = 1; j < tr.samples.size(); ++j) {
      const sim::Sample& smp = tr.samples[j];
      const Totals f = totals(smp);
      impulse += h * f.t2;
      across = std::max(across, std::abs(f.t1));
      if (std::isnan(t_stop) && smp.x(6) < 1e-3) t_stop = smp.t;
      if (smp.x(6) < 0.05) continue;  // sliding: v_x well above 0
      coulomb = std::max(coulomb, std::abs(f.t2 - mu * f.n));
      ++sliding;
    }
    const double v_end = tr.final_state(6);
    std::printf(
        "[ mujoco   ] %s: |u_t2 - mu u_n| <= %.3e N over %d sliding steps, |u_t1| <= "
        "%.3e N, impulse %.12g N s (m (v0 - v_end) = %.12g), stop %.6g s (closed form "
        "%.6g)\n",
        cone_name(cone).c_str(), coulomb, sliding, across, impulse, mass * (v0 - v_end), t_stop,
        v0 / (mu * kG));
    EXPECT_GT(sliding, 250);
    EXPECT_LE(coulomb, 1e-12);  // rounding of O(1) N
    EXPECT_LE(across, 1e-9);    // MuJoCo's solver tolerance (1e-8) of O(0.1) N
    EXPECT_NEAR(impulse, mass * (v0 - v_end), 1e-12);
    EXPECT_NEAR(t_stop, v0 / (mu * kG), 2e-3);
  }
}

// Joint stops in a scene of bodies are MuJoCo joint ranges (soft as its
// contacts). The gripper's fingers keep their URDF stops (0 <= q <= 0.2 m),
// their springs (40 N/m, 0.1 kg: w = 20 rad/s) pull them from 0.15 m toward
// -0.05 m, so q = -0.05 + 0.2 cos(20 t) meets the stop q = 0 at
// t* = acos(0.25) / 20 = 0.06591 s; the limit's force comes within 2 h
// after it, and the finger rests at the stop sunk by the soft constraint's
// r = f (1 - d) A dmax^2 tc^2 / d^2 with f = 40 * 0.05 = 2 N, A = 1 / 0.1:
// 8.91e-6 m (the closed form of the header, d = 0.9; 1e-8 m: d's rise and
// the solver's tolerance). The table is an obstacle that makes it a scene of
// bodies; nothing touches it.
TEST(MujocoBodies, JointStopsAreJointRanges) {
  const std::string path = ::testing::TempDir() + "/stop_bodies.yaml";
  std::ofstream(path) << "bodies:\n  - {name: gripper, urdf: " << kRobots
                      << "two_finger_gripper.urdf, joints: [{name: left}, {name: right}], q0: "
                         "{left: 0.15, right: 0.15}}\n"
                      << "  - {name: table, urdf: " << kData
                      << "table.urdf, base: {type: fixed, pose: {xyz: [0, 0, -1]}}}\n"
                      << "springs:\n"
                         "  - {name: l, joint: gripper.left, stiffness: 40, rest: -0.05}\n"
                         "  - {name: r, joint: gripper.right, stiffness: 40, rest: -0.05}\n"
                      << "t_end: 0.3\n";
  const mech::Model m = scene::load_model(path);
  check_expressible(m);
  const auto& c = m.mechanical->constraints;
  const int lower =
      static_cast<int>(std::find(c.begin(), c.end(), "gripper.left_lower") - c.begin());
  ASSERT_LT(lower, static_cast<int>(c.size()));
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::acos(0.25) / 20.0;
  std::printf("[ mujoco   ] finger stop: first force %.6g (exact %.6g), rest q %.9g\n",
              first_contact(tr, lower), t_star, tr.final_state(0));
  EXPECT_GT(first_contact(tr, lower), t_star);
  EXPECT_LE(first_contact(tr, lower), t_star + 2 * h);
  EXPECT_NEAR(tr.final_state(0), -2.0 * 0.1 * 10.0 * 0.9025 * 4e-6 / 0.81, 1e-8);
  EXPECT_NEAR(tr.final_state(1), tr.final_state(0), 1e-15);  // the fingers alike
  // At rest the stop holds the spring's force there, 40 (q + 0.05) N (the
  // solver's tolerance, 1e-8 of it, and more).
  EXPECT_NEAR(tr.samples.back().u(lower), 40.0 * (tr.final_state(0) + 0.05), 1e-6);
}

// Only the scene's named pairs collide: the ball falls through a table
// that no contact names (tests/bullet/data/ball_through_table_scene.yaml)
// and meets the floor at sqrt(2 * 0.8 / g); it touches nothing before.
TEST(MujocoBodies, OnlyTheNamedPairsCollide) {
  const mech::Model m = scene::load_model(kData + "ball_through_table_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_FALSE(tr.events.empty());
  const double t = tr.events.front().t, t_star = std::sqrt(2.0 * 0.8 / kG);
  EXPECT_GT(t, t_star);
  EXPECT_LE(t, t_star + 2 * h);  // the first force (above)
}

// What a scene of bodies cannot have in MuJoCo is refused before anything
// runs, in one line naming the body and the joint: a mimic joint.
TEST(MujocoBodies, RefusesAMimicJointInOneLine) {
  const std::string path = ::testing::TempDir() + "/mimic_bodies.yaml";
  std::ofstream(path) << "bodies:\n  - {name: pair, urdf: " << kData
                      << "mimic_pair.urdf, joints: [{name: lead}]}\n  - {name: ball, urdf: "
                      << kData << "ball.urdf, base: {type: floating}}\nt_end: 0.1\n";
  const mech::Model m = scene::load_model(path);
  try {
    check_expressible(m);
    FAIL() << "a mimic joint";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("body 'pair': joint 'follow' is a mimic"), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}

// A one-URDF scene with explicit contact points (the box of
// robots/box_drop_scene.yaml on four points of its bottom face) is refused by
// MuJoCo's URDF path in one line that names the way out: the same scene as
// `bodies:` with one body runs, its points meeting the floor after the free
// fall of 0.2 m, within 2 h of sqrt(2 0.2 / g) (the first force, above).
TEST(MujocoBodies, OneUrdfSceneWithPointsRunsWrittenAsOneBody) {
  const std::string points =
      "points: [[0.05, 0.05, -0.05], [-0.05, -0.05, -0.05], [0.05, -0.05, -0.05], "
      "[-0.05, 0.05, -0.05]], name: p}\n";
  const std::string rest =
      "planes: [{name: floor, point: [0, 0, 0], normal: [0, 0, 1]}]\n"
      "initial: {q: {box.z: 0.25}}\nt_end: 0.5\n";
  const std::string base = "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}";
  const std::string one = ::testing::TempDir() + "/box_points.yaml";
  std::ofstream(one) << "urdf: " << kRobots << "box.urdf\n"
                     << base << "\n"
                     << rest << "contacts:\n  - {link: box, plane: floor, " << points;
  try {
    check_expressible(scene::load_model(one));
    FAIL() << "explicit points on a one-URDF scene";
  } catch (const std::invalid_argument& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("contact 'p.point0' has explicit points"), std::string::npos) << what;
    EXPECT_NE(what.find("write the scene as `bodies:` with this one body"), std::string::npos)
        << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
  const std::string bodies = ::testing::TempDir() + "/box_points_bodies.yaml";
  std::ofstream(bodies) << "bodies:\n  - {name: box, urdf: " << kRobots << "box.urdf, " << base
                        << "}\n"
                        << rest << "contacts:\n  - {link: box/box, plane: floor, " << points;
  const mech::Model m = scene::load_model(bodies);
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_mujoco(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.2 / kG);
  for (int row = 0; row < 4; ++row) {
    EXPECT_GT(first_contact(tr, row), t_star) << row;
    EXPECT_LE(first_contact(tr, row), t_star + 2 * h) << row;
  }
}

}  // namespace
}  // namespace lcsim::mujoco
