// Inputs that vary in time (issue 29; docs/inputs.md) in the exact method:
// force inputs through the appended exosystem, breakpoints as scheduled
// events. Every number is checked against a closed form derived here, and
// event times against roots of the closed forms found here by bisection.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>

#include "support/bisect.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

mech::Model parse(const std::string& yaml) { return io::parse_matrix_model(yaml, "test.yaml"); }

sim::Trajectory run(const mech::Model& m, double t_end, double dt_out = 0.0) {
  sim::Options o;
  o.t_end = t_end;
  o.dt_out = dt_out;
  return sim::make_integrator("event")->run(m, m.initial, o);
}

using test_support::bisect;

// A free mass m = 2 kg pushed by a PWL force (N): 0 at 0 s, 2 at 1 s, 2 at
// 2 s, a jump to -1 at 2 s, -1 at 3 s and after. Hand integration piece by
// piece: on a piece u = u0 + s tau, v = v0 + (u0 tau + s tau^2/2)/m,
// q = q0 + v0 tau + (u0 tau^2/2 + s tau^3/6)/m.
TEST(Inputs, PwlForceBreakpointsAreScheduledEventsAndTheStateIsExact) {
  const mech::Model m = parse(R"(
name: pwl_mass
inputs:
  - {name: push, kind: pwl, points: [[0, 0], [1, 2], [2, 2], [2, -1], [3, -1]]}
mechanical:
  M: [[2]]
  force_inputs: [{input: push, gain: [1]}]
initial: [0.5, -0.25]
)");
  const sim::Trajectory tr = run(m, 3.5);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  // The breakpoints after t = 0: 1, 2 (a jump) and 3 s, each a scheduled event.
  ASSERT_EQ(tr.events.size(), 3u);
  const double want_t[] = {1.0, 2.0, 3.0};
  for (int i = 0; i < 3; ++i) {
    EXPECT_EQ(tr.events[i].type, sim::EventType::kSchedule);
    EXPECT_EQ(sim::to_string(tr.events[i].type), "schedule");
    EXPECT_EQ(tr.events[i].t, want_t[i]);  // scheduled: the breakpoint itself
    EXPECT_NE(tr.events[i].note.find("'push'"), std::string::npos) << tr.events[i].note;
  }
  // The pieces (start, u0, slope) and the hand integration.
  const double mass = 2.0;
  struct Piece {
    double t0, u0, s;
  };
  const Piece pieces[] = {{0, 0, 2}, {1, 2, 0}, {2, -1, 0}, {3, -1, 0}};
  double q = 0.5, v = -0.25;
  const auto advance = [&](const Piece& p, double tau, double& qq, double& vv) {
    qq = q + v * tau + (p.u0 * tau * tau / 2 + p.s * tau * tau * tau / 6) / mass;
    vv = v + (p.u0 * tau + p.s * tau * tau / 2) / mass;
  };
  for (int i = 0; i < 4; ++i) {
    const double t1 = i < 3 ? pieces[i + 1].t0 : 3.5;
    double q1, v1;
    advance(pieces[i], t1 - pieces[i].t0, q1, v1);
    const VectorXd& x = i < 3 ? tr.events[i].state_before : tr.final_state;
    // Each piece is one matrix exponential of a 5-state system with entries
    // of order 1 over at most 1 s: rounding of a few hundred ulp of |x| ~ 1.
    EXPECT_NEAR(x(0), q1, 1e-13) << "piece " << i;
    EXPECT_NEAR(x(1), v1, 1e-13) << "piece " << i;
    if (i < 3) {
      EXPECT_EQ(tr.events[i].state_after, tr.events[i].state_before);  // no impulse
    }
    q = q1, v = v1;
  }
}

// A 1 kg block on the floor (q >= 0) under gravity, lifted by a ramp force
// u = 20 t N: it leaves the floor when 20 t = g, t* = g/20 (a release, the
// contact force -g + 20 t crossing zero: a root of a Bohl function of the
// exosystem). After it, q = 10/3 (t^3 - t*^3) - 10 t*^2 (t - t*) - g/2 (t - t*)^2.
TEST(Inputs, RampForceLiftsABlockOffTheFloorAtTheClosedFormTime) {
  const mech::Model m = parse(R"(
inputs:
  - {name: lift, kind: ramp, slope: 20}
mechanical:
  M: [[1]]
  E: [[1]]
  f: [-9.81]
  constraints: [floor]
  force_inputs: [{input: lift, gain: [1]}]
initial: [0, 0]
)");
  const sim::Trajectory tr = run(m, 1.0);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kRelease);
  const double ts = 9.81 / 20.0;
  // The contact force's root: the LCS's rounding at rate 20 N/s.
  EXPECT_NEAR(tr.events[0].t, ts, 1e-12);
  const double t = 1.0, d = t - ts;
  const double q = 10.0 / 3.0 * (t * t * t - ts * ts * ts) - 10.0 * ts * ts * d - 9.81 / 2 * d * d;
  const double v = 10.0 * (t * t - ts * ts) - 9.81 * d;
  EXPECT_NEAR(tr.final_state(0), q, 1e-12);
  EXPECT_NEAR(tr.final_state(1), v, 1e-12);
}

// A ball above a shaker table z(t) = A sin(w t), written relative to the
// table (r = q - z >= 0, r'' = -g - z'' + lambda): the table's acceleration
// is a sine force input of amplitude A w^2, and the ball dropped from rest
// at height h starts with r'(0) = -A w. The closed form of the gap is
// r(t) = h - g t^2/2 - A sin(w t) (free fall minus the table); its first
// root, found here by bisection, is the first impact.
TEST(Inputs, ShakerTableFirstImpactAtTheRootOfTheClosedFormGap) {
  const double A = 0.05, f = 5.0, w = 2.0 * std::numbers::pi * f, h = 0.3, g = 9.81;
  const std::string yaml =
      "inputs:\n  - {name: table, kind: sine, amplitude: " + std::to_string(A * w * w) +
      ", frequency: 5}\n" + "mechanical:\n  M: [[1]]\n  E: [[1]]\n  f: [-9.81]\n" +
      "  restitution: [0.5]\n  constraints: [table]\n" +
      "  force_inputs: [{input: table, gain: [1]}]\n" + "initial: [0.3, " + std::to_string(-A * w) +
      "]\n";
  mech::Model m = parse(yaml);
  // std::to_string's 6 digits: take the exact numbers the closed form uses.
  m.mechanical->inputs[0].amplitude = A * w * w;
  m.initial(1) = -A * w;
  const sim::Trajectory tr = run(m, 0.4);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  const auto gap = [&](double t) { return h - g * t * t / 2 - A * std::sin(w * t); };
  // The gap stays positive up to 0.2 s (checked on a fine grid) and
  // decreases on [0.2, 0.3] (r' = -g t - A w cos(w t) <= -g t + A w < 0 for
  // t > A w / g = 0.16 s), from > 0 to < 0: one root there, the first.
  for (int i = 0; i <= 2000; ++i) ASSERT_GT(gap(0.2 * i / 2000), 0.0);
  ASSERT_LT(gap(0.3), 0.0);
  const double t_hit = bisect(gap, 0.2, 0.3);
  // The event's time resolution: rounding of the gap (~1e-16 of its terms)
  // over the approach rate (~3 m/s), and the monitor's root tolerance.
  EXPECT_NEAR(tr.events[0].t, t_hit, 1e-12);
  // Newton's law on the relative velocity: r'+ = -e r'-.
  const double rate = -g * t_hit - A * w * std::cos(w * t_hit);
  EXPECT_NEAR(tr.events[0].state_before(1), rate, 1e-10);
  EXPECT_NEAR(tr.events[0].state_after(1), -0.5 * rate, 1e-10);
}

// The same table as a moving stop (mechanical.gap_inputs, robots/
// shaker_table.yaml): the ball's height q with q - z(t) >= 0, z = A sin(w t)
// a sine input entering the gap with gain -1. The gap's closed form is the
// same, h - g t^2/2 - A sin(w t); Newton's law acts on the velocity
// relative to the table: v+ - z' = -e (v- - z'), z' = A w cos(w t).
TEST(Inputs, ShakerTableAsAMovingStop) {
  const double A = 0.05, w = 2.0 * std::numbers::pi * 5.0, h = 0.3, g = 9.81;
  mech::Model m =
      io::load_matrix_model(std::string(LCSIM_SOURCE_DIR) + "/robots/shaker_table.yaml");
  const sim::Trajectory tr = run(m, 0.4, 1e-3);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  const auto gap = [&](double t) { return h - g * t * t / 2 - A * std::sin(w * t); };
  const double t_hit = bisect(gap, 0.2, 0.3);  // bracket as in the test above
  EXPECT_NEAR(tr.events[0].t, t_hit, 1e-12);   // as above
  const double v_minus = -g * t_hit, dz = A * w * std::cos(w * t_hit);
  // v at the event from the phase's exponential: the time's resolution
  // (1e-12 s) times the acceleration g, and rounding.
  EXPECT_NEAR(tr.events[0].state_before(1), v_minus, 1e-10);
  EXPECT_NEAR(tr.events[0].state_after(1), dz - 0.5 * (v_minus - dz), 1e-10);
  // Every sample above the moving table (to the gaps' rounding).
  for (const sim::Sample& s : tr.samples)
    EXPECT_GE(s.x(0) - A * std::sin(w * s.t), -1e-12) << "t = " << s.t;
}

// A periodic pulse force on a free mass: every edge is a scheduled event at
// delay + k period + (0, rise, rise + width, rise + width + fall).
TEST(Inputs, PulseEdgesAreScheduledEvents) {
  const mech::Model m = parse(R"(
inputs:
  - {name: p, kind: pulse, v1: 0, v2: 1, delay: 0.1, rise: 0.01, fall: 0.02, width: 0.2, period: 0.5}
mechanical:
  M: [[1]]
  force_inputs: [{input: p, gain: [1]}]
initial: [0, 0]
)");
  const sim::Trajectory tr = run(m, 1.05);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  std::vector<double> want;
  for (int k = 0; k < 3; ++k)
    for (double e : {0.0, 0.01, 0.21, 0.23})
      if (0.1 + k * 0.5 + e < 1.05) want.push_back(0.1 + k * 0.5 + e);
  ASSERT_EQ(tr.events.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(tr.events[i].type, sim::EventType::kSchedule);
    EXPECT_NEAR(tr.events[i].t, want[i], 1e-15);  // the same sum in another order
  }
  // The impulse of one period: the trapezoid's area 0.01/2 + 0.2 + 0.02/2 =
  // 0.215 N s; two full periods by t = 1.05 and the velocity is their sum.
  EXPECT_NEAR(tr.final_state(1), 2 * 0.215, 1e-13);
}

// A moving stop is refused by the time-stepping methods with one line (no
// run on a model they would simulate wrongly).
TEST(Inputs, MovingStopRefused) {
  const mech::Model m = parse(R"(
inputs:
  - {name: s, kind: step, time: 0.5, final: 1}
mechanical:
  M: [[1]]
  E: [[1]]
  gap_inputs: [{input: s, gain: [0.1]}]
initial: [1, 0]
)");
  for (const char* method : {"euler", "moreau-jean"}) {
    sim::Options o;
    o.t_end = 1.0;
    o.h = 0.01;
    const sim::Trajectory tr = sim::make_integrator(method)->run(m, m.initial, o);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << method;
    EXPECT_NE(tr.message.find("gap_inputs"), std::string::npos) << tr.message;
    EXPECT_TRUE(tr.samples.empty()) << method;
  }
}

// Backward Euler and Moreau-Jean evaluate the force inputs per step: a unit
// mass pushed by u = sin(2 pi t) N from q = 0.5 m, v = -0.25 m/s has
// v = v0 + (1 - cos(w t))/w and q = q0 + v0 t + (t - sin(w t)/w)/w. Their
// errors at t = 1.25 s against it halve (backward Euler, first order: ratio
// 2) and quarter (Moreau-Jean with theta = 1/2, the trapezoidal rule on a
// free mass: ratio 4) with h; within 10%, the next term of the error being
// O(h) relative to the leading one (1e-3 at h = 1e-3).
TEST(Inputs, TimeSteppingEvaluatesInputsPerStep) {
  const mech::Model m = parse(R"(
inputs:
  - {name: push, kind: sine, amplitude: 1, frequency: 1}
mechanical:
  M: [[1]]
  force_inputs: [{input: push, gain: [1]}]
initial: [0.5, -0.25]
)");
  const double w = 2.0 * std::numbers::pi, t = 1.25;
  VectorXd exact(2);
  exact << 0.5 - 0.25 * t + (t - std::sin(w * t) / w) / w, -0.25 + (1.0 - std::cos(w * t)) / w;
  // The exact method first: its exosystem is the sine, to rounding.
  const sim::Trajectory ev = run(m, t);
  ASSERT_EQ(ev.status, Status::kCompleted) << ev.message;
  EXPECT_NEAR((ev.final_state - exact).norm(), 0.0, 1e-13);
  for (const auto& [method, order] : {std::pair{"euler", 1}, {"moreau-jean", 2}}) {
    double err[2];
    for (int i = 0; i < 2; ++i) {
      sim::Options o;
      o.t_end = t;
      o.h = i == 0 ? 1e-3 : 5e-4;
      const sim::Trajectory tr = sim::make_integrator(method)->run(m, m.initial, o);
      ASSERT_EQ(tr.status, Status::kCompleted) << method << ": " << tr.message;
      err[i] = (tr.final_state - exact).norm();
    }
    const double ratio = err[0] / err[1], want = order == 1 ? 2.0 : 4.0;
    EXPECT_NEAR(ratio, want, 0.1 * want) << method << ": " << err[0] << ", " << err[1];
  }
}

}  // namespace
}  // namespace lcsim
