// The circuit layer's private parts: the structural checks and the reduction.
#pragma once

#include <lcsim/circuit/circuit.hpp>
#include <vector>

namespace lcsim::circuit::detail {

// V, C, E and H fix a voltage across their terminals.
bool voltage_defined(ElementKind k);
// InputError naming a node that no element joins to ground, or that only
// one terminal touches.
void check_floating(const Netlist& net);
// InputError naming the elements of a loop of capacitors and voltage sources.
void check_voltage_loops(const Netlist& net);
// The form of each diode, in element order: kVoltage where a diode joins two
// parts that resistors, capacitors and voltage sources leave apart (a
// bridge's tank), kCurrent otherwise; then InputError naming a cut set of
// inductors and current sources if any part is still apart from ground.
std::vector<DiodeForm> diode_forms_and_cut_sets(const Netlist& net);

// A switch's control voltage as a function of time: c + g . w(t), w the
// states of the circuit's breakpoint inputs (mech::exosystem_states).
struct SwitchControl {
  double c = 0.0;
  Eigen::VectorXd g;
};
// The switches' states at t = 0 and after each time at which some switch
// changes, up to `horizon` (s), with a note per time ("S1 on, S2 off").
struct SwitchSchedule {
  std::vector<bool> initial;
  std::vector<double> times;
  std::vector<std::vector<bool>> after;
  std::vector<std::string> notes;
};
SwitchSchedule switch_schedule(const Netlist& net, const std::vector<int>& switches,
                               const std::vector<SwitchControl>& controls,
                               const std::vector<mech::Input>& inputs, double horizon);

// The circuit's initial state (circuit states then the exosystem): with uic
// from IC= and .ic, else the operating point (docs/circuits.md). `note` says
// which.
Eigen::VectorXd initial_state(const Circuit& c, std::string& note);

}  // namespace lcsim::circuit::detail
