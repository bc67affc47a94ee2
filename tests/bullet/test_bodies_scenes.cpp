// Bullet (src/bullet/bodies_world.cpp) on scenes of several bodies, and the
// friction multipliers of its samples, against closed forms.
//
// Tolerances. Bullet's contact rows are speculative (target velocity
// -distance / h, ERP 0): a point stops at its target in the step that would
// cross it and nothing pushes it back, so a body at rest is where the exact
// run has it up to the sequential-impulse solver's residual (1e-9 asserted,
// as tests/bullet/test_contact_scenes.cpp). Bullet's step is semi-implicit
// Euler: from rest under gravity it runs ahead of the exact fall by
// g h t / 2, at most half a step in time at the landing (the speed there is
// g t), so a landing step ends within 1.5 h of the exact impact.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>

namespace lcsim::bullet {
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

sim::Trajectory exact_run(const mech::Model& m, const sim::Options& o) {
  const auto event = sim::make_integrator("event");
  return event->run(m, m.initial, sim::keep_used(o, event->options_used()));
}

TEST(BulletBodies, BallDroppedOntoATableMeetsItAtTheFreeFallTimeAndRestsOnIt) {
  const mech::Model m = scene::load_model(kData + "ball_table_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_bullet(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.25 / kG);
  const double t_bt = first_contact(tr, 0);
  std::printf("[ bullet   ] ball on table: first contact %.6g (exact %.6g), rest z %.17g\n", t_bt,
              t_star, tr.final_state(2));
  EXPECT_LE(std::abs(t_bt - t_star), 1.5 * h);
  EXPECT_NEAR(tr.final_state(2), 0.65, 1e-9);  // on the top face, not in it
  EXPECT_GE(tr.max_violation, -1e-9);
  EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-9);
  // Inelastic: the kinetic energy at impact is lost, the rest of the drop's
  // m g h too (the ball ends at rest 0.25 m lower).
  EXPECT_NEAR(tr.energy_initial - tr.energy_final, 1.0 * kG * 0.25, 1e-8);
}

TEST(BulletBodies, GripperClosesOnTheBoxAsTheExactRunDoes) {
  const mech::Model m = scene::load_model(kRobots + "gripper_box_scene.yaml");
  const double h = 1e-3;
  const sim::Options o = options(m, h);
  const sim::Trajectory ex = exact_run(m, o);
  ASSERT_EQ(ex.status, sim::RunStatus::kCompleted) << ex.message;
  const sim::Trajectory bt = simulate_bullet(m, m.initial, o);
  ASSERT_EQ(bt.status, sim::RunStatus::kCompleted) << bt.message;
  // Each finger (q = 0.05 + 0.1 cos(20 t), its spring an explicit force in
  // Bullet's semi-implicit step: a phase error of O(h)) meets the box's face
  // at q = 0.11 m, both in the same step, within a step of the exact time.
  const double t_star = std::acos(0.6) / 20.0;
  const auto& c = m.mechanical->constraints;
  double t_left = NAN;
  for (const char* tip : {"left_tip.sphere0", "right_tip.sphere0"}) {
    const int row = static_cast<int>(std::find(c.begin(), c.end(), tip) - c.begin());
    ASSERT_LT(row, static_cast<int>(c.size())) << tip;
    const double t = first_contact(bt, row);
    EXPECT_LE(std::abs(t - t_star), h) << tip;
    if (std::isnan(t_left))
      t_left = t;
    else
      EXPECT_EQ(t, t_left);
  }
  const Comparison cmp = compare_trajectories(ex, bt, 1e-12);
  std::printf("[ bullet   ] gripper: final difference %.3e\n", cmp.error_final);
  EXPECT_LE(cmp.error_final, 1e-9);
  EXPECT_GE(bt.max_violation, -1e-9);
}

// The box sliding on the floor (tests/bullet/data/box_slide_bodies_scene.yaml,
// mu = 0.3, 1 m/s along +x = -t2): the floor's friction on the box is along
// +t2, against the velocity, and on the cone's boundary while it slides, so
// each step's friction multipliers sum to mu times its normal ones; nothing
// acts along t1. They are the whole horizontal force on the box, so their
// impulse is its momentum change, sum h u_t2 = m (v0 - v_x(T)), to rounding
// (1e-12 N s); the friction is then -mu m g on average over the slide, and
// the box sticks at v0 / (mu g) = 0.33979 s to Bullet's step (measured:
// 0.340; 2 h asserted). Bullet's "cone" (two directions, implicit cone) and
// "box" friction agree along a tangent.
TEST(BulletBodies, SlidingBoxFeelsMuMgAgainstItsVelocity) {
  const mech::Model m = scene::load_model(kData + "box_slide_bodies_scene.yaml");
  const double h = 1e-3, mu = 0.3, mass = 1.2, v0 = 1.0;
  for (WorldSettings::Friction f :
       {WorldSettings::Friction::kCone, WorldSettings::Friction::kBox}) {
    WorldSettings s;
    s.friction = f;
    const sim::Trajectory tr = simulate_bullet(m, m.initial, options(m, h), s);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_EQ(tr.samples.back().u_t.size(), 8);  // the box's eight corners
    ASSERT_EQ(tr.samples.back().u_t2.size(), 8);
    double coulomb = 0.0, across = 0.0, impulse = 0.0, t_stop = NAN;
    int sliding = 0;
    for (std::size_t j = 1; j < tr.samples.size(); ++j) {
      const sim::Sample& smp = tr.samples[j];
      const double t1 = smp.u_t.sum(), t2 = smp.u_t2.sum(), n = smp.u.sum();
      impulse += h * t2;
      across = std::max(across, std::abs(t1));
      if (std::isnan(t_stop) && smp.x(6) < 1e-3) t_stop = smp.t;
      if (smp.x(6) < 0.05) continue;  // sliding: v_x well above 0
      coulomb = std::max(coulomb, std::abs(t2 - mu * n));
      ++sliding;
    }
    const double v_end = tr.final_state(6);
    std::printf(
        "[ bullet   ] %s: |u_t2 - mu u_n| <= %.3e N over %d sliding steps, |u_t1| <= %.3e "
        "N, impulse %.12g N s (m (v0 - v_end) = %.12g), stop %.6g s (closed form %.6g)\n",
        friction_name(f).c_str(), coulomb, sliding, across, impulse, mass * (v0 - v_end), t_stop,
        v0 / (mu * kG));
    EXPECT_GT(sliding, 250);
    EXPECT_LE(coulomb, 1e-9);  // the solver's residual on O(1) N
    EXPECT_LE(across, 1e-9);
    EXPECT_NEAR(impulse, mass * (v0 - v_end), 1e-12);
    EXPECT_NEAR(t_stop, v0 / (mu * kG), 2 * h);
  }
}

// The legged robot (robots/vision60_drop_scene.yaml, a one-body `bodies:`
// scene: floating base, 12 PD-held joints) dropped 0.03 m: free fall is a
// rigid translation, so its four toes land together at sqrt(2 h / g) =
// 0.0782 s, Bullet's within 1.5 steps (above). Its dampers (20 N m s/rad
// on light legs) are explicit joint torques in Bullet, stable only for h
// below 6.7e-4 s (the run's own warning): at h = 1e-3 the run must end as a
// numerical failure, never completed; at h = 1e-4 it lands.
TEST(BulletBodies, LeggedRobotLandsOnItsFourToesAtTheFreeFallTime) {
  const mech::Model m = scene::load_model(kRobots + "vision60_drop_scene.yaml");
  sim::Options o = options(m, 1e-3);
  o.t_end = 0.15;
  const sim::Trajectory coarse = simulate_bullet(m, m.initial, o);
  EXPECT_EQ(coarse.status, sim::RunStatus::kNumericalFailure) << coarse.message;
  o.h = o.dt_out = 1e-4;
  const sim::Trajectory tr = simulate_bullet(m, m.initial, o);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double t_star = std::sqrt(2.0 * 0.03 / kG);
  for (int toe = 0; toe < 4; ++toe) {
    EXPECT_LE(std::abs(first_contact(tr, toe) - t_star), 1.5 * o.h) << "toe " << toe;
    EXPECT_EQ(first_contact(tr, toe), first_contact(tr, 0)) << "toe " << toe;
  }
}

// Only the scene's named pairs collide: the ball falls through a table
// that no contact names (tests/bullet/data/ball_through_table_scene.yaml)
// and meets the floor at sqrt(2 * 0.8 / g); it touches nothing before.
TEST(BulletBodies, OnlyTheNamedPairsCollide) {
  const mech::Model m = scene::load_model(kData + "ball_through_table_scene.yaml");
  const double h = 1e-3;
  const sim::Trajectory tr = simulate_bullet(m, m.initial, options(m, h));
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_FALSE(tr.events.empty());
  const double t = tr.events.front().t, t_star = std::sqrt(2.0 * 0.8 / kG);
  EXPECT_LE(std::abs(t - t_star), 1.5 * h);  // the landing step (above)
}

// A body Bullet's model of a scene of bodies cannot hold (a mimic joint) is
// refused before anything runs, in one line naming the body and the joint.
TEST(BulletBodies, RefusesAMimicJointInOneLine) {
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

}  // namespace
}  // namespace lcsim::bullet
