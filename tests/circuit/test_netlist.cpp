// The netlist reader (issue 29): SPICE numbers, comments and continuation
// lines, subcircuits, the reduction's matrices against hand-derived ones, and
// every refusal: one line naming the file, the line and the element.
#include <gtest/gtest.h>

#include <lcsim/circuit/circuit.hpp>
#include <lcsim/io/csv.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim {
namespace {

using circuit::parse_circuit;
using circuit::spice_number;

TEST(SpiceNumber, ReadsUnitSuffixesExactly) {
  // Each value is the correctly rounded decimal: "10u" is the literal 1e-5.
  EXPECT_EQ(*spice_number("10u"), 1e-5);
  EXPECT_EQ(*spice_number("1k"), 1e3);
  EXPECT_EQ(*spice_number("1meg"), 1e6);
  EXPECT_EQ(*spice_number("2.2MEG"), 2.2e6);
  EXPECT_EQ(*spice_number("10uF"), 1e-5);
  EXPECT_EQ(*spice_number("4.7nF"), 4.7e-9);
  EXPECT_EQ(*spice_number("3p"), 3e-12);
  EXPECT_EQ(*spice_number("5f"), 5e-15);
  EXPECT_EQ(*spice_number("1.5m"), 1.5e-3);  // milli, not mega
  EXPECT_EQ(*spice_number("1M"), 1e-3);      // SPICE: M is milli too
  EXPECT_EQ(*spice_number("2g"), 2e9);
  EXPECT_EQ(*spice_number("1t"), 1e12);
  EXPECT_EQ(*spice_number("1e-6"), 1e-6);
  EXPECT_EQ(*spice_number("1e3k"), 1e6);
  EXPECT_EQ(*spice_number("-2.5V"), -2.5);
  EXPECT_EQ(*spice_number("10Hz"), 10.0);  // 'h' is no scale: a unit
  EXPECT_EQ(*spice_number(".5"), 0.5);
  EXPECT_NEAR(*spice_number("1mil"), 25.4e-6, 1e-21);
  for (const char* bad : {"abc", "", "1k2", "1.5.2", "k1", "-", ".", "1e999"})
    EXPECT_FALSE(spice_number(bad).has_value()) << bad;
}

TEST(Netlist, CommentsContinuationsCaseAndSubcircuits) {
  const char* text = R"(* the title line is never read as an element
* a comment
.SUBCKT divider top mid
rA top mid 1K   ; an inline comment
RB mid 0
+ 3k $ another
.ENDS
V1 IN 0 DC 4
X1 in OUT divider
c1 out 0 1U
.tran 1u 1m
.END
R9 this line comes after .end
)";
  const circuit::Circuit c = parse_circuit(text, "div.cir");
  ASSERT_EQ(c.netlist.elements.size(), 4u);
  EXPECT_EQ(c.netlist.elements[1].name, "X1.rA");
  EXPECT_EQ(c.netlist.elements[2].value, 3e3);
  // The Thevenin circuit of the divider: dv/dt = (3 - v) / (750 ohm * 1 uF);
  // the operating point (no uic) is v = 3 V.
  const lcs::Lcs& s = *c.model.lcs;
  EXPECT_NEAR(s.A(0, 0), -1.0 / (750.0 * 1e-6), 1e-9);
  EXPECT_NEAR(s.A(0, 1), 4.0 * 0.75 / (750.0 * 1e-6), 1e-9);  // the constant state times V1
  EXPECT_NEAR(c.model.initial(0), 3.0, 1e-12);
  EXPECT_EQ(c.model.state_names[1], "1");
  EXPECT_EQ(c.model.t_end, 1e-3);
}

// The message of the InputError that `text` gives ("" if none).
std::string error_of(const std::string& text) {
  try {
    (void)parse_circuit(text, "bad.cir");
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Netlist, RefusesBadInputOnOneLineNamingLineAndElement) {
  const struct {
    const char* text;
    const char* message;
  } cases[] = {
      {"t\nV1 a 0 1\nQ1 a b c npn\nR1 a 0 1k\n",
       "bad.cir:3: Q1: unknown element type 'Q' (lcsim reads R, C, L, V, I, E, F, G, H, D, S and "
       "X)"},
      {"t\nV1 a 0 1\nR1 a\n", "bad.cir:3: R1: missing node or value (expected `name n+ n- value`)"},
      {"t\nV1 a 0 1\nR1 a 0 abc\n", "bad.cir:3: R1: non-numeric value 'abc'"},
      {"t\nV1 a 0 1\nC1 a 0 1u\nR1 a 0 1k\n",
       "bad.cir:3: C1: a loop of capacitors and voltage sources (C1 and V1): their voltages are "
       "not independent (add a resistance in the loop)"},
      {"t\nI1 0 a 1m\nL1 a b 1m\nR1 b 0 1k\nR2 a 0 1k\nI2 c 0 1\nL2 c 0 1\n",
       "bad.cir:6: I2: a cut set of inductors and current sources (I2 and L2) around node(s) c: no "
       "resistor, capacitor or voltage source joins them to ground, so their currents are not "
       "independent"},
      {"t\nV1 a 0 1\nR1 a b 1k\n", "bad.cir:3: R1: floating node 'b': nothing else connects to it"},
      {"t\nV1 a 0 1\nR1 a 0 1k\nR2 b c 1k\nR3 c b 1k\n",
       "bad.cir:4: R2: floating node 'b': no path to ground (node 0) through any element"},
      {"t\nV1 a 0 PWL(0 0 2m 1 1m 2)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PWL times decrease (0.001 s after 0.002 s)"},
      // PWL and PULSE are read (test_sources.cpp); their bad values are refused.
      {"t\nV1 a 0 PWL(0 0 1m x)\nR1 a 0 1k\n", "bad.cir:2: V1: non-numeric value 'x'"},
      {"t\nV1 a 0 PULSE(0 1 0 -1n 1n 1m 2m)\nR1 a 0 1k\n",
       "bad.cir:2: V1: PULSE TR must be >= 0 (got -1e-09 s)"},
      // Switches are read now (test_switches.cpp); one without its .model is refused.
      {"t\nV1 a 0 1\nS1 a 0 c 0 sw\nR1 a 0 1k\n", "bad.cir:3: S1: no .model 'sw' of type SW"},
      {"t\nV1 a 0 1\nD1 a 0 nomodel\n", "bad.cir:3: D1: no .model 'nomodel'"},
      {"t\nV1 a 0 1\nR1 a 0 1k\n.model d1 D(IS=1e-14 XYZ=1)\n",
       "bad.cir:4: .model d1: unknown diode parameter 'XYZ' (lcsim reads RON or RS, and VON; "
       "docs/circuits.md)"},
      {"t\nV1 a 0 1\nR1 a 0 1k\n.ac dec 10 1 1k\n",
       "bad.cir:4: .ac is not supported (lcsim reads .tran, .ic, .model, .subckt, .end)"},
      {"t\nV1 a 0 1\nX1 a sub\nR1 a 0 1k\n.subckt sub p q\nR1 p q 1\n.ends\n",
       "bad.cir:3: X1: missing node: sub has 2 ports (got 1 nodes)"},
      {"t\n+ R1 a 0 1\n",
       "bad.cir:2: a continuation line ('+') with no line before it to continue"},
      {"t\nV1 a 0 SIN(0 1 1k -1m)\nR1 a 0 1k\n",
       "bad.cir:2: V1: SIN delay TD must be >= 0 (got -0.001 s)"},
      {"t\nV1 a 0 1\nR1 a 0 0\n", "bad.cir:3: R1: zero resistance (got 0)"},
  };
  for (const auto& c : cases) {
    const std::string m = error_of(c.text);
    EXPECT_EQ(m, c.message) << c.text;
    EXPECT_EQ(m.find('\n'), std::string::npos);
  }
}

TEST(Netlist, OperatingPointNeedsADcPath) {
  // C2 in series with C1: no DC path, so the operating point leaves their
  // voltages undetermined; uic starts them from 0 instead.
  const char* text = "t\nV1 a 0 1\nR1 a b 1k\nC1 b c 1u\nC2 c 0 1u\n.tran 1u 1m\n";
  EXPECT_EQ(
      error_of(text),
      "bad.cir: operating point: the DC equations (capacitors open, inductors shorted) have "
      "no unique solution for C1.v, C2.v (a capacitor without a DC path, a loop of inductors, "
      "or an inductor across a voltage that .ic holds): give .ic values or use `.tran ... uic`");
  const std::string uic = std::string(text) + ".tran 1u 1m uic\n";
  EXPECT_EQ(error_of(uic), "");
}

TEST(Netlist, OperatingPointSolvesTheDiodes) {
  // 5 V through 1 kOhm into a diode with VON = 0.7 V and RON = 100 ohm to
  // ground, C1 across it: the diode conducts (5 - 0.7)/1100 A and V(a) =
  // 0.7 + 100 * that = 1.0909... V (exact: 0.7 + 430/1100).
  const char* text =
      "t\nV1 in 0 5\nR1 in a 1k\nD1 a 0 dm\nC1 a 0 1u\n.model dm D(VON=0.7 RON=100)\n";
  const circuit::Circuit c = parse_circuit(text, "op.cir");
  EXPECT_NEAR(c.model.initial(0), 0.7 + 100.0 * 4.3 / 1100.0, 1e-12);
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// The linear controlled sources against values by hand, at the operating
// point (no diodes: the outputs are output_x times the initial state).
TEST(Netlist, ControlledSourcesByHand) {
  const char* text = R"(controlled sources
V1 in 0 2
R1 in 0 1k
E1 e 0 in 0 3
Re e 0 1k
G1 0 g in 0 1m
Rg g 0 1k
F1 0 f V1 2
Rf f 0 1k
H1 h 0 V1 500
Rh h 0 1k
R2 in c 1k
C1 c 0 1u
)";
  const circuit::Circuit c = parse_circuit(text, "ctl.cir");
  const mech::Model& m = c.model;
  const auto value = [&](const std::string& name) {
    for (std::size_t i = 0; i < m.output_names.size(); ++i)
      if (m.output_names[i] == name) return (m.output_x.row(i) * m.initial)(0);
    ADD_FAILURE() << "no output " << name;
    return 0.0;
  };
  // I(V1): the current entering V1's + terminal, -2 mA (R1 draws 2 mA; C1
  // draws none at the operating point). E: 3 * 2 V; G: 1 mS * 2 V into g
  // (its current flows from n+ = 0 through it to n- = g); F: 2 * I(V1) from
  // 0 into f; H: 500 ohm * I(V1). Rounding only: 1e-12.
  EXPECT_NEAR(value("I(V1)"), -2e-3, 1e-15);
  EXPECT_NEAR(value("V(e)"), 6.0, 1e-12);
  EXPECT_NEAR(value("V(g)"), 2.0, 1e-12);
  EXPECT_NEAR(value("V(f)"), -4.0, 1e-12);
  EXPECT_NEAR(value("V(h)"), -1.0, 1e-12);
  EXPECT_NEAR(value("V(c)"), 2.0, 1e-12);
  EXPECT_NEAR(value("I(G1)"), 2e-3, 1e-15);
  EXPECT_NEAR(value("I(F1)"), -4e-3, 1e-15);
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// Subcircuits inside subcircuits: names and nodes get each instance's path;
// the values by hand (two halving dividers in a row, the second loading the
// first: V(q) = 8/5, V(XQ.m) = 2 V(q)). A circuit without diodes writes its
// outputs from the state alone.
TEST(Netlist, NestedSubcircuitsAndOutputsWithoutDiodes) {
  const char* text = R"(nested
.subckt half in out
R1 in out 1k
R2 out 0 1k
.ends
.subckt quarter a b
X1 a m half
X2 m b half
.ends
V1 top 0 8
XQ top q quarter
C1 q 0 1u
.tran 1u 1m
)";
  const circuit::Circuit c = parse_circuit(text, "nested.cir");
  EXPECT_EQ(c.netlist.elements[2].name, "XQ.X1.R2");
  EXPECT_NEAR(c.model.initial(0), 1.6, 1e-15);
  sim::Options opt;
  opt.t_end = 1e-3;
  opt.dt_out = 1e-3;
  const sim::Trajectory tr = sim::simulate(c.model, opt);
  ASSERT_TRUE(tr.ok()) << tr.message;
  const std::string csv = io::trajectory_csv(c.model, tr);
  const std::size_t row = csv.find('\n') + 1;
  EXPECT_EQ(csv.substr(0, row - 1),
            "t,C1.v,1,V(top),V(q),V(XQ.m),I(V1),I(XQ.X1.R1),I(XQ.X1.R2),I(XQ.X2.R1),I(XQ.X2.R2),"
            "I(C1),mode");
  // Row 0 is the operating point, every output filled: V(top) = 8, V(q) =
  // 1.6, V(XQ.m) = 3.2, I(V1) = -4.8 mA (rounding only: 1e-12 relative).
  const std::vector<std::string> cells = io::split(csv.substr(row, csv.find('\n', row) - row), ',');
  ASSERT_EQ(cells.size(), 12u);  // the empty mode cell last (no diode) is not split out
  const double expected[] = {0, 1.6, 1, 8, 1.6, 3.2, -4.8e-3, 4.8e-3, 3.2e-3, 1.6e-3, 1.6e-3, 0};
  for (std::size_t i = 0; i < 12; ++i)
    EXPECT_NEAR(std::stod(cells[i]), expected[i], 1e-12 * 8) << "column " << i;
}

}  // namespace
}  // namespace lcsim
