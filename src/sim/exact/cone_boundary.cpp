// Stick forces reaching the polygon at an event (issue 27; docs/friction.md,
// "Stick forces reaching the polygon together"). When a sticking contact's
// force reaches a face of its polygon, the acceleration-level selection is
// degenerate: stick, with the force exactly on the face, solves the cone
// LCP (cone_guess.cpp), and so does slip on that face; what decides is the
// next derivative, the rate at which the force leaves the polygon, as the
// LDCP's levels decide for the normals. The selection's first candidate
// (all stick) then fails its own monitors: the stick monitor of that face
// starts at zero and leaves it downwards. When several contacts reach their
// polygons together (four toes on a floor, two of them by symmetry), the
// enumeration of select_cone_friction cannot reach the combination that
// slips them all: (1 + 4d)^k combinations, odometer order, at most 4096.
//
// The boundary set B is read from the first candidate's phase: the contacts
// with a friction monitor starting at zero (within its noise) with a nonzero
// derivative, of either sign (one leaving upwards alone may leave downwards
// once another contact of B slips), or failing from a value beyond its noise
// (a force a rounding outside its face). The other contacts keep their first
// candidate: their monitors start strictly inside, and a change of mode of
// B that keeps B's forces where they are (below) leaves every force
// continuous at the event, so theirs stay inside. Each contact of B gets
// the modes whose force is where its stick force is:
//   - sticking, its force on face j of the polygon (strictly inside it: one
//     monitor at zero): stick, or slip with the force on face j (the
//     velocity along -n_j); at a vertex (the monitors of faces j and j+1 at
//     zero): stick, slip on either face, or on the edge between them;
//   - a planar contact (d = 1) sticking at the edge +mu u_N (-mu u_N):
//     stick, slip- (slip+);
//   - in another mode (a slip whose sliding stops, or reaches a bisector):
//     its candidates from cone_candidates.
// Every combination over B is judged by its phase's monitors (consistent).
// One passes: it is the selection. Several pass: the motion is not decided
// by the monitors' first nonzero derivatives, and the selection is refused
// naming two of them. None: "" with `found` false, and the caller goes on as
// before.
#include <algorithm>
#include <lcsim/core/format.hpp>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// At most this many combinations over B are judged (4^k for k contacts each
// on one face: every contact of a quadruped at a vertex is 4^4 = 256).
constexpr size_t kMaxBoundaryCombinations = 4096;

// The modes of a sticking cone contact with d edge pairs whose stick
// monitors of the faces marked in `zero` start at zero.
std::vector<FrictionMode> boundary_modes(const std::vector<char>& zero, int d) {
  std::vector<FrictionMode> out{FrictionMode::kStick};
  const int n = 2 * d;
  for (int j = 0; j < n; ++j) {
    if (!zero[static_cast<size_t>(j)]) continue;
    out.push_back(cone_face((j + d) % n));  // the force on face j: velocity along -n_j
    // Faces j and j+1 meet at vertex j+1: the force on that edge.
    if (zero[static_cast<size_t>((j + 1) % n)]) out.push_back(cone_edge((j + 1 + d) % n));
  }
  return out;
}

}  // namespace

std::string EventDriven::select_cone_boundary(double t, const lcs::IndexSet& mode,
                                              const lcs::IndexSet& undetermined,
                                              const std::vector<std::vector<FrictionMode>>& cand,
                                              const VectorXd& xa, std::vector<FrictionMode>& fm,
                                              bool& found) {
  found = false;
  std::string err;
  const Phase& ph = make_phase(mode, fm, undetermined, xa, err);  // the first candidate's
  if (!err.empty()) return "";
  const MonitorStart& st = selection_start(ph, xa, t);
  // Per contact: which of its monitors (in the order add_friction_monitors
  // adds them) start at zero with a nonzero derivative.
  std::vector<std::vector<char>> zero(cand.size());
  std::vector<char> in_b(cand.size(), 0);
  for (size_t j = 0; j < ph.monitors.size(); ++j) {
    const int f = ph.monitors[j].friction;
    if (f < 0) continue;
    auto& z = zero[static_cast<size_t>(f)];
    // At zero with a nonzero derivative, or failing from a value beyond its
    // noise (a stick force a rounding outside its face: the state 1e-13 s
    // after another toe's slip, Vision 60 at d = 8).
    z.push_back(st.m0[j] >= 1 || (st.m0[j] == 0 && !(st.d0[j] > 0.0)) ? 1 : 0);
    if (z.back()) in_b[static_cast<size_t>(f)] = 1;
  }
  std::vector<size_t> b;
  std::vector<std::vector<FrictionMode>> modes;
  double total = 1.0;
  for (size_t f = 0; f < cand.size(); ++f) {
    if (!in_b[f] || cand[f].size() < 2) continue;
    b.push_back(f);
    if (fm[f] == FrictionMode::kStick && is_cone(f))
      modes.push_back(boundary_modes(zero[f], cone_d(f)));
    else if (fm[f] == FrictionMode::kStick &&
             zero[f].size() == 2)  // planar: -mu u_N, +mu u_N edges
      modes.push_back({FrictionMode::kStick,
                       zero[f][0] ? FrictionMode::kSlipNegative : FrictionMode::kSlipPositive});
    else
      modes.push_back(cand[f]);
    total *= static_cast<double>(modes.back().size());
  }
  if (b.empty() || total > static_cast<double>(kMaxBoundaryCombinations)) return "";
  std::vector<std::vector<FrictionMode>> passed;
  std::vector<FrictionMode> trial = fm;
  for (size_t code = 0; code < static_cast<size_t>(total) && passed.size() < 2; ++code) {
    size_t c = code;
    for (size_t k = 0; k < b.size(); ++k) {
      trial[b[k]] = modes[k][c % modes[k].size()];
      c /= modes[k].size();
    }
    std::string why;
    const Phase& tp = make_phase(mode, trial, undetermined, xa, why);
    if (why.empty() && consistent(tp, xa, t)) passed.push_back(trial);
  }
  if (passed.empty()) return "";
  if (passed.size() == 1) {
    fm = passed.front();
    found = true;
    return "";
  }
  const mech::MechanicalModel& m = *model_.mechanical;
  const auto list = [&](const std::vector<FrictionMode>& p) {
    std::string s;
    for (const size_t f : b)
      s += text(s.empty() ? "" : ", ", "'",
                m.constraints[static_cast<size_t>(m.friction[f].contact)], "' ",
                friction_mode_name(p[f], cone_d(f)));
    return s;
  };
  return text("stick / slip selection at t = ", t,
              ": stick forces reach their polygons together and more than one mode is consistent "
              "(",
              list(passed[0]), "; and ", list(passed[1]),
              "): the motion is not decided by the first nonzero derivatives (not resolved)");
}

}  // namespace lcsim::sim::detail
