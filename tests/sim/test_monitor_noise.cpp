// The event-driven method's noise band of a monitor at a phase start is the
// rounding of that monitor's own terms, not of the whole state (issue 24,
// Talos): a contact left open by a gap of 1e-9 and approaching was not armed
// because the band was 64 eps |w|_1 max|z|, and max|z| was an unrelated
// coordinate (a clamped joint balanced to 2.7e5). Its return was found only
// once the gap reached minus the band (-2.5e-9), which re-initialisation
// rejects as infeasible, or never when the band was wider than the whole
// excursion. The reference values are closed forms, not lcsim runs.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/sim/sim.hpp>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// x1 falls from rest at gap delta onto a stop x1 >= 0 under a unit force;
// x2 is a free coordinate at rest far away (|x2| = far), coupled to nothing.
// The exact motion: x1 = delta - t^2/2 lands at t* = sqrt(2 delta), the
// inelastic impact stops it, and it rests on the stop from then on.
sim::Trajectory drop_next_to_far_coordinate(double delta, double far, double t_end) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  MatrixXd E(1, 2);
  E << 1, 0;
  m.E = E.sparseView();
  m.g = VectorXd::Zero(1);
  m.f = Eigen::Vector2d(-1.0, 0.0);
  m.restitution = VectorXd::Zero(1);
  const mech::Model model = mech::model_of(m, "drop-next-to-far-coordinate");
  VectorXd x0(4);
  x0 << delta, far, 0.0, 0.0;
  sim::Options opt;
  opt.t_end = t_end;
  return sim::simulate_event_driven(model, x0, opt);
}

TEST(MonitorNoise, SmallGapApproachingIsFoundNextToALargeCoordinate) {
  // delta = 1e-10 is open for re-initialisation (its zero test is
  // 1e-9 |gap| + 1e-13), while the old band 64 eps max|z| was 1.4e-8 with
  // x2 = 1e6: the contact was never armed, x1 passed through the stop
  // (-4.9e-9 at t_end) and the run said "completed" with no event.
  for (const double far : {1.0, 1e6, 1e12}) {
    SCOPED_TRACE(far);
    const double delta = 1e-10, t_end = 1e-4;
    const sim::Trajectory tr = drop_next_to_far_coordinate(delta, far, t_end);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_EQ(tr.events.size(), 1u);
    EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
    // The gap delta - t^2/2 is evaluated from x1 and the force term only
    // (x2 is decoupled: its entries of e^{A t} are exact zeros), so its
    // rounding is ~eps delta and t*'s resolution eps delta / t* ~ 1e-21 s;
    // Brent stops within 2 eps t* ~ 6e-21 s. 1e-12 t* (1.4e-17 s) bounds both
    // with room, and excludes the old late detection at -1.4e-8
    // (t = 1.7e-4 s, after t_end).
    const double t_star = std::sqrt(2.0 * delta);
    EXPECT_NEAR(tr.events[0].t, t_star, 1e-12 * t_star);
    // At rest on the stop after the inelastic impact: the impact sets the
    // rate to zero and re-initialisation projects the closed gap onto zero.
    EXPECT_EQ(tr.final_state(0), 0.0);
    EXPECT_EQ(tr.final_state(2), 0.0);
    EXPECT_EQ(tr.final_state(1), far);  // never moved
    EXPECT_EQ(tr.final_state(3), 0.0);
    EXPECT_GE(tr.max_violation, -1e-20);  // rounding of a gap at 1e-10: ~eps 1e-10
  }
}

// The bouncing ball of robots/ball.yaml (unit mass, g = 9.81, e = 0.5,
// dropped from 1 m at rest) with a root tolerance in time: impacts at
// t1 = sqrt(2/g) and then every 2 e^i t1, accumulating at t* = 3 t1.
// Brent returns an event within event_time_tol of the crossing, on either
// side, so the gap there is down to -tol |rate|; re-initialisation tested a
// gap for zero with the time's resolution 16 ulp(t) only, so every run with
// event_time_tol > 0 failed at the first impact ("the state is infeasible",
// gap -1e-6 for tol = 1e-6), and the accumulation's limit left the ball out
// of its own closure (gap +1e-10) and took a second limit 2e-6 s later.
TEST(MonitorNoise, EventTimeToleranceIsPartOfTheZeroTests) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(1, 1).sparseView();
  m.E = MatrixXd::Identity(1, 1).sparseView();
  m.g = VectorXd::Zero(1);
  const double g = 9.81;
  m.f = VectorXd::Constant(1, -g);
  m.restitution = VectorXd::Constant(1, 0.5);
  const mech::Model model = mech::model_of(m, "ball");
  const double t1 = std::sqrt(2.0 / g), v1 = std::sqrt(2.0 * g);  // first impact, its speed
  for (const double tol : {1e-9, 1e-6, 1e-4}) {
    SCOPED_TRACE(tol);
    sim::Options opt;
    opt.t_end = 3.0;
    opt.event_time_tol = tol;
    const sim::Trajectory tr = sim::simulate_event_driven(model, Eigen::Vector2d(1.0, 0.0), opt);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_GE(tr.events.size(), 2u);
    // Brent's bracket ends within tol + 4 ulp(t) of the root.
    EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
    EXPECT_NEAR(tr.events[0].t, t1, tol + 1e-15);
    // One limit, the last event, with the ball closed and at rest after it.
    for (size_t i = 0; i + 1 < tr.events.size(); ++i)
      EXPECT_EQ(tr.events[i].type, sim::EventType::kImpact) << i;
    EXPECT_EQ(tr.events.back().type, sim::EventType::kAccumulation);
    EXPECT_EQ(tr.events.back().mode_after, lcs::IndexSet{0});
    // The limit is taken, without extrapolation, once an interval is below
    // 16 times the sum of its two impacts' resolutions (each >= tol): the
    // tail left, d r/(1 - r) = d for r = 0.5, is below 32 tol. The impacts'
    // own errors (each <= tol) come on top; measured in total: 1.3 tol
    // (extrapolated), 27 tol, 18.5 tol.
    EXPECT_NEAR(tr.events.back().t, 3.0 * t1, 32.0 * tol);
    EXPECT_EQ(tr.final_state(0), 0.0);
    EXPECT_EQ(tr.final_state(1), 0.0);
    // An event state lies within tol + 4 ulp(t) of the crossing, at a rate
    // below the first impact's speed.
    EXPECT_GE(tr.max_violation, -(tol + 1e-15) * v1);
  }
}

}  // namespace
}  // namespace lcsim
