// Circuits: SPICE netlists of resistors, capacitors, inductors, sources,
// linear controlled sources and ideal diodes, reduced by modified nodal
// analysis to an LCS in state form (thesis §2.2 and §5.2, eq. (5.3)): the
// capacitor voltages and inductor currents are the states, one
// complementarity pair per diode, and the sources are the states of an
// exosystem appended to the state (mech::Model::exo_states), so the exact
// method simulates a circuit like any other model. docs/circuits.md.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/io/input_error.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/mech/mech.hpp>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace lcsim::circuit {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using io::InputError;

// A SPICE number: a decimal number, then an optional scale suffix (f p n u m
// k meg g t, any case; "mil" = 25.4e-6) and unit letters, which are ignored
// ("10u", "1k", "1meg", "10uF", "2.2MEGohm", "5V"). nullopt for anything else
// ("abc", "1k2", "1.5.2", "", a non-finite value).
std::optional<double> spice_number(const std::string& text);

enum class ElementKind {
  kResistor,       // R: value in ohm
  kCapacitor,      // C: value in F
  kInductor,       // L: value in H
  kVoltageSource,  // V: DC, SIN, PULSE or PWL
  kCurrentSource,  // I: as V (flows from n+ through the source to n-)
  kVcvs,           // E: v(n+, n-) = value * v(nc+, nc-)
  kCccs,           // F: i = value * I(control)
  kVccs,           // G: i = value * v(nc+, nc-)
  kCcvs,           // H: v(n+, n-) = value * I(control)
  kDiode,          // D: ideal, with a forward voltage and an on-resistance
  kSwitch,         // S: a resistor of RON (on) or ROFF (off) by its control v(nc+, nc-)
};

// A source's waveform: a constant, or SPICE's SIN(VO VA FREQ TD THETA PHASE)
// with TD = 0: VO + VA exp(-THETA t) sin(2 pi FREQ t + PHASE), PHASE in
// degrees (V or A; FREQ in Hz, THETA in 1/s).
struct Waveform {
  bool sine = false;
  double dc = 0.0;  // the constant (sine = false) or VO
  double amplitude = 0.0, frequency = 0.0, damping = 0.0, phase_deg = 0.0;
  // PULSE, PWL and SIN with TD > 0: the signal as a mech::Input (V or A), its
  // exosystem at the tail of the state and its breakpoints the exact
  // method's scheduled events (mech::Model::inputs); unset otherwise.
  std::optional<mech::Input> input;
};

struct Element {
  std::string name;  // as written, prefixed "X1." inside subcircuit instance X1
  ElementKind kind = ElementKind::kResistor;
  std::string where;            // "<file>:<line>" of its line, for messages
  std::vector<int> nodes;       // indices into Netlist::nodes: n+, n- (then nc+, nc- for E, G, S)
  double value = 0.0;           // R, C, L, or the gain of E, F, G, H
  std::string control;          // F, H: the voltage source whose current controls them
  std::optional<double> ic;     // C: IC= (V), L: IC= (A)
  Waveform wave;                // V, I
  double von = 0.0, ron = 0.0;  // D: forward voltage (V) and on-resistance (ohm); S: RON
  // S (.model SW): off resistance (ohm), threshold and hysteresis (V): on
  // when v(nc+, nc-) > vt + vh, off when < vt - vh, else as it was; its state
  // at t = 0 inside that window (`ON` on its line, else off).
  double roff = 0.0, vt = 0.0, vh = 0.0;
  bool starts_on = false;
};

// What a netlist says, subcircuits expanded.
struct Netlist {
  std::string source;  // the file, for messages
  std::string title;
  std::vector<std::string> nodes;  // nodes[0] is ground ("0")
  std::vector<Element> elements;
  std::map<int, double> ic;         // .ic V(node)=value (V), by node index
  std::string ic_where;             // "<file>:<line>" of the first .ic
  bool tran = false;                // a .tran line was read
  double tstep = 0.0, tstop = 0.0;  // s
  bool uic = false;
};

// Reads a netlist (docs/circuits.md: the subset read, and what is refused).
// InputError "<file>:<line>: <element>: <what>" on anything it cannot read.
Netlist parse_netlist(const std::string& text, const std::string& source);

// How a diode enters the LCS (thesis §5.2: u_i = I_i, y_i = -V_i or the
// other way round). kCurrent: u = its current, y = von + ron u - v. kVoltage
// (chosen where the diode alone joins a part of the circuit to the rest, as
// in a bridge, so that the circuit's equations stay regular): u = von + ron
// i - v, y = i; the pair is then active (u > 0) while the diode blocks.
enum class DiodeForm { kCurrent, kVoltage };

// A netlist as a model: an `lcs:` mech::Model with named states (capacitor
// voltages "C1.v", inductor currents "L1.i", then the exosystem: "1", and
// "V1.sin", "V1.cos" per sine source), pairs named by their diodes, outputs
// V(node) and I(element), the initial state and t_end of .tran.
struct Circuit {
  Netlist netlist;
  mech::Model model;
  int circuit_states = 0;          // states before the exosystem
  std::vector<int> state_element;  // the element of each circuit state
  std::vector<int> diode_element;  // the element of each complementarity pair
  std::vector<DiodeForm> diode_form;
  std::vector<int> switch_element;  // the element of each switch (S), in netlist order
  // Per configuration (mech::Model::configurations), which switches are on.
  std::vector<std::vector<bool>> switch_on;
  MatrixXd energy;           // K: stored energy x'Kx / 2 (J) = diag(C, L)
  std::string initial_note;  // how the initial state was found
  // The diodes conducting in an LCS mode (the sorted indices of the pairs
  // with u > 0, sim::Sample::mode), by name.
  std::vector<std::string> conducting(const std::vector<int>& mode) const;
};

// The reduction (modified nodal analysis, docs/circuits.md). InputError for
// a circuit it cannot reduce: a floating node, a loop of capacitors and
// voltage sources, a cut set of inductors and current sources, singular
// equations, an operating point that does not exist.
Circuit build_circuit(const Netlist& netlist);
// parse_netlist then build_circuit.
Circuit load_circuit(const std::filesystem::path& path);
Circuit parse_circuit(const std::string& text, const std::string& source);

// A netlist file: its extension is .cir, .sp, .spi, .spice or .net (any case).
bool is_netlist_path(const std::filesystem::path& path);

// Thesis Ch. 5 on the circuit with its sources set to zero (the LCS on the
// circuit states alone): passive when the stored energy x'Kx/2 is a storage
// function (lcs::verify_passivity_certificate with K = energy); not passive
// when A has an eigenvalue in the open right half plane (L(K) <= 0 with K > 0
// forbids it) or lcs::analyze_well_posedness's necessary conditions fail;
// else unknown. Then Assumption 5.2.2 (B of full column rank, (A, B, C)
// minimal): with both, Theorems 5.5.2 and 5.5.3 give one solution from every
// state; without it, Theorem 3.6.3's local verdict.
struct PassivityReport {
  std::string passive = "unknown";  // "yes", "no" or "unknown"
  std::string passive_reason;
  bool full_column_rank_b = false, controllable = false, observable = false;
  bool globally_well_posed = false;            // Theorems 5.5.2-5.5.3 apply
  bool locally_well_posed = false;             // Theorem 3.6.3 (on the circuit states)
  std::string verdict;                         // one sentence
  std::vector<std::string> negative_elements;  // R, C, L with a negative value
};
PassivityReport judge_passivity(const Circuit& c);

}  // namespace lcsim::circuit
