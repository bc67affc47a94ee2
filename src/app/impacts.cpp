// Impacts at a state (impacts.hpp): the request checked field by field, each
// law applied once, the result as JSON.
#include <lcsim/app/impact_map.hpp>
#include <lcsim/app/impacts.hpp>
#include <lcsim/io/input_error.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/lcp/lcp.hpp>

namespace lcsim::app {
namespace {

const mech::MechanicalModel& mechanical(const mech::Model& model) {
  if (!model.is_mechanical())
    throw io::InputError("model '" + model.name +
                         "': impact rules need a mechanical model (M, E), not `lcs:`");
  return *model.mechanical;
}

Eigen::VectorXd state(const mech::Model& model, const Eigen::VectorXd& x0) {
  const Eigen::VectorXd x = x0.size() ? x0 : model.initial;
  if (x.size() != model.state_size())
    throw io::InputError("x0: expected " + std::to_string(model.state_size()) +
                         " entries (q then v) (got " + std::to_string(x.size()) + ")");
  return x;
}

// With friction, every law means the laws that handle it and naming another
// is an input error (ImpactLaw::handles_friction).
std::vector<std::string> rule_list(const std::vector<std::string>& rules, bool friction) {
  if (!rules.empty()) {
    for (const auto& n : rules)  // an unknown name: std::invalid_argument
      if (friction && !impact::make_impact_law(n)->handles_friction())
        throw io::InputError("rules: impact law '" + n +
                             "' does not handle friction, and the model has friction");
    return rules;
  }
  std::vector<std::string> out;
  for (const auto& n : impact::impact_law_names())
    if (!friction || impact::make_impact_law(n)->handles_friction()) out.push_back(n);
  return out;
}

nlohmann::json names_json(const mech::MechanicalModel& m, const impact::IndexSet& set) {
  nlohmann::json a = nlohmann::json::array();
  for (int i : set) a.push_back(m.constraints[i]);
  return a;
}

// A law's row: its state after (q unchanged, v+), impulse, mode and energies;
// with friction, the friction impulse and outcome per contact too.
nlohmann::json result_json(const mech::MechanicalModel& m, const Eigen::VectorXd& q,
                           const impact::ImpactResult& r) {
  Eigen::VectorXd after(q.size() + r.v_after.size());
  after << q, r.v_after;
  nlohmann::json j = {{"ok", r.ok()},
                      {"state_after", io::to_json(after)},
                      {"impulse", io::to_json(r.impulse)},
                      {"mode", names_json(m, r.mode)},
                      {"energy_before", r.energy_before},
                      {"energy_after", r.energy_after},
                      {"worst_violation", r.worst_rate},
                      {"admissible", r.admissible},
                      {"message", r.message}};
  if (!m.has_friction()) return j;  // frictionless output unchanged
  nlohmann::json outcome = nlohmann::json::object();
  for (const auto& fc : m.friction)
    outcome[m.constraints[fc.contact]] =
        r.outcome.empty() ? "none" : impact::to_string(r.outcome[fc.contact]);
  j["friction_impulse"] = io::to_json(
      r.friction_impulse.size() ? r.friction_impulse : Eigen::VectorXd::Zero(m.num_constraints()));
  j["friction_outcome"] = outcome;
  if (m.has_friction_3d()) {  // planar models' output unchanged
    // The impulse along each 3-D contact's second tangent, and every
    // frictional contact's mode with its cone facet (impact::cone_mode_text).
    nlohmann::json mode = nlohmann::json::object();
    for (const auto& fc : m.friction)
      mode[m.constraints[fc.contact]] =
          r.outcome.empty()
              ? "open"
              : impact::cone_mode_text(r.outcome[fc.contact],
                                       r.facet.empty() ? impact::ConeFacet{} : r.facet[fc.contact]);
    j["friction_impulse2"] =
        io::to_json(r.friction_impulse2.size() ? r.friction_impulse2
                                               : Eigen::VectorXd::Zero(m.num_constraints()));
    j["friction_mode"] = mode;
  }
  j["painleve"] = r.painleve;
  j["energy_gain"] = r.energy_gain;
  return j;
}

}  // namespace

Eigen::VectorXd resolve_restitution(const mech::MechanicalModel& m, const Eigen::VectorXd& given) {
  if (given.size() == 0) return m.restitution;
  mech::MechanicalModel with = m;
  with.restitution = given;
  if (auto p = mech::check_mechanical(with))
    throw io::InputError("restitution (" + p->field + "): " + p->what);
  return given;
}

std::string ImpactsAtState::failures() const {
  std::string s;
  for (const auto& [name, r] : results)
    if (!r.ok()) s += (s.empty() ? "" : "; ") + name + ": " + r.message;
  return s;
}

ImpactsAtState impacts_at_state(const mech::Model& model, const ImpactsRequest& request) {
  const mech::MechanicalModel& m = mechanical(model);
  const int N = m.dofs();
  ImpactsAtState out;
  out.x0 = state(model, request.x0);
  const std::vector<std::string> rules = rule_list(request.rules, m.has_friction());
  impact::ImpactInput in;
  in.model = &m;
  in.q = out.x0.head(N);
  in.v = out.x0.tail(N);
  in.closed = out.closed = closed_constraints(m, in.q, "x0");
  in.restitution = out.restitution = resolve_restitution(m, request.restitution);
  const auto solver = lcp::make_solver("pivot");
  for (const auto& name : rules) {
    const auto law = impact::make_impact_law(name);
    if (const std::string note = impact::laws().alias_note(name); !note.empty())
      out.notes.push_back(note);
    bool seen = false;
    for (const auto& row : out.results) seen = seen || row.first == law->name();
    if (!seen) out.results.emplace_back(law->name(), law->apply(in, *solver));
  }
  return out;
}

nlohmann::json impacts_json(const mech::Model& model, const ImpactsAtState& impacts) {
  const mech::MechanicalModel& m = mechanical(model);
  const Eigen::VectorXd q = impacts.x0.head(m.dofs());
  nlohmann::json j;
  j["model"] = model.name;
  j["state_before"] = io::to_json(impacts.x0);
  j["closed"] = names_json(m, impacts.closed);
  j["restitution"] = io::to_json(impacts.restitution);
  nlohmann::json rules = nlohmann::json::object();
  for (const auto& [name, r] : impacts.results) rules[name] = result_json(m, q, r);
  j["rules"] = rules;
  if (!impacts.notes.empty()) j["notes"] = impacts.notes;
  return j;
}

}  // namespace lcsim::app
