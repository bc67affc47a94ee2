// Forward sensitivities of the exact method through the events added by
// issue 28's second round (docs/sensitivities.md): scheduled events of a
// model's inputs (robots/pwl_lift.yaml, robots/shaker_table.yaml) and a
// general LCS's mode changes without a jump (circuits/*.cir).
//
// Every derivative is compared with central differences of the exact method
// itself, at the end state and at every event time: D(h) = (x(T; theta + h)
// - x(T; theta - h)) / 2h with the step h = 1e-4 max(1, |theta|) per entry
// (1e-4 of the entry's scale: the truncation c h^2 is then ~1e-8 relative,
// far above the run's rounding). The tolerance is tests/sim/
// test_sensitivity.cpp's: 4 |D(h) - D(h/2)| (Richardson's estimate of
// D(h/2)'s truncation with a margin of 12) plus 64e-13 max(1, |x|) / h (the
// run's rounding, ~1e-13 of the state, over the step, with a margin of 32).
// Every perturbed run must have the run's events (else the difference would
// straddle one).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

#include "support/coupled_bar.hpp"
#include "support/sensitivity_fd.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

mech::Model load(const std::string& path) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/" + path);
}

sim::Trajectory run(const mech::Model& m, const VectorXd& x0, double T,
                    std::vector<std::string> sens = {}) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, x0, opt, "event");
}

using Perturbation = test_support::FdColumn;

Perturbation force(int i, double f) {
  return {"f[" + std::to_string(i) + "]", f,
          [i](mech::Model& m, VectorXd&, double d) { m.mechanical->f(i) += d; }};
}
Perturbation gap(int c, const std::string& name, double g) {
  return {"g[" + name + "]", g,
          [c](mech::Model& m, VectorXd&, double d) { m.mechanical->g(c) += d; }};
}

// Compares every column (x0 entries when `x0`, then `ps`) against central
// differences at T (tests/support/sensitivity_fd.hpp); returns the number of
// entries compared.
int expect_matches_fd(const mech::Model& m, const VectorXd& x0, double T,
                      const std::vector<Perturbation>& ps, bool x0_columns,
                      const std::string& absent = "") {
  std::vector<Perturbation> all;
  if (x0_columns)
    for (int i = 0; i < x0.size(); ++i)
      all.push_back({"x0[" + std::to_string(i) + "]", x0(i),
                     [i](mech::Model&, VectorXd& x, double d) { x(i) += d; }});
  all.insert(all.end(), ps.begin(), ps.end());
  std::vector<std::string> names;
  if (x0_columns) names.push_back("x0");
  for (const auto& p : ps) names.push_back(p.column);
  const sim::Trajectory tr = run(m, x0, T, names);
  EXPECT_TRUE(tr.ok()) << tr.message;
  if (!tr.ok()) return 0;
  // A loss only where `absent` says (the run's words), and none otherwise.
  for (const auto& l : tr.sensitivity_losses)
    if (absent.empty() || l.reason.find(absent) == std::string::npos)
      ADD_FAILURE() << "t = " << l.t << " '" << l.contact << "': " << l.reason;
  return test_support::expect_columns_match_fd(m, x0, T, tr, all);
}

int count_type(const sim::Trajectory& tr, sim::EventType type) {
  int k = 0;
  for (const auto& e : tr.events) k += e.type == type;
  return k;
}

// The block lifted by a ramp (robots/pwl_lift.yaml). From the file's start
// (on the floor) to T = 2.5 s: the release at 0.654 s (the floor's force
// reaching zero under the ramp: dt/df[0] = -1/30 s/N), the scheduled events
// at 1 s (the ramp's end) and 1.5 s (the force's jump to zero), the fall and
// the first impact at 2.466 s; x0 is absent there (a zero gap at the start:
// one-sided derivatives only) while f[0] is compared. From a raised start
// (0.5 m, 2 m/s up) to T = 2.45 s: the block stays in flight through both
// scheduled events and hits the floor twice (2.150 s, 2.401 s) before its
// bounces accumulate (2.508 s, where the derivative is not computed).
TEST(SensitivityEvents, PwlLiftThroughScheduledEvents) {
  const mech::Model m = load("robots/pwl_lift.yaml");
  const sim::Trajectory plain = run(m, m.initial, 2.5);
  ASSERT_TRUE(plain.ok()) << plain.message;
  EXPECT_EQ(count_type(plain, sim::EventType::kSchedule), 2);
  EXPECT_EQ(count_type(plain, sim::EventType::kRelease), 1);
  EXPECT_EQ(count_type(plain, sim::EventType::kImpact), 1);
  // x(T) (2 entries) and 4 event times for f[0] (g[floor] is absent with x0).
  EXPECT_EQ(expect_matches_fd(m, m.initial, 2.5, {force(0, -19.62), gap(0, "floor", 0.0)}, true,
                              "zero gap at the start"),
            6);
  VectorXd x0(2);
  x0 << 0.5, 2.0;
  const sim::Trajectory raised = run(m, x0, 2.45);
  ASSERT_TRUE(raised.ok()) << raised.message;
  EXPECT_EQ(count_type(raised, sim::EventType::kSchedule), 2);
  EXPECT_EQ(count_type(raised, sim::EventType::kImpact), 2);
  // 4 columns, each x(T) and 4 event times.
  EXPECT_EQ(expect_matches_fd(m, x0, 2.45, {force(0, -19.62), gap(0, "floor", 0.0)}, true), 24);
}

// The ball on the shaker table (robots/shaker_table.yaml): impacts on a
// moving stop (the law on the velocity relative to the table, so the
// post-impact velocity depends on the table's state: the saltation's
// J_vw x'- term), to T = 1.5 s: three impacts (0.230, 0.772, 1.365 s).
TEST(SensitivityEvents, ShakerTableThroughMovingStopImpacts) {
  const mech::Model m = load("robots/shaker_table.yaml");
  const double T = 1.5;
  const sim::Trajectory plain = run(m, m.initial, T);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(count_type(plain, sim::EventType::kImpact), 3);
  const int n = expect_matches_fd(m, m.initial, T, {force(0, -9.81), gap(0, "table", 0.0)}, true);
  EXPECT_EQ(n, 4 * (2 + static_cast<int>(plain.events.size())));
  std::cout << "shaker table: " << plain.events.size() << " events, " << n << " entries\n";
}

// The circuits: general LCSs whose diode events move no state (the
// feedthrough of a diode in series with a resistor, or the bridge's rows,
// leave x continuous), so the saltation is the vector fields' jump alone.
// The half-wave RLC (one diode) to T = 1 ms: 3 events; the diode bridge
// (four diodes switching at once at each zero of V(a)) to 1 ms: 3 events,
// each one event of four constraints whose monitors are the same function
// of x up to positive factors (docs/sensitivities.md); the half-wave
// rectifier to 30 ms and the diode clamp to 1.5 ms (sine sources: the
// exosystem's states are columns x0 too): 4 events each. The rectifier's
// own start is on its diode's switching surface (V(out) = V(in) = 0, no
// feedthrough: only one-sided derivatives, reported below), so it starts
// here with C1 at 1 V (blocking until the source reaches 1 V).
TEST(SensitivityEvents, CircuitsAgainstFiniteDifferences) {
  struct File {
    const char* name;
    double T, v0;  // v0: the first state's start (NaN: the file's)
  };
  const double file = std::nan("");
  for (const File& f : {File{"circuits/half_wave_rlc.cir", 1e-3, file},
                        File{"circuits/diode_bridge.cir", 1e-3, file},
                        File{"circuits/half_wave_rectifier.cir", 3e-2, 1.0},
                        File{"circuits/diode_clamp.cir", 1.5e-3, file}}) {
    const char* name = f.name;
    const mech::Model m = load(name);
    const double T = f.T;
    VectorXd x0 = m.initial;
    if (!std::isnan(f.v0)) x0(0) = f.v0;
    const sim::Trajectory plain = run(m, x0, T);
    ASSERT_TRUE(plain.ok()) << plain.message;
    const int n = static_cast<int>(x0.size());
    EXPECT_EQ(expect_matches_fd(m, x0, T, {}, true),
              n * (n + static_cast<int>(plain.events.size())))
        << name;
    std::cout << name << ": " << plain.events.size() << " events\n";
  }
}

// A circuit with a PULSE source (an `lcs:` model with inputs): a 1000 V/s
// ramp charging C1 (from 0.1 V) through R1 and D1 from 0.1 ms, the
// breakpoints at 1, 2 and 3 ms scheduled events, D1 releasing at 2.197 ms on
// the fall. The PULSE's exosystem (V1.p, V1.r) is re-set to a function of t
// at each breakpoint, so its rows of dx/dx0 are zero from the first one on;
// every column, the exosystem's initial state included (it moves the
// contact until the reset), against central differences.
TEST(SensitivityEvents, CircuitWithPulseSourceThroughScheduledEvents) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                  ("lcsim_pulse_" + std::to_string(::getpid()) + ".cir");
  std::ofstream(p) << "PULSE into an RC through a diode\nV1 in 0 PULSE(0 1 0 1m 1m 1m 4m)\n"
                      "R1 in a 1k\nD1 a out ideal\nC1 out 0 1u\n.model ideal D\n"
                      ".ic V(out)=0.1\n.tran 10u 3.5m uic\n";
  const mech::Model m = scene::load_model(p.string());
  std::filesystem::remove(p);
  const double T = 3.5e-3;
  const sim::Trajectory tr = run(m, m.initial, T, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  EXPECT_EQ(count_type(tr, sim::EventType::kSchedule), 3);
  const int n = static_cast<int>(m.initial.size());  // C1.v, 1, V1.p, V1.r
  ASSERT_EQ(n, 4);
  EXPECT_EQ(tr.dx_final.bottomRows(2).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(expect_matches_fd(m, m.initial, T, {}, true),
            n * (n + static_cast<int>(tr.events.size())));
}

// The closed form: with I(L1) = 0 at the start and no source, both circuits
// are homogeneous (x(t; s x0) = s x(t; x0) for s > 0: the LCS is linear and
// its complementarity a cone), so the state is proportional to the initial
// capacitor voltage V0 and the diode events do not move with it:
// dx(T)/dV0 = x(T) / V0 and dt_k/dV0 = 0 at every event (t1 =
// atan(wd/alpha)/wd, then every pi/w0 or pi/wd). Tolerance: 1e-12 of the
// state's size (the run and its derivative are each good to ~1e-13 of it,
// tests/circuit's closed forms; a margin of 10), and for the event times
// 1e-12 T / V0 (a time derivative of a size T / V0 would shift the events
// by T for a change of V0 of V0).
TEST(SensitivityEvents, CircuitsClosedFormInInitialVoltage) {
  for (const char* name : {"circuits/half_wave_rlc.cir", "circuits/diode_bridge.cir"}) {
    const mech::Model m = load(name);
    const double T = 5e-3, V0 = m.initial(0);
    ASSERT_EQ(V0, 10.0);
    ASSERT_EQ(m.initial(1), 0.0);
    const sim::Trajectory tr = run(m, m.initial, T, {"x0"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    EXPECT_TRUE(tr.sensitivity_losses.empty()) << name;
    ASSERT_GE(tr.events.size(), 15u) << name;
    const double xs = tr.final_state.head(2).cwiseAbs().maxCoeff();
    for (int i = 0; i < 2; ++i)
      EXPECT_NEAR(tr.dx_final(i, 0), tr.final_state(i) / V0, 1e-12 * xs / V0) << name << " " << i;
    double worst = 0.0;
    for (const sim::Event& e : tr.events) {
      ASSERT_TRUE(e.dt_exists[0]);
      worst = std::max(worst, std::abs(e.dt(0)));
      EXPECT_NEAR(e.dt(0), 0.0, 1e-12 * T / V0) << name << " event at " << e.t;
    }
    std::cout << name << ": dx/dV0 - x/V0 = "
              << (tr.dx_final.col(0).head(2) - tr.final_state.head(2) / V0).cwiseAbs().maxCoeff()
              << ", max |dt_k/dV0| = " << worst << " s/V over " << tr.events.size() << " events\n";
  }
}

// A general LCS started on a switching surface of a row without
// feedthrough (the rectifier's file start: V(out) = V(in) = 0): x0 is
// absent, the loss names the row; a start off it has no loss.
TEST(SensitivityEvents, LcsStartOnSwitchingSurfaceHasNoDerivative) {
  const mech::Model m = load("circuits/half_wave_rectifier.cir");
  const sim::Trajectory tr = run(m, m.initial, 1e-2, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  EXPECT_EQ(tr.sensitivity_losses[0].t, 0.0);
  EXPECT_EQ(tr.sensitivity_losses[0].contact, "D1");  // the pair's name (was "y0")
  EXPECT_NE(tr.sensitivity_losses[0].reason.find("switching surface"), std::string::npos);
  for (char e : tr.dx_final_exists) EXPECT_FALSE(e);
  EXPECT_EQ(tr.dx_final.cwiseAbs().maxCoeff(), 0.0);
  VectorXd x0 = m.initial;
  x0(0) = 1.0;
  EXPECT_TRUE(run(m, x0, 1e-2, {"x0"}).sensitivity_losses.empty());
}

// Planar friction (x0 only): the stick / slip events of the files, to their
// own horizons. Each starts on its floor (a zero gap: the entries that move
// the gap or its rate, y0 and vy0, are absent), and the mass on a spring
// starts to slip from rest (vx0, which moves its sliding velocity, is
// absent: one side of it reverses first); the other entries are compared,
// at x(T) and every event time. Block: one stick (slip -> stick at
// v0/(mu g)); spring: slip reversal at pi/2 and stick at pi; incline: one
// stick; belt: stick at 0.21 s, slip at 1.33 s (the stick force reaching the
// cone's edge, where the sliding velocity starts with zero acceleration).
TEST(SensitivityEvents, PlanarFrictionAgainstFiniteDifferences) {
  struct File {
    const char* name;
    int columns;  // entries of x0 with a derivative
  };
  for (const File& f :
       {File{"robots/block_on_floor_friction.yaml", 2}, File{"robots/mass_spring_friction.yaml", 1},
        File{"robots/incline_friction.yaml", 2}, File{"robots/belt_friction.yaml", 2}}) {
    const mech::Model m = load(f.name);
    const double T = m.t_end;
    const sim::Trajectory plain = run(m, m.initial, T);
    ASSERT_TRUE(plain.ok()) << plain.message;
    ASSERT_GE(plain.events.size(), 1u) << f.name;
    const int n = static_cast<int>(m.initial.size());
    EXPECT_EQ(expect_matches_fd(m, m.initial, T, {}, true, "at the start"),
              f.columns * (n + static_cast<int>(plain.events.size())))
        << f.name;
    std::cout << f.name << ": " << plain.events.size() << " events\n";
  }
}

// The block sliding to rest on the floor (robots/block_on_floor_friction.yaml:
// v0 = 2 m/s, mu = 0.4, g = 9.81): it stops at t* = v0/(mu g) after
// v0^2/(2 mu g), so dt*/dv0 = 1/(mu g), and at T = 1 > t*: dx/dx0 = 1,
// dx/dv0 = v0/(mu g), dv/d(x0, v0) = 0; before the stop (T = 0.3 s):
// x = x0 + v0 T - mu g T^2/2, dx/dv0 = T, dv/dv0 = 1. Tolerance 1e-13 of the
// entries' size 1 (the run is good to ~1e-15 here: one phase per
// exponential of a nilpotent matrix; margin 100).
TEST(SensitivityEvents, BlockSlidingToRestClosedForm) {
  const mech::Model m = load("robots/block_on_floor_friction.yaml");
  const double v0 = m.initial(2), mu = 0.4, g = 9.81;
  ASSERT_EQ(v0, 2.0);
  ASSERT_EQ(m.mechanical->friction[0].mu, mu);
  const sim::Trajectory tr = run(m, m.initial, 1.0, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_NEAR(tr.events[0].t, v0 / (mu * g), 1e-13);
  EXPECT_NEAR(tr.final_state(0), v0 * v0 / (2 * mu * g), 1e-13);
  ASSERT_TRUE(tr.events[0].dt_exists[2]);
  EXPECT_NEAR(tr.events[0].dt(2), 1 / (mu * g), 1e-13);
  EXPECT_NEAR(tr.events[0].dt(0), 0.0, 1e-13);
  EXPECT_NEAR(tr.dx_final(0, 0), 1.0, 1e-13);
  EXPECT_NEAR(tr.dx_final(0, 2), v0 / (mu * g), 1e-13);
  EXPECT_NEAR(tr.dx_final(2, 0), 0.0, 1e-13);
  EXPECT_NEAR(tr.dx_final(2, 2), 0.0, 1e-13);
  const double Ts = 0.3;
  const sim::Trajectory early = run(m, m.initial, Ts, {"x0"});
  ASSERT_TRUE(early.ok()) << early.message;
  EXPECT_NEAR(early.dx_final(0, 2), Ts, 1e-13);
  EXPECT_NEAR(early.dx_final(2, 2), 1.0, 1e-13);
  EXPECT_NEAR(early.dx_final(0, 0), 1.0, 1e-13);
}

// What stays refused with friction: backward Euler's restitution (its step
// map through stick / slip is test_sensitivity_stepping.cpp's; it ignores
// restitution), and a second tangent (here not orthogonal to the normal: the
// model check's refusal comes first) in either method (Moreau–Jean's step
// map is test_sensitivity_stepping.cpp's).
TEST(SensitivityEvents, FrictionRefusals) {
  const mech::Model m = load("robots/block_on_floor_friction.yaml");
  sim::Options opt;
  opt.t_end = 0.1;
  // (f[1], then M[0][0] were refused here; f, g, K, D, M, e and an input's
  // parameters are computed now: tests/sim/test_sensitivity_friction_params.cpp.)
  // (euler's x0, f, g, K, D, M and mu are computed now through stick / slip:
  // tests/sim/test_sensitivity_stepping.cpp.)
  opt.sensitivity = {"x0", "e[floor]"};
  sim::Trajectory tr = sim::simulate(m, m.initial, opt, "euler");
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_NE(tr.message.find("method 'euler' does not compute it (backward Euler ignores "
                            "restitution"),
            std::string::npos)
      << tr.message;
  // A point sliding on a floor with a 3-D cone: the exact method computes x0,
  // f, g, K, D, mu, M and e through it (tests/sim/test_sensitivity_cone.cpp;
  // M, e were refused by name here before the cone impact map took them).
  mech::MechanicalModel p;
  p.M = Eigen::MatrixXd::Identity(3, 3).sparseView();
  p.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  p.f = Eigen::Vector3d(0, 0, -9.81);
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), 0.3);
  c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
  p.friction.push_back(c);
  const mech::Model m3 = mech::model_of(p, "point3d");
  const VectorXd x0 = (VectorXd(6) << 0, 0, 0, 1, 0.5, 0).finished();
  for (const char* name : {"mu[0]", "M[0][0]", "e[0]"}) {
    opt.sensitivity = {"x0", name};
    tr = sim::simulate(m3, x0, opt, "event");
    EXPECT_TRUE(tr.ok()) << name << ": " << tr.message;
    EXPECT_EQ(tr.sensitivity_columns.size(), 7u) << name;
  }
}

// The schemes take force inputs (their derivative is tested in
// test_sensitivity_stepping.cpp) and refuse a moving stop, which only the
// exact method simulates, with or without sensitivities.
TEST(SensitivityEvents, SchemesTakeForceInputsAndRefuseMovingStops) {
  const mech::Model lift = load("robots/pwl_lift.yaml"), shaker = load("robots/shaker_table.yaml");
  sim::Options opt;
  opt.t_end = 0.1;
  opt.sensitivity = {"x0"};
  for (const char* method : {"euler", "moreau-jean"}) {
    const sim::Trajectory ok = sim::simulate(lift, lift.initial, opt, method);
    EXPECT_TRUE(ok.ok()) << method << ": " << ok.message;
    EXPECT_EQ(ok.sensitivity_columns.size(), 2u) << method;
    const sim::Trajectory tr = sim::simulate(shaker, shaker.initial, opt, method);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << method;
    EXPECT_NE(tr.message.find("method 'event'"), std::string::npos) << tr.message;
  }
}

// --- A general LCS's jumps and its own entries (docs/sensitivities.md) ---

// The entry (i, j) of A, B, C or D of a general LCS as a column.
Perturbation lcs_entry(char kind, int i, int j, const std::string& name, double value) {
  return {name, value, [kind, i, j](mech::Model& m, VectorXd&, double d) {
            lcs::Lcs& s = *m.lcs;
            (kind == 'A' ? s.A : kind == 'B' ? s.B : kind == 'C' ? s.C : s.D)(i, j) += d;
          }};
}

// A general LCS whose events jump: body 1 (q1, v1) on a spring, coupled to
// body 2 (q2, v2), pushed by a sine w1 = sin 2t (w1, w2, weight 0.3) and a
// constant w3 = 1 (weight 1), against two stops: q1 >= 0 and q2 + 0.1 w3
// >= 0 (y = C x, u the stops' forces: relative degree 2, D = 0). Reaching a
// stop is a jump x+ = P_I x that zeroes its body's velocity (for stop1
// T_I = span(B_1, A B_1) = span(e_v1, e_q1), V_I = {q1 = v1 = 0}), so the
// saltation is S+ = P S- + (P x'- - x'+) dt/dtheta + dP x-. From
// (0.3, 0, 0, 0, 0, 2, 1) to T = 6: stop1 at 0.664 (held from then on),
// stop2 at 4.287 (body 2 leaves it at once: its force would pull).
mech::Model jumping_lcs() {
  mech::Model m;
  m.name = "jumping_lcs";
  lcs::Lcs s;
  s.A = Eigen::MatrixXd::Zero(7, 7);
  s.A(0, 1) = 1;
  s.A(1, 0) = -2, s.A(1, 2) = 1, s.A(1, 4) = 0.3, s.A(1, 6) = -1;
  s.A(2, 3) = 1;
  s.A(3, 0) = 1, s.A(3, 2) = -1;
  s.A(4, 5) = 1;
  s.A(5, 4) = -4;
  s.B = Eigen::MatrixXd::Zero(7, 2);
  s.B(1, 0) = 1, s.B(3, 1) = 1;
  s.C = Eigen::MatrixXd::Zero(2, 7);
  s.C(0, 0) = 1;
  s.C(1, 2) = 1, s.C(1, 6) = 0.1;
  s.D = Eigen::MatrixXd::Zero(2, 2);
  m.lcs = s;
  m.pair_names = {"stop1", "stop2"};
  m.initial = VectorXd(7);
  m.initial << 0.3, 0, 0, 0, 0, 2, 1;
  m.t_end = 6;
  return m;
}

// Every x0 entry and five entries (the springs A[1][0], A[3][2], the
// constant load A[1][6] (an lcs: model's f: a column on a constant state),
// the stop's gain B[1][0] and stop2's offset C[stop2][6] (its g)) against
// central differences at x(T) and both event times: (7 + 5) columns x
// (7 + 2) entries. The jumps' x0 part is P_I (lcs::projection); their
// parameter part dP_I x- (sensitivity_lcs.cpp).
TEST(SensitivityEvents, LcsJumpsAgainstFiniteDifferences) {
  const mech::Model m = jumping_lcs();
  const double T = 6.0;
  const sim::Trajectory plain = run(m, m.initial, T);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 2u);
  EXPECT_EQ(count_type(plain, sim::EventType::kImpact), 2);
  EXPECT_EQ(plain.events[0].mode_after, (lcs::IndexSet{0}));
  EXPECT_EQ(plain.events[1].mode_after, (lcs::IndexSet{0}));
  const std::vector<Perturbation> ps = {
      lcs_entry('A', 1, 0, "A[1][0]", -2.0), lcs_entry('A', 3, 2, "A[3][2]", -1.0),
      lcs_entry('A', 1, 6, "A[1][6]", -1.0), lcs_entry('B', 1, 0, "B[1][stop1]", 1.0),
      lcs_entry('C', 1, 6, "C[stop2][6]", 0.1)};
  // The pair is C's row: C[6][stop2] names no pair 6 and is refused.
  sim::Options bad;
  bad.t_end = T;
  bad.sensitivity = {"C[6][stop2]"};
  const sim::Trajectory refused = sim::simulate(m, m.initial, bad, "event");
  EXPECT_EQ(refused.status, Status::kInvalidInput);
  EXPECT_NE(refused.message.find("no pair '6'"), std::string::npos) << refused.message;
  EXPECT_EQ(expect_matches_fd(m, m.initial, T, ps, true), 12 * 9);
}

// A release after a jump: the LCS above with the sine's weight 3 (A[1][4]):
// body 1 hits stop1 at 2.371 s (a jump; the event's root leaves q1 at
// -2.2e-16, which the jump keeps), is held, and is pulled off at 3.165 s
// (its force reaching zero), then hits again at 5.612 s. The free phase
// after the release starts with y0 = q1 = -2.2e-16, within mode selection's
// zero test, opening by its second derivative: the monitor follows it from
// the start as an opening at zero (monitors.cpp), where it used to see a
// spurious event 1.5e-6 s later (changing no mode: "grazing", every column
// lost). Now x0 and four entries against central differences at x(T) and
// the three event times: (7 + 4) columns x (7 + 3) entries, no loss.
TEST(SensitivityEvents, LcsReleaseAfterJumpAgainstFiniteDifferences) {
  mech::Model m = jumping_lcs();
  m.lcs->A(1, 4) = 3.0;
  const double T = 6.0;
  const sim::Trajectory plain = run(m, m.initial, T);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 3u);
  EXPECT_EQ(plain.events[0].type, sim::EventType::kImpact);
  EXPECT_EQ(plain.events[1].type, sim::EventType::kRelease);
  EXPECT_EQ(plain.events[2].type, sim::EventType::kImpact);
  EXPECT_NEAR(plain.events[1].t, 3.16465594546351, 1e-9);
  const std::vector<Perturbation> ps = {
      lcs_entry('A', 1, 0, "A[1][0]", -2.0), lcs_entry('A', 1, 4, "A[1][4]", 3.0),
      lcs_entry('A', 1, 6, "A[1][6]", -1.0), lcs_entry('C', 1, 6, "C[stop2][6]", 0.1)};
  EXPECT_EQ(expect_matches_fd(m, m.initial, T, ps, true), 11 * 10);
}

// An entry that changes a leading row index is a singular perturbation:
// B[0][0] makes C B nonzero (stop1's relative degree 2 -> 1), D[stop1][0]
// makes it 0. Each is reported absent, naming the pair, from the first phase
// in which the row is in the mode (the first impact) -- x0 and A[1][0] go
// on. A jump's parameter columns survive it (above), and the model's plain
// run is unchanged by the request.
TEST(SensitivityEvents, LcsEntryChangingLeadingIndexIsAbsent) {
  const mech::Model m = jumping_lcs();
  const sim::Trajectory tr = run(m, m.initial, 6.0, {"x0", "A[1][0]", "B[0][0]", "D[stop1][0]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  const sim::SensitivityLoss& l = tr.sensitivity_losses[0];
  EXPECT_EQ(l.contact, "stop1");
  EXPECT_NEAR(l.t, tr.events[0].t, 1e-15);
  EXPECT_NE(l.reason.find("leading row index"), std::string::npos) << l.reason;
  EXPECT_EQ(l.columns, (std::vector<int>{8, 9}));
  for (int c = 0; c < 8; ++c) EXPECT_TRUE(tr.dx_final_exists[static_cast<size_t>(c)]);
  EXPECT_FALSE(tr.dx_final_exists[8]);
  EXPECT_FALSE(tr.dx_final_exists[9]);
  EXPECT_EQ(tr.dx_final.rightCols(2).cwiseAbs().maxCoeff(), 0.0);
  const sim::Trajectory plain = run(m, m.initial, 6.0);
  EXPECT_EQ(plain.final_state, tr.final_state);
}

// A circuit's own entries (circuits/half_wave_rlc.cir, 3 states: C1.v,
// L1.i and the source's constant "1"; D1's row has the feedthrough R1 =
// 1 kOhm), by the states' and the pair's names or indices: A[C1.v][C1.v]
// (no load on the tank: 0), A[C1.v][L1.i] (-1/C1), A[L1.i][C1.v] (1/L1),
// B[0][D1] (the diode current into C1), C[D1][0] and D[D1][D1] (R1) against
// central differences to T = 1 ms (3 events): 6 columns x (3 + 3) entries.
TEST(SensitivityEvents, CircuitEntriesAgainstFiniteDifferences) {
  const mech::Model m = load("circuits/half_wave_rlc.cir");
  ASSERT_EQ(m.pair_names, std::vector<std::string>{"D1"});
  const lcs::Lcs& s = *m.lcs;
  const double T = 1e-3;
  const sim::Trajectory plain = run(m, m.initial, T);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 3u);
  const std::vector<Perturbation> ps = {lcs_entry('A', 0, 0, "A[C1.v][C1.v]", s.A(0, 0)),
                                        lcs_entry('A', 0, 1, "A[C1.v][L1.i]", s.A(0, 1)),
                                        lcs_entry('A', 1, 0, "A[L1.i][C1.v]", s.A(1, 0)),
                                        lcs_entry('B', 0, 0, "B[0][D1]", s.B(0, 0)),
                                        lcs_entry('C', 0, 0, "C[D1][0]", s.C(0, 0)),
                                        lcs_entry('D', 0, 0, "D[D1][D1]", s.D(0, 0))};
  EXPECT_EQ(expect_matches_fd(m, m.initial, T, ps, false), 6 * 6);
  // The source's constant state is named "1": a name is looked up before
  // an index, so A[1][0] is its row (refused: an input's own dynamics).
  sim::Options o;
  o.t_end = T;
  o.sensitivity = {"A[1][0]"};
  const sim::Trajectory refused = sim::simulate(m, m.initial, o, "event");
  EXPECT_EQ(refused.status, Status::kInvalidInput);
  EXPECT_NE(refused.message.find("exosystem"), std::string::npos) << refused.message;
}

// --- Impacts with planar friction (sensitivity_friction.cpp) ---

// The block of robots/block_on_floor_friction.yaml (unit mass, mu = 0.4,
// g = 9.81, plastic floor) dropped from y0 = 0.2 with vy0 = 0 lands at
// t1 = w/g, w = sqrt(2 g y0) (the approach rate), with the normal impulse w.
// Sticking (|vx0| <= mu w, vx0 = 0.5): at rest from t1, x(T) = x0 + vx0 t1,
// so dx/dy0 = vx0/w, dx/dvx0 = t1, dx/dvy0 = vx0/g, dx/dx0 = 1, every other
// entry 0; dt1/dy0 = 1/w, dt1/dvy0 = 1/g. Sliding (vx0 = 2 > mu w): vT+ =
// vx0 - mu w, then x(T) = x0 + vx0 t1 + vT+ s - mu g s^2/2 (s = T - t1)
// until the stick at t1 + vT+/(mu g) = 0.510: at T = 0.4, dx/dy0 = mu,
// dvx/dy0 = 0, dx/dvx0 = T, dvx/dvx0 = 1, dx/dvy0 = mu T, dvx/dvy0 = mu.
// Tolerance 1e-12: the run and its derivative are good to a few ulp here
// (two phases of nilpotent exponentials, one linear solve); margin ~1000.
TEST(SensitivityEvents, FrictionImpactBlockClosedForm) {
  const mech::Model m = load("robots/block_on_floor_friction.yaml");
  const double mu = 0.4, g = 9.81, y0 = 0.2, w = std::sqrt(2 * g * y0), t1 = w / g;
  ASSERT_EQ(m.mechanical->friction[0].mu, mu);
  struct Case {
    double vx0, T;
    Eigen::Matrix4d dx;  // rows x, y, vx, vy; columns x0, y0, vx0, vy0
  };
  Eigen::Matrix4d stick = Eigen::Matrix4d::Zero(), slip = Eigen::Matrix4d::Zero();
  stick.row(0) << 1, 0.5 / w, t1, 0.5 / g;
  slip.row(0) << 1, mu, 0.4, mu * 0.4;
  slip.row(2) << 0, 0, 1, mu;
  for (const Case& c : {Case{0.5, 0.5, stick}, Case{2.0, 0.4, slip}}) {
    VectorXd x0(4);
    x0 << 0, y0, c.vx0, 0;
    const sim::Trajectory tr = run(m, x0, c.T, {"x0"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    EXPECT_TRUE(tr.sensitivity_losses.empty());
    ASSERT_EQ(tr.events.size(), 1u);
    const sim::Event& e = tr.events[0];
    EXPECT_EQ(e.type, sim::EventType::kImpact);
    ASSERT_EQ(e.friction_mode_after.size(), 1u);
    EXPECT_EQ(e.friction_mode_after[0],
              c.vx0 < mu * w ? sim::FrictionMode::kStick : sim::FrictionMode::kSlipPositive);
    EXPECT_NEAR(e.t, t1, 1e-14);
    EXPECT_NEAR(e.dt(1), 1 / w, 1e-12);
    EXPECT_NEAR(e.dt(2), 0.0, 1e-12);
    EXPECT_NEAR(e.dt(3), 1 / g, 1e-12);
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j)
        EXPECT_NEAR(tr.dx_final(i, j), c.dx(i, j), 1e-12)
            << "vx0 = " << c.vx0 << ": dx[" << i << "]/dx0[" << j << "]";
  }
}

// On the boundary between the two (vx0 = mu w: the impact leaves the block
// stuck with |P_T| = mu P_N, or sliding at zero velocity, as rounding
// decides) the impact map has a kink: no derivative, reported at t1 naming
// the floor, every column absent.
TEST(SensitivityEvents, FrictionImpactAtStickSlipBoundaryHasNoDerivative) {
  const mech::Model m = load("robots/block_on_floor_friction.yaml");
  const double mu = 0.4, g = 9.81, y0 = 0.2, w = std::sqrt(2 * g * y0);
  VectorXd x0(4);
  x0 << 0, y0, mu * w, 0;
  const sim::Trajectory tr = run(m, x0, 0.5, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  const sim::SensitivityLoss& l = tr.sensitivity_losses[0];
  EXPECT_EQ(l.contact, "floor");
  EXPECT_NEAR(l.t, w / g, 1e-14);
  EXPECT_NE(l.reason.find("stick and slip meet"), std::string::npos) << l.reason;
  for (char e : tr.dx_final_exists) EXPECT_FALSE(e);
  EXPECT_EQ(tr.dx_final.cwiseAbs().maxCoeff(), 0.0);
}

// A planar bar (x, y, theta; M = diag(1, 1, 0.1), gravity) landing on its
// corner, gap y - 0.5 theta, tangential velocity x' + 0.2 y' + 0.4 theta'
// (orthogonal to the normal row): the Delassus matrix couples normal and
// tangent (W_NT = 0.2 - 2 = -1.8; W_NN - mu |W_NT| > 0), so the impact
// turns the bar and its stick or slip outcome depends on every entry of
// x0. From (0, 0.3, 0, 1, 0, omega0) with mu = 1.5 (sticks) and mu = 0.2
// (slides), plastic, and with mu = 0.2 and e = 0.5 (a bounce, restitution
// on the approaching normal only: impacts at 0.228 and 0.476 s, the third
// at 0.59998 too close to 0.6 for differences), to T = 0.6 s (0.55 s with
// e): every entry of x0 against central differences at x(T) and every
// event time (6 x (6 + events)).
TEST(SensitivityEvents, FrictionImpactBarAgainstFiniteDifferences) {
  struct Case {
    double mu, e, T;
  };
  for (const auto& [mu, e, T] : {Case{1.5, 0.0, 0.6}, Case{0.2, 0.0, 0.6}, Case{0.2, 0.5, 0.55}}) {
    mech::Model m = test_support::coupled_bar(mu, e);
    m.t_end = T;
    const sim::Trajectory plain = run(m, m.initial, m.t_end);
    ASSERT_TRUE(plain.ok()) << plain.message;
    ASSERT_GE(plain.events.size(), 1u);
    EXPECT_EQ(plain.events[0].type, sim::EventType::kImpact);
    const int n = expect_matches_fd(m, m.initial, m.t_end, {}, true);
    EXPECT_EQ(n, 6 * (6 + static_cast<int>(plain.events.size()))) << "mu = " << mu;
    std::cout << "bar, mu = " << mu << ", e = " << e << ": " << plain.events.size()
              << " events, after the first impact "
              << sim::to_string(plain.events[0].friction_mode_after[0]) << "\n";
  }
}

// An input's own parameter: a sine's amplitude (amplitude[push]), which
// enters the exosystem's output row only (value = offset + amplitude s), so
// the phases' dAcl and dF_I carry it as a column of H and no event's
// re-initialisation moves with it. A unit mass on a unit spring, pushed
// into a plastic stop q >= -0.5 by f = -0.8 and pulled by a damped sine
// (amplitude 2, 0.3 Hz, damping 0.1 1/s): impact at 2.841 s, release under
// the sine at 3.413 s (a multiplier monitor: dF_I), impact at 6.360 s,
// release at 6.747 s; to T = 8: x0, amplitude[push], f[0] against central
// differences at x(T) and each event time (4 x (2 + 4) entries). The
// amplitude of a non-sine is refused.
TEST(SensitivityEvents, SineAmplitudeAgainstFiniteDifferences) {
  const std::filesystem::path p = std::filesystem::temp_directory_path() /
                                  ("lcsim_pushed_" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(p) << "name: pushed\ninputs:\n"
                      "  - {name: push, kind: sine, amplitude: 2, frequency: 0.3, damping: 0.1}\n"
                      "  - {name: lift, kind: constant, value: 1}\n"
                      "mechanical:\n  M: [[1]]\n  K: [[1]]\n  f: [-0.8]\n  E: [[1]]\n"
                      "  g: [0.5]\n  restitution: [0]\n  constraints: [stop]\n"
                      "  coordinates: [x]\n  force_inputs: [{input: push, gain: [1]}]\n"
                      "initial: [0, 0]\nt_end: 8\n";
  const mech::Model m = scene::load_model(p.string());
  std::filesystem::remove(p);
  const sim::Trajectory plain = run(m, m.initial, 8.0);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 4u);
  const Perturbation amp{"amplitude[push]", 2.0, [](mech::Model& mm, VectorXd&, double d) {
                           mm.mechanical->inputs[0].amplitude += d;
                         }};
  EXPECT_EQ(expect_matches_fd(m, m.initial, 8.0, {amp, force(0, -0.8)}, true), 4 * 6);
  for (const char* bad : {"amplitude[lift]", "amplitude[nope]"}) {
    sim::Options o;
    o.t_end = 1.0;
    o.sensitivity = {bad};
    const sim::Trajectory tr = sim::simulate(m, m.initial, o, "event");
    EXPECT_EQ(tr.status, Status::kInvalidInput) << bad;
  }
  const mech::Model shaker = load("robots/shaker_table.yaml");
  sim::Options o;
  o.t_end = 0.1;
  o.sensitivity = {"amplitude[table]"};
  // On a moving stop the amplitude was refused; it is computed now (against
  // central differences in tests/sim/test_sensitivity_inputs.cpp).
  const sim::Trajectory tr = sim::simulate(shaker, shaker.initial, o, "event");
  EXPECT_TRUE(tr.ok()) << tr.message;
  EXPECT_TRUE(tr.dx_final_exists[0]);
}

// Every column lost at the start (the ball leaving the ground from a zero
// gap: x0 and g[ground] have one-sided derivatives only), then an impact:
// the run carries nothing and completes with every entry absent (a
// regression test: the phases' parameter terms must exist, empty, when no
// column does).
TEST(SensitivityEvents, EveryColumnLostAtTheStartThenAnImpact) {
  const mech::Model m = load("robots/ball.yaml");
  VectorXd x0(2);
  x0 << 0.0, 2.0;
  const sim::Trajectory tr = run(m, x0, 1.0, {"x0", "g[ground]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  for (char e : tr.dx_final_exists) EXPECT_FALSE(e);
  EXPECT_EQ(tr.dx_final.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_EQ(run(m, x0, 1.0).final_state, tr.final_state);
}

}  // namespace
}  // namespace lcsim
