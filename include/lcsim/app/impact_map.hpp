// The impact map of thesis Figure 3.5 (`lcsim impacts --map`): Moreau's rule
// (or another law) applied on a grid of pre-impact velocities, each cell
// giving the mode and the post-impact velocity.
//
// Two spellings:
//   all closed   a two-coordinate model whose every gap is zero at q (the
//                figure, at x1 = x2 = 0); the axes are the velocities v1, v2;
//   --closed a,b two named constraints of any model closed at q; the axes are
//                their approach velocities E_a v, E_b v, and the pre-impact
//                velocity of a cell is the base velocity changed least in the
//                kinetic metric to give them: v = v0 + M^{-1} E_J' W^{-1}
//                (w - E_J v0), W = E_J M^{-1} E_J'.
// Checks (io::InputError naming the option and the value, 0-based indices):
// names or indices unknown, repeated, not two; the two rows dependent (W
// singular: their rates cannot be set apart); a named gap not zero at the
// given q; another constraint violated or also closed at q.
#pragma once

#include <Eigen/Dense>
#include <lcsim/impact/impact.hpp>
#include <lcsim/mech/mech.hpp>
#include <string>
#include <vector>

namespace lcsim::app {

struct MapRange {
  double lo = 0.0, hi = 1.0;
  int n = 41;  // grid points, in [2, 2001]
};
// "lo:hi" or "lo:hi:n" (n = 41 when omitted); InputError names `what`.
MapRange parse_map_range(const std::string& text, const std::string& what);

// Constraint names or 0-based indices, comma-separated ("shoulder_lower,3").
std::vector<int> parse_constraint_list(const mech::MechanicalModel& m, const std::string& text,
                                       const std::string& what);

// The constraints with zero gap at q (|gap| <= 1e-9 (|E_i||q| + |g_i|) +
// 1e-13, the integrator's zero test); InputError naming `what` if some gap is
// negative beyond that (thesis §3.8: no impact from an inadmissible state).
impact::IndexSet closed_constraints(const mech::MechanicalModel& m, const Eigen::VectorXd& q,
                                    const std::string& what);

// q moved least in the kinetic metric onto E_J q + g_J = 0 (J = `closed`):
// q + M^{-1} E_J' W^{-1} (-(E_J q + g_J)). InputError if W is singular.
Eigen::VectorXd close_contacts(const mech::MechanicalModel& m, const Eigen::VectorXd& q,
                               const std::vector<int>& closed, const std::string& what);

struct ImpactMapSpec {
  Eigen::VectorXd q, v0;    // configuration and base velocity (N each)
  std::vector<int> closed;  // empty: every constraint, two coordinates
  MapRange axis1, axis2;
  Eigen::VectorXd restitution;  // per constraint (k); empty = the model's
  std::string law = "newton";
};

struct ImpactMapCell {
  Eigen::Vector2d before, after;  // on the map's axes (m/s or rad/s)
  impact::IndexSet mode;
};

struct ImpactMap {
  std::vector<std::string> axes;      // "v1"/"v2", or the closed constraints' names
  std::vector<int> axis_constraints;  // --closed: the two constraints (0-based); else empty
  std::vector<int> closed;            // the closed set (0-based)
  std::vector<ImpactMapCell> cells;   // axis1 outer, axis2 inner
  std::string failure;                // "" or the first cell where the law failed
};

// Validates the spec as above (what = "--map" / "--closed" in messages) and
// computes the map. A law that fails at a cell stops the map with `failure`.
ImpactMap impact_map(const mech::MechanicalModel& m, const ImpactMapSpec& spec);

// CSV: "v1,v2,mode,v1+,v2+" for the all-closed map, "rate_<i>,rate_<j>,mode,
// rate_<i>+,rate_<j>+" (0-based constraint indices) for --closed; the mode
// is the constraint names joined by '+', or "unconstrained".
std::string impact_map_csv(const mech::MechanicalModel& m, const ImpactMap& map);

}  // namespace lcsim::app
