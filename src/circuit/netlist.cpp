// The SPICE netlist reader (docs/circuits.md): element lines, .model,
// .subckt/.ends with X instances, .ic, .tran, .end; what lcsim does not model
// is refused by name.
#include <algorithm>
#include <cmath>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>
#include <set>
#include <unordered_map>

#include "circuit/lines.hpp"

namespace lcsim::circuit {
namespace {

using detail::Line;
using detail::lower;

struct DiodeModel {
  double von = 0.0, ron = 0.0;
};

// .model name SW(VT VH RON ROFF), SPICE's defaults (ngspice: ROFF = 1/GMIN).
struct SwitchModel {
  double vt = 0.0, vh = 0.0, ron = 1.0, roff = 1e12;
};

// A PULSE's arguments as written (NaN where omitted), turned into a
// mech::Input once .tran gives tstep and tstop (its defaults: read_pulse).
struct PendingPulse {
  std::size_t element = 0;
  std::string where;
  double v[7];
};

struct Subckt {
  std::string name;
  std::vector<std::string> ports;
  std::vector<Line> body;
};

// The reader's state: the netlist so far, the definitions, and where a line is.
struct Reader {
  std::string source;
  Netlist net;
  std::unordered_map<std::string, int> node_index;  // lower-case name -> index
  std::unordered_map<std::string, Subckt> subckts;  // by lower-case name
  std::unordered_map<std::string, DiodeModel> models;
  std::unordered_map<std::string, SwitchModel> switch_models;
  std::vector<std::string> diode_model_of;  // per element (lower-case), for diodes and switches
  std::vector<Line> top;
  std::set<std::string> element_names;  // lower-case
  std::vector<PendingPulse> pulses;

  std::string where(const Line& l) const {
    return (l.file.empty() ? source : l.file) + ":" + std::to_string(l.number);
  }
  [[noreturn]] void fail(const Line& l, const std::string& what) const {
    throw InputError(where(l) + ": " + what);
  }
  [[noreturn]] void fail(const Line& l, const std::string& element, const std::string& what) const {
    throw InputError(where(l) + ": " + element + ": " + what);
  }
  double number(const Line& l, const std::string& element, const std::string& tok) const {
    const std::optional<double> v = spice_number(tok);
    if (!v) fail(l, element, "non-numeric value '" + tok + "'");
    return *v;
  }
};

// A scope: the prefix of names inside a subcircuit instance ("X1.") and its
// ports mapped to the caller's node indices.
struct Scope {
  std::string prefix;
  std::unordered_map<std::string, int> ports;  // lower-case port name -> node
};

int node_of(Reader& r, const Scope& s, const std::string& name) {
  const std::string key = lower(name);
  if (key == "0" || key == "gnd") return 0;
  if (auto it = s.ports.find(key); it != s.ports.end()) return it->second;
  const std::string full = lower(s.prefix) + key;
  if (auto it = r.node_index.find(full); it != r.node_index.end()) return it->second;
  const int index = static_cast<int>(r.net.nodes.size());
  r.net.nodes.push_back(s.prefix + name);
  r.node_index.emplace(full, index);
  return index;
}

// Tokens from `i` up to the matching ")" when tokens[i] is "(", else the
// numeric tokens from i: the arguments of SIN(...), PWL(...), D(...).
std::vector<std::string> arguments(const Line& l, std::size_t& i) {
  std::vector<std::string> args;
  const auto& t = l.tokens;
  if (i < t.size() && t[i] == "(") {
    for (++i; i < t.size() && t[i] != ")"; ++i) args.push_back(t[i]);
    if (i < t.size()) ++i;  // the ")"
    return args;
  }
  for (; i < t.size() && spice_number(t[i]); ++i) args.push_back(t[i]);
  return args;
}

void read_sine(const Reader& r, const Line& l, const std::string& name,
               const std::vector<std::string>& args, Waveform& w) {
  if (args.size() < 2 || args.size() > 6)
    r.fail(l, name,
           "SIN takes VO VA [FREQ [TD [THETA [PHASE]]]] (got " + std::to_string(args.size()) +
               " values)");
  double v[6] = {0.0, 0.0, std::nan(""), 0.0, 0.0, 0.0};
  for (std::size_t j = 0; j < args.size(); ++j) v[j] = r.number(l, name, args[j]);
  if (!std::isnan(v[2]) && !(v[2] > 0.0))
    r.fail(l, name, "SIN frequency must be > 0 (got " + format_number(v[2]) + " Hz)");
  if (v[3] < 0.0) r.fail(l, name, "SIN delay TD must be >= 0 (got " + format_number(v[3]) + " s)");
  if (v[3] > 0.0 && v[5] != 0.0)
    r.fail(l, name,
           "SIN with both a delay TD and a PHASE is not yet supported (SPICE holds VO + VA "
           "sin(PHASE) before TD, lcsim's delayed sine VO); give TD = 0 or PHASE = 0");
  if (v[3] > 0.0) {  // a mech::Input: VO until TD, then the (damped) sine from TD
    mech::Input in;
    in.name = name;
    in.kind = "sine";
    in.sine = true;
    in.offset = v[0];
    in.amplitude = v[1];
    in.frequency = v[2];  // NaN: 1 / tstop, filled in once .tran is read
    in.damping = v[4];
    in.origin = v[3];
    w.input = in;
    w.sine = false;
    return;
  }
  w.sine = true;
  w.dc = v[0];
  w.amplitude = v[1];
  w.frequency = v[2];  // NaN: 1 / tstop, filled in once .tran is read
  w.damping = v[4];
  w.phase_deg = v[5];
}

// PWL(T1 V1 T2 V2 ...): V1 before T1, linear between the points, the last
// value after the last; two points at one time are a jump.
mech::Input read_pwl(const Reader& r, const Line& l, const std::string& name,
                     const std::vector<std::string>& args) {
  if (args.empty() || args.size() % 2 != 0)
    r.fail(l, name,
           "PWL takes pairs of time and value (got " + std::to_string(args.size()) + " values)");
  mech::Input in;
  in.name = name;
  in.kind = "pwl";
  for (std::size_t j = 0; j < args.size(); j += 2) {
    in.times.push_back(r.number(l, name, args[j]));
    in.values.push_back(r.number(l, name, args[j + 1]));
  }
  if (std::string what = mech::check_input(in); !what.empty()) r.fail(l, name, "PWL " + what);
  return in;
}

// PWL's options after its points, as ngspice reads them (either order):
// td=value delays the whole sequence; r=value repeats it from the time point
// `value` to the last one, over and over. lcsim repeats the whole sequence
// only (r equal to the first time point, ngspice's usual r=0): a later r
// would need a second exosystem per source, and is refused.
void pwl_options(const Reader& r, const Line& l, const std::string& name, std::size_t& i,
                 mech::Input& in) {
  const auto& t = l.tokens;
  std::optional<double> repeat, delay;
  while (i + 2 < t.size() && (lower(t[i]) == "r" || lower(t[i]) == "td") && t[i + 1] == "=") {
    std::optional<double>& o = lower(t[i]) == "r" ? repeat : delay;
    if (o) r.fail(l, name, "PWL " + t[i] + "= given twice");
    o = r.number(l, name, t[i + 2]);
    i += 3;
  }
  if (delay) {
    if (*delay < 0.0) r.fail(l, name, "PWL td must be >= 0 (got " + format_number(*delay) + " s)");
    in.origin = *delay;
  }
  if (!repeat) return;
  const double v = *repeat, start = in.times.front();
  if (std::find(in.times.begin(), in.times.end(), v) == in.times.end())
    r.fail(l, name, "PWL r= must be one of its time points (got " + format_number(v) + " s)");
  if (v != start)
    r.fail(l, name,
           "PWL r= after the first time point is not yet supported (got " + format_number(v) +
               " s; lcsim repeats the whole sequence, r = " + format_number(start) + " s)");
  if (!(in.times.back() > v))
    r.fail(l, name, "PWL r= needs points after it (the sequence to repeat has zero length)");
  for (double& x : in.times) x -= start;  // one period, [0, Tn - T1], from origin td + T1
  in.period = in.times.back();
  in.origin += start;
}

// PULSE(V1 V2 [TD [TR [TF [PW [PER]]]]]): its arguments, checked; the
// mech::Input is made once .tran is read (make_pulse).
void read_pulse(Reader& r, const Line& l, const std::string& name,
                const std::vector<std::string>& args) {
  if (args.size() < 2 || args.size() > 7)
    r.fail(l, name,
           "PULSE takes V1 V2 [TD [TR [TF [PW [PER]]]]] (got " + std::to_string(args.size()) +
               " values)");
  PendingPulse p;
  p.element = r.net.elements.size();
  p.where = r.where(l);
  static const char* const kNames[7] = {"V1", "V2", "TD", "TR", "TF", "PW", "PER"};
  for (std::size_t j = 0; j < 7; ++j) {
    p.v[j] = j < args.size() ? r.number(l, name, args[j]) : std::nan("");
    if (j >= 2 && p.v[j] < 0.0)
      r.fail(l, name,
             std::string("PULSE ") + kNames[j] + " must be >= 0 (got " + format_number(p.v[j]) +
                 " s)");
  }
  r.pulses.push_back(p);
}

// V and I: [DC] value, SIN(...), AC ... (ignored: no AC analysis).
Waveform read_source(Reader& r, const Line& l, const std::string& name, std::size_t i) {
  Waveform w;
  bool have_dc = false;
  const auto& t = l.tokens;
  while (i < t.size()) {
    const std::string k = lower(t[i]);
    if (k == "dc") {
      ++i;
      if (i < t.size() && t[i] == "=") ++i;
      if (i >= t.size()) r.fail(l, name, "DC without a value");
      if (!w.sine && !w.input) w.dc = r.number(l, name, t[i]);
      have_dc = true;
      ++i;
    } else if (k == "ac") {
      ++i;
      for (int j = 0; j < 2 && i < t.size() && spice_number(t[i]); ++j) ++i;
    } else if (k == "sin" || k == "sine") {
      ++i;
      read_sine(r, l, name, arguments(l, i), w);
    } else if (k == "pwl") {
      ++i;
      w.input = read_pwl(r, l, name, arguments(l, i));
      w.sine = false;
      pwl_options(r, l, name, i, *w.input);
    } else if (k == "pulse") {
      ++i;
      read_pulse(r, l, name, arguments(l, i));
      w.input = mech::Input{};  // made by make_pulse once .tran is read
      w.sine = false;
    } else if (k == "exp" || k == "sffm" || k == "am" || k == "trnoise" || k == "trrandom") {
      r.fail(
          l, name,
          "the source function " + t[i] + " is not supported (lcsim reads DC, SIN, PULSE and PWL)");
    } else if (!have_dc && !w.sine && !w.input) {
      w.dc = r.number(l, name, t[i]);
      have_dc = true;
      ++i;
    } else {
      r.fail(l, name, "unexpected '" + t[i] + "'");
    }
  }
  if (w.input) w.dc = 0.0;  // a time function wins over DC in the transient, as SIN does
  return w;
}

// The number of nodes of an element type, and its usage line.
int node_count(char type) { return (type == 'e' || type == 'g' || type == 's') ? 4 : 2; }
std::string usage(char type) {
  switch (type) {
    case 'e':
    case 'g':
      return "name n+ n- nc+ nc- gain";
    case 'f':
    case 'h':
      return "name n+ n- vcontrol gain";
    case 'd':
      return "name anode cathode model";
    case 's':
      return "name n+ n- nc+ nc- model [ON|OFF]";
    case 'v':
    case 'i':
      return "name n+ n- [DC] value | SIN(VO VA FREQ TD THETA PHASE) | PULSE(...) | PWL(...)";
    default:
      return "name n+ n- value";
  }
}

// C and L: value [IC=x].
void read_value_ic(const Reader& r, const Line& l, Element& e, std::size_t i) {
  const auto& t = l.tokens;
  e.value = r.number(l, e.name, t[i++]);
  while (i < t.size()) {
    if (lower(t[i]) == "ic" && i + 2 < t.size() + 0 && t[i + 1] == "=") {
      e.ic = r.number(l, e.name, t[i + 2]);
      i += 3;
    } else {
      r.fail(l, e.name, "unexpected '" + t[i] + "'");
    }
  }
}

void no_more(const Reader& r, const Line& l, const Element& e, std::size_t i) {
  if (i < l.tokens.size()) r.fail(l, e.name, "unexpected '" + l.tokens[i] + "'");
}

// The value of a two-terminal element (R, C, L), which must not be zero.
void check_nonzero(const Reader& r, const Line& l, const Element& e, const char* what) {
  if (e.value == 0.0) r.fail(l, e.name, std::string("zero ") + what + " (got 0)");
}

ElementKind kind_of(char type) {
  switch (type) {
    case 'r':
      return ElementKind::kResistor;
    case 'c':
      return ElementKind::kCapacitor;
    case 'l':
      return ElementKind::kInductor;
    case 'v':
      return ElementKind::kVoltageSource;
    case 'i':
      return ElementKind::kCurrentSource;
    case 'e':
      return ElementKind::kVcvs;
    case 'f':
      return ElementKind::kCccs;
    case 'g':
      return ElementKind::kVccs;
    case 'h':
      return ElementKind::kCcvs;
    case 's':
      return ElementKind::kSwitch;
    default:
      return ElementKind::kDiode;
  }
}

void refuse_type(const Reader& r, const Line& l, const std::string& name) {
  const char type = static_cast<char>(std::tolower(static_cast<unsigned char>(name[0])));
  if (type == 'w')
    r.fail(l, name,
           "current-controlled switches are not supported (lcsim reads S, whose control is a "
           "voltage)");
  if (std::string("rclvidefghxs").find(type) == std::string::npos)
    r.fail(l, name,
           "unknown element type '" + std::string(1, name[0]) +
               "' (lcsim reads R, C, L, V, I, E, F, G, H, D, S and X)");
}

void read_element(Reader& r, const Scope& s, const Line& l) {
  const std::string& first = l.tokens[0];
  const std::string name = s.prefix + first;
  refuse_type(r, l, name.substr(s.prefix.size()));
  const char type = static_cast<char>(std::tolower(static_cast<unsigned char>(first[0])));
  if (!r.element_names.insert(lower(name)).second) r.fail(l, name, "a second element of this name");
  const int nn = node_count(type);
  const std::size_t need = 1 + nn + ((type == 'f' || type == 'h') ? 2 : 1);
  if (l.tokens.size() < need)
    r.fail(l, name, "missing node or value (expected `" + usage(type) + "`)");
  Element e;
  e.name = name;
  e.kind = kind_of(type);
  e.where = r.where(l);
  for (int j = 1; j <= nn; ++j) {
    if (l.tokens[j] == "(" || l.tokens[j] == ")" || l.tokens[j] == "=")
      r.fail(l, name, "missing node (expected `" + usage(type) + "`)");
    e.nodes.push_back(node_of(r, s, l.tokens[j]));
  }
  std::size_t i = 1 + nn;
  std::string model;
  switch (type) {
    case 'r':
      e.value = r.number(l, name, l.tokens[i++]);
      no_more(r, l, e, i);
      check_nonzero(r, l, e, "resistance");
      break;
    case 'c':
    case 'l':
      read_value_ic(r, l, e, i);
      check_nonzero(r, l, e, type == 'c' ? "capacitance" : "inductance");
      break;
    case 'v':
    case 'i':
      e.wave = read_source(r, l, name, i);
      break;
    case 'e':
    case 'g':
      e.value = r.number(l, name, l.tokens[i++]);
      no_more(r, l, e, i);
      break;
    case 'f':
    case 'h':
      e.control = lower(s.prefix) + lower(l.tokens[i++]);
      e.value = r.number(l, name, l.tokens[i++]);
      no_more(r, l, e, i);
      break;
    case 's':  // model [ON|OFF]
      model = lower(l.tokens[i++]);
      if (i < l.tokens.size() && (lower(l.tokens[i]) == "on" || lower(l.tokens[i]) == "off"))
        e.starts_on = lower(l.tokens[i++]) == "on";
      no_more(r, l, e, i);
      break;
    default:  // 'd'
      model = lower(l.tokens[i++]);
      no_more(r, l, e, i);
      break;
  }
  r.net.elements.push_back(e);
  r.diode_model_of.push_back(model);
}

void expand(Reader& r, const std::vector<Line>& lines, const Scope& s, int depth);

void read_instance(Reader& r, const Scope& s, const Line& l, int depth) {
  const std::string name = s.prefix + l.tokens[0];
  if (l.tokens.size() < 2)
    r.fail(l, name, "missing subcircuit name (expected `Xname nodes... subckt`)");
  const auto it = r.subckts.find(lower(l.tokens.back()));
  if (it == r.subckts.end()) r.fail(l, name, "no .subckt '" + l.tokens.back() + "'");
  const Subckt& sub = it->second;
  const std::size_t given = l.tokens.size() - 2;
  if (given != sub.ports.size())
    r.fail(l, name,
           (given < sub.ports.size() ? "missing node: " : "too many nodes: ") + sub.name + " has " +
               std::to_string(sub.ports.size()) + " ports (got " + std::to_string(given) +
               " nodes)");
  if (depth > 32) r.fail(l, name, "subcircuits nested more than 32 deep (a recursive .subckt?)");
  if (!r.element_names.insert(lower(name)).second) r.fail(l, name, "a second element of this name");
  Scope inner;
  inner.prefix = name + ".";
  for (std::size_t j = 0; j < given; ++j)
    inner.ports[lower(sub.ports[j])] = node_of(r, s, l.tokens[1 + j]);
  expand(r, sub.body, inner, depth + 1);
}

void expand(Reader& r, const std::vector<Line>& lines, const Scope& s, int depth) {
  for (const Line& l : lines) {
    const char type = static_cast<char>(std::tolower(static_cast<unsigned char>(l.tokens[0][0])));
    if (type == 'x')
      read_instance(r, s, l, depth);
    else
      read_element(r, s, l);
  }
}

// The name=value pairs of a .model line (the parentheses dropped), in order.
std::vector<std::pair<std::string, double>> model_parameters(const Reader& r, const Line& l) {
  const auto& t = l.tokens;
  std::vector<std::pair<std::string, double>> p;
  for (std::size_t i = 3; i < t.size(); ++i) {
    if (t[i] == "(" || t[i] == ")") continue;
    if (i + 2 >= t.size() || t[i + 1] != "=")
      r.fail(l, ".model " + t[1] + ": expected name=value (got '" + t[i] + "')");
    p.emplace_back(t[i], r.number(l, ".model " + t[1] + ": " + t[i], t[i + 2]));
    i += 2;
  }
  return p;
}

// .model name SW(VT VH RON ROFF): RON and ROFF finite and > 0 (a switch is a
// resistor in both states: docs/circuits.md), VH >= 0 (ngspice's negative
// hysteresis is another state machine, not read).
void read_switch_model(Reader& r, const Line& l) {
  const std::string name = ".model " + l.tokens[1];
  SwitchModel m;
  for (const auto& [key_as_written, v] : model_parameters(r, l)) {
    const std::string key = lower(key_as_written);
    const std::string what = name + ": " + key_as_written;
    if (key == "vt") {
      m.vt = v;
    } else if (key == "vh") {
      if (v < 0.0) r.fail(l, what + " must be >= 0 (got " + format_number(v) + ")");
      m.vh = v;
    } else if (key == "ron" || key == "roff") {
      if (!(v > 0.0)) r.fail(l, what + " must be > 0 (got " + format_number(v) + ")");
      (key == "ron" ? m.ron : m.roff) = v;
    } else {
      r.fail(l, name + ": unknown switch parameter '" + key_as_written +
                    "' (lcsim reads VT, VH, RON and ROFF; docs/circuits.md)");
    }
  }
  r.switch_models[lower(l.tokens[1])] = m;
}

void read_model(Reader& r, const Line& l) {
  const auto& t = l.tokens;
  if (t.size() < 3)
    r.fail(l, ".model: expected `.model name D(params)` or `.model name SW(params)`");
  const std::string type = lower(t[2]);
  if (type == "sw") return read_switch_model(r, l);
  if (type == "csw")
    r.fail(l, ".model " + t[1] +
                  ": current-controlled switches (CSW) are not supported (lcsim reads SW)");
  if (type != "d")
    r.fail(l, ".model " + t[1] + ": model type '" + t[2] +
                  "' is not supported (lcsim reads D and SW)");
  DiodeModel m;
  static const std::set<std::string> ignored = {"is", "n",    "cjo",   "cj0", "cj",  "vj", "m",
                                                "tt", "bv",   "ibv",   "eg",  "xti", "kf", "af",
                                                "fc", "tnom", "level", "js",  "pb",  "mj"};
  for (const auto& [key_as_written, v] : model_parameters(r, l)) {
    const std::string key = lower(key_as_written);
    if (key == "ron" || key == "rs") {
      if (v < 0.0)
        r.fail(l, ".model " + t[1] + ": " + key_as_written + " must be >= 0 (got " +
                      format_number(v) + ")");
      m.ron = v;
    } else if (key == "von") {
      m.von = v;
    } else if (!ignored.count(key)) {
      r.fail(l, ".model " + t[1] + ": unknown diode parameter '" + key_as_written +
                    "' (lcsim reads RON or RS, and VON; docs/circuits.md)");
    }
  }
  r.models[lower(t[1])] = m;
}

void read_ic(Reader& r, const Line& l) {
  const auto& t = l.tokens;
  std::size_t i = 1;
  if (r.net.ic_where.empty()) r.net.ic_where = r.where(l);
  while (i < t.size()) {
    if (i + 5 >= t.size() + 0 || lower(t[i]) != "v" || t[i + 1] != "(" || t[i + 3] != ")" ||
        t[i + 4] != "=")
      r.fail(l, ".ic: expected V(node)=value (at '" + t[i] + "')");
    const std::string key = lower(t[i + 2]);
    int node = 0;
    if (key != "0" && key != "gnd") {
      const auto it = r.node_index.find(key);
      if (it == r.node_index.end()) r.fail(l, ".ic: no node '" + t[i + 2] + "' in the circuit");
      node = it->second;
    }
    r.net.ic[node] = r.number(l, ".ic V(" + t[i + 2] + ")", t[i + 5]);
    i += 6;
  }
}

void read_tran(Reader& r, const Line& l) {
  const auto& t = l.tokens;
  std::vector<double> v;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (lower(t[i]) == "uic") {
      r.net.uic = true;
      continue;
    }
    v.push_back(r.number(l, ".tran", t[i]));
  }
  if (v.size() < 2 || v.size() > 4)
    r.fail(l, ".tran: expected `.tran tstep tstop [tstart [tmax]] [uic]`");
  if (!(v[0] > 0.0)) r.fail(l, ".tran: tstep must be > 0 (got " + format_number(v[0]) + ")");
  if (!(v[1] > 0.0)) r.fail(l, ".tran: tstop must be > 0 (got " + format_number(v[1]) + ")");
  if (v.size() >= 3 && v[2] != 0.0)
    r.fail(l, ".tran: tstart > 0 is not yet supported (got " + format_number(v[2]) +
                  " s): lcsim writes the run from 0");
  r.net.tran = true;
  r.net.tstep = v[0];
  r.net.tstop = v[1];
}

// The first pass: definitions (.subckt bodies, .model) and control lines,
// and the element lines of the top level, in order.
void first_pass(Reader& r, const std::vector<Line>& lines) {
  static const std::set<std::string> ignored = {".options", ".option", ".opt",  ".print",
                                                ".plot",    ".probe",  ".save", ".op",
                                                ".width",   ".temp",   ".title"};
  Subckt* open = nullptr;
  bool control = false;
  for (const Line& l : lines) {
    const std::string k = lower(l.tokens[0]);
    if (control) {
      control = k != ".endc";
      continue;
    }
    if (k == ".end") break;
    if (k == ".subckt") {
      if (open) r.fail(l, ".subckt inside .subckt " + open->name + " is not supported");
      if (l.tokens.size() < 2) r.fail(l, ".subckt: expected `.subckt name ports...`");
      Subckt s{l.tokens[1], {l.tokens.begin() + 2, l.tokens.end()}, {}};
      open = &(r.subckts[lower(s.name)] = s);
    } else if (k == ".ends") {
      if (!open) r.fail(l, ".ends without .subckt");
      open = nullptr;
    } else if (k == ".model") {
      read_model(r, l);
    } else if (k == ".control") {
      control = true;
    } else if (k[0] == '.') {
      if (ignored.count(k)) continue;  // output and option lines: nothing to model
      if (k != ".ic" && k != ".tran")
        r.fail(l,
               l.tokens[0] + " is not supported (lcsim reads .tran, .ic, .model, .subckt, .end)");
      if (open) r.fail(l, l.tokens[0] + " inside .subckt " + open->name + " is not supported");
      r.top.push_back(l);  // .ic and .tran: read after the elements
    } else if (open) {
      open->body.push_back(l);
    } else {
      r.top.push_back(l);
    }
  }
  if (open) throw InputError(r.source + ": .subckt " + open->name + " has no .ends");
}

// A PULSE as SPICE (ngspice) reads it: TD 0, and TR, TF (tstep), PW and PER
// (tstop) taking their defaults when omitted or 0. One period's points from
// TD, cut at PER when the pulse is longer (its value there is its value at
// PER, and the next period starts at V1), repeated every PER.
mech::Input make_pulse(const Reader& r, const PendingPulse& p, const std::string& name) {
  const auto defaulted = [](double x) { return std::isnan(x) || x == 0.0; };
  if (!r.net.tran &&
      (defaulted(p.v[3]) || defaulted(p.v[4]) || defaulted(p.v[5]) || defaulted(p.v[6])))
    throw InputError(p.where + ": " + name +
                     ": PULSE without TR, TF, PW or PER (or 0) takes tstep or tstop, and there "
                     "is no .tran");
  const auto value = [&](int j, double fallback) { return defaulted(p.v[j]) ? fallback : p.v[j]; };
  const double tr = value(3, r.net.tstep), tf = value(4, r.net.tstep);
  const double pw = value(5, r.net.tstop), per = value(6, r.net.tstop);
  mech::Input in;
  in.name = name;
  in.kind = "pulse";
  in.origin = std::isnan(p.v[2]) ? 0.0 : p.v[2];
  in.period = per;
  const double t[4] = {0.0, tr, tr + pw, tr + pw + tf};
  const double v[4] = {p.v[0], p.v[1], p.v[1], p.v[0]};
  for (int j = 0; j < 4; ++j) {
    if (t[j] <= per) {
      in.times.push_back(t[j]);
      in.values.push_back(v[j]);
      continue;
    }
    const double a = (per - t[j - 1]) / (t[j] - t[j - 1]);  // t[j - 1] <= per < t[j]
    in.times.push_back(per);
    in.values.push_back(v[j - 1] + a * (v[j] - v[j - 1]));
    break;
  }
  if (std::string what = mech::check_input(in); !what.empty())
    throw InputError(p.where + ": " + name + ": PULSE " + what);
  return in;
}

// Diodes get their model's parameters, F and H their controlling source.
void resolve(Reader& r) {
  for (std::size_t i = 0; i < r.net.elements.size(); ++i) {
    Element& e = r.net.elements[i];
    if (e.kind == ElementKind::kDiode) {
      const auto it = r.models.find(r.diode_model_of[i]);
      if (it == r.models.end())
        throw InputError(e.where + ": " + e.name + ": no .model '" + r.diode_model_of[i] + "'" +
                         (r.switch_models.count(r.diode_model_of[i]) ? " of type D" : ""));
      e.von = it->second.von;
      e.ron = it->second.ron;
    }
    if (e.kind == ElementKind::kSwitch) {
      const auto it = r.switch_models.find(r.diode_model_of[i]);
      if (it == r.switch_models.end())
        throw InputError(e.where + ": " + e.name + ": no .model '" + r.diode_model_of[i] +
                         "' of type SW");
      e.ron = it->second.ron;
      e.roff = it->second.roff;
      e.vt = it->second.vt;
      e.vh = it->second.vh;
    }
    if (e.kind == ElementKind::kCccs || e.kind == ElementKind::kCcvs) {
      bool found = false;
      for (const Element& c : r.net.elements)
        found |= c.kind == ElementKind::kVoltageSource && lower(c.name) == e.control;
      if (!found)
        throw InputError(e.where + ": " + e.name + ": no voltage source '" + e.control +
                         "' to measure its current");
    }
    if (e.wave.sine && std::isnan(e.wave.frequency)) {
      if (!r.net.tran)
        throw InputError(e.where + ": " + e.name +
                         ": SIN without FREQ takes 1/tstop, and there is no .tran");
      e.wave.frequency = 1.0 / r.net.tstop;
    }
    if (e.wave.input && e.wave.input->sine && std::isnan(e.wave.input->frequency)) {
      if (!r.net.tran)
        throw InputError(e.where + ": " + e.name +
                         ": SIN without FREQ takes 1/tstop, and there is no .tran");
      e.wave.input->frequency = 1.0 / r.net.tstop;
    }
  }
  for (const PendingPulse& p : r.pulses)
    r.net.elements[p.element].wave.input = make_pulse(r, p, r.net.elements[p.element].name);
}

}  // namespace

Netlist parse_netlist(const std::string& text, const std::string& source) {
  Reader r;
  r.source = source;
  r.net.source = source;
  r.net.nodes = {"0"};
  detail::Lines lines = detail::split_lines(text, source);
  detail::apply_params(lines, source);
  r.net.title = lines.title;
  first_pass(r, lines.lines);
  std::vector<Line> elements, controls;
  for (const Line& l : r.top) (l.tokens[0][0] == '.' ? controls : elements).push_back(l);
  expand(r, elements, Scope{}, 0);
  for (const Line& l : controls) {
    if (lower(l.tokens[0]) == ".ic")
      read_ic(r, l);
    else
      read_tran(r, l);
  }
  resolve(r);
  if (r.net.elements.empty()) throw InputError(source + ": no elements (an empty circuit)");
  return r.net;
}

}  // namespace lcsim::circuit
