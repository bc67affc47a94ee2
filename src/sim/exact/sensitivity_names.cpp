// The columns of a forward-sensitivity run (Options::sensitivity) and the
// run's check of them (check_sensitivity): "x0", and parameters of a
// frictionless mechanical model named f[i], g[c], e[c], K[i][j], D[i][j],
// M[i][j] with i, j a coordinate's 0-based index or name and c a
// constraint's, or of a general LCS named A[i][j], B[i][j], C[i][j],
// D[i][j] with its states' and pairs' names or indices, or an input's own
// (amplitude[in], frequency[in], pwl_v[in][k], ...; docs/sensitivities.md).
#include <algorithm>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <set>

#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim {

namespace detail {

namespace {

// The index of `key` among `names` (a 0-based number or a name), or -1.
int resolve(const std::string& key, const std::vector<std::string>& names) {
  if (key.empty()) return -1;
  for (size_t i = 0; i < names.size(); ++i)
    if (names[i] == key) return static_cast<int>(i);
  if (key.empty() ||
      !std::all_of(key.begin(), key.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return -1;
  if (key.size() > 9) return -1;
  const int i = std::stoi(key);
  return i < static_cast<int>(names.size()) ? i : -1;
}

// The bracketed keys of "K[0][1]" after the kind letter: {"0", "1"}; empty
// when the text is not of that form.
std::vector<std::string> keys(const std::string& s) {
  std::vector<std::string> out;
  size_t p = 1;
  while (p < s.size()) {
    if (s[p] != '[') return {};
    const size_t close = s.find(']', p);
    if (close == std::string::npos) return {};
    out.push_back(s.substr(p + 1, close - p - 1));
    p = close + 1;
  }
  return out;
}

// An input's own parameter (sensitivity_inputs.cpp): the name before the
// brackets, its kind letter, whether it takes a point index, and the input
// family it applies to ('s' sine, 'p' piecewise linear, 'u' a pulse, 'r' a
// step or a ramp (its time), 'b' both).
struct InputName {
  const char* word;
  char kind;
  bool point;
  char family;
};
constexpr InputName kInputNames[] = {
    {"amplitude", 'a', false, 's'}, {"offset", 'o', false, 's'}, {"frequency", 'w', false, 's'},
    {"damping", 'z', false, 's'},   {"phase", 'p', false, 's'},  {"delay", 'y', false, 'b'},
    {"pwl_v", 'v', true, 'p'},      {"pwl_t", 't', true, 'p'},   {"time", 't', false, 'r'},
    {"v1", '1', false, 'u'},        {"v2", '2', false, 'u'},     {"rise", 'r', false, 'u'},
    {"width", 'd', false, 'u'},     {"fall", 'l', false, 'u'},   {"period", 'T', false, 'u'}};

// Why a piecewise linear input's time parameter has one-sided derivatives
// only ("" if it has both): points of one time that move apart (a jump
// split, a zero rise or width), or a periodic input's point at 0 or at the
// period, or its period down to its last point.
std::string one_sided_times(const mech::Input& in, const SensParam& p) {
  const size_t n = in.times.size();
  std::vector<char> moves(n, 0);
  const auto mark = [&](std::initializer_list<size_t> at) {
    for (size_t k : at)
      if (k < n) moves[k] = 1;
  };
  switch (p.kind) {
    case 't':
      for (size_t k = 0; k < n; ++k) moves[k] = in.times[k] == in.times[static_cast<size_t>(p.j)];
      break;
    case 'r':
      mark({1, 2, 3});
      break;
    case 'd':
      mark({2, 3});
      break;
    case 'l':
      mark({3});
      break;
    case 'T':
      return in.times.back() == in.period
                 ? "the pulse fills its period (rise + width + fall = period): a shorter period "
                   "is not a pulse"
                 : "";
    default:
      return "";
  }
  for (size_t k = 0; k + 1 < n; ++k)
    if (in.times[k] == in.times[k + 1] && moves[k] != moves[k + 1])
      return "points " + std::to_string(k) + " and " + std::to_string(k + 1) +
             " share a time and one of them moves (a zero rise, width or fall): the times "
             "would cross";
  for (size_t k = 0; k < n && in.period > 0.0; ++k)
    if (moves[k] && (in.times[k] == 0.0 || in.times[k] == in.period))
      return "a periodic input's point at the period's start or end moves out of its period";
  return "";
}

// "" when the input's kind has the parameter, else why not.
std::string kind_fits(const mech::Input& in, const InputName& w) {
  const bool fits = w.family == 'b' || (w.family == 's' && in.sine) ||
                    (w.family == 'p' && !in.sine) || (w.family == 'u' && in.kind == "pulse") ||
                    (w.family == 'r' && (in.kind == "step" || in.kind == "ramp"));
  if (fits) return "";
  return std::string("input '") + in.name + "' is a " + in.kind + ": it has no " + w.word +
         " (a sine: amplitude, offset, frequency, damping, phase, delay; piecewise linear: "
         "pwl_v[in][k], pwl_t[in][k], delay; a step or ramp also time; a pulse also v1, v2, "
         "rise, width, fall, period)";
}

// "" when the parameter has a two-sided derivative at the input's values.
std::string two_sided(const mech::Input& in, const SensParam& p) {
  if (in.sine && p.kind == 'y' && in.origin == 0.0 && in.amplitude * std::sin(in.phase) != 0.0)
    return "the sine starts off its offset at t = 0 with a zero delay: only one-sided "
           "derivatives exist";
  return in.sine ? "" : one_sided_times(in, p);
}

}  // namespace

bool parse_input_param(const mech::MechanicalModel& m, const std::string& s, SensParam& p,
                       std::string& error) {
  const size_t open = s.find('[');
  if (open == std::string::npos) return false;
  const std::string word = s.substr(0, open);
  const InputName* w = nullptr;
  for (const InputName& c : kInputNames)
    if (word == c.word) w = &c;
  if (w == nullptr) return false;
  const std::string bad = "sensitivity '" + s + "': ";
  const std::vector<std::string> k = keys(s.substr(open - 1));
  if (k.size() != (w->point ? 2u : 1u)) {
    error = bad + "expected " + (w->point ? "two indices, as " : "one index, as ") + word +
            (w->point ? "[push][1]" : "[push]");
    return true;
  }
  std::vector<std::string> names;
  for (const mech::Input& in : m.inputs) names.push_back(in.name);
  p.kind = w->kind;
  p.name = s;
  p.i = resolve(k[0], names);
  if (p.i < 0) {
    error = bad + "no input '" + k[0] + "'";
    return true;
  }
  const mech::Input& in = m.inputs[static_cast<size_t>(p.i)];
  if (error = kind_fits(in, *w); !error.empty()) {
    error = bad + error;
    return true;
  }
  if (w->point) {
    std::vector<std::string> points(in.times.size());
    p.j = resolve(k[1], points);
    if (p.j < 0) {
      error = bad + "no point '" + k[1] + "' (input '" + in.name + "' has " +
              std::to_string(in.times.size()) + ", from 0)";
      return true;
    }
  } else {
    p.j = 0;  // time[in]: a step's or a ramp's one time, point 0
  }
  error = two_sided(in, p);
  if (!error.empty()) error = bad + error;
  return true;
}

namespace {

std::string parse_one(const mech::MechanicalModel& m, const std::string& s, SensParam& p) {
  const std::string bad = "sensitivity '" + s + "': ";
  if (std::string error; parse_input_param(m, s, p, error)) return error;
  if (s.rfind("mu[", 0) == 0) {  // a contact's friction coefficient: kind 'u'
    const std::vector<std::string> k = keys(s.substr(1));
    if (k.size() != 1u) return bad + "expected one index, as mu[floor]";
    p.kind = 'u';
    p.name = s;
    p.i = resolve(k[0], m.constraints);
    if (p.i < 0) return bad + "no constraint '" + k[0] + "'";
    for (size_t f = 0; f < m.friction.size(); ++f)
      if (m.friction[f].contact == p.i) p.j = static_cast<int>(f);
    if (p.j < 0) return bad + "constraint '" + k[0] + "' has no friction (mechanical.friction)";
    return "";
  }
  if (s.size() < 2 || std::string("fgeKDM").find(s[0]) == std::string::npos)
    return bad +
           "not a parameter name (x0, f[i], g[c], e[c], K[i][j], D[i][j], M[i][j], or an "
           "input's: amplitude[in], frequency[in], pwl_v[in][k], ...)";
  p.kind = s[0];
  p.name = s;
  const std::vector<std::string> k = keys(s);
  const bool matrix = p.kind == 'K' || p.kind == 'D' || p.kind == 'M';
  if (k.size() != (matrix ? 2u : 1u))
    return bad + (matrix ? "expected two indices, as " + std::string(1, p.kind) + "[0][1]"
                         : "expected one index, as " + std::string(1, p.kind) + "[0]");
  const bool on_constraint = p.kind == 'g' || p.kind == 'e';
  const auto& names = on_constraint ? m.constraints : m.coordinates;
  p.i = resolve(k[0], names);
  if (p.i < 0)
    return bad + "no " + (on_constraint ? "constraint" : "coordinate") + " '" + k[0] + "'";
  if (matrix) {
    p.j = resolve(k[1], m.coordinates);
    if (p.j < 0) return bad + "no coordinate '" + k[1] + "'";
  }
  return "";
}

// A general LCS's entry: A[state][state], B[state][pair], C[pair][state],
// D[pair][pair]. The exosystem's rows of A and B are the inputs' own
// dynamics (kept autonomous, re-set at breakpoints): not named.
std::string parse_one_lcs(const mech::Model& model, const std::string& s, SensParam& p) {
  const std::string bad = "sensitivity '" + s + "': ";
  const lcs::Lcs& sys = *model.lcs;
  if (s.size() < 2 || std::string("ABCD").find(s[0]) == std::string::npos)
    return bad + "not a parameter name of a general LCS (x0, A[i][j], B[i][j], C[i][j], D[i][j])";
  p.kind = s[0];
  p.name = s;
  const std::vector<std::string> k = keys(s);
  if (k.size() != 2u) return bad + "expected two indices, as " + std::string(1, p.kind) + "[0][1]";
  auto names = [](const std::vector<std::string>& given, int count) {
    std::vector<std::string> out = given;
    if (static_cast<int>(out.size()) != count) out.assign(static_cast<size_t>(count), "");
    return out;
  };
  const std::vector<std::string> states = names(model.state_names, sys.n()),
                                 pairs = names(model.pair_names, sys.k());
  const bool row_state = p.kind == 'A' || p.kind == 'B', col_state = p.kind == 'A' || p.kind == 'C';
  p.i = resolve(k[0], row_state ? states : pairs);
  if (p.i < 0) return bad + "no " + (row_state ? "state" : "pair") + " '" + k[0] + "'";
  p.j = resolve(k[1], col_state ? states : pairs);
  if (p.j < 0) return bad + "no " + (col_state ? "state" : "pair") + " '" + k[1] + "'";
  if (row_state && p.i >= sys.n() - model.exo_states)
    return bad + "state '" + k[0] + "' is an input's (the exosystem's, the last " +
           std::to_string(model.exo_states) + " of " + std::to_string(sys.n()) +
           " states): its dynamics are the input's own, not named";
  return "";
}

}  // namespace

SensColumns parse_sensitivity(const mech::Model& model, const std::vector<std::string>& asked) {
  SensColumns c;
  std::set<std::string> seen;
  for (const std::string& s : asked) {
    if (!seen.insert(s).second) {
      c.error = "sensitivity '" + s + "': asked twice";
      return c;
    }
    if (s == "x0") {
      c.x0 = true;
      continue;
    }
    SensParam p;
    c.error =
        model.is_mechanical() ? parse_one(*model.mechanical, s, p) : parse_one_lcs(model, s, p);
    if (!c.error.empty()) return c;
    c.params.push_back(p);
  }
  return c;
}

}  // namespace detail

namespace {

// What a time-stepping scheme's step map cannot differentiate: "" or why.
// The schemes know the kinds f, K, D, M, g, e and a (step_sensitivity.cpp);
// any other kind is refused by name, never taken as a zero column.
std::string refuse_for_scheme(const detail::SensColumns& c, std::string_view method) {
  for (const detail::SensParam& p : c.params) {
    if (std::string_view(method == "moreau-jean" || method == "euler" ? "fKDMgeau" : "fKDMgea")
            .find(p.kind) == std::string_view::npos)
      return "Options::sensitivity '" + p.name + "': method '" + std::string(method) +
             "' does not compute it (the method 'event' does)";
    if (method == "moreau-jean" && p.kind == 'g')
      return "Options::sensitivity '" + p.name +
             "': method 'moreau-jean' does not compute it (its step map depends on the gap "
             "offsets only through the active set, so its derivative there is zero or absent; "
             "the method 'event' computes it)";
    if (method == "euler" && p.kind == 'e')
      return "Options::sensitivity '" + p.name +
             "': method 'euler' does not compute it (backward Euler ignores restitution; the "
             "method 'event' computes it)";
  }
  return "";
}

// Friction: Moreau–Jean's and backward Euler's step maps at their stick /
// slip outcome, planar or 3-D (step_sensitivity.cpp, the columns the scheme
// knows); the exact
// method through planar stick / slip, x0 and the parameters that leave the
// friction's columns as they are; "" or why not.
std::string refuse_friction(const mech::Model& model, const Options& opt, std::string_view method,
                            const OptionsUsed& used) {
  const std::string head =
      "Options::sensitivity: model '" + model.name + "' has mechanical.friction; ";
  // Backward Euler's step with friction is Moreau–Jean's at theta = 1 with
  // the normal rows on the gap (step_sensitivity.hpp's euler_gap): the same
  // pieces, planar and 3-D.
  if (method == "moreau-jean" || method == "euler") return "";
  const mech::MechanicalModel& m = *model.mechanical;
  // The exact method differentiates 3-D phases and impacts
  // (sensitivity_cone*.cpp); the other methods (but moreau-jean) do not.
  for (size_t f = 0; f < m.friction.size() && !used.event_search; ++f)
    if (m.friction[f].is_3d())
      return head + "mechanical.friction[" + std::to_string(f) +
             "] is a 3-D contact (tangent2): sensitivities through 3-D friction are not computed "
             "by the method '" +
             std::string(method) + "' (moreau-jean's step map is)";
  if (!used.event_search)
    return head + "method '" + std::string(method) +
           "' does not compute sensitivities through stick / slip (methods 'event', "
           "'moreau-jean' and 'euler' do)";
  // The free acceleration's parameters, the gap offsets, the mass matrix and
  // the restitutions: f, K, D, g, M, e, and a force input's own parameters
  // (sensitivity_friction.cpp; a model with friction has no moving stop).
  for (const std::string& s : opt.sensitivity) {
    detail::SensParam input;
    std::string input_error;  // parse_sensitivity reports it
    if (s != "x0" && s.rfind("mu[", 0) != 0 &&
        !(s.size() > 1 && std::string("fgKDMe").find(s[0]) != std::string::npos && s[1] == '[') &&
        !detail::parse_input_param(m, s, input, input_error))
      return "Options::sensitivity '" + s + "': not computed with friction (model '" + model.name +
             "' has mechanical.friction; through planar stick / slip x0, f[i], g[c], K[i][j], "
             "D[i][j], M[i][j], e[c], mu[c] and an input's own parameters are)";
  }
  // Through 3-D stick / slip and 3-D impacts (sensitivity_cone*.cpp) the
  // same columns: M[i][j] and e[c] through the cone impact's map, an input's
  // own parameters through the phases (a model with friction has no moving
  // stop, so they do not enter an impact).
  return "";
}

}  // namespace

std::string check_sensitivity(const mech::Model& model, const Options& opt, std::string_view method,
                              const OptionsUsed& used) {
  if (opt.sensitivity.empty()) return "";
  if (!used.sensitivity)
    return "method '" + std::string(method) +
           "' does not compute Options::sensitivity (the methods 'event', 'euler' and "
           "'moreau-jean' do)";
  const bool friction = model.is_mechanical() && model.mechanical->has_friction();
  if (friction) {
    if (const std::string why = refuse_friction(model, opt, method, used); !why.empty()) return why;
  }
  const std::string law = used.impact ? impact::make_impact_law(opt.impact)->name() : "";
  // With friction the law is a friction law: its impacts are reported
  // absent (sensitivity.cpp), so any law is taken.
  if (!friction && used.impact && model.is_mechanical() && law != "moreau-restitution" &&
      law != "newton" && law != "inelastic")
    return "Options::sensitivity: impact law '" + opt.impact +
           "' has no derivative computed (moreau-restitution, newton and inelastic are linear "
           "at a fixed active set)";
  const detail::SensColumns c = detail::parse_sensitivity(model, opt.sensitivity);
  if (!c.error.empty()) return c.error;
  if (!model.is_mechanical() && !c.params.empty() && !used.event_search)
    return "Options::sensitivity '" + c.params.front().name + "': method '" + std::string(method) +
           "' does not compute a general LCS's parameters (the method 'event' does)";
  return used.event_search ? "" : refuse_for_scheme(c, method);
}

}  // namespace lcsim::sim
