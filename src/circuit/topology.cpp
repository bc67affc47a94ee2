// The structure of a circuit, judged before its equations are formed: a
// floating node, a loop of capacitors and voltage sources, a cut set of
// inductors and current sources (each makes modified nodal analysis singular,
// or leaves the state form without an LCS), and the form of each diode.
#include <algorithm>
#include <deque>
#include <lcsim/circuit/circuit.hpp>
#include <numeric>

#include "circuit/reduce.hpp"

namespace lcsim::circuit::detail {
namespace {

struct UnionFind {
  std::vector<int> parent;
  explicit UnionFind(std::size_t n) : parent(n) { std::iota(parent.begin(), parent.end(), 0); }
  int find(int a) {
    while (parent[a] != a) a = parent[a] = parent[parent[a]];
    return a;
  }
  bool unite(int a, int b) {
    a = find(a), b = find(b);
    if (a == b) return false;
    parent[a] = b;
    return true;
  }
};

// "R1, C2 and V1": at most 8 names, then how many more.
std::string name_list(const Netlist& net, const std::vector<int>& elements) {
  std::string s;
  const std::size_t shown = std::min<std::size_t>(elements.size(), 8);
  for (std::size_t i = 0; i < shown; ++i)
    s += (i == 0 ? "" : (i + 1 == elements.size() ? " and " : ", ")) +
         net.elements[elements[i]].name;
  if (shown < elements.size()) s += " and " + std::to_string(elements.size() - shown) + " more";
  return s;
}

std::string node_list(const Netlist& net, const std::vector<int>& nodes) {
  std::string s;
  const std::size_t shown = std::min<std::size_t>(nodes.size(), 8);
  for (std::size_t i = 0; i < shown; ++i) s += (i ? ", " : "") + net.nodes[nodes[i]];
  if (shown < nodes.size()) s += ", ...";
  return s;
}

// The elements on a path from a to b through `branches` (element indices
// already joined without a loop), by breadth-first search.
std::vector<int> path_between(const Netlist& net, const std::vector<int>& branches, int a, int b) {
  std::vector<std::vector<std::pair<int, int>>> adj(net.nodes.size());
  for (int e : branches) {
    adj[net.elements[e].nodes[0]].push_back({net.elements[e].nodes[1], e});
    adj[net.elements[e].nodes[1]].push_back({net.elements[e].nodes[0], e});
  }
  std::vector<std::pair<int, int>> from(net.nodes.size(), {-1, -1});
  std::deque<int> queue{a};
  from[a] = {a, -1};
  while (!queue.empty()) {
    const int v = queue.front();
    queue.pop_front();
    for (const auto& [w, e] : adj[v])
      if (from[w].first < 0) {
        from[w] = {v, e};
        queue.push_back(w);
      }
  }
  std::vector<int> path;
  for (int v = b; v != a && from[v].first >= 0; v = from[v].first) path.push_back(from[v].second);
  return path;
}

}  // namespace

bool voltage_defined(ElementKind k) {
  return k == ElementKind::kVoltageSource || k == ElementKind::kCapacitor ||
         k == ElementKind::kVcvs || k == ElementKind::kCcvs;
}

void check_floating(const Netlist& net) {
  const std::size_t nn = net.nodes.size();
  std::vector<std::vector<int>> at(nn);
  UnionFind all(nn);
  for (std::size_t i = 0; i < net.elements.size(); ++i) {
    const Element& e = net.elements[i];
    at[e.nodes[0]].push_back(static_cast<int>(i));
    if (e.nodes[1] != e.nodes[0]) at[e.nodes[1]].push_back(static_cast<int>(i));
    all.unite(e.nodes[0], e.nodes[1]);
  }
  // A switch's control may be a voltage source that drives nothing else (a
  // node only it touches): its voltage is the source's, and MNA stays regular.
  std::vector<bool> sensed(nn, false);
  for (const Element& e : net.elements)
    if (e.kind == ElementKind::kSwitch) sensed[e.nodes[2]] = sensed[e.nodes[3]] = true;
  for (std::size_t v = 1; v < nn; ++v) {
    if (at[v].size() == 1 && sensed[v] && voltage_defined(net.elements[at[v][0]].kind)) continue;
    if (at[v].empty())
      throw InputError(net.source + ": floating node '" + net.nodes[v] +
                       "': no element connects to it (it is only sensed by a controlled source)");
    if (at[v].size() == 1)
      throw InputError(net.elements[at[v][0]].where + ": " + net.elements[at[v][0]].name +
                       ": floating node '" + net.nodes[v] + "': nothing else connects to it");
  }
  for (std::size_t v = 1; v < nn; ++v)
    if (all.find(static_cast<int>(v)) != all.find(0))
      throw InputError(net.elements[at[v][0]].where + ": " + net.elements[at[v][0]].name +
                       ": floating node '" + net.nodes[v] +
                       "': no path to ground (node 0) through any element");
}

void check_voltage_loops(const Netlist& net) {
  UnionFind uf(net.nodes.size());
  std::vector<int> joined;
  for (std::size_t i = 0; i < net.elements.size(); ++i) {
    const Element& e = net.elements[i];
    if (!voltage_defined(e.kind)) continue;
    if (!uf.unite(e.nodes[0], e.nodes[1])) {
      std::vector<int> loop = path_between(net, joined, e.nodes[0], e.nodes[1]);
      loop.insert(loop.begin(), static_cast<int>(i));
      throw InputError(e.where + ": " + e.name + ": a loop of capacitors and voltage sources (" +
                       name_list(net, loop) +
                       "): their voltages are not independent (add a resistance in the loop)");
    }
    joined.push_back(static_cast<int>(i));
  }
}

std::vector<DiodeForm> diode_forms_and_cut_sets(const Netlist& net) {
  const std::size_t nn = net.nodes.size();
  UnionFind uf(nn);
  for (const Element& e : net.elements)
    if (voltage_defined(e.kind) || e.kind == ElementKind::kResistor ||
        e.kind == ElementKind::kSwitch)  // a resistor of RON or ROFF
      uf.unite(e.nodes[0], e.nodes[1]);
  std::vector<DiodeForm> forms;
  for (const Element& e : net.elements)
    if (e.kind == ElementKind::kDiode)
      forms.push_back(uf.unite(e.nodes[0], e.nodes[1]) ? DiodeForm::kVoltage : DiodeForm::kCurrent);
  for (std::size_t v = 1; v < nn; ++v) {
    if (uf.find(static_cast<int>(v)) == uf.find(0)) continue;
    const int root = uf.find(static_cast<int>(v));
    std::vector<int> nodes, cut;
    for (std::size_t w = 1; w < nn; ++w)
      if (uf.find(static_cast<int>(w)) == root) nodes.push_back(static_cast<int>(w));
    for (std::size_t i = 0; i < net.elements.size(); ++i) {
      const Element& e = net.elements[i];
      if ((uf.find(e.nodes[0]) == root) != (uf.find(e.nodes[1]) == root))
        cut.push_back(static_cast<int>(i));
    }
    const Element& first = net.elements[cut.empty() ? 0 : cut[0]];
    throw InputError(first.where + ": " + first.name + ": a cut set of inductors and current " +
                     "sources (" + name_list(net, cut) + ") around node(s) " +
                     node_list(net, nodes) +
                     ": no resistor, capacitor or voltage source joins them to ground, so their "
                     "currents are not independent");
  }
  return forms;
}

}  // namespace lcsim::circuit::detail
