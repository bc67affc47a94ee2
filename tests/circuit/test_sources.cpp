// Sources with breakpoints (issue 29): SPICE's PWL, PULSE and SIN with a
// delay, read as mech::Inputs whose exosystems end an `lcs:` model's state
// and whose breakpoints are the exact method's scheduled events. Each run is
// checked against the closed form of the RC circuit on each linear piece,
// derived here.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>

#include "support/run_lcsim.hpp"

namespace lcsim {
namespace {

using circuit::Circuit;
using std::numbers::pi;

// Tolerances. A scheduled event is the breakpoint itself (the same double as
// the netlist's time, or the sum TD + TR + ... that Input::next_breakpoint
// forms): compared to 1e-15 s, a few ulp of 1e-3 s. A diode's release is a
// root of a Bohl function, found to a few ulp of t; the state it starts
// from carries ~1e-15 relative rounding per phase, which moves a zero of a
// 1 V signal slewing at ~1e3 V/s by ~1e-18 s: 1e-12 s leaves margin and
// still catches an event misplaced by a wrong piece (a wrong slope moves it
// by ~1e-5 s). Voltages: 1e-12 V on 1 V, three orders above the rounding of
// a few matrix exponentials (~1e-15 relative), far below any modelling error
// (an input off by one piece is off by ~1e-3 V or more).
constexpr double kBreakTol = 1e-15;  // s
constexpr double kEventTol = 1e-12;  // s
constexpr double kVoltTol = 1e-12;   // V

sim::Trajectory run(const Circuit& c, double t_end, double dt_out) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  EXPECT_TRUE(tr.ok()) << tr.message;
  return tr;
}

double output(const mech::Model& m, const sim::Sample& s, const std::string& name) {
  for (std::size_t r = 0; r < m.output_names.size(); ++r)
    if (m.output_names[r] == name) {
      const auto i = static_cast<Eigen::Index>(r);
      const double from_x = m.output_x.row(i).dot(s.x);
      return m.output_u.cols() == 0 ? from_x : from_x + m.output_u.row(i).dot(s.u);
    }
  ADD_FAILURE() << "no output " << name;
  return 0.0;
}

std::vector<const sim::Event*> events_of(const sim::Trajectory& tr, sim::EventType type) {
  std::vector<const sim::Event*> out;
  for (const sim::Event& e : tr.events)
    if (e.type == type) out.push_back(&e);
  return out;
}

// An RC low-pass (tau = 1 ms) under a PWL: a ramp of 1000 V/s to 1 V at
// 1 ms, held to 2 ms, a jump to 0 there.
const char* kPwlRc = R"(PWL into an RC
V1 in 0 PWL(0 0 1m 1 2m 1 2m 0)
R1 in out 1k
C1 out 0 1u
.tran 10u 3m uic
)";

// v' = (u - v) / tau on each piece from v(0) = 0: under u = a t,
// v = a (t - tau + tau e^(-t/tau)); under u = 1, 1 + (v1 - 1) e^(-s/tau);
// under u = 0, v2 e^(-s/tau).
double pwl_rc(double t) {
  const double tau = 1e-3, a = 1e3, t1 = 1e-3, t2 = 2e-3;
  const double v1 = a * tau * std::exp(-1.0), v2 = 1.0 + (v1 - 1.0) * std::exp(-1.0);
  if (t <= t1) return a * (t - tau + tau * std::exp(-t / tau));
  if (t < t2) return 1.0 + (v1 - 1.0) * std::exp(-(t - t1) / tau);
  return v2 * std::exp(-(t - t2) / tau);
}

TEST(PwlSource, IsAnInputOfTheLcsModel) {
  const Circuit c = circuit::parse_circuit(kPwlRc, "pwl.cir");
  ASSERT_EQ(c.model.inputs.size(), 1u);
  EXPECT_EQ(c.model.inputs[0].name, "V1");
  // The constant "1", then the PWL's (value, slope), at the state's end.
  EXPECT_EQ(c.model.exo_states, 3);
  EXPECT_EQ(c.model.state_names, (std::vector<std::string>{"C1.v", "1", "V1.p", "V1.r"}));
  EXPECT_EQ(c.model.exo_initial, Eigen::Vector3d(1.0, 0.0, 1e3));
}

TEST(PwlSource, RcMatchesThePiecewiseClosedForm) {
  const Circuit c = circuit::parse_circuit(kPwlRc, "pwl.cir");
  const sim::Trajectory tr = run(c, 3e-3, 1e-5);
  // Breakpoints at 1 ms and 2 ms (the two points at 2 ms are one jump; the
  // point at 0 is the start, no event), each a scheduled event.
  const auto sched = events_of(tr, sim::EventType::kSchedule);
  ASSERT_EQ(sched.size(), 2u);
  EXPECT_NEAR(sched[0]->t, 1e-3, kBreakTol);
  EXPECT_NEAR(sched[1]->t, 2e-3, kBreakTol);
  EXPECT_EQ(sched[0]->note, "breakpoint of input 'V1'");
  EXPECT_NEAR(sched[0]->state_after(0), pwl_rc(1e-3), kVoltTol);
  EXPECT_NEAR(sched[1]->state_after(0), pwl_rc(2e-3), kVoltTol);
  EXPECT_EQ(tr.events.size(), 2u);  // no diode: the breakpoints are the only events
  std::size_t checked = 0;
  for (const sim::Sample& s : tr.samples) {
    if (s.t == 2e-3) continue;  // the jump: two samples (before, after) at t2
    EXPECT_NEAR(output(c.model, s, "V(out)"), pwl_rc(s.t), kVoltTol) << "t = " << s.t;
    EXPECT_NEAR(output(c.model, s, "V(in)"), c.model.inputs[0].value(s.t), kVoltTol);
    ++checked;
  }
  EXPECT_GE(checked, 300u);
}

// A PULSE through a diode into a capacitor: R1 from the source to D1's
// anode, C1 on its cathode, nothing else, so the capacitor charges while the
// source is above it and holds once the diode blocks. PULSE(0 1 0 1m 1m 1m
// 4m): a rise of 1000 V/s over [0, 1m], 1 V to 2 ms, a fall to 0 at 3 ms.
const char* kPulseDiode = R"(PULSE into an RC through a diode
V1 in 0 PULSE(0 1 0 1m 1m 1m 4m)
R1 in a 1k
D1 a out ideal
C1 out 0 1u
.model ideal D
.tran 10u 3.5m uic
)";

TEST(PulseSource, ChargesThroughTheDiodeAndHoldsWhereTheClosedFormSays) {
  const Circuit c = circuit::parse_circuit(kPulseDiode, "pulse.cir");
  const sim::Trajectory tr = run(c, 3.5e-3, 1e-5);
  // While D1 conducts the circuit is the RC above (tau = 1 ms, a = 1000 V/s,
  // a tau = 1): v(1m) = e^-1, v(2m) = 1 + (e^-1 - 1) e^-1. On the fall
  // u = 1 - a s the conducting solution is v = 1 + a tau - a s + (v2 - 1 -
  // a tau) e^(-s/tau), and D1's current (u - v)/R vanishes at e^(-s/tau) =
  // a tau / (1 + a tau - v2): s* = tau ln(2 - v2). From there D1 blocks and
  // C1 holds v = u(s*) = 1 - a s*.
  const double tau = 1e-3, v1 = std::exp(-1.0), v2 = 1.0 + (v1 - 1.0) * std::exp(-1.0);
  const double s_star = tau * std::log(2.0 - v2), t_off = 2e-3 + s_star;
  const double v_hold = 1.0 - 1e3 * s_star;
  const auto sched = events_of(tr, sim::EventType::kSchedule);
  ASSERT_EQ(sched.size(), 3u);  // 1 ms, 2 ms, 3 ms (the next period is at 4 ms)
  EXPECT_NEAR(sched[0]->t, 1e-3, kBreakTol);
  EXPECT_NEAR(sched[1]->t, 2e-3, kBreakTol);
  EXPECT_NEAR(sched[2]->t, 3e-3, kBreakTol);
  EXPECT_NEAR(sched[0]->state_after(0), v1, kVoltTol);
  EXPECT_NEAR(sched[1]->state_after(0), v2, kVoltTol);
  const auto off = events_of(tr, sim::EventType::kRelease);
  ASSERT_EQ(off.size(), 1u);
  EXPECT_NEAR(off[0]->t, t_off, kEventTol);
  EXPECT_TRUE(c.conducting(off[0]->mode_after).empty());
  EXPECT_NEAR(off[0]->state_after(0), v_hold, kVoltTol);
  for (const sim::Sample& s : tr.samples) {
    if (s.t <= t_off) continue;
    EXPECT_NEAR(output(c.model, s, "V(out)"), v_hold, kVoltTol) << "t = " << s.t;
    // D1 blocks: reverse biased (V(a) = u, no current through R1).
    EXPECT_LE(output(c.model, s, "V(a)") - output(c.model, s, "V(out)"), kVoltTol);
  }
}

// SPICE's defaults (ngspice's vsrcload): TD 0; TR and TF tstep, PW and PER
// tstop when omitted or 0; a pulse longer than its period is cut at PER.
TEST(PulseSource, TakesSpiceDefaultsFromTran) {
  const circuit::Netlist n = circuit::parse_netlist(
      "t\nV1 a 0 PULSE(1 3)\nR1 a 0 1k\nV2 b 0 PULSE(0 2 1m 0 0 4m 3m)\nR2 b 0 1\n"
      ".tran 1m 10m\n",
      "p.cir");
  const mech::Input& p = *n.elements[0].wave.input;
  // TR = TF = 1m, PW = PER = 10m: rise over [0, 1m], 3 to the period's end.
  EXPECT_EQ(p.period, 10e-3);
  EXPECT_DOUBLE_EQ(p.value(0.5e-3), 2.0);
  EXPECT_EQ(p.value(5e-3), 3.0);
  // V2: TD 1m, TR = TF = tstep = 1m (given as 0), PW 4m, PER 3m: the pulse
  // is cut at 3 ms into its period (at 1m + 3m = 4 ms), still at 2 V.
  const mech::Input& q = *n.elements[2].wave.input;
  EXPECT_EQ(q.value(0.5e-3), 0.0);
  EXPECT_DOUBLE_EQ(q.value(1.5e-3), 1.0);
  EXPECT_EQ(q.value(3.5e-3), 2.0);
  // The next period rises again from V1 at 4 ms (to 1e-12: the rounding of
  // the period's start, ~1e-18 s, times the slope 2000 V/s).
  EXPECT_NEAR(q.value(4.25e-3), 0.5, 1e-12);
  EXPECT_NEAR(q.value(4.5e-3), 1.0, 1e-12);
}

// SIN(VO VA FREQ TD): VO until TD, then the sine from TD (the RC response
// to A sin(w s) from rest: A / (1 + (w tau)^2) (sin ws - w tau cos ws +
// w tau e^(-s/tau))).
TEST(SineSource, DelayIsAScheduledStart) {
  const char* text = R"(delayed sine
V1 in 0 SIN(0 2 1k 0.5m)
R1 in out 1k
C1 out 0 100n
.tran 1u 2m uic
)";
  const Circuit c = circuit::parse_circuit(text, "sin.cir");
  ASSERT_EQ(c.model.inputs.size(), 1u);
  const sim::Trajectory tr = run(c, 2e-3, 1e-5);
  const auto sched = events_of(tr, sim::EventType::kSchedule);
  ASSERT_EQ(sched.size(), 1u);
  EXPECT_EQ(sched[0]->t, 0.5e-3);
  const double tau = 1e-4, w = 2 * pi * 1e3, wt = w * tau, td = 0.5e-3;
  for (const sim::Sample& s : tr.samples) {
    const double u = s.t - td;
    const double v = u <= 0.0
                         ? 0.0
                         : 2.0 / (1 + wt * wt) *
                               (std::sin(w * u) - wt * std::cos(w * u) + wt * std::exp(-u / tau));
    // 1e-9 V: the sine's exosystem over 1.5 periods rounds at ~1e-15 of
    // |S tau| ~ 1e4 per phase times the 2 V amplitude.
    EXPECT_NEAR(output(c.model, s, "V(out)"), v, 1e-9) << "t = " << s.t;
  }
}

TEST(Sources, BadInputIsOneLineNamingTheElement) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t\nV1 a 0 PWL(0 0 2m 1 1m 2)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL times decrease (0.001 s after 0.002 s)"},
      {"t\nV1 a 0 PWL(0 0 1m)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL takes pairs of time and value (got 3 values)"},
      {"t\nV1 a 0 PULSE(0 1 0 1n 1n -1m 2m)\nR1 a 0 1k\n.tran 1u 1m\n",
       "bad.cir:2: V1: PULSE PW must be >= 0 (got -0.001 s)"},
      {"t\nV1 a 0 PULSE(0 1 0 1n 1n 1m)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PULSE without TR, TF, PW or PER (or 0) takes tstep or tstop, and there is "
       "no .tran"},
      {"t\nV1 a 0 PULSE(0)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PULSE takes V1 V2 [TD [TR [TF [PW [PER]]]]] (got 1 values)"},
      {"t\nV1 a 0 SIN(0 1 1k 1m 0 30)\nR1 a 0 1k\n",
       "bad.cir:2: V1: SIN with both a delay TD and a PHASE is not yet supported (SPICE holds VO + "
       "VA sin(PHASE) before TD, lcsim's delayed sine VO); give TD = 0 or PHASE = 0"},
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

// Backward Euler would integrate a PWL's exosystem across its breakpoints:
// it refuses, one line, invalid input (Moreau–Jean refuses every `lcs:`
// model already).
TEST(Sources, TimeSteppingMethodsRefuseInputsWithBreakpoints) {
  const Circuit c = circuit::parse_circuit(kPwlRc, "pwl.cir");
  for (const char* method : {"euler"}) {
    sim::Options opt;
    opt.t_end = 1e-3;
    opt.h = 1e-5;
    const sim::Trajectory tr = sim::simulate(c.model, opt, method);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << method;
    EXPECT_EQ(tr.message, std::string("method '") + method +
                              "' does not simulate inputs with breakpoints (model 'pwl' has 1: "
                              "PULSE, PWL or delayed SIN sources); method 'event' does");
  }
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// `.include`: a file relative to the netlist's directory (and, nested, to
// the including file's), its lines in place of the directive; a refusal in
// it names the included file and its line; a missing file names the
// directive's line.
TEST(Include, ReadsFilesRelativeToTheIncludingFile) {
  const std::filesystem::path dir = cli_test::private_temp("include", "");
  std::filesystem::create_directories(dir / "lib");
  const auto write = [](const std::filesystem::path& p, const std::string& text) {
    std::ofstream(p) << text;
  };
  write(dir / "lib" / "parts.inc",
        "* parts\nR2 out 0 1k\n.include \"models.inc\"\n.end\nR9 x 0 1\n");
  write(dir / "lib" / "models.inc", ".model ideal D(RON=2)\n");
  write(dir / "top.cir",
        "top\nV1 in 0 1\nR1 in out 1k\n.inc lib/parts.inc\nD1 out 0 ideal\n.tran 1u 1m\n");
  const circuit::Netlist n = circuit::load_circuit(dir / "top.cir").netlist;
  ASSERT_EQ(n.elements.size(), 4u);  // V1, R1, R2 (R9 after the included .end is not read), D1
  EXPECT_EQ(n.elements[2].name, "R2");
  EXPECT_EQ(n.elements[3].ron, 2.0);
  EXPECT_EQ(n.tstop, 1e-3);  // lines after the .include are the netlist's
  write(dir / "lib" / "models.inc", ".model ideal D(XYZ=2)\n");
  const std::string models = (dir / "lib" / "models.inc").string();
  try {
    (void)circuit::load_circuit(dir / "top.cir");
    ADD_FAILURE() << "accepted XYZ";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              models +
                  ":1: .model ideal: unknown diode parameter 'XYZ' (lcsim reads RON or RS, "
                  "and VON; docs/circuits.md)");
  }
  std::filesystem::remove(dir / "lib" / "models.inc");
  try {
    (void)circuit::load_circuit(dir / "top.cir");
    ADD_FAILURE() << "accepted a missing include";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()), (dir / "lib" / "parts.inc").string() +
                                         ":3: .include: " + models + ": cannot open: no such file");
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lcsim
