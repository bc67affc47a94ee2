// Ideal switches (S with .model SW; docs/circuits.md): a switch is a
// resistor of RON or ROFF, its on and off times the threshold crossings of a
// control that sources alone fix, scheduled events at which the exact
// method swaps the circuit's matrices. Against closed forms: an RC charged
// through a switch (hysteresis: on above VT + VH, off below VT - VH), an RL
// opened into a freewheeling diode (the diode's conduction interval), and
// the refusals.
#include <gtest/gtest.h>

#include <cmath>
#include <complex>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using circuit::Circuit;

// Tolerances. Switch times are computed by one division on a linear piece of
// the control (a + (threshold - v_a) / slope): a few ulp of t, so 1e-15 s at
// t ~ 1e-3 s. Diode event times: a root of a Bohl function to a few ulp of
// t, moved by the state's rounding (~1e-15 relative per phase, a handful of
// phases) divided by the diode current's slope (>= 1e-2 A/s at its zero,
// for a state of ~1 A): ~1e-13 s; 1e-12 s is the suite's event tolerance.
// Voltages: 1e-9 V on 10 V (1e-10 relative, four orders above the matrix
// exponentials' rounding and far below any modelling error: ROFF's leak in
// the closed forms moves them by 1e-5 V over a millisecond at ROFF = 1e9).
constexpr double kSwitchTol = 1e-15;  // s
constexpr double kEventTol = 1e-12;   // s
constexpr double kVoltTol = 1e-9;     // V
constexpr double kAmpTol = 1e-11;     // A: 1e-11 relative on ~1 A

sim::Trajectory run(const Circuit& c, double t_end, double dt_out) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  EXPECT_TRUE(tr.ok()) << tr.message;
  return tr;
}

// An output of a sample, in the configuration the sample records.
double output(const mech::Model& m, const sim::Sample& s, const std::string& name) {
  int r = -1;
  for (std::size_t i = 0; i < m.output_names.size(); ++i)
    if (m.output_names[i] == name) r = static_cast<int>(i);
  if (r < 0) {
    ADD_FAILURE() << "no output " << name;
    return 0.0;
  }
  const auto& c = m.configurations.at(static_cast<std::size_t>(s.configuration));
  const double from_x = c.output_x.row(r).dot(s.x);
  return c.output_u.cols() == 0 ? from_x : from_x + c.output_u.row(r).dot(s.u);
}

std::vector<const sim::Event*> schedule_events(const sim::Trajectory& tr) {
  std::vector<const sim::Event*> out;
  for (const sim::Event& e : tr.events)
    if (e.type == sim::EventType::kSchedule) out.push_back(&e);
  return out;
}

// V1 charges C1 through R1 and the switch S1. The control ramps 0 -> 2 V over
// [1, 1.5] ms and back 2 -> 0 V over [3, 3.5] ms (4000 V/s): on where it
// exceeds VT + VH = 1.5 V (t = 1.375 ms), off where it falls below
// VT - VH = 0.5 V (t = 3.375 ms), not at VT = 1 V either way.
const char* kRcSwitch = R"(switch charges an RC
V1 in 0 10
S1 in a ctl 0 sw
R1 a b 1k
C1 b 0 1u IC=0
Vc ctl 0 PWL(0 0 1m 0 1.5m 2 3m 2 3.5m 0)
.model sw SW(VT=1 VH=0.5 RON=10 ROFF=1e9)
.tran 1u 5m uic
)";

TEST(Switch, ChargesAnRcFromItsScheduledOnTime) {
  const Circuit c = circuit::parse_circuit(kRcSwitch, "rc.cir");
  const mech::Model& m = c.model;
  const double t_on = 1e-3 + 1.5 / 4000.0, t_off = 3e-3 + 1.5 / 4000.0;
  ASSERT_EQ(m.switch_times.size(), 2u);
  EXPECT_NEAR(m.switch_times[0], t_on, kSwitchTol);
  EXPECT_NEAR(m.switch_times[1], t_off, kSwitchTol);
  EXPECT_EQ(m.switch_config, (std::vector<int>{0, 1, 0}));
  EXPECT_EQ(m.switch_notes, (std::vector<std::string>{"S1 on", "S1 off"}));
  ASSERT_EQ(m.configurations.size(), 2u);
  // The closed form: v' = (10 - v) / ((R1 + Rs) C1), Rs = ROFF, RON, ROFF.
  const double tau_off = (1e3 + 1e9) * 1e-6, tau_on = (1e3 + 10.0) * 1e-6;
  const auto v_of = [&](double t) {
    const double v1 = 10.0 * (1.0 - std::exp(-std::min(t, t_on) / tau_off));
    if (t <= t_on) return v1;
    const double v2 = 10.0 + (v1 - 10.0) * std::exp(-(std::min(t, t_off) - t_on) / tau_on);
    if (t <= t_off) return v2;
    return 10.0 + (v2 - 10.0) * std::exp(-(t - t_off) / tau_off);
  };
  const sim::Trajectory tr = run(c, 5e-3, 1e-5);
  const std::vector<const sim::Event*> ev = schedule_events(tr);
  int switches = 0;
  for (const sim::Event* e : ev) {
    if (e->note.find("switch: ") == std::string::npos) continue;
    EXPECT_NEAR(e->t, switches == 0 ? t_on : t_off, kSwitchTol) << e->note;
    ++switches;
  }
  EXPECT_EQ(switches, 2);
  double worst = 0.0;
  bool on_seen = false;
  for (const sim::Sample& s : tr.samples) {
    worst = std::max(worst, std::abs(output(m, s, "V(b)") - v_of(s.t)));
    // The switch's current in the configuration recorded: (10 - v) / (R1 + Rs).
    const double rs = s.configuration == 1 ? 10.0 : 1e9;
    EXPECT_NEAR(output(m, s, "I(S1)"), (10.0 - s.x(0)) / (1e3 + rs), 1e-12) << s.t;
    if (s.configuration == 1) {
      on_seen = true;
      EXPECT_GE(s.t, t_on - kSwitchTol);
      EXPECT_LE(s.t, t_off + kSwitchTol);
    }
  }
  EXPECT_TRUE(on_seen);
  EXPECT_LT(worst, kVoltTol);
  EXPECT_NEAR(tr.final_state(0), v_of(5e-3), kVoltTol);
}

// L1 and R1 carry the current V1 drives through the switch; the switch opens
// at 5 ms (its control falls through VT = 1 V over [5, 5.001] ms: t_off =
// 5.0005 ms) and the freewheeling diode D1 carries the inductor's current,
// i = i0 exp(-R (t - t_off) / L), V(a) = 0, until it has fallen to the leak
// ROFF lets through, V1 / ROFF: the diode conducts on [t_off, t_off + (L/R)
// ln(i0 ROFF / V1)].
const char* kRlFreewheel = R"(switch opens an RL into a freewheeling diode
V1 in 0 10
S1 in a ctl 0 sw
L1 a b 10m
R1 b 0 10
D1 0 a ideal
Vc ctl 0 PWL(0 2 5m 2 5.001m 0)
.model sw SW(VT=1 RON=0.1 ROFF=1e6)
.model ideal D
.tran 1u 20m uic
)";

TEST(Switch, OpensAnRlIntoAFreewheelingDiodeForItsClosedFormInterval) {
  const Circuit c = circuit::parse_circuit(kRlFreewheel, "rl.cir");
  const mech::Model& m = c.model;
  const double L = 10e-3, R = 10.0, ron = 0.1, roff = 1e6, V = 10.0;
  const double t_off = 5e-3 + 1e-6 / 2.0;
  ASSERT_EQ(m.switch_times.size(), 1u);
  EXPECT_NEAR(m.switch_times[0], t_off, kSwitchTol);
  const double i0 = V / (R + ron) * (1.0 - std::exp(-(R + ron) * t_off / L));
  const double t_end_conduction = t_off + (L / R) * std::log(i0 * roff / V);
  const sim::Trajectory tr = run(c, 20e-3, 1e-5);
  // Events: the switch (D1 starts conducting there), D1's release.
  double t_release = -1.0;
  bool conducting_after_switch = false;
  for (const sim::Event& e : tr.events) {
    if (e.type == sim::EventType::kSchedule && e.note.find("S1 off") != std::string::npos) {
      EXPECT_NEAR(e.t, t_off, kSwitchTol);
      conducting_after_switch = e.mode_after == lcs::IndexSet{0};
    }
    if (e.type == sim::EventType::kRelease) t_release = e.t;
  }
  EXPECT_TRUE(conducting_after_switch);
  EXPECT_NEAR(t_release, t_end_conduction, kEventTol);
  // The current: charging through RON, then the freewheeling decay.
  double worst_i = 0.0, worst_v = 0.0;
  for (const sim::Sample& s : tr.samples) {
    if (s.t > t_end_conduction - 1e-6) break;
    const double i = s.t <= t_off ? V / (R + ron) * (1.0 - std::exp(-(R + ron) * s.t / L))
                                  : i0 * std::exp(-R * (s.t - t_off) / L);
    worst_i = std::max(worst_i, std::abs(s.x(0) - i));
    if (s.t > t_off) worst_v = std::max(worst_v, std::abs(output(m, s, "V(a)")));
  }
  EXPECT_LT(worst_i, kAmpTol);
  EXPECT_LT(worst_v, kVoltTol);
}

// Bad input: one line naming the netlist line and the switch or .model.
TEST(Switch, BadInputIsOneLineNamingTheSwitch) {
  const std::string body = "V1 in 0 10\nR1 a 0 1k\nVc c 0 PWL(0 0 1m 2)\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t\n" + body + "S1 in a c 0 sw\n.model sw SW(RON=0)\n.tran 1u 2m\n",
       "bad.cir:6: .model sw: RON must be > 0 (got 0)"},
      {"t\n" + body + "S1 in a c 0 sw\n.model sw SW(VH=-1)\n.tran 1u 2m\n",
       "bad.cir:6: .model sw: VH must be >= 0 (got -1)"},
      {"t\n" + body + "S1 in a c 0 sw\n.model sw SW(VON=1)\n.tran 1u 2m\n",
       "bad.cir:6: .model sw: unknown switch parameter 'VON' (lcsim reads VT, VH, RON and ROFF; "
       "docs/circuits.md)"},
      {"t\n" + body + "S1 in a c 0 sw\n.tran 1u 2m\n", "bad.cir:5: S1: no .model 'sw' of type SW"},
      {"t\n" + body + "S1 in a c 0 sw\n.model sw SW\n",
       "bad.cir:5: S1: a switch's on and off times are computed up to .tran's tstop, and there "
       "is no .tran"},
      {"t\n" + body + "W1 in a V1 sw\n.tran 1u 2m\n",
       "bad.cir:5: W1: current-controlled switches are not supported (lcsim reads S, whose "
       "control is a voltage)"},
      {"t\n" + body + "S1 in a c 0 sw\n.model sw CSW\n.tran 1u 2m\n",
       "bad.cir:6: .model sw: current-controlled switches (CSW) are not supported (lcsim reads "
       "SW)"},
      // A control that depends on the circuit's state: the capacitor's voltage.
      {"t\nV1 in 0 10\nR1 in b 1k\nC1 b 0 1u\nS1 in a b 0 sw\nR2 a 0 1k\n.model sw SW\n"
       ".tran 1u 2m\n",
       "bad.cir:5: S1: its control v(b, 0) depends on the circuit's state C1: lcsim schedules a "
       "switch whose control sources alone fix (a DC, PULSE or PWL voltage source across nc+ "
       "nc-)"},
      // On another switch: S2's control divides Vc through S1.
      {"t\n" + body + "S1 c d c 0 sw\nR2 d 0 1k\nS2 in a d 0 sw\n.model sw SW\n.tran 1u 2m\n",
       "bad.cir:7: S2: its control v(d, 0) depends on the state of a switch: lcsim schedules a "
       "switch whose control sources alone fix (a DC, PULSE or PWL voltage source across nc+ "
       "nc-)"},
      {"t\nV1 in 0 10\nR1 a 0 1k\nVc c 0 SIN(0 1 1k)\nS1 in a c 0 sw\n.model sw SW\n"
       ".tran 1u 2m\n",
       "bad.cir:5: S1: its control v(c, 0) depends on a SIN source: lcsim schedules a switch "
       "whose control sources alone fix (a DC, PULSE or PWL voltage source across nc+ nc-)"},
  };
  for (const auto& [text, message] : cases) {
    try {
      (void)circuit::parse_circuit(text, "bad.cir");
      ADD_FAILURE() << "accepted: " << text;
    } catch (const io::InputError& e) {
      EXPECT_EQ(std::string(e.what()), message);
    }
  }
}

// The time-stepping methods, sensitivities and a horizon beyond .tran's
// tstop (where the schedule ends) are refused, one line each.
TEST(Switch, RunsThatCannotFollowTheSwapsAreRefused) {
  const Circuit c = circuit::parse_circuit(kRcSwitch, "rc.cir");
  sim::Options opt;
  opt.t_end = 1e-3;
  opt.h = 1e-5;
  sim::Trajectory tr = sim::simulate(c.model, opt, "euler");
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_EQ(tr.message,
            "method 'euler' does not simulate switched circuits (model 'rc' has ideal switches); "
            "method 'event' does");
  sim::Options late;
  late.t_end = 6e-3;
  tr = sim::simulate(c.model, late);
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_EQ(tr.message,
            "t_end = 0.006 s is beyond the switch schedule of model 'rc', known up to .tran's "
            "tstop = 0.005 s");
}

// A switched model built or altered by hand (mech::Model's switch fields)
// whose schedule is inconsistent is refused in one line before any run,
// never read out of range.
TEST(Switch, AnInconsistentScheduleIsRefusedNotRead) {
  const Circuit c = circuit::parse_circuit(kRcSwitch, "rc.cir");
  sim::Options opt;
  opt.t_end = 1e-3;
  mech::Model bad = c.model;
  bad.switch_config.back() = 7;
  sim::Trajectory tr = sim::simulate(bad, opt);
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_NE(tr.message.find("model 'rc': switch_config["), std::string::npos) << tr.message;
  EXPECT_NE(tr.message.find("] = 7 is not one of the"), std::string::npos) << tr.message;
  bad = c.model;
  bad.switch_notes.clear();
  tr = sim::simulate(bad, opt);
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_NE(tr.message.find("switch_notes 0 for"), std::string::npos) << tr.message;
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// x' = A x + b on a 2 x 2 system from x0 over t, in closed form: x_p + E(t)
// (x0 - x_p), x_p = -A^{-1} b, E(t) = [(l1 e^{l2 t} - l2 e^{l1 t}) I +
// (e^{l1 t} - e^{l2 t}) A] / (l1 - l2) for A's two distinct eigenvalues
// l1, l2 (complex or real), written out by hand: no matrix exponential of
// lcsim's.
Eigen::Vector2d two_by_two(const Eigen::Matrix2d& A, const Eigen::Vector2d& b,
                           const Eigen::Vector2d& x0, double t) {
  using cd = std::complex<double>;
  const double tr = A.trace(), det = A.determinant();
  const cd root = std::sqrt(cd(tr * tr / 4.0 - det, 0.0));
  const cd l1 = tr / 2.0 + root, l2 = tr / 2.0 - root;
  const cd e1 = std::exp(l1 * t), e2 = std::exp(l2 * t);
  const cd p = (l1 * e2 - l2 * e1) / (l1 - l2), q = (e1 - e2) / (l1 - l2);
  const Eigen::Matrix2d E = p.real() * Eigen::Matrix2d::Identity() + q.real() * A;
  const Eigen::Vector2d xp = -A.inverse() * b;
  return xp + E * (x0 - xp);
}

// circuits/buck_converter.cir over its first 20 periods, piece by piece in
// closed form (state v = V(out), i = L1's current). Switch on (RON, D1
// blocking): L i' = Vin - RON i - v. Switch off, D1 conducting (sw at 0 V):
// L i' = -v. Before the first on time (0.5 ns from rest) D1 blocks and ROFF
// carries i: L i' = Vin - ROFF i - v. Always C v' = i - v / R. The diode
// conducts while i exceeds the leak Vin / ROFF (asserted on the closed form:
// continuous conduction), so these are the only pieces.
TEST(BuckConverter, FirstPeriodsMatchThePiecewiseClosedForm) {
  const Circuit c =
      circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/buck_converter.cir");
  const double Vin = 12.0, R = 6.0, L = 200e-6, C = 5e-6, ron = 0.01, roff = 1e6, T = 10e-6;
  const double t_on = 0.5e-9, t_off = 5.0005e-6;  // the PULSE's edges through VT = 0.5 V
  const auto A_of = [&](double rs) {
    Eigen::Matrix2d A;
    A << -1.0 / (R * C), 1.0 / C, -1.0 / L, -rs / L;
    return A;
  };
  const Eigen::Vector2d b_on(0.0, Vin / L), zero(0.0, 0.0);
  const int periods = 20;
  const sim::Trajectory tr = run(c, periods * T, T / 8.0);
  // The schedule's events, in order: on, off, on, ... at k T + t_on, k T + t_off.
  std::vector<const sim::Event*> sw;
  for (const sim::Event& e : tr.events)
    if (e.type == sim::EventType::kSchedule && e.note.find("switch: S1") != std::string::npos)
      sw.push_back(&e);
  ASSERT_EQ(sw.size(), 2u * periods);
  // States: L1.i, C1.v (netlist order), then the exosystem; x here is (v, i).
  Eigen::Vector2d x = two_by_two(A_of(roff), b_on, zero, t_on);
  double worst_v = 0.0, worst_i = 0.0, least_i = 1e9;
  for (int k = 0; k < periods; ++k) {
    for (int edge = 0; edge < 2; ++edge) {
      const sim::Event& e = *sw[2 * k + edge];
      const double t = k * T + (edge == 0 ? t_on : t_off);
      EXPECT_NEAR(e.t, t, kSwitchTol) << e.note;
      // Mid-edge: no breakpoint of Vg's PULSE falls there.
      EXPECT_EQ(e.note, std::string("switch: S1 ") + (edge == 0 ? "on" : "off"));
      worst_v = std::max(worst_v, std::abs(e.state_before(1) - x(0)));
      worst_i = std::max(worst_i, std::abs(e.state_before(0) - x(1)));
      // D1 conducts after each off time and blocks after each on time.
      EXPECT_EQ(e.mode_after, edge == 0 ? lcs::IndexSet{} : lcs::IndexSet{0}) << t;
      if (edge == 0) {
        x = two_by_two(A_of(ron), b_on, x, t_off - t_on);
      } else {
        for (int j = 1; j <= 8; ++j)  // the least current of the off interval, on a grid
          least_i = std::min(least_i, two_by_two(A_of(0.0), zero, x, j * (T - t_off) / 8.0)(1));
        x = two_by_two(A_of(0.0), zero, x, T - t_off + t_on);
      }
    }
  }
  EXPECT_GT(least_i, 100.0 * Vin / roff);  // continuous conduction: D1 never releases
  EXPECT_LT(worst_v, kVoltTol);
  EXPECT_LT(worst_i, kAmpTol);
}

}  // namespace
}  // namespace lcsim
