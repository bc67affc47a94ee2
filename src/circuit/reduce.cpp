// Modified nodal analysis reduced to an LCS in state form (thesis §2.2, §5.2).
//
// Each capacitor is a voltage source of its state's value, each inductor a
// current source of its state's value, each current-form diode a current
// source u_i, each voltage-form diode a voltage source von + ron i - u_i,
// each independent source its exosystem row. What is left is a resistive
// network with controlled sources, whose MNA equations M z = N p (z: node
// voltages, then the currents of the voltage-defined branches; p = (x, w, u))
// give every voltage and current as a linear function of the state and of
// the diode variables: Z = M^{-1} N. Then C dv/dt = i_C, L di/dt = v_L,
// w' = S w, and y per diode.
#include "circuit/reduce.hpp"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>
#include <map>
#include <numbers>

#include "circuit/lines.hpp"

namespace lcsim::circuit {
namespace {

using RowVector = Eigen::RowVectorXd;

// Where each quantity sits: states, exosystem, pairs, MNA unknowns.
struct Layout {
  int nodes = 0;                            // non-ground nodes
  std::vector<int> branch;                  // per element: its MNA branch (-1: none)
  std::vector<int> state;                   // per element: its circuit state (-1: none)
  std::vector<int> pair;                    // per element: its complementarity pair (-1: none)
  std::vector<int> exo;                     // per element: its first exosystem state (sine), -1
  std::vector<bool> on;                     // per element: a switch that is on (RON, else ROFF)
  int branches = 0, nc = 0, nw = 1, k = 0;  // nw: the constant state "1" first
  int n() const { return nc + nw; }
  int unknowns() const { return nodes + branches; }
};

Layout lay_out(const Netlist& net, const std::vector<DiodeForm>& forms) {
  Layout L;
  L.nodes = static_cast<int>(net.nodes.size()) - 1;
  const std::size_t ne = net.elements.size();
  L.branch.assign(ne, -1);
  L.state.assign(ne, -1);
  L.pair.assign(ne, -1);
  L.exo.assign(ne, -1);
  L.on.assign(ne, false);
  for (std::size_t i = 0; i < ne; ++i) {
    const Element& e = net.elements[i];
    if (e.kind == ElementKind::kCapacitor || e.kind == ElementKind::kInductor) L.state[i] = L.nc++;
    if (e.kind == ElementKind::kDiode) L.pair[i] = L.k++;
    const bool vform = e.kind == ElementKind::kDiode && forms[L.pair[i]] == DiodeForm::kVoltage;
    if (detail::voltage_defined(e.kind) || vform) L.branch[i] = L.branches++;
  }
  for (std::size_t i = 0; i < ne; ++i)
    if (net.elements[i].wave.sine) {
      L.exo[i] = L.nw;
      L.nw += 2;
    }
  // Then the sources with breakpoints (PULSE, PWL, delayed SIN), last: the
  // mech::Model::inputs, whose exosystems end the state.
  for (std::size_t i = 0; i < ne; ++i)
    if (const auto& in = net.elements[i].wave.input) {
      L.exo[i] = L.nw;
      L.nw += in->exo_size();
    }
  return L;
}

// The equations M z = N p of the resistive network.
struct Mna {
  MatrixXd M, N;
  const Layout* L;
  // Row/column of node v (-1: ground).
  int at(int v) const { return v - 1; }
  void add(int r, int c, double x) {
    if (r >= 0 && c >= 0) M(r, c) += x;
  }
  // A current `row` (over p) leaving node a and entering node b.
  void inject(int a, int b, const RowVector& row) {
    if (at(a) >= 0) N.row(at(a)) -= row;
    if (at(b) >= 0) N.row(at(b)) += row;
  }
  // Branch column j: its current leaves node a, enters node b; its row says
  // v_a - v_b = ... (the caller adds the rest).
  void branch(int j, int a, int b) {
    add(at(a), j, 1.0);
    add(at(b), j, -1.0);
    add(j, at(a), 1.0);
    add(j, at(b), -1.0);
  }
};

// The row over p = (x, w, u) of a source's value.
RowVector source_row(const Element& e, const Layout& L, int exo) {
  RowVector r = RowVector::Zero(L.n() + L.k);
  r(L.nc) = e.wave.dc;  // the constant state "1"
  if (e.wave.sine) r(L.nc + exo) = e.wave.amplitude;
  if (e.wave.input) r.segment(L.nc + exo, e.wave.input->exo_size()) = e.wave.input->exo_output();
  return r;
}

int control_branch(const Netlist& net, const Layout& L, const Element& e) {
  for (std::size_t j = 0; j < net.elements.size(); ++j)
    if (net.elements[j].kind == ElementKind::kVoltageSource &&
        detail::lower(net.elements[j].name) == e.control)
      return L.nodes + L.branch[j];
  throw std::logic_error("control_branch: unresolved " + e.control);
}

// A resistor's value, or a switch's RON or ROFF in the configuration L.on.
double resistance(const Element& e, const Layout& L, std::size_t i) {
  if (e.kind != ElementKind::kSwitch) return e.value;
  return L.on[i] ? e.ron : e.roff;
}

// Stamps one element (a long switch over the element kinds, one case each).
void stamp(Mna& m, const Netlist& net, const Layout& L, std::size_t i) {
  const Element& e = net.elements[i];
  const int a = e.nodes[0], b = e.nodes[1], j = L.branch[i] >= 0 ? L.nodes + L.branch[i] : -1;
  const int P = L.n() + L.k;
  switch (e.kind) {
    case ElementKind::kResistor:
    case ElementKind::kSwitch: {
      const double g = 1.0 / resistance(e, L, i);
      m.add(m.at(a), m.at(a), g), m.add(m.at(b), m.at(b), g);
      m.add(m.at(a), m.at(b), -g), m.add(m.at(b), m.at(a), -g);
      break;
    }
    case ElementKind::kCapacitor:
      m.branch(j, a, b);
      m.N(j, L.state[i]) = 1.0;
      break;
    case ElementKind::kInductor:
      m.inject(a, b, RowVector::Unit(P, L.state[i]));
      break;
    case ElementKind::kVoltageSource:
      m.branch(j, a, b);
      m.N.row(j) = source_row(e, L, L.exo[i]);
      break;
    case ElementKind::kCurrentSource:
      m.inject(a, b, source_row(e, L, L.exo[i]));
      break;
    case ElementKind::kVcvs:
      m.branch(j, a, b);
      m.add(j, m.at(e.nodes[2]), -e.value), m.add(j, m.at(e.nodes[3]), e.value);
      break;
    case ElementKind::kCcvs:
      m.branch(j, a, b);
      m.add(j, control_branch(net, L, e), -e.value);
      break;
    case ElementKind::kVccs:
      m.add(m.at(a), m.at(e.nodes[2]), e.value), m.add(m.at(a), m.at(e.nodes[3]), -e.value);
      m.add(m.at(b), m.at(e.nodes[2]), -e.value), m.add(m.at(b), m.at(e.nodes[3]), e.value);
      break;
    case ElementKind::kCccs: {
      const int c = control_branch(net, L, e);
      m.add(m.at(a), c, e.value), m.add(m.at(b), c, -e.value);
      break;
    }
    case ElementKind::kDiode:
      if (j < 0) {  // current form: u_i flows from anode to cathode
        m.inject(a, b, RowVector::Unit(P, L.n() + L.pair[i]));
      } else {  // voltage form: v = von + ron i - u_i
        m.branch(j, a, b);
        m.add(j, j, -e.ron);
        m.N(j, L.nc) = e.von;
        m.N(j, L.n() + L.pair[i]) = -1.0;
      }
      break;
  }
}

// Z = M^{-1} N, or InputError when the equations are singular.
MatrixXd solve_mna(const Netlist& net, const Layout& L) {
  Mna m;
  m.L = &L;
  m.M = MatrixXd::Zero(L.unknowns(), L.unknowns());
  m.N = MatrixXd::Zero(L.unknowns(), L.n() + L.k);
  for (std::size_t i = 0; i < net.elements.size(); ++i) stamp(m, net, L, i);
  Eigen::FullPivLU<MatrixXd> lu(m.M);
  lu.setThreshold(1e-12 * static_cast<double>(L.unknowns()));
  if (!lu.isInvertible())
    throw InputError(net.source + ": the circuit's equations are singular (rank " +
                     std::to_string(lu.rank()) + " of " + std::to_string(L.unknowns()) +
                     "): controlled sources that fix a voltage or current twice?");
  return lu.solve(m.N);
}

// The row over p of each voltage and current the outputs and the LCS need.
struct Quantities {
  const Netlist* net;
  const Layout* L;
  MatrixXd Z;
  RowVector zero() const { return RowVector::Zero(L->n() + L->k); }
  RowVector node(int v) const { return v == 0 ? zero() : RowVector(Z.row(v - 1)); }
  RowVector across(const Element& e) const { return node(e.nodes[0]) - node(e.nodes[1]); }
  RowVector branch(std::size_t i) const { return Z.row(L->nodes + L->branch[i]); }
  RowVector current(std::size_t i) const;
};

RowVector Quantities::current(std::size_t i) const {
  const Element& e = net->elements[i];
  const int P = L->n() + L->k;
  switch (e.kind) {
    case ElementKind::kResistor:
    case ElementKind::kSwitch:
      return across(e) / resistance(e, *L, i);
    case ElementKind::kInductor:
      return RowVector::Unit(P, L->state[i]);
    case ElementKind::kCurrentSource:
      return source_row(e, *L, L->exo[i]);
    case ElementKind::kVccs:
      return e.value * (node(e.nodes[2]) - node(e.nodes[3]));
    case ElementKind::kCccs:
      return e.value * RowVector(Z.row(control_branch(*net, *L, e)));
    case ElementKind::kDiode:
      if (L->branch[i] < 0) return RowVector::Unit(P, L->n() + L->pair[i]);
      return branch(i);
    default:
      return branch(i);  // C, V, E, H
  }
}

// The LCS (A, B, C, D) and the exosystem block.
lcs::Lcs assemble(const Netlist& net, const Layout& L, const Quantities& q,
                  const std::vector<DiodeForm>& forms) {
  const int n = L.n(), k = L.k;
  MatrixXd AB = MatrixXd::Zero(n, n + k), CD = MatrixXd::Zero(k, n + k);
  for (std::size_t i = 0; i < net.elements.size(); ++i) {
    const Element& e = net.elements[i];
    if (e.kind == ElementKind::kCapacitor) AB.row(L.state[i]) = q.branch(i) / e.value;
    if (e.kind == ElementKind::kInductor) AB.row(L.state[i]) = q.across(e) / e.value;
    if (e.wave.sine) {  // s' = -theta s + omega c, c' = -omega s - theta c
      const int s = L.nc + L.exo[i];
      const double w = 2.0 * std::numbers::pi * e.wave.frequency, th = e.wave.damping;
      AB(s, s) = -th, AB(s, s + 1) = w, AB(s + 1, s) = -w, AB(s + 1, s + 1) = -th;
    }
    if (const auto& in = e.wave.input) {  // its own exosystem (mech::Input)
      const int s = L.nc + L.exo[i], z = in->exo_size();
      AB.block(s, s, z, z) = in->exo_matrix();
    }
    if (e.kind == ElementKind::kDiode) {
      const int p = L.pair[i];
      if (forms[p] == DiodeForm::kCurrent) {  // y = von + ron u - v
        CD.row(p) = -q.across(e);
        CD(p, L.nc) += e.von;
        CD(p, n + p) += e.ron;
      } else {  // y = i
        CD.row(p) = q.branch(i);
      }
    }
  }
  lcs::Lcs s;
  s.A = AB.leftCols(n);
  s.B = AB.rightCols(k);
  s.C = CD.leftCols(n);
  s.D = CD.rightCols(k);
  return s;
}

void name_and_output(Circuit& c, const Layout& L, const Quantities& q) {
  const Netlist& net = c.netlist;
  mech::Model& m = c.model;
  m.state_names.assign(L.n(), "");
  m.exo_initial = VectorXd::Zero(L.nw);
  m.exo_initial(0) = 1.0;
  m.state_names[L.nc] = "1";
  std::vector<RowVector> rows;
  for (std::size_t v = 1; v < net.nodes.size(); ++v) {
    m.output_names.push_back("V(" + net.nodes[v] + ")");
    rows.push_back(q.node(static_cast<int>(v)));
  }
  for (std::size_t i = 0; i < net.elements.size(); ++i) {
    const Element& e = net.elements[i];
    if (L.state[i] >= 0) {
      m.state_names[L.state[i]] = e.name + (e.kind == ElementKind::kCapacitor ? ".v" : ".i");
      c.state_element.push_back(static_cast<int>(i));
    }
    if (const auto& in = e.wave.input) {  // value and slope, or offset and sine
      const int s = L.nc + L.exo[i];
      const std::vector<std::string> parts = in->sine
                                                 ? std::vector<std::string>{".o", ".sin", ".cos"}
                                                 : std::vector<std::string>{".p", ".r"};
      for (std::size_t j = 0; j < parts.size(); ++j)
        m.state_names[s + static_cast<int>(j)] = e.name + parts[j];
      m.exo_initial.segment(L.exo[i], in->exo_size()) = in->exo_state(0.0);
      m.inputs.push_back(*in);
    } else if (L.exo[i] >= 0) {
      m.state_names[L.nc + L.exo[i]] = e.name + ".sin";
      m.state_names[L.nc + L.exo[i] + 1] = e.name + ".cos";
      const double phi = e.wave.phase_deg * std::numbers::pi / 180.0;
      m.exo_initial(L.exo[i]) = std::sin(phi);
      m.exo_initial(L.exo[i] + 1) = std::cos(phi);
    }
    if (L.pair[i] >= 0) {
      m.pair_names.push_back(e.name);
      c.diode_element.push_back(static_cast<int>(i));
    }
    m.output_names.push_back("I(" + e.name + ")");
    rows.push_back(q.current(i));
  }
  const auto no = static_cast<Eigen::Index>(rows.size());
  m.output_x.resize(no, L.n());
  m.output_u.resize(no, L.k);
  for (Eigen::Index r = 0; r < no; ++r) {
    m.output_x.row(r) = rows[r].head(L.n());
    if (L.k > 0) m.output_u.row(r) = rows[r].tail(L.k);  // no row view of an empty matrix
  }
}

// Switch j's control v(nc+) - v(nc-) over p, in the configuration `on` (per
// element).
RowVector control_row(const Netlist& net, Layout& L, const std::vector<bool>& on, int element) {
  L.on = on;
  const Quantities q{&net, &L, solve_mna(net, L)};
  const Element& e = net.elements[element];
  return q.node(e.nodes[2]) - q.node(e.nodes[3]);
}

// Each switch's control as c + g . w(t) over the breakpoint inputs' states:
// InputError naming the switch when it depends on the circuit's state (a
// capacitor, an inductor, a diode), on a sine, or on another switch (the
// control differs with every switch on and every switch off).
std::vector<detail::SwitchControl> switch_controls(const Circuit& c, Layout& L) {
  const Netlist& net = c.netlist;
  std::vector<bool> none(net.elements.size(), false), all = none;
  for (int i : c.switch_element) all[i] = true;
  int inputs = 0;  // the breakpoint inputs' states, the last of the exosystem
  for (const Element& e : net.elements)
    if (e.wave.input) inputs += e.wave.input->exo_size();
  std::vector<detail::SwitchControl> out;
  for (int i : c.switch_element) {
    const Element& e = net.elements[i];
    const RowVector off = control_row(net, L, none, i), row = control_row(net, L, all, i);
    const double tiny = 1e-12 * row.cwiseAbs().maxCoeff();
    const auto fail = [&](const std::string& what) {
      throw InputError(e.where + ": " + e.name + ": its control v(" + net.nodes[e.nodes[2]] + ", " +
                       net.nodes[e.nodes[3]] + ") " + what +
                       ": lcsim schedules a switch whose control sources alone fix "
                       "(a DC, PULSE or PWL voltage source across nc+ nc-)");
    };
    for (int j = 0; j < L.nc; ++j)
      if (std::abs(row(j)) > tiny)
        fail("depends on the circuit's state " + net.elements[c.state_element[j]].name);
    for (int p = 0; p < L.k; ++p)
      if (std::abs(row(L.n() + p)) > tiny)
        fail("depends on the diode " + net.elements[c.diode_element[p]].name);
    for (int w = 1; w < L.nw - inputs; ++w)
      if (std::abs(row(L.nc + w)) > tiny) fail("depends on a SIN source");
    for (const Element& s : net.elements)
      if (s.wave.input && s.wave.input->sine &&
          !row.segment(L.nc + L.exo[&s - net.elements.data()], 3).isZero(tiny))
        fail("depends on the delayed SIN source " + s.name);
    if (!(row - off).isZero(tiny)) fail("depends on the state of a switch");
    out.push_back({row(L.nc), row.segment(L.nc + L.nw - inputs, inputs).transpose()});
  }
  return out;
}

// L.on for configuration `config` (c.switch_on).
void set_switches(const Circuit& c, Layout& L, int config) {
  L.on.assign(c.netlist.elements.size(), false);
  for (std::size_t j = 0; j < c.switch_element.size(); ++j)
    L.on[c.switch_element[j]] = c.switch_on[config][j];
}

// The switches' schedule (mech::Model::switch_times and the rest), and
// c.switch_on per configuration in the order the schedule visits them; L.on
// left at configuration 0's. Nothing without switches.
void schedule_switches(Circuit& c, Layout& L) {
  const Netlist& net = c.netlist;
  for (std::size_t i = 0; i < net.elements.size(); ++i)
    if (net.elements[i].kind == ElementKind::kSwitch)
      c.switch_element.push_back(static_cast<int>(i));
  if (c.switch_element.empty()) return;
  const Element& first = net.elements[c.switch_element[0]];
  if (!net.tran)
    throw InputError(first.where + ": " + first.name +
                     ": a switch's on and off times are computed up to .tran's tstop, and there "
                     "is no .tran");
  const std::vector<detail::SwitchControl> controls = switch_controls(c, L);
  std::vector<mech::Input> inputs;
  for (const Element& e : net.elements)
    if (e.wave.input) inputs.push_back(*e.wave.input);
  const detail::SwitchSchedule s =
      detail::switch_schedule(net, c.switch_element, controls, inputs, net.tstop);
  std::map<std::vector<bool>, int> index;
  const auto config_of = [&](const std::vector<bool>& on) {
    const auto [it, added] = index.emplace(on, static_cast<int>(index.size()));
    if (added) c.switch_on.push_back(on);
    return it->second;
  };
  mech::Model& m = c.model;
  m.switch_config.push_back(config_of(s.initial));
  for (std::size_t t = 0; t < s.times.size(); ++t) {
    m.switch_times.push_back(s.times[t]);
    m.switch_config.push_back(config_of(s.after[t]));
  }
  m.switch_notes = s.notes;
  m.switch_horizon = net.tstop;
  set_switches(c, L, 0);
}

// Each configuration's LCS and outputs (mech::Model::configurations): the
// same reduction with each switch's RON or ROFF.
void build_configurations(Circuit& c, Layout& L) {
  for (std::size_t j = 0; j < c.switch_on.size(); ++j) {
    set_switches(c, L, static_cast<int>(j));
    const Quantities q{&c.netlist, &L, solve_mna(c.netlist, L)};
    Circuit scratch;
    scratch.netlist = c.netlist;
    name_and_output(scratch, L, q);
    c.model.configurations.push_back(
        {assemble(c.netlist, L, q, c.diode_form), scratch.model.output_x, scratch.model.output_u});
  }
  if (!c.switch_on.empty()) set_switches(c, L, 0);
}

}  // namespace

std::vector<std::string> Circuit::conducting(const std::vector<int>& mode) const {
  std::vector<std::string> on;
  for (std::size_t p = 0; p < diode_element.size(); ++p) {
    const bool active = std::find(mode.begin(), mode.end(), static_cast<int>(p)) != mode.end();
    if (active == (diode_form[p] == DiodeForm::kCurrent))
      on.push_back(netlist.elements[diode_element[p]].name);
  }
  return on;
}

Circuit build_circuit(const Netlist& net) {
  detail::check_floating(net);
  detail::check_voltage_loops(net);
  Circuit c;
  c.netlist = net;
  c.diode_form = detail::diode_forms_and_cut_sets(net);
  Layout L = lay_out(net, c.diode_form);
  c.circuit_states = L.nc;
  for (std::size_t i = 0; i < net.elements.size(); ++i) {  // names for switch_controls' messages
    if (L.state[i] >= 0) c.state_element.push_back(static_cast<int>(i));
    if (L.pair[i] >= 0) c.diode_element.push_back(static_cast<int>(i));
  }
  schedule_switches(c, L);
  c.state_element.clear();
  c.diode_element.clear();
  build_configurations(c, L);
  const Quantities q{&net, &L, solve_mna(net, L)};
  c.circuit_states = L.nc;
  c.model.lcs = assemble(net, L, q, c.diode_form);
  c.model.exo_states = L.nw;
  c.model.name = std::filesystem::path(net.source).stem().string();
  c.model.source = net.source;
  name_and_output(c, L, q);
  c.energy = MatrixXd::Zero(L.nc, L.nc);
  for (int s = 0; s < L.nc; ++s) c.energy(s, s) = net.elements[c.state_element[s]].value;
  if (net.tran) c.model.t_end = net.tstop;
  c.model.initial = detail::initial_state(c, c.initial_note);
  if (auto p = mech::check_model(c.model))
    throw InputError(net.source + ": " + p->field + ": " + p->what);
  return c;
}

Circuit parse_circuit(const std::string& text, const std::string& source) {
  return build_circuit(parse_netlist(text, source));
}

Circuit load_circuit(const std::filesystem::path& path) {
  return parse_circuit(io::read_file(path), path.string());
}

bool is_netlist_path(const std::filesystem::path& path) {
  const std::string ext = detail::lower(path.extension().string());
  return ext == ".cir" || ext == ".sp" || ext == ".spi" || ext == ".spice" || ext == ".net";
}

}  // namespace lcsim::circuit
