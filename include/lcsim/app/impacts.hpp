// Impacts at a state (`lcsim impacts MODEL`, Python's `lcsim.impacts`): the
// impact laws of src/impact applied to one state (q, v) of a mechanical model,
// the closed set being the constraints with zero gap at q
// (closed_constraints, impact_map.hpp: the integrator's zero test).
//
// Input errors are io::InputError naming the request's field (x0, rules,
// restitution) and the value; an unknown law name is std::invalid_argument
// (impact::make_impact_law). A law that fails is its result's status, not an
// exception (ImpactsAtState::failures).
#pragma once

#include <Eigen/Dense>
#include <lcsim/impact/impact.hpp>
#include <lcsim/mech/mech.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

namespace lcsim::app {

struct ImpactsRequest {
  // The state (q, v), 2N entries (m, m/s or rad, rad/s); empty: the model's
  // initial state.
  Eigen::VectorXd x0;
  // Law names or aliases (impact::impact_law_names, "moreau"); empty: every
  // law, or on a model with friction every law that handles it (naming one
  // that does not is an input error).
  std::vector<std::string> rules;
  // One coefficient per constraint, each in [0, 1] (checked as the model's own,
  // mech::check_mechanical); empty: the model's.
  Eigen::VectorXd restitution;
};

struct ImpactsAtState {
  Eigen::VectorXd x0;           // the state the laws were applied to (q, v)
  impact::IndexSet closed;      // constraints with zero gap at q (0-based)
  Eigen::VectorXd restitution;  // the coefficients used, one per constraint
  // By each law's own name, once each, in the order asked: an alias
  // ("moreau") gives its law's row ("newton").
  std::vector<std::pair<std::string, impact::ImpactResult>> results;
  std::vector<std::string> notes;  // what each alias asked for means

  // "" when every law computed its result, else "law: message; ...".
  std::string failures() const;
};

// The restitution coefficients to use: `given` (one per constraint, each in
// [0, 1], checked as the model's own by mech::check_mechanical; InputError
// "restitution (mechanical.restitution[i]): ...") or, when empty, the model's.
Eigen::VectorXd resolve_restitution(const mech::MechanicalModel& m, const Eigen::VectorXd& given);

// Checks `request` against `model` (mechanical; x0 of its state's size; the
// start admissible, E q + g >= 0; the rules; the restitution) and applies each
// law with the principal pivoting LCP solver.
ImpactsAtState impacts_at_state(const mech::Model& model, const ImpactsRequest& request);

// What `lcsim impacts --json` prints: the model's name, the state before, the
// closed constraints and the restitution, then per law its state after,
// impulse, mode, energies, worst violation, admissibility and message; on a
// model with friction also the friction impulse, outcome per contact,
// Painlevé and energy-gain flags. Constraint names, not indices.
nlohmann::json impacts_json(const mech::Model& model, const ImpactsAtState& impacts);

}  // namespace lcsim::app
