// The Bullet scene ("rb6", src/bullet/world.cpp) against lcsim's exact
// event-driven solution, and the comparison function itself.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace lcsim::bullet {
namespace {

mech::Model load(const std::string& name) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
}

sim::Trajectory exact_run(const mech::Model& m, const Eigen::VectorXd& x0, double dt_out) {
  sim::Options o;
  o.t_end = m.t_end;
  o.dt_out = dt_out;
  return sim::simulate_event_driven(m, x0, o);
}

sim::Trajectory bullet_run(const mech::Model& m, const Eigen::VectorXd& x0, double h,
                           double dt_out) {
  sim::Options o;
  o.t_end = m.t_end;
  o.h = h;
  o.dt_out = dt_out;
  return simulate_bullet(m, x0, o);
}

// Bullet's step is semi-implicit Euler with explicit spring forces: first
// order in h. Measured final errors (T = 3, notes/bullet.md and
// `lcsim compare`): S1 2.09e-4 at h = 1e-3, 2.12e-5 at 1e-4, i.e.
// C = 0.21; S2 1.51e-4 and 1.51e-5, C = 0.151, with deviation over time
// 1.77e-4 / 1.77e-5 (C = 0.177). The bound 3 C h leaves a factor 3 for a
// different Bullet build or FPU ordering while still failing on a zeroth-order
// error (an O(1) or an O(sqrt h) mistake exceeds it at h = 1e-4).
TEST(BulletWorld, TwoCartsAgreesWithExactToFirstOrder) {
  const mech::Model m = load("two_carts.yaml");
  for (double h : {1e-3, 1e-4}) {
    const double dt = std::max(1.0, std::round(m.t_end / (2000 * h))) * h;
    const sim::Trajectory ex = exact_run(m, m.initial, dt);
    const sim::Trajectory bt = bullet_run(m, m.initial, h, dt);
    ASSERT_EQ(bt.status, sim::RunStatus::kCompleted) << bt.message;
    const Comparison c = compare_trajectories(ex, bt, 1e-9 * h);
    EXPECT_LE(c.error_final, 3 * 0.21 * h) << "h = " << h;
    // 6DOF2 limits are speculative: never crossed (round-off only).
    EXPECT_GE(c.max_violation, -1e-12);
    // Event times. Activation: the limit row caps the approach speed at
    // stop_erp * gap / h = 0.2 gap / h, so at impact speed 1 it engages when
    // gap < 5 h, i.e. 4-5 steps early (measured -4 h). Release: first step
    // without impulse, measured 1.2 h late.
    ASSERT_EQ(c.event_shifts.size(), 2u);
    EXPECT_TRUE(c.event_shifts[0].activation);
    EXPECT_LE(std::abs(c.event_shifts[0].shift), 5.5 * h);
    EXPECT_FALSE(c.event_shifts[1].activation);
    EXPECT_LE(std::abs(c.event_shifts[1].shift), 2.5 * h);
    // Bullet's energy change minus the exact one, measured -7.65e-5 / -7.66e-6:
    // first order too.
    EXPECT_LE(std::abs(c.energy_drift), 3 * 0.077 * h);
  }
}

TEST(BulletWorld, HookRunAgreesWithExactToFirstOrder) {
  const mech::Model m = load("two_carts_hook.yaml");
  Eigen::VectorXd x0(4);
  x0 << 0, 0, -1, 2;
  for (double h : {1e-3, 1e-4}) {
    const double dt = std::max(1.0, std::round(m.t_end / (2000 * h))) * h;
    const sim::Trajectory ex = exact_run(m, x0, dt);
    const sim::Trajectory bt = bullet_run(m, x0, h, dt);
    ASSERT_EQ(bt.status, sim::RunStatus::kCompleted) << bt.message;
    const Comparison c = compare_trajectories(ex, bt, 1e-9 * h);
    EXPECT_LE(c.error_final, 3 * 0.151 * h) << "h = " << h;
    // No event at a later time here, so the deviation over time is first order
    // too (measured 1.768e-4 and 1.768e-5).
    EXPECT_LE(c.deviation_max, 3 * 0.177 * h) << "h = " << h;
    EXPECT_GE(c.max_violation, -1e-12);
    // The hook engages at t = 0 (the impact of Example 3.8.3 leaves x1 = x2
    // with the hook active); Bullet reports it at the end of its first step.
    ASSERT_FALSE(c.event_shifts.empty());
    for (const auto& s : c.event_shifts) EXPECT_LE(std::abs(s.shift), 1.5 * h);
  }
}

// The ball of robots/ball.yaml with e = 0: lands at t = sqrt(2/9.81) and
// stays. Bullet's limit is approached speculatively (never crossed), so the
// penetration bound is round-off: |gap| <= 1e-12 m, measured 0; at rest the
// height decays geometrically (factor 1 - stop_erp per step) to 0.
TEST(BulletWorld, InelasticBallStopsWithoutPenetrating) {
  mech::Model m = load("ball.yaml");
  m.mechanical->restitution.setZero();
  for (double h : {1e-3, 1e-4}) {
    const sim::Trajectory bt = bullet_run(m, m.initial, h, 0.0);
    ASSERT_EQ(bt.status, sim::RunStatus::kCompleted) << bt.message;
    EXPECT_GE(bt.max_violation, -1e-12);
    EXPECT_LE(std::abs(bt.final_state(0)), 1e-12);
    EXPECT_LE(std::abs(bt.final_state(1)), 1e-12);
    ASSERT_FALSE(bt.events.empty());
    // Landing: exact t = 0.4515..., Bullet engages a few steps early (see above).
    EXPECT_NEAR(bt.events.front().t, std::sqrt(2 / 9.81), 6 * h);
  }
}

// Settings Bullet cannot use are refused before a world is built, naming the
// setting and its value (a stop ERP of 0 would never push a limit back; a
// NaN would reach Bullet's solver).
TEST(BulletWorld, UnusableSettingsAreInput) {
  const mech::Model m = load("ball.yaml");
  sim::Options o;
  o.t_end = 0.1;
  o.h = 1e-3;
  auto refused = [&](bullet::WorldSettings s, const std::string& needle) {
    EXPECT_NE(bullet::settings_error(s).find(needle), std::string::npos)
        << bullet::settings_error(s);
    const sim::Trajectory tr = bullet::simulate_bullet(m, m.initial, o, s);
    EXPECT_EQ(tr.status, sim::RunStatus::kInvalidInput);
    EXPECT_NE(tr.message.find(needle), std::string::npos) << tr.message;
  };
  EXPECT_EQ(bullet::settings_error({}), "");
  bullet::WorldSettings s;
  s.stop_erp = 0.0;
  refused(s, "stop_erp must be in (0, 1] (got 0)");
  s = {};
  s.solver_iterations = 0;
  refused(s, "solver_iterations must be >= 1 (got 0)");
  s = {};
  s.limit_range = std::nan("");
  refused(s, "limit_range must be finite and > 0 (got nan)");
}

// The comparison reports a deviation of exactly the size put in.
TEST(BulletCompare, PerturbedTrajectoryGivesTheDeviationPutIn) {
  const mech::Model m = load("two_carts.yaml");
  const sim::Trajectory ex = exact_run(m, m.initial, 1e-2);
  sim::Trajectory other = ex;
  const double delta = 3e-3;
  for (auto& s : other.samples)
    if (s.t > 1.5 && s.t < 1.6) s.x(1) += delta;
  for (auto& e : other.events) e.t += 0.02;  // every switch 20 ms late
  const Comparison c = compare_trajectories(ex, other, 1e-12);
  EXPECT_NEAR(c.deviation_max, delta, 1e-15);
  EXPECT_GT(c.deviation_t, 1.5);
  EXPECT_LT(c.deviation_t, 1.6);
  EXPECT_EQ(c.error_final, 0.0);
  EXPECT_EQ(c.samples_compared, static_cast<long>(other.samples.size()));
  ASSERT_EQ(c.event_shifts.size(), 2u);
  for (const auto& s : c.event_shifts) EXPECT_NEAR(s.shift, 0.02, 1e-12);
  EXPECT_EQ(c.unmatched_other, 0);
  EXPECT_EQ(c.energy_drift, 0.0);

  // A trajectory identical to the exact one deviates by nothing.
  const Comparison same = compare_trajectories(ex, ex, 1e-12);
  EXPECT_EQ(same.deviation_max, 0.0);
  for (const auto& s : same.event_shifts) EXPECT_EQ(s.shift, 0.0);
}

TEST(BulletWorld, InexpressibleModelsAreRefusedNamingTheConstraint) {
  mech::Model m = load("two_carts_hook.yaml");
  m.mechanical->E.coeffRef(1, 1) = 1.0;  // hook row now x1 + x2 >= 0
  try {
    check_expressible(m);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'hook'"), std::string::npos) << e.what();
  }
  // An input error: thrown before anything runs (the CLI exits 2).
  sim::Options o;
  o.t_end = 1;
  EXPECT_THROW((void)simulate_bullet(m, Eigen::VectorXd::Zero(4), o), std::invalid_argument);

  mech::Model nd = load("two_carts.yaml");
  nd.mechanical->M.coeffRef(0, 1) = nd.mechanical->M.coeffRef(1, 0) = 0.1;
  EXPECT_THROW(check_expressible(nd), std::invalid_argument);
}

// The scene's known limits are said, not hidden: an infeasible start is
// refused as by lcsim's own methods; restitution that Bullet's limits do not
// reproduce at stop ERP 0.2, and explicit springs past omega h = 2, warn.
TEST(BulletWorld, InfeasibleStartAndUnreproducibleSettingsAreReported) {
  mech::Model ball = load("ball.yaml");  // e = 0.5
  sim::Trajectory tr = bullet_run(ball, Eigen::Vector2d(-0.1, 0.0), 1e-3, 0.0);
  EXPECT_EQ(tr.status, sim::RunStatus::kInvalidInput);
  EXPECT_NE(tr.message.find("constraint 'ground' is violated at t = 0 (gap = -0.1)"),
            std::string::npos)
      << tr.message;

  tr = bullet_run(ball, ball.initial, 1e-3, 0.0);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.warning_count(), 1);
  EXPECT_EQ(tr.warning_count("bullet-restitution-lost"), 1);
  EXPECT_NE(tr.first_warning().find("restitution is lost or reduced"), std::string::npos);
  // What the warning says: no rebound (the ball ends at rest on the ground).
  EXPECT_LE(std::abs(tr.final_state(1)), 1e-9);

  // omega = sqrt(k) = 1e3 rad/s against h = 1e-2: omega h = 10 > 2.
  mech::Model stiff = load("two_carts.yaml");
  stiff.mechanical->K *= 1e6;
  stiff.t_end = 0.1;
  tr = bullet_run(stiff, stiff.initial, 1e-2, 0.0);
  bool said = false;
  for (const auto& w : tr.warnings) said |= w.message.find("omega h up to") != std::string::npos;
  EXPECT_TRUE(said) << "no warning about explicit springs";
  // The safe side stays quiet: omega h <= 2 with the unit springs at 1e-2.
  tr = bullet_run(load("two_carts.yaml"), load("two_carts.yaml").initial, 1e-2, 0.0);
  EXPECT_TRUE(tr.warnings.empty()) << tr.first_warning();
}

// No registration call: linking lcsim::bullet is enough (its INTERFACE
// source src/bullet/autoregister/register_bullet.cpp).
TEST(BulletWorld, RegisteredAsIntegratorAndSolvers) {
  EXPECT_EQ(sim::make_integrator("bullet")->name(), "bullet");
  for (const char* n : {"bullet-dantzig", "bullet-lemke", "bullet-pgs"})
    EXPECT_EQ(lcp::make_solver(n)->name(), n);
}

// Options::progress, as for lcsim's time stepping (tests/sim/test_progress.cpp):
// 3 / 1e-4 = 30000 steps, a report every kProgressSteps = 1024 steps at
// t = j h: floor(30000 / 1024) = 29 reports.
TEST(BulletWorld, ReportsProgressEveryKProgressSteps) {
  const mech::Model model = mech::two_carts_model(false);
  sim::Options opt;
  opt.t_end = 3.0;
  opt.h = 1e-4;
  opt.record_samples = false;
  std::vector<double> ts;
  opt.progress = [&ts](double t) { ts.push_back(t); };
  const sim::Trajectory tr = simulate_bullet(model, Eigen::Vector4d(0, -1, -1, 0), opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(ts.size(), 30000u / sim::Options::kProgressSteps);
  for (std::size_t i = 0; i < ts.size(); ++i)
    EXPECT_EQ(ts[i], static_cast<double>((i + 1) * sim::Options::kProgressSteps) * 1e-4);
}

}  // namespace
}  // namespace lcsim::bullet
