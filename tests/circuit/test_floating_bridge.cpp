// Ideal bridges whose four diodes all block (issue 29): the load floats, D1's
// reverse voltage (its pair's u, voltage form) is not unique, the state is.
// Each run is checked against closed forms derived here, piece by piece, with
// the switching times found independently (a scan and a bisection).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "support/bisect.hpp"

namespace lcsim {
namespace {

using circuit::Circuit;
using std::numbers::pi;

// Tolerances (as tests/circuit/test_closed_forms.cpp argues them): an event
// time is a root of a Bohl function located to a few ulp of t; the states
// each phase starts from carry ~1e-15 relative rounding per phase, which
// moves a crossing slewing at >= 10 V/s (the slowest here, the rectifier's
// release) by < 1e-15 * 10 V / 10 V/s = 1e-15 s: 1e-12 s keeps three orders
// of margin. Voltages: 1e-9 V on 10 V is 1e-10 relative, five orders above
// the rounding of a few dozen matrix exponentials and far below any
// modelling error (a missed event moves a voltage by volts).
constexpr double kEventTol = 1e-12;  // s
constexpr double kVoltTol = 1e-9;    // V

using test_support::bisect;
// The first sign change of f after a (f(a) > 0), scanned in steps of h
// (far below the half periods here), then bisected.
template <class F>
double first_root(F f, double a, double h) {
  double t = a + h;
  while (f(t) > 0) t += h;
  return bisect(f, t - h, t);
}

int column(const mech::Model& m, const std::string& name) {
  for (std::size_t i = 0; i < m.output_names.size(); ++i)
    if (m.output_names[i] == name) return static_cast<int>(i);
  ADD_FAILURE() << "no output " << name;
  return 0;
}
double output(const mech::Model& m, const sim::Sample& s, const std::string& name) {
  const int r = column(m, name);
  return m.output_x.row(r).dot(s.x) + m.output_u.row(r).dot(s.u);
}

std::vector<const sim::Event*> mode_events(const sim::Trajectory& tr) {
  std::vector<const sim::Event*> ev;
  for (const sim::Event& e : tr.events)
    if (e.type != sim::EventType::kStart) ev.push_back(&e);
  return ev;
}

// /tmp/br/blk.cir of the issue: the bridge's tank (C1, L1) at 5 V, its load
// (R1 || C2) at 10 V, so every diode blocks at t = 0.
const char* kBlocking = R"(Bridge all blocking from the start
C1 a 0 1u IC=5
L1 a 0 10m
D1 a p ideal
D2 0 p ideal
D3 m a ideal
D4 m 0 ideal
R1 p m 1k
C2 p m 1u IC=10
.model ideal D
.tran 1u 5m uic
.end
)";

constexpr double kC = 1e-6, kL = 10e-3, kR = 1e3;  // F, H, ohm (C1 = C2 = kC)

// Tank and load, by hand. State (v, i, w): V(a), L1's current (a to ground),
// the load's voltage V(p) - V(m).
struct Tank {
  double v, i, w;
};
// All four diodes blocking from s at t0: the tank rings undamped, the load
// decays through R1: v = v0 cos - i0 sqrt(L/C) sin, i = i0 cos + v0
// sqrt(C/L) sin (C v' = -i, L i' = v), w = w0 e^{-(t-t0)/(R C)}.
Tank blocking(const Tank& s, double t) {
  const double w0 = 1.0 / std::sqrt(kL * kC), z = std::sqrt(kL / kC);
  const double c = std::cos(w0 * t), sn = std::sin(w0 * t);
  return {s.v * c - s.i * z * sn, s.i * c + s.v / z * sn, s.w * std::exp(-t / (kR * kC))};
}
// Two diodes conducting (D2, D3 when v < 0; D1, D4 when v > 0): the load's
// capacitor is across the tank (w = |v|), a parallel RLC of 2C:
// 2C v' = -i - v/R, L i' = v, underdamped.
Tank conducting(const Tank& s, double t) {
  const double C = 2 * kC, a = 1.0 / (2 * kR * C), wd = std::sqrt(1.0 / (kL * C) - a * a);
  const double dv0 = -s.i / C - s.v / (kR * C);
  const double b = (dv0 + a * s.v) / wd;
  const double e = std::exp(-a * t), c = std::cos(wd * t), sn = std::sin(wd * t);
  const double v = e * (s.v * c + b * sn);
  const double dv = e * ((-a * s.v + wd * b) * c + (-a * b - wd * s.v) * sn);
  return {v, -C * dv - v / kR, std::abs(v)};
}
// The bridge's current while conducting: the load's, w/R + C w', with
// w = -v (v < 0) and C v' = (C / 2C) (-i - v/R).
double bridge_current(const Tank& s) { return -s.v / kR + 0.5 * (s.i + s.v / kR); }

TEST(FloatingBridge, AllBlockingRingsUntilTheLoadMeetsTheTank) {
  const Circuit c = circuit::parse_circuit(kBlocking, "blk.cir");
  sim::Options opt;
  opt.t_end = 1.3e-3;
  opt.dt_out = 1e-6;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  ASSERT_TRUE(tr.ok()) << tr.message;
  const Tank s0{5.0, 0.0, 10.0};
  // t1: the load's voltage meets -v (v < 0: D2 and D3 start conducting).
  // Before it, w > 5 V >= |v| until t = RC ln 2 = 0.69 ms and v > 0 up to
  // 0.79 ms, so the first root of w + v after 0.8 ms is the first of w - |v|.
  const auto gap1 = [&](double t) { return blocking(s0, t).w + blocking(s0, t).v; };
  const double t1 = bisect(gap1, 0.8e-3, 0.9e-3);
  const Tank s1 = blocking(s0, t1);
  // t2: the bridge's current returns to zero: all four block again.
  const double t2 =
      first_root([&](double t) { return bridge_current(conducting(s1, t - t1)); }, t1, 1e-6);
  const Tank s2 = conducting(s1, t2 - t1);
  // t3: the tank swings up to meet the load (v > 0: D1 and D4).
  const double t3 = first_root(
      [&](double t) {
        const Tank s = blocking({s2.v, s2.i, -s2.v}, t - t2);
        return s.w - std::abs(s.v);
      },
      t2, 1e-6);
  ASSERT_LT(t3, opt.t_end.value());
  // Nothing happens at the tank's zeros (0.157 ms, 0.47 ms, ...): the load
  // floats and D1's reverse voltage follows.
  const std::vector<const sim::Event*> ev = mode_events(tr);
  ASSERT_GE(ev.size(), 3u);
  EXPECT_NEAR(ev[0]->t, t1, kEventTol);
  EXPECT_NEAR(ev[1]->t, t2, kEventTol);
  EXPECT_NEAR(ev[2]->t, t3, kEventTol);
  EXPECT_EQ(c.conducting(ev[0]->mode_after), (std::vector<std::string>{"D2", "D3"}));
  EXPECT_TRUE(c.conducting(ev[1]->mode_after).empty());
  EXPECT_EQ(c.conducting(ev[2]->mode_after), (std::vector<std::string>{"D1", "D4"}));
  int checked = 0;
  for (const sim::Sample& smp : tr.samples) {
    if (smp.t > t3) break;
    const Tank want = smp.t <= t1   ? blocking(s0, smp.t)
                      : smp.t <= t2 ? conducting(s1, smp.t - t1)
                                    : blocking({s2.v, s2.i, -s2.v}, smp.t - t2);
    EXPECT_NEAR(output(c.model, smp, "V(a)"), want.v, kVoltTol) << "t = " << smp.t;
    EXPECT_NEAR(smp.x(1), want.i, kVoltTol / kR) << "t = " << smp.t;
    EXPECT_NEAR(output(c.model, smp, "V(p)") - output(c.model, smp, "V(m)"), want.w, kVoltTol)
        << "t = " << smp.t;
    // The recorded pairs are an admissible choice: every u, y >= 0 (to the
    // rounding of 10 V), and D1's reverse voltage is the least one.
    for (Eigen::Index r = 0; r < smp.u.size(); ++r) {
      EXPECT_GE(smp.u(r), -kVoltTol) << "t = " << smp.t << " u" << r;
      EXPECT_GE(smp.y(r), -kVoltTol) << "t = " << smp.t << " y" << r;
    }
    ++checked;
  }
  EXPECT_GT(checked, 1000);
}

// Above 12 diodes the modes are not enumerated (4096 phases at most): the
// same bridge with nine more diodes, each reverse biased by -1 V into a
// capacitor of its own, runs through the all-blocking phase (its free pair
// needs no enumeration) and is refused where the load meets the tank (t1 of
// the test above, where the LDCP's levels fail: D1 active, D2 and D3
// undecided), in one line naming the time and those diodes.
TEST(FloatingBridge, AboveTwelveDiodesTheRefusalNamesTimeAndDiodes) {
  std::string text = kBlocking;
  std::string extra = "Vb b 0 -1\n";
  for (int i = 1; i <= 9; ++i) {  // each into its own capacitor (leading index 1)
    const std::string n = std::to_string(i);
    extra += "DX" + n + " b c" + n + " ideal\nCX" + n + " c" + n + " 0 1u\n";
  }
  text.insert(text.find(".model"), extra);
  const Circuit c = circuit::parse_circuit(text, "blk13.cir");
  ASSERT_EQ(c.model.pair_names.size(), 13u);
  sim::Options opt;
  opt.t_end = 1e-3;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  ASSERT_EQ(tr.status, Status::kNumericalFailure);
  EXPECT_EQ(tr.message.find('\n'), std::string::npos) << tr.message;
  const Tank s0{5.0, 0.0, 10.0};
  const double t1 =
      bisect([&](double t) { return blocking(s0, t).w + blocking(s0, t).v; }, 0.8e-3, 0.9e-3);
  char when[64];
  std::snprintf(when, sizeof when, "mode selection at t = %.6g s: ", t1);  // short_number's digits
  EXPECT_EQ(tr.message.rfind(when, 0), 0u) << tr.message << " / " << when;
  EXPECT_NE(tr.message.find("(active: D1; undecided: D2, D3)"), std::string::npos) << tr.message;
}

// /tmp/br/fw.cir of the issue (circuits/full_wave_rectifier.cir).
constexpr double kRs = 1.0, kRl = 1e3, kCl = 100e-6, kAmp = 10.0;  // ohm, ohm, F, V
const double kOmega = 2 * pi * 50;                                 // rad/s

double source(double t) { return kAmp * std::sin(kOmega * t); }
// Charging through two diodes from w0 at t0, the source's sign s: the load
// C w' = (s v_src - w)/Rs - w/R, i.e. w' = -a w + s b sin(W t).
double charging(double w0, double t0, double s, double t) {
  const double a = 1 / (kRs * kCl) + 1 / (kRl * kCl), b = kAmp / (kRs * kCl);
  const auto wp = [&](double tt) {
    return s * b * (a * std::sin(kOmega * tt) - kOmega * std::cos(kOmega * tt)) /
           (a * a + kOmega * kOmega);
  };
  return wp(t) + (w0 - wp(t0)) * std::exp(-a * (t - t0));
}

TEST(FullWaveRectifier, ChargesDecaysAndTurnsOnWhereTheClosedFormSays) {
  const Circuit c =
      circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/full_wave_rectifier.cir");
  sim::Options opt;
  opt.t_end = 23e-3;
  opt.dt_out = 1e-5;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  ASSERT_TRUE(tr.ok()) << tr.message;
  // From the operating point (all zero) D1 and D4 conduct at once; they stop
  // where the diode current (v_src - w)/Rs returns to zero after the peak.
  const auto w_a = [&](double t) { return charging(0.0, 0.0, 1.0, t); };
  const double t_off1 = bisect([&](double t) { return source(t) - w_a(t); }, 5e-3, 6e-3);
  const double w_off1 = w_a(t_off1);
  // All four block: w decays through R1 until -v_src meets it (D2, D3).
  const auto w_b = [&](double t) { return w_off1 * std::exp(-(t - t_off1) / (kRl * kCl)); };
  const double t_on1 = bisect([&](double t) { return w_b(t) + source(t); }, 10e-3, 15e-3);
  const auto w_c = [&](double t) { return charging(w_b(t_on1), t_on1, -1.0, t); };
  const double t_off2 = bisect([&](double t) { return -source(t) - w_c(t); }, 15e-3, 16e-3);
  const auto w_d = [&](double t) { return w_c(t_off2) * std::exp(-(t - t_off2) / (kRl * kCl)); };
  const double t_on2 = bisect([&](double t) { return w_d(t) - source(t); }, 20e-3, 25e-3);
  const std::vector<const sim::Event*> ev = mode_events(tr);
  ASSERT_GE(ev.size(), 3u);
  EXPECT_NEAR(ev[0]->t, t_off1, kEventTol);
  EXPECT_NEAR(ev[1]->t, t_on1, kEventTol);
  EXPECT_NEAR(ev[2]->t, t_off2, kEventTol);
  EXPECT_TRUE(c.conducting(ev[0]->mode_after).empty());
  EXPECT_EQ(c.conducting(ev[1]->mode_after), (std::vector<std::string>{"D2", "D3"}));
  EXPECT_TRUE(c.conducting(ev[2]->mode_after).empty());
  EXPECT_GT(t_on2, opt.t_end.value());  // the run ends in the decay
  EXPECT_EQ(ev.size(), 3u);
  for (const sim::Sample& s : tr.samples) {
    const double want = s.t <= t_off1   ? w_a(s.t)
                        : s.t <= t_on1  ? w_b(s.t)
                        : s.t <= t_off2 ? w_c(s.t)
                                        : w_d(s.t);
    EXPECT_NEAR(output(c.model, s, "V(p)") - output(c.model, s, "V(m)"), want, kVoltTol)
        << "t = " << s.t;
  }
}

// Backward Euler on the same netlist converges to the exact run to first
// order: its largest deviation over the first 24 ms halves with h.
TEST(FullWaveRectifier, BackwardEulerConvergesToTheExactRunToFirstOrder) {
  const Circuit c =
      circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/full_wave_rectifier.cir");
  sim::Options opt;
  opt.t_end = 24e-3;
  opt.dt_out = 1e-4;
  const sim::Trajectory exact = sim::simulate(c.model, opt);
  ASSERT_TRUE(exact.ok()) << exact.message;
  const auto load = [&](const sim::Sample& s) {
    return output(c.model, s, "V(p)") - output(c.model, s, "V(m)");
  };
  const auto deviation = [&](double h) {
    sim::Options o = opt;
    o.h = h;
    const sim::Trajectory tr = sim::simulate(c.model, o, "euler");
    EXPECT_TRUE(tr.ok()) << tr.message;
    double worst = 0.0;
    std::size_t j = 0;
    for (const sim::Sample& s : tr.samples) {
      while (j < exact.samples.size() && exact.samples[j].t < s.t - 1e-12) ++j;
      if (j == exact.samples.size() || std::abs(exact.samples[j].t - s.t) > 1e-12) continue;
      worst = std::max(worst, std::abs(load(s) - load(exact.samples[j])));
    }
    return worst;
  };
  const double e1 = deviation(2e-6), e2 = deviation(1e-6);
  // First order: e(h) ~ K h. The ratio of two halvings is 2 up to the O(h^2)
  // terms and the grid's alignment with the switching times (within 25%).
  EXPECT_GT(e1, 0.0);
  EXPECT_NEAR(e1 / e2, 2.0, 0.5) << e1 << " " << e2;
  EXPECT_LT(e2, 0.05);  // K h with K ~ |w''| / 2 * (time constant) ~ 1e4 V/s: 1e-2 V at 1 us
}

}  // namespace
}  // namespace lcsim
