// .param with {expr} values, and PWL's r= and td= options (ngspice's
// meaning; docs/circuits.md), each against values worked out by hand, and
// their refusals.
#include <gtest/gtest.h>

#include <lcsim/circuit/circuit.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using circuit::Netlist;

const circuit::Element& element(const Netlist& n, const std::string& name) {
  for (const circuit::Element& e : n.elements)
    if (e.name == name) return e;
  throw std::runtime_error("no element " + name);
}

// Values are exact: each {expr} is written back with 17 digits, which reads
// to the same double as the expression's value.
TEST(Param, NamesAndExpressionsGiveTheValues) {
  const Netlist n = circuit::parse_netlist(R"(params
.param r=1k c={2.2u} rr = {r*2}
.param half={ (r + rr) / 2 - -1 } vin=12
V1 in 0 {vin}
R1 in out {r}
R2 out 0 {rr}
R3 out 0 { half }
C1 out 0 {c} IC={vin/4}
.tran {1u} {c*r}
)",
                                           "p.cir");
  EXPECT_EQ(element(n, "R1").value, 1e3);
  EXPECT_EQ(element(n, "R2").value, 2e3);
  EXPECT_EQ(element(n, "R3").value, (1e3 + 2e3) / 2.0 + 1.0);
  EXPECT_EQ(element(n, "C1").value, 2.2e-6);
  EXPECT_EQ(*element(n, "C1").ic, 3.0);
  EXPECT_EQ(element(n, "V1").wave.dc, 12.0);
  EXPECT_EQ(n.tstep, 1e-6);
  EXPECT_EQ(n.tstop, 2.2e-6 * 1e3);
}

TEST(Param, BadUseIsOneLineNamingTheLine) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t\nV1 a 0 1\nR1 a 0 {x*2}\n", "bad.cir:3: R1: unknown parameter 'x' in 'x*2'"},
      {"t\n.param a=1\nV1 a 0 1\nR1 a 0 {a/0}\n", "bad.cir:4: R1: division by zero in 'a/0'"},
      {"t\nV1 a 0 1\nR1 a 0 {1k\n",
       "bad.cir:3: R1: a '{' without its '}' (or text after it) in '{1k'"},
      {"t\n.param a\nV1 a 0 1\nR1 a 0 1\n", "bad.cir:2: .param: expected name=value (at 'a')"},
      {"t\n.param a=2 b={a+}\nV1 a 0 1\nR1 a 0 1\n",
       "bad.cir:2: .param b: a value is missing in 'a+'"},
      {"t\n.param a=1x2\nV1 a 0 1\nR1 a 0 1\n",
       "bad.cir:2: .param a: non-numeric value '1x2' in '1x2'"},
      {"t\n.subckt s p q\n.param a=1\nR1 p q 1\n.ends\nV1 a 0 1\nX1 a 0 s\n",
       "bad.cir:3: .param inside .subckt is not supported (lcsim reads global .param)"},
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

// td= delays the sequence; r= (the first time point) repeats it from there:
// PWL(1m 0 2m 1 3m 0) r=1m td=0.5m is 0 until 1.5 ms, then a triangle of
// period 2 ms: 0 at 1.5, 1 at 2.5, 0 at 3.5, 1 at 4.5 ms, ...
TEST(PwlOptions, DelayAndRepeatAsNgspiceReadsThem) {
  const Netlist n = circuit::parse_netlist(
      "t\nV1 a 0 PWL(1m 0 2m 1 3m 0) r=1m td=0.5m\nR1 a 0 1k\n.tran 1u 10m\n", "p.cir");
  const mech::Input& in = *element(n, "V1").wave.input;
  EXPECT_NEAR(in.period, 2e-3, 1e-18);  // 3m - 1m, to an ulp
  const std::vector<std::pair<double, double>> expect = {
      {0.0, 0.0},    {1.4e-3, 0.0}, {2.0e-3, 0.5}, {2.5e-3, 1.0}, {3.0e-3, 0.5},
      {3.5e-3, 0.0}, {4.0e-3, 0.5}, {4.5e-3, 1.0}, {9.0e-3, 0.5}};
  // 1e-12: the repetition's times are sums of the period and the points (a
  // few ulp of 1e-2 s on a slope of 1000 V/s).
  for (const auto& [t, v] : expect) EXPECT_NEAR(in.value(t), v, 1e-12) << t;
  // td alone: the sequence moved, not repeated.
  const Netlist d =
      circuit::parse_netlist("t\nV1 a 0 PWL(0 0 1m 1) td=2m\nR1 a 0 1k\n.tran 1u 10m\n", "p.cir");
  const mech::Input& delayed = *element(d, "V1").wave.input;
  EXPECT_EQ(delayed.period, 0.0);
  EXPECT_EQ(delayed.value(1.9e-3), 0.0);
  EXPECT_NEAR(delayed.value(2.5e-3), 0.5, 1e-12);
  EXPECT_EQ(delayed.value(5e-3), 1.0);
}

// The repeated PWL's breakpoints are the exact method's scheduled events.
TEST(PwlOptions, RepeatedBreakpointsAreScheduledEvents) {
  const circuit::Circuit c = circuit::parse_circuit(
      "t\nV1 a 0 PWL(0 0 1m 1 2m 0) r=0\nR1 a b 1k\nC1 b 0 1u\n.tran 1u 5m uic\n", "p.cir");
  sim::Options opt;
  opt.t_end = 5e-3;
  opt.dt_out = 1e-3;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  ASSERT_TRUE(tr.ok()) << tr.message;
  std::vector<double> times;
  for (const sim::Event& e : tr.events)
    if (e.type == sim::EventType::kSchedule) times.push_back(e.t);
  const std::vector<double> expect = {1e-3, 2e-3, 3e-3, 4e-3};
  ASSERT_EQ(times.size(), expect.size());
  for (std::size_t i = 0; i < times.size(); ++i) EXPECT_NEAR(times[i], expect[i], 1e-15);
}

TEST(PwlOptions, BadOptionsAreOneLineNamingTheSource) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"t\nV1 a 0 PWL(0 0 1m 1) r=0.5m\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL r= must be one of its time points (got 5e-04 s)"},
      {"t\nV1 a 0 PWL(0 0 1m 1 2m 0) r=1m\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL r= after the first time point is not yet supported (got 0.001 s; lcsim "
       "repeats the whole sequence, r = 0 s)"},
      {"t\nV1 a 0 PWL(0 0 1m 1) td=-1m\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL td must be >= 0 (got -0.001 s)"},
      {"t\nV1 a 0 PWL(0 0 1m 1) r=0 r=0\nR1 a 0 1k\n", "bad.cir:2: V1: PWL r= given twice"},
      {"t\nV1 a 0 PWL(1m 1) r=1m\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL r= needs points after it (the sequence to repeat has zero length)"},
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

}  // namespace
}  // namespace lcsim
