// A circuit's initial state: `.tran ... uic` starts from the IC= values and
// the .ic node voltages; without uic from the DC operating point that the
// sources at t = 0 and .ic imply (docs/circuits.md, "Initial state").
#include <Eigen/LU>
#include <cmath>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/lcp/lcp.hpp>

#include "circuit/reduce.hpp"

namespace lcsim::circuit::detail {
namespace {

std::optional<double> ic_of(const Netlist& net, int node) {
  if (node == 0) return 0.0;
  const auto it = net.ic.find(node);
  if (it == net.ic.end()) return std::nullopt;
  return it->second;
}

// uic: IC= on the element, else a capacitor's .ic node voltages (0 where not
// given), an inductor's 0.
VectorXd uic_state(const Circuit& c, VectorXd x) {
  const Netlist& net = c.netlist;
  for (int s = 0; s < c.circuit_states; ++s) {
    const Element& e = net.elements[c.state_element[s]];
    if (e.ic) {
      x(s) = *e.ic;
    } else if (e.kind == ElementKind::kCapacitor) {
      x(s) = ic_of(net, e.nodes[0]).value_or(0.0) - ic_of(net, e.nodes[1]).value_or(0.0);
    }
  }
  return x;
}

// Without uic: the capacitors whose two terminals have .ic values (ground is
// 0) are held at their difference; every .ic node must belong to one.
std::vector<bool> fix_capacitors(const Circuit& c, VectorXd& x) {
  const Netlist& net = c.netlist;
  std::vector<bool> fixed(c.circuit_states, false), used(net.nodes.size(), false);
  for (int s = 0; s < c.circuit_states; ++s) {
    const Element& e = net.elements[c.state_element[s]];
    const auto a = ic_of(net, e.nodes[0]), b = ic_of(net, e.nodes[1]);
    if (e.kind != ElementKind::kCapacitor || !a || !b || (e.nodes[0] == 0 && e.nodes[1] == 0))
      continue;
    if (e.nodes[0] != 0 && !net.ic.count(e.nodes[0])) continue;
    if (e.nodes[1] != 0 && !net.ic.count(e.nodes[1])) continue;
    fixed[s] = true;
    x(s) = *a - *b;
    used[e.nodes[0]] = used[e.nodes[1]] = true;
  }
  for (const auto& [node, value] : net.ic)
    if (!used[node])
      throw InputError(net.ic_where + ": .ic V(" + net.nodes[node] + ")=" + format_number(value) +
                       ": without uic lcsim holds .ic through capacitors whose terminals all "
                       "have .ic values (or are ground); no capacitor joins '" +
                       net.nodes[node] + "' so (not yet supported: use uic, or add its .ic)");
  return fixed;
}

}  // namespace

// The operating point: with the exosystem and the fixed capacitors given
// (G), the free circuit states R solve A_RR x_R + A_RG x_G + B_R u = 0, and
// the diodes y = C x + D u the LCP 0 <= q + M u ⟂ u >= 0 with
// M = D - C_R A_RR^{-1} B_R, q = C_G x_G - C_R A_RR^{-1} A_RG x_G.
VectorXd initial_state(const Circuit& c, std::string& note) {
  const Netlist& net = c.netlist;
  const lcs::Lcs& s = *c.model.lcs;
  const int n = s.n(), k = s.k();
  VectorXd x = VectorXd::Zero(n);
  x.tail(c.model.exo_states) = c.model.exo_initial;
  if (net.uic) {
    note = "uic: the states from IC= and .ic (0 where not given)";
    return uic_state(c, x);
  }
  const std::vector<bool> fixed = fix_capacitors(c, x);
  std::vector<int> R, G;
  for (int i = 0; i < n; ++i) (i < c.circuit_states && !fixed[i] ? R : G).push_back(i);
  const int nr = static_cast<int>(R.size());
  const MatrixXd ARR = s.A(R, R), ARG = s.A(R, G), BR = s.B(R, Eigen::all);
  const MatrixXd CR = s.C(Eigen::all, R), CG = s.C(Eigen::all, G);
  const VectorXd xG = x(G);
  // A resistive circuit has no free state (nr = 0): no factorisation of the
  // empty A_RR (Eigen asserts on it, and reads past it without assertions).
  Eigen::FullPivLU<MatrixXd> lu;
  lu.setThreshold(1e-12 * std::max(1, nr));
  if (nr > 0) lu.compute(ARR);
  if (nr > 0 && !lu.isInvertible()) {
    // The states the first null vector moves (to 1e-9 of its largest entry).
    const VectorXd v = lu.kernel().col(0);
    std::string states;
    for (int i = 0; i < nr; ++i)
      if (std::abs(v(i)) > 1e-9 * v.cwiseAbs().maxCoeff())
        states += (states.empty() ? "" : ", ") + c.model.state_names[R[i]];
    throw InputError(net.source +
                     ": operating point: the DC equations (capacitors open, inductors "
                     "shorted) have no unique solution for " +
                     states +
                     " (a capacitor without a DC path, a loop of inductors, or an inductor "
                     "across a voltage that .ic holds): give .ic values or use `.tran ... uic`");
  }
  const VectorXd T = nr > 0 ? VectorXd(lu.solve(ARG * xG)) : VectorXd::Zero(0);
  // No solve with an empty right-hand side (Eigen offsets a null pointer).
  const MatrixXd U = nr > 0 && k > 0 ? MatrixXd(lu.solve(BR)) : MatrixXd::Zero(nr, k);
  VectorXd u = VectorXd::Zero(k);
  if (k > 0) {
    const MatrixXd M = s.D - CR * U;
    const VectorXd q = CG * xG - CR * T;
    const lcp::Result r = lcp::make_solver("pivot")->solve(M, q, lcp::Options{});
    if (!r.ok())
      throw InputError(net.source +
                       ": operating point: the diodes' LCP at t = 0 has no solution (" + r.message +
                       "): use `.tran ... uic` and give the initial state");
    u = r.z;
  }
  if (nr > 0) x(R) = -T - U * u;
  note = "the operating point at t = 0 (capacitors open, inductors shorted, diodes by an LCP)";
  return x;
}

}  // namespace lcsim::circuit::detail
