// Forward sensitivities in an input's own parameters (docs/sensitivities.md,
// src/sim/exact/sensitivity_inputs.cpp): a sine's amplitude, offset,
// frequency, damping, phase and delay, a piecewise linear input's point
// values and times (pwl_v, pwl_t), a step's time, a pulse's levels, rise,
// width, fall, period and delay; on forces and on a moving stop.
//
// Closed forms where there are (the shaker table's first impact time, a PWL
// force on a free mass); elsewhere central differences of the exact method
// with the step and tolerance of tests/sim/test_sensitivity_events.cpp:
// D(h) = (x(T; theta + h) - x(T; theta - h)) / 2h, h = 1e-4 max(1, |theta|),
// tolerance 4 |D(h) - D(h/2)| (Richardson's estimate of D(h/2)'s truncation,
// margin 12) plus 64e-13 max(1, |x|) / h (the run's rounding ~1e-13 of the
// state over the step, margin 32); every perturbed run must have the run's
// events.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "support/sensitivity_fd.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;
constexpr double kPi = std::numbers::pi;

mech::Model load(const std::string& path) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/" + path);
}

mech::Model from_text(const std::string& name, const std::string& yaml) {
  const std::filesystem::path p =
      std::filesystem::temp_directory_path() /
      ("lcsim_sensin_" + name + "_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(p) << yaml;
  mech::Model m = scene::load_model(p.string());
  std::filesystem::remove(p);
  return m;
}

sim::Trajectory run(const mech::Model& m, const VectorXd& x0, double T,
                    std::vector<std::string> sens = {}) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, x0, opt, "event");
}

// A parameter: its column name, its value (the step's scale) and how to
// move it in a copy of the model.
struct Param {
  std::string column;
  double theta;
  std::function<void(mech::Input&, double)> apply;
  int input = 0;
};

// Every column of `ps` against central differences at x(T) and at every
// event time (tests/support/sensitivity_fd.hpp); returns the number of
// entries compared (no loss that ends a column expected).
int expect_matches_fd(const mech::Model& m, const VectorXd& x0, double T,
                      const std::vector<Param>& ps) {
  std::vector<std::string> names;
  std::vector<test_support::FdColumn> cols;
  for (const Param& p : ps) {
    names.push_back(p.column);
    cols.push_back({p.column, p.theta, [p](mech::Model& mm, VectorXd&, double d) {
                      p.apply(mm.mechanical->inputs[static_cast<size_t>(p.input)], d);
                    }});
  }
  const sim::Trajectory tr = run(m, x0, T, names);
  EXPECT_TRUE(tr.ok()) << tr.message;
  if (!tr.ok()) return 0;
  for (const auto& l : tr.sensitivity_losses)  // one that ends a column
    if (!l.columns.empty())
      ADD_FAILURE() << "t = " << l.t << " '" << l.contact << "': " << l.reason;
  for (size_t c = 0; c < ps.size(); ++c) EXPECT_TRUE(tr.dx_final_exists[c]) << ps[c].column;
  return test_support::expect_columns_match_fd(m, x0, T, tr, cols);
}

// A sine's parameters, by name.
std::vector<Param> sine_params(const mech::Input& in, int input, bool delay) {
  std::vector<Param> ps = {
      {"amplitude[" + in.name + "]", in.amplitude,
       [](mech::Input& i, double d) { i.amplitude += d; }, input},
      {"offset[" + in.name + "]", in.offset, [](mech::Input& i, double d) { i.offset += d; },
       input},
      {"frequency[" + in.name + "]", in.frequency,
       [](mech::Input& i, double d) { i.frequency += d; }, input},
      {"damping[" + in.name + "]", in.damping, [](mech::Input& i, double d) { i.damping += d; },
       input},
      {"phase[" + in.name + "]", in.phase, [](mech::Input& i, double d) { i.phase += d; }, input}};
  if (delay)
    ps.push_back({"delay[" + in.name + "]", in.origin,
                  [](mech::Input& i, double d) { i.origin += d; }, input});
  return ps;
}

// The shaker table (robots/shaker_table.yaml): a ball dropped from rest at
// h = 0.3 m onto a table at z = A sin(2 pi f t + phi) + o (A = 0.05 m,
// f = 5 Hz, phi = o = 0). Its first impact is the first root of
// gap(t) = h - g t^2 / 2 - z(t), so by the implicit function theorem
// dt1/dtheta = -(d gap/d theta) / (d gap/d t):
//   d gap/dt = -g t - 2 pi f A cos(a), a = 2 pi f t + phi,
//   d gap/df = -2 pi t A cos(a), d gap/dA = -sin(a), d gap/dphi = -A cos(a),
//   d gap/do = -1.
// The run's t1 is the root to 1e-12 s (tests/sim/test_inputs.cpp), and the
// formula's rounding is ~1e-15 s per unit of the parameter: compared to
// 1e-9 relative (the root's error times d(dt1/dtheta)/dt, O(10) here).
// Then every sine parameter of the moving stop against central differences
// through three impacts (T = 1.5 s; the stop's rate enters each impact:
// dv+/dtheta = (1 + e) d(gdot)/dtheta, and the table's gap monitors move
// with the amplitude).
TEST(SensitivityInputs, ShakerTableImpactTimeClosedForm) {
  const mech::Model m = load("robots/shaker_table.yaml");
  const std::vector<Param> ps = sine_params(m.mechanical->inputs[0], 0, false);
  std::vector<std::string> names;
  for (const Param& p : ps) names.push_back(p.column);
  const sim::Trajectory tr = run(m, m.initial, 0.3, names);
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  const sim::Event& e = tr.events[0];
  const double t = e.t, g = 9.81, A = 0.05, f = 5.0, a = 2 * kPi * f * t;
  EXPECT_NEAR(t, 0.2300234805629, 1e-12);
  const double dgdt = -g * t - 2 * kPi * f * A * std::cos(a);
  // d gap/d theta for amplitude, offset, frequency, damping (the factor
  // e^(-d t) has d/dd = -t at d = 0), phase.
  const double dgap[] = {-std::sin(a), -1.0, -2 * kPi * t * A * std::cos(a), A * t * std::sin(a),
                         -A * std::cos(a)};
  for (size_t c = 0; c < ps.size(); ++c) {
    ASSERT_TRUE(e.dt_exists[c]);
    const double want = -dgap[c] / dgdt;
    EXPECT_NEAR(e.dt(static_cast<Eigen::Index>(c)), want, 1e-9 * std::max(1.0, std::abs(want)))
        << ps[c].column;
  }
  const sim::Trajectory plain = run(m, m.initial, 1.5);
  ASSERT_EQ(plain.events.size(), 3u);
  EXPECT_EQ(expect_matches_fd(m, m.initial, 1.5, ps), 5 * (2 + 3));
}

// A PWL force on a free 1 kg mass from rest: u(t) through the points (0, 0),
// (1, 2), (2, 2), (2, -1) (a rise, a hold, a jump to -1 held after), to
// T = 3 s. x(T) = int_0^T (T - s) u(s) ds and v(T) = int_0^T u(s) ds are
// linear in the values: each pwl_v column is the integral of its hat
// function (v: 1/2, 1, 1/2, 1; x: 4/3, 2, 2/3, 1/2). In the times, by
// Leibniz's rule on the pieces: point 0 (the rise from (t0, 0) to (1, 2)):
// x = (T - t0) L - 2 L^2 / 3 + ..., L = 1 - t0: dx/dt0 = -L - (T - t0) +
// 4 L / 3 = -8/3, dv/dt0 = -1; point 1 (the rise's end): x = T t1 -
// 2 t1^2 / 3 + 2 int_t1^2 (T - s) ds: dx/dt1 = T - 4 t1 / 3 - 2 (T - t1) =
// -7/3, dv/dt1 = 1 - 2 = -1; the jump (points 2 and 3, one time): it moves
// the step of 2 - (-1) = 3 N, dx/dt = (T - 2) 3 = 3, dv/dt = 3. The
// breakpoints at 1 s and 2 s move with their point's time (dt_b = 1), with
// no other. Exact to rounding: 1e-12 (the run's states are ~1e-15 exact,
// the phases' Taylor sums to eps/4).
TEST(SensitivityInputs, PwlForceOnFreeMassClosedForm) {
  const mech::Model m =
      from_text("pwl_mass",
                "name: pwl_mass\ninputs:\n"
                "  - {name: push, kind: pwl, points: [[0, 0], [1, 2], [2, 2], [2, -1]]}\n"
                "mechanical:\n  M: [[1]]\n  E: [[1]]\n  g: [100]\n  constraints: [far]\n"
                "  force_inputs: [{input: push, gain: [1]}]\ninitial: [0, 0]\nt_end: 3\n");
  const std::vector<std::string> cols = {"pwl_v[push][0]", "pwl_v[push][1]", "pwl_v[push][2]",
                                         "pwl_v[push][3]", "pwl_t[push][0]", "pwl_t[push][1]",
                                         "pwl_t[push][2]", "pwl_t[push][3]"};
  const sim::Trajectory tr = run(m, m.initial, 3.0, cols);
  ASSERT_TRUE(tr.ok()) << tr.message;
  EXPECT_TRUE(tr.sensitivity_losses.empty());
  const double dx[] = {4.0 / 3, 2.0, 2.0 / 3, 0.5, -8.0 / 3, -7.0 / 3, 3.0, 3.0};
  const double dv[] = {0.5, 1.0, 0.5, 1.0, -1.0, -1.0, 3.0, 3.0};
  for (size_t c = 0; c < cols.size(); ++c) {
    ASSERT_TRUE(tr.dx_final_exists[c]) << cols[c];
    const auto col = static_cast<Eigen::Index>(c);
    EXPECT_NEAR(tr.dx_final(0, col), dx[c], 1e-12) << cols[c];
    EXPECT_NEAR(tr.dx_final(1, col), dv[c], 1e-12) << cols[c];
  }
  ASSERT_EQ(tr.events.size(), 2u);  // the breakpoints at 1 s and 2 s
  for (size_t k = 0; k < 2; ++k)
    for (size_t c = 0; c < cols.size(); ++c) {
      const bool moves = (k == 0 && c == 5) || (k == 1 && (c == 6 || c == 7));
      EXPECT_EQ(tr.events[k].dt(static_cast<Eigen::Index>(c)), moves ? 1.0 : 0.0)
          << "event " << k << " d/d" << cols[c];
    }
  // The same against central differences (2 + 2 entries per column).
  std::vector<Param> ps;
  for (int k = 0; k < 4; ++k) {
    ps.push_back({cols[static_cast<size_t>(k)], 1.0,
                  [k](mech::Input& in, double d) { in.values[static_cast<size_t>(k)] += d; }});
  }
  ps.push_back({"pwl_t[push][1]", 1.0, [](mech::Input& in, double d) { in.times[1] += d; }});
  ps.push_back({"pwl_t[push][2]", 2.0, [](mech::Input& in, double d) {
                  in.times[2] += d;
                  in.times[3] += d;
                }});
  EXPECT_EQ(expect_matches_fd(m, m.initial, 3.0, ps), 6 * 4);
}

// The block lifted by a PWL force (robots/pwl_lift.yaml) from a raised
// start (0.5 m, 2 m/s) to T = 2.45 s: in flight through both breakpoints
// (1 s, 1.5 s: the jump to zero), then two impacts on the floor. Each
// point's value and time (the jump's two points as one) against central
// differences (the delay is 0 here, a boundary: tested on the pulse); then
// from the
// file's start (on the floor), the release under the ramp (a multiplier
// monitor, whose dF_I is zero: the input is a state, so its value moves
// the release through S's rows of w).
TEST(SensitivityInputs, PwlLiftPointsAgainstFiniteDifferences) {
  const mech::Model m = load("robots/pwl_lift.yaml");
  VectorXd x0(2);
  x0 << 0.5, 2.0;
  std::vector<Param> ps;
  for (int k = 0; k < 4; ++k)
    ps.push_back({"pwl_v[lift][" + std::to_string(k) + "]", 30.0,
                  [k](mech::Input& in, double d) { in.values[static_cast<size_t>(k)] += d; }});
  ps.push_back({"pwl_t[lift][1]", 1.0, [](mech::Input& in, double d) { in.times[1] += d; }});
  ps.push_back({"pwl_t[lift][2]", 1.5, [](mech::Input& in, double d) {
                  in.times[2] += d;
                  in.times[3] += d;
                }});
  const sim::Trajectory plain = run(m, x0, 2.45);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 4u);
  EXPECT_EQ(expect_matches_fd(m, x0, 2.45, ps), 6 * (2 + 4));
  // From the floor: the release at 0.654 s, both breakpoints, an impact.
  const sim::Trajectory floor = run(m, m.initial, 2.5);
  ASSERT_EQ(floor.events.size(), 4u);
  EXPECT_EQ(expect_matches_fd(m, m.initial, 2.5, ps), 6 * (2 + 4));
}

// A unit mass on a unit spring pushed into a plastic stop q >= -0.5 by
// f = -0.8 and pulled by a damped sine force (amplitude 2, 0.3 Hz, damping
// 0.1 1/s, phase 0.4, offset 0.1, delay 0.5 s): the delay's breakpoint,
// impact, release under the sine (a multiplier monitor: dF_I in the
// exosystem's columns), impact, release, to T = 8 s. Every sine parameter
// against central differences: 6 x (2 + 5) entries.
TEST(SensitivityInputs, DampedSineForceAgainstFiniteDifferences) {
  const mech::Model m =
      from_text("pushed",
                "name: pushed\ninputs:\n"
                "  - {name: push, kind: damped_sine, amplitude: 2, frequency: 0.3, damping: 0.1,"
                " phase: 0.4, offset: 0.1, delay: 0.5}\n"
                "mechanical:\n  M: [[1]]\n  K: [[1]]\n  f: [-0.8]\n  E: [[1]]\n"
                "  g: [0.5]\n  restitution: [0]\n  constraints: [stop]\n"
                "  coordinates: [x]\n  force_inputs: [{input: push, gain: [1]}]\n"
                "initial: [0, 0]\nt_end: 8\n");
  const sim::Trajectory plain = run(m, m.initial, 8.0);
  ASSERT_TRUE(plain.ok()) << plain.message;
  const int events = static_cast<int>(plain.events.size());
  ASSERT_EQ(events, 5);  // 0.5 s, 3.202, 3.694, 6.698, 7.057
  EXPECT_EQ(expect_matches_fd(m, m.initial, 8.0, sine_params(m.mechanical->inputs[0], 0, true)),
            6 * (2 + events));
}

// A periodic pulse force (v1 = -2, v2 = 3, rise 0.1, width 0.3, fall 0.2,
// period 1, delay 0.25) on a unit mass on a spring (K = 4) above a stop
// (q >= -0.1, e = 0.5), from rest, to T = 2.2 s: its eight edges are
// scheduled events, and the mass pulled by v1 hits the stop at 0.328 s
// (9 events); each pulse parameter against central differences at x(T)
// and every event time (width, rise and fall move the points after them;
// the period moves the second repetition's points): 7 x (2 + 9) entries.
TEST(SensitivityInputs, PulseForceAgainstFiniteDifferences) {
  const mech::Model m = from_text(
      "pulsed",
      "name: pulsed\ninputs:\n"
      "  - {name: p, kind: pulse, v1: -2, v2: 3, rise: 0.1, width: 0.3, fall: 0.2,"
      " period: 1, delay: 0.25}\n"
      "mechanical:\n  M: [[1]]\n  K: [[4]]\n  E: [[1]]\n  g: [0.1]\n  restitution: [0.5]\n"
      "  constraints: [stop]\n  force_inputs: [{input: p, gain: [1]}]\n"
      "initial: [0, 0]\nt_end: 2.2\n");
  const sim::Trajectory plain = run(m, m.initial, 2.2);
  ASSERT_TRUE(plain.ok()) << plain.message;
  const int events = static_cast<int>(plain.events.size());
  EXPECT_EQ(events, 9);
  const std::vector<Param> ps = {
      {"v1[p]", 1.0, [](mech::Input& in, double d) { in.values[0] += d, in.values[3] += d; }},
      {"v2[p]", 3.0, [](mech::Input& in, double d) { in.values[1] += d, in.values[2] += d; }},
      {"rise[p]", 0.1,
       [](mech::Input& in, double d) { in.times[1] += d, in.times[2] += d, in.times[3] += d; }},
      {"width[p]", 0.3, [](mech::Input& in, double d) { in.times[2] += d, in.times[3] += d; }},
      {"fall[p]", 0.2, [](mech::Input& in, double d) { in.times[3] += d; }},
      {"period[p]", 1.0, [](mech::Input& in, double d) { in.period += d; }},
      {"delay[p]", 0.25, [](mech::Input& in, double d) { in.origin += d; }}};
  EXPECT_EQ(expect_matches_fd(m, m.initial, 2.2, ps), 7 * (2 + events));
}

// A step force's time (time[s], one point pair moving as one: the jump)
// against the closed form on a free unit mass: u = 2 N from t_s = 0.5 s,
// x(T) = (T - t_s)^2, v(T) = 2 (T - t_s), so dx/dt_s = -2 (T - t_s),
// dv/dt_s = -2, and the breakpoint's dt/dt_s = 1.
TEST(SensitivityInputs, StepTimeClosedForm) {
  const mech::Model m =
      from_text("stepped",
                "name: stepped\ninputs:\n  - {name: s, kind: step, time: 0.5, final: 2}\n"
                "mechanical:\n  M: [[1]]\n  E: [[1]]\n  g: [100]\n"
                "  force_inputs: [{input: s, gain: [1]}]\ninitial: [0, 0]\nt_end: 2\n");
  const sim::Trajectory tr = run(m, m.initial, 2.0, {"time[s]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_NEAR(tr.dx_final(0, 0), -2 * 1.5, 1e-12);
  EXPECT_NEAR(tr.dx_final(1, 0), -2.0, 1e-12);
  EXPECT_EQ(tr.events[0].dt(0), 1.0);
}

// The refusals: a name that does not fit the input's kind, a point out of
// range, a time whose points would cross (a pulse of zero rise), a periodic
// input's point at the period's start; and the losses: two inputs' coinciding
// breakpoints, one moving.
TEST(SensitivityInputs, RefusalsAndLosses) {
  const mech::Model m = from_text(
      "two",
      "name: two\ninputs:\n  - {name: s, kind: sine, amplitude: 1, frequency: 1}\n"
      "  - {name: w, kind: pwl, points: [[0, 0], [1, 1], [1, 2]]}\n"
      "  - {name: p, kind: pulse, v1: 0, v2: 1, width: 0.2, period: 1}\n"
      "  - {name: k, kind: step, time: 1, final: 1}\n"
      "mechanical:\n  M: [[1]]\n  E: [[1]]\n  g: [100]\n"
      "  force_inputs: [{input: s, gain: [1]}, {input: w, gain: [1]}, {input: p, gain: [1]},"
      " {input: k, gain: [1]}]\ninitial: [0, 0]\nt_end: 2\n");
  for (const char* bad : {"frequency[w]", "pwl_v[s][0]", "pwl_v[w][3]", "width[w]", "rise[p]",
                          "pwl_t[p][0]", "time[w]", "v1[nope]", "pwl_t[w]"}) {
    sim::Options o;
    o.t_end = 0.5;
    o.sensitivity = {bad};
    const sim::Trajectory tr = sim::simulate(m, m.initial, o, "event");
    EXPECT_EQ(tr.status, Status::kInvalidInput) << bad;
    EXPECT_NE(tr.message.find(bad), std::string::npos) << tr.message;
  }
  // w's jump at 1 s coincides with k's step: moving w's time alone parts
  // them (one-sided), moving its value does not.
  const sim::Trajectory tr = run(m, m.initial, 2.0, {"pwl_t[w][1]", "pwl_v[w][2]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  EXPECT_EQ(tr.sensitivity_losses[0].t, 1.0);
  EXPECT_NE(tr.sensitivity_losses[0].reason.find("coinciding breakpoints"), std::string::npos);
  EXPECT_FALSE(tr.dx_final_exists[0]);
  EXPECT_TRUE(tr.dx_final_exists[1]);
  // d x(2)/d v_2 = int_1^2 (2 - s) ds = 1/2 (the value after the last point).
  EXPECT_NEAR(tr.dx_final(0, 1), 0.5, 1e-12);
}

}  // namespace
}  // namespace lcsim
