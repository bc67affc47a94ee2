// Circuits against closed forms derived here (issue 29): the diode bridge
// (a parallel RLC circuit, since an ideal full-wave bridge always presents
// its load), a half-wave RLC circuit (damped while its diode conducts,
// undamped while it blocks), an RC low-pass driven by a (damped) sine, and
// the half-wave rectifier's turn-off and turn-on times.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>

#include "support/bisect.hpp"

namespace lcsim {
namespace {

using circuit::Circuit;
using std::numbers::pi;

constexpr double kC = 1e-6, kL = 10e-3, kR = 1e3;  // F, H, ohm
const double kAlpha = 1.0 / (2.0 * kR * kC);       // 1/s
const double kW0 = 1.0 / std::sqrt(kL * kC);       // rad/s
const double kWd = std::sqrt(kW0 * kW0 - kAlpha * kAlpha);

// Tolerances. Event times: the exact method finds a root of a Bohl function
// to a few ulp of t (~1e-19 s here); the state it starts each phase from
// carries the rounding of the matrix exponentials (~1e-15 relative per phase,
// a few dozen phases), which moves a zero crossing of a 10 V signal slewing
// at ~1e5 V/s by ~1e-15 * 10 / 1e5 = 1e-19 s per phase: 1e-12 s leaves seven
// orders of margin and still catches an event misplaced by one ulp of the
// period's arithmetic gone wrong. Voltages: 1e-9 V on 10 V is 1e-10
// relative, five orders above the expected rounding (~1e-14 relative) and
// far below any modelling error (a forward voltage, a missing term).
constexpr double kEventTol = 1e-12;  // s
constexpr double kVoltTol = 1e-9;    // V

// The parallel RLC from (v0, i0) (V, A; i0 the inductor current from the top
// node to ground): C v' = -i - v/R, L i' = v. Returns v(t) and i(t).
std::pair<double, double> damped(double v0, double i0, double t) {
  const double dv0 = -i0 / kC - v0 / (kR * kC);
  const double b = (dv0 + kAlpha * v0) / kWd;
  const double e = std::exp(-kAlpha * t), c = std::cos(kWd * t), s = std::sin(kWd * t);
  const double v = e * (v0 * c + b * s);
  const double dv = e * ((-kAlpha * v0 + kWd * b) * c + (-kAlpha * b - kWd * v0) * s);
  return {v, -kC * dv - v / kR};
}
// The LC tank from (0, i0): v = -(i0 / (C w0)) sin(w0 t), i = i0 cos(w0 t).
std::pair<double, double> undamped(double i0, double t) {
  return {-(i0 / (kC * kW0)) * std::sin(kW0 * t), i0 * std::cos(kW0 * t)};
}

sim::Trajectory run(const Circuit& c, double t_end, double dt_out) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  EXPECT_TRUE(tr.ok()) << tr.message;
  return tr;
}

int column(const mech::Model& m, const std::string& name) {
  for (std::size_t i = 0; i < m.output_names.size(); ++i)
    if (m.output_names[i] == name) return static_cast<int>(i);
  ADD_FAILURE() << "no output " << name;
  return 0;
}
double output(const mech::Model& m, const sim::Sample& s, const std::string& name) {
  const int r = column(m, name);
  const double from_x = m.output_x.row(r).dot(s.x);
  // No row view of an empty output_u (a circuit without diodes).
  return m.output_u.cols() == 0 ? from_x : from_x + m.output_u.row(r).dot(s.u);
}

const char* kBridge = R"(diode bridge
C1 a 0 1u IC=10
L1 a 0 10m
D1 a p ideal
D2 0 p ideal
D3 m a ideal
D4 m 0 ideal
R1 p m 1k
.model ideal D
.tran 1u 5m uic
.end
)";

// The dynamics of the bridge's LCS in a fixed mode I (y_I = 0, u_rest = 0):
// x' = (A - B_I D_II^{-1} C_I) x on the circuit states.
Eigen::MatrixXd mode_dynamics(const Circuit& c, const std::vector<int>& I) {
  const lcs::Lcs& s = *c.model.lcs;
  const Eigen::MatrixXd DII = s.D(I, I), CI = s.C(I, Eigen::all), BI = s.B(Eigen::all, I);
  return (s.A - BI * DII.lu().solve(CI)).topLeftCorner(c.circuit_states, c.circuit_states);
}

TEST(DiodeBridge, EachConductingPairPresentsTheLoad) {
  const Circuit c = circuit::parse_circuit(kBridge, "bridge.cir");
  EXPECT_EQ(c.model.state_names[0], "C1.v");
  EXPECT_EQ(c.model.initial(0), 10.0);
  // D1 alone joins the load's nodes to the tank: it is the one diode in
  // voltage form (active while it blocks).
  ASSERT_EQ(c.diode_form.size(), 4u);
  EXPECT_EQ(c.diode_form[0], circuit::DiodeForm::kVoltage);
  // The parallel RLC: C v' = -i - v/R, L i' = v, whichever pair conducts.
  Eigen::Matrix2d rlc;
  rlc << -1.0 / (kR * kC), -1.0 / kC, 1.0 / kL, 0.0;
  // D1 and D4 conduct (V(a) > 0): the active pairs are D4's (current form).
  const std::vector<int> positive{3}, negative{0, 1, 2};  // D2, D3 conduct, D1 blocks
  EXPECT_EQ(c.conducting(positive), (std::vector<std::string>{"D1", "D4"}));
  EXPECT_EQ(c.conducting(negative), (std::vector<std::string>{"D2", "D3"}));
  // Relative 1e-12: one LU of a 4 x 4 MNA system and a 3 x 3 solve.
  for (const auto& I : {positive, negative})
    EXPECT_LT((mode_dynamics(c, I) - rlc).norm(), 1e-12 * rlc.norm()) << mode_dynamics(c, I);
}

// The bridge over 5 ms against the parallel RLC: the closed form's events are
// the zeros of V(a), t1 = atan(wd/alpha)/wd and then every pi/wd; after each
// the other pair conducts (D2, D3 while V(a) < 0, D1, D4 while V(a) > 0).
// At each zero all four diodes switch at once and the LCS's D has a zero
// diagonal (D1 in voltage form) and equal rows (D3, D4): D + D' >= 0, no
// P-matrix; the LDCP picks the mode through D's columns (src/lcs/ldcp.cpp).
// Tolerances: kEventTol and kVoltTol above; the inductor current to
// kVoltTol / R = 1e-12 A (0.09 A at the first zero, rounding ~1e-16 A), and
// the load through the same outputs the CSV writes.
TEST(DiodeBridge, ExactRunIsTheParallelRlcOverFiveMilliseconds) {
  const Circuit c = circuit::parse_circuit(kBridge, "bridge.cir");
  const double t_end = 5e-3;
  const sim::Trajectory tr = run(c, t_end, 1e-6);
  ASSERT_TRUE(tr.ok()) << tr.message;
  std::vector<double> zeros;
  for (double t = std::atan(kWd / kAlpha) / kWd; t < t_end; t += pi / kWd) zeros.push_back(t);
  ASSERT_EQ(zeros.size(), 16u);  // 5 ms holds 16 half periods after t1
  std::vector<const sim::Event*> events;
  for (const sim::Event& e : tr.events)
    if (e.type != sim::EventType::kStart) events.push_back(&e);
  ASSERT_EQ(events.size(), zeros.size());
  const std::vector<std::string> negative{"D2", "D3"}, positive{"D1", "D4"};
  for (std::size_t j = 0; j < zeros.size(); ++j) {
    EXPECT_NEAR(events[j]->t, zeros[j], kEventTol) << "event " << j;
    EXPECT_EQ(c.conducting(events[j]->mode_after), j % 2 == 0 ? negative : positive) << j;
    EXPECT_NEAR(events[j]->state_after(0), 0.0, kVoltTol) << "event " << j;
    EXPECT_NEAR(events[j]->state_after(1), damped(10.0, 0.0, zeros[j]).second, kVoltTol / kR) << j;
  }
  EXPECT_GE(tr.samples.size(), 5001u);  // the grid, and each event's samples
  for (const sim::Sample& s : tr.samples) {
    const auto [v, i] = damped(10.0, 0.0, s.t);
    EXPECT_NEAR(output(c.model, s, "V(a)"), v, kVoltTol) << "t = " << s.t;
    EXPECT_NEAR(s.x(1), i, kVoltTol / kR) << "t = " << s.t;
    // The load always sees |V(a)|, the full-wave rectified tank voltage.
    EXPECT_NEAR(output(c.model, s, "V(p)") - output(c.model, s, "V(m)"), std::abs(v), kVoltTol)
        << "t = " << s.t;
    EXPECT_NEAR(output(c.model, s, "I(R1)"), std::abs(v) / kR, kVoltTol / kR) << "t = " << s.t;
  }
  EXPECT_DOUBLE_EQ(tr.samples.back().t, t_end);
}

const char* kHalfWave = R"(half-wave RLC
C1 a 0 1u
L1 a 0 10m
D1 a m ideal
R1 m 0 1k
.ic V(a)=10
.model ideal D
.tran 1u 3m uic
)";

TEST(HalfWaveRlc, DampedWhileConductingUndampedWhileNot) {
  const Circuit c = circuit::parse_circuit(kHalfWave, "half_wave.cir");
  const sim::Trajectory tr = run(c, 3e-3, 0.0);
  // The closed form phase by phase: conducting from (10 V, 0) until v = 0 at
  // t1 = atan(wd/500)/wd; blocking for pi/w0 (v < 0, undamped); conducting
  // again from (0, -i) for pi/wd; and so on.
  std::vector<double> t{std::atan(kWd / kAlpha) / kWd};
  double i = damped(10.0, 0.0, t[0]).second;
  while (t.back() < 3e-3) {
    const bool conducting_next = t.size() % 2 == 0;
    if (conducting_next) {
      t.push_back(t.back() + pi / kWd);
      i = damped(0.0, i, pi / kWd).second;
    } else {
      t.push_back(t.back() + pi / kW0);
      i = undamped(i, pi / kW0).second;
    }
  }
  std::vector<const sim::Event*> events;
  for (const sim::Event& e : tr.events)
    if (e.type != sim::EventType::kStart) events.push_back(&e);
  ASSERT_GE(events.size(), 5u);
  for (std::size_t j = 0; j < events.size() && t[j] < 3e-3; ++j) {
    EXPECT_NEAR(events[j]->t, t[j], kEventTol) << "event " << j;
    EXPECT_EQ(c.conducting(events[j]->mode_after).size(), j % 2 == 0 ? 0u : 1u) << "event " << j;
    // At every event the capacitor voltage is zero and the inductor current
    // alternates in sign with the closed form's magnitudes.
    EXPECT_NEAR(events[j]->state_after(0), 0.0, kVoltTol);
  }
  // The inductor current at the events against the closed form.
  double ij = damped(10.0, 0.0, t[0]).second;
  for (std::size_t j = 0; j < events.size() && t[j] < 3e-3; ++j) {
    EXPECT_NEAR(events[j]->state_after(1), ij, kVoltTol / kR) << "event " << j;
    ij = j % 2 == 0 ? undamped(ij, pi / kW0).second : damped(0.0, ij, pi / kWd).second;
  }
}

// Two ideal diodes in parallel share a current that is not unique (only the
// sum is: D has equal rows and columns, B rank 1); the state is (Ch. 4-5),
// so the waveform is the one diode's, sample for sample. Tolerance: kVoltTol.
TEST(HalfWaveRlc, ParallelDiodesGiveTheOneDiodeWaveform) {
  const std::string one = kHalfWave;
  std::string two = one;
  two.insert(two.find("R1 m 0"), "D2 a m ideal\n");
  const Circuit c1 = circuit::parse_circuit(one, "one.cir");
  const Circuit c2 = circuit::parse_circuit(two, "two.cir");
  ASSERT_EQ(c2.diode_form.size(), 2u);
  const sim::Trajectory t1 = run(c1, 3e-3, 1e-5), t2 = run(c2, 3e-3, 1e-5);
  ASSERT_EQ(t1.samples.size(), t2.samples.size());
  for (std::size_t j = 0; j < t1.samples.size(); ++j) {
    ASSERT_EQ(t1.samples[j].t, t2.samples[j].t);
    EXPECT_NEAR(t2.samples[j].x(0), t1.samples[j].x(0), kVoltTol) << "t = " << t1.samples[j].t;
    EXPECT_NEAR(t2.samples[j].x(1), t1.samples[j].x(1), kVoltTol / kR) << "t = " << t1.samples[j].t;
  }
}

// RC low-pass from rest driven by VA exp(-theta t) sin(w t + phi): the
// closed form of v' = (u(t) - v)/tau by the complex exponential response.
double rc_response(double VA, double w, double theta, double phi, double tau, double t) {
  using cd = std::complex<double>;
  const cd s(-theta, w);
  // u = Im(VA e^{i phi} e^{s t}); particular solution Im(VA e^{i phi} e^{st} / (1 + s tau)).
  const cd a = VA * std::exp(cd(0, phi)) / (1.0 + s * tau);
  const double particular = std::imag(a * std::exp(s * t));
  return particular - std::imag(a) * std::exp(-t / tau);
}

TEST(SineSource, RcLowPassMatchesItsClosedForm) {
  const char* text = R"(RC low-pass
V1 in 0 SIN(0.5 2 1k 0 300 30)
R1 in out 1k
C1 out 0 100n
.ic V(out)=0
.tran 1u 2m uic
)";
  const Circuit c = circuit::parse_circuit(text, "rc.cir");
  EXPECT_EQ(c.model.exo_states, 3);  // the constant and the oscillator
  const sim::Trajectory tr = run(c, 2e-3, 1e-5);
  const double tau = 1e-4, w = 2 * pi * 1e3, phi = 30 * pi / 180;
  for (const sim::Sample& s : tr.samples) {
    const double vin = 0.5 + 2 * std::exp(-300 * s.t) * std::sin(w * s.t + phi);
    const double vout = 0.5 * (1 - std::exp(-s.t / tau)) + rc_response(2, w, 300, phi, tau, s.t);
    EXPECT_NEAR(output(c.model, s, "V(in)"), vin, kVoltTol) << "t = " << s.t;
    EXPECT_NEAR(output(c.model, s, "V(out)"), vout, kVoltTol) << "t = " << s.t;
  }
}

// Bisection (tests/support/bisect.hpp), not the simulator's own root finder.
using test_support::bisect;

TEST(HalfWaveRectifier, TurnsOffAndOnWhereTheClosedFormSays) {
  const Circuit c =
      circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/half_wave_rectifier.cir");
  const sim::Trajectory tr = run(c, 60e-3, 1e-4);
  const double w = 2 * pi * 50, rc = 1e3 * 100e-6;
  // Off where the diode current C v' + v/R of v = 10 sin(wt) reaches zero.
  const double t_off = (pi - std::atan(w * rc)) / w;
  const double v_off = 10 * std::sin(w * t_off);
  // On where the source meets the decaying capacitor voltage again.
  const auto gap = [&](double t) {
    return 10 * std::sin(w * t) - v_off * std::exp(-(t - t_off) / rc);
  };
  const double t_on = bisect(gap, 0.015, 0.5 * pi / w + 0.02);
  std::vector<double> times;
  for (const sim::Event& e : tr.events)
    if (e.type != sim::EventType::kStart) times.push_back(e.t);
  ASSERT_GE(times.size(), 2u);
  EXPECT_NEAR(times[0], t_off, kEventTol);
  // The turn-on time is a tangency-free crossing; the bisection's own error is
  // ~1 ulp and the exact method's is the same order: 1e-12 s holds.
  EXPECT_NEAR(times[1], t_on, kEventTol);
}

// The run's worst complementarity violation is min(0, C x + D u) over the
// samples, D u included: a diode in series with a resistor has C x < 0 while
// it conducts (before the fix, the half-wave RLC circuit reported -10 V).
// Rounding of a 10 V state: ~1e-14; 1e-9 V is the voltage tolerance above.
TEST(ShippedCircuits, ReportNoComplementarityViolation) {
  for (const char* name : {"diode_bridge", "half_wave_rlc", "half_wave_rectifier", "diode_clamp"}) {
    const Circuit c =
        circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/" + name + ".cir");
    const sim::Trajectory tr = run(c, 20e-3, 1e-4);
    EXPECT_GE(tr.max_violation, -kVoltTol) << name;
  }
}

}  // namespace
}  // namespace lcsim
