// The switch schedule of a circuit with ideal switches (docs/circuits.md):
// each switch's control voltage is a known piecewise-linear function of
// time (sources alone fix it), so its on and off times are the threshold
// crossings of that function, with SPICE's hysteresis: on when the control
// exceeds VT + VH, off when it falls below VT - VH, unchanged between.
#include <algorithm>
#include <cmath>
#include <lcsim/circuit/circuit.hpp>
#include <limits>
#include <map>

#include "circuit/reduce.hpp"

namespace lcsim::circuit::detail {
namespace {

struct Toggle {
  double t;
  int sw;
  bool on;
};

// The exosystem matrix of `inputs`, block by block (w' = S w).
MatrixXd exo_matrix(const std::vector<mech::Input>& inputs) {
  int size = 0;
  for (const mech::Input& in : inputs) size += in.exo_size();
  MatrixXd S = MatrixXd::Zero(size, size);
  int at = 0;
  for (const mech::Input& in : inputs) {
    S.block(at, at, in.exo_size(), in.exo_size()) = in.exo_matrix();
    at += in.exo_size();
  }
  return S;
}

// One switch over the piece [a, b) on which its control is va + slope (t - a):
// a jump at a (the control's value there crossing a threshold), then at
// most one crossing inside (the piece is monotone and VT - VH <= VT + VH).
void switch_on_piece(const Element& e, int sw, double a, double b, double va, double slope,
                     bool& on, std::vector<Toggle>& out) {
  const double on_th = e.vt + e.vh, off_th = e.vt - e.vh;
  if (a > 0.0 && ((!on && va > on_th) || (on && va < off_th))) {
    on = !on;
    out.push_back({a, sw, on});
  }
  double t = std::numeric_limits<double>::infinity();
  if (!on && slope > 0.0 && va <= on_th) t = a + (on_th - va) / slope;
  if (on && slope < 0.0 && va >= off_th) t = a + (off_th - va) / slope;
  if (!(t < b)) return;
  on = !on;
  if (t <= 0.0) return;  // at t = 0 itself: the state the run starts in
  out.push_back({t, sw, on});
}

}  // namespace

SwitchSchedule switch_schedule(const Netlist& net, const std::vector<int>& switches,
                               const std::vector<SwitchControl>& controls,
                               const std::vector<mech::Input>& inputs, double horizon) {
  const MatrixXd S = exo_matrix(inputs);
  SwitchSchedule s;
  const std::size_t ns = switches.size();
  std::vector<bool> on(ns);
  std::vector<Toggle> toggles;
  double a = 0.0;
  while (a < horizon) {
    const double next = inputs.empty() ? horizon : mech::next_breakpoint(inputs, a);
    const double b = std::min(next, horizon);
    const VectorXd w = inputs.empty() ? VectorXd() : mech::exosystem_states(inputs, a);
    const VectorXd dw = inputs.empty() ? VectorXd() : VectorXd(S * w);
    for (std::size_t j = 0; j < ns; ++j) {
      const Element& e = net.elements[switches[j]];
      const double va = controls[j].c + (inputs.empty() ? 0.0 : controls[j].g.dot(w));
      const double slope = inputs.empty() ? 0.0 : controls[j].g.dot(dw);
      if (a == 0.0) on[j] = va > e.vt + e.vh ? true : va < e.vt - e.vh ? false : e.starts_on;
      bool state = on[j];
      switch_on_piece(e, static_cast<int>(j), a, b, va, slope, state, toggles);
      on[j] = state;
    }
    a = b;
  }
  // The initial states: each switch's before its first toggle.
  s.initial.assign(ns, false);
  std::vector<bool> seen(ns, false);
  for (const Toggle& t : toggles)
    if (!seen[t.sw]) seen[t.sw] = true, s.initial[t.sw] = !t.on;
  for (std::size_t j = 0; j < ns; ++j)
    if (!seen[j]) s.initial[j] = on[j];
  std::stable_sort(toggles.begin(), toggles.end(),
                   [](const Toggle& x, const Toggle& y) { return x.t < y.t; });
  std::vector<bool> now = s.initial;
  for (std::size_t i = 0; i < toggles.size();) {
    const double t = toggles[i].t;
    std::string note;
    for (; i < toggles.size() && toggles[i].t == t; ++i) {
      now[toggles[i].sw] = toggles[i].on;
      note += (note.empty() ? "" : ", ") + net.elements[switches[toggles[i].sw]].name +
              (toggles[i].on ? " on" : " off");
    }
    s.times.push_back(t);
    s.after.push_back(now);
    s.notes.push_back(note);
  }
  return s;
}

}  // namespace lcsim::circuit::detail
