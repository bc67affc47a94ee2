// `lcsim impacts MODEL`: compare the impact rules of src/impact on one state,
// or draw the impact map of thesis Figure 3.5 for a two-coordinate model.
//
//   lcsim impacts MODEL [--x0 q,v] [--rules all|a,b] [--restitution e|e1,e2,..] [--json]
//   lcsim impacts MODEL --map lo:hi[:n],lo:hi[:n] [--x0 q,v] [--plot map.png]  (q = 0 by default)
//   lcsim impacts MODEL --map ... --closed a,b   (any model: the map over the
//                                                 approach velocities of a, b)
//
// The closed set is the constraints with zero gap at q, with the integrator's
// tolerance |gap| <= 1e-9 (|E_i||q| + |g_i|) + 1e-13 (src/app/impact_map.hpp). Exit 2 on bad input,
// 3 if a rule failed (the table is printed first).
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <lcsim/app/impact_map.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <sstream>

#include "cli/command.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"

namespace lcsim::cli {
namespace {

struct ImpactsArgs {
  std::string model;
  std::string x0;
  std::string rules = "all";
  std::string restitution;
  bool json = false;
  std::string map;
  std::string plot;
  std::string closed;
};

std::string fmt_vec(const Eigen::VectorXd& v) {
  std::string s = "(";
  char buf[64];
  for (int i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.6g", i ? ", " : "", v(i));
    s += buf;
  }
  return s + ")";
}

std::string mode_text(const mech::MechanicalModel& m, const impact::IndexSet& mode,
                      const char* sep) {
  if (mode.empty()) return "unconstrained";
  std::string s;
  for (size_t i = 0; i < mode.size(); ++i) s += (i ? sep : "") + m.constraints[mode[i]];
  return s;
}

// The state (q, v) to work on: --x0 or the model's initial state.
Eigen::VectorXd initial_state(const ImpactsArgs& a, const mech::Model& model) {
  return resolve_initial_state(model, a.model, a.x0, "state");
}

Eigen::VectorXd restitution(const ImpactsArgs& a, const mech::MechanicalModel& m) {
  const int k = m.num_constraints();
  if (a.restitution.empty()) return m.restitution;
  Eigen::VectorXd e = io::parse_vector(a.restitution, "--restitution");
  if (e.size() == 1) e = Eigen::VectorXd::Constant(k, e(0));
  if (e.size() != k)
    throw io::InputError("--restitution: give one coefficient or " + std::to_string(k) +
                         " (one per constraint), got " + std::to_string(e.size()));
  for (int i = 0; i < k; ++i)
    if (!(e(i) >= 0.0 && e(i) <= 1.0))
      throw io::InputError("--restitution: coefficients must lie in [0, 1] (got " +
                           std::to_string(e(i)) + ")");
  return e;
}

// With friction, "all" is the laws that handle it and naming another is an
// input error (ImpactLaw::handles_friction).
std::vector<std::string> rule_list(const std::string& text, bool friction) {
  std::vector<std::string> out;
  if (text == "all") {
    for (const auto& n : impact::impact_law_names())
      if (!friction || impact::make_impact_law(n)->handles_friction()) out.push_back(n);
    return out;
  }
  out = io::split(text, ',');
  if (out.empty()) throw io::InputError("--rules: empty list (give all or a,b,...)");
  for (const auto& n : out)  // invalid_argument -> exit 2
    if (friction && !impact::make_impact_law(n)->handles_friction())
      throw io::InputError("--rules: impact law '" + n +
                           "' does not handle friction, and the model has friction");
  return out;
}

void run_compare(const ImpactsArgs& a, const mech::Model& model) {
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  const Eigen::VectorXd x0 = initial_state(a, model);
  const std::vector<std::string> rules = rule_list(a.rules, m.has_friction());
  impact::ImpactInput in;
  in.model = &m;
  in.q = x0.head(N);
  in.v = x0.tail(N);
  in.closed = app::closed_constraints(m, in.q, "--x0");
  in.restitution = restitution(a, m);
  const auto solver = lcp::make_solver("pivot");
  // Rows by the law's own name: an alias ("moreau") gives its law's row
  // ("newton"), once, and a note saying what the alias means.
  std::vector<std::pair<std::string, impact::ImpactResult>> results;
  std::vector<std::string> notes;
  for (const auto& name : rules) {
    const auto law = impact::make_impact_law(name);
    if (const std::string note = impact::laws().alias_note(name); !note.empty())
      notes.push_back(note);
    bool seen = false;
    for (const auto& row : results) seen = seen || row.first == law->name();
    if (!seen) results.emplace_back(law->name(), law->apply(in, *solver));
  }

  std::string failures;
  for (const auto& [name, r] : results)
    if (!r.ok()) failures += (failures.empty() ? "" : "; ") + name + ": " + r.message;
  if (a.json) {
    nlohmann::json j;
    j["model"] = model.name;
    j["state_before"] = io::to_json(x0);
    nlohmann::json closed = nlohmann::json::array();
    for (int i : in.closed) closed.push_back(m.constraints[i]);
    j["closed"] = closed;
    j["restitution"] = io::to_json(in.restitution);
    nlohmann::json js = nlohmann::json::object();
    for (const auto& [name, r] : results) {
      Eigen::VectorXd after(2 * N);
      after << in.q, r.v_after;
      nlohmann::json mode = nlohmann::json::array();
      for (int i : r.mode) mode.push_back(m.constraints[i]);
      js[name] = {{"ok", r.ok()},
                  {"state_after", io::to_json(after)},
                  {"impulse", io::to_json(r.impulse)},
                  {"mode", mode},
                  {"energy_before", r.energy_before},
                  {"energy_after", r.energy_after},
                  {"worst_violation", r.worst_rate},
                  {"admissible", r.admissible},
                  {"message", r.message}};
      if (m.has_friction()) {  // frictionless output unchanged
        nlohmann::json outcome = nlohmann::json::object();
        for (const auto& fc : m.friction)
          outcome[m.constraints[fc.contact]] =
              r.outcome.empty() ? "none" : impact::to_string(r.outcome[fc.contact]);
        js[name]["friction_impulse"] =
            io::to_json(r.friction_impulse.size() ? r.friction_impulse
                                                  : Eigen::VectorXd::Zero(m.num_constraints()));
        js[name]["friction_outcome"] = outcome;
        js[name]["painleve"] = r.painleve;
        js[name]["energy_gain"] = r.energy_gain;
      }
    }
    j["rules"] = js;
    if (!notes.empty()) j["notes"] = notes;
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("model %s at state %s, closed {", model.name.c_str(), fmt_vec(x0).c_str());
    for (size_t i = 0; i < in.closed.size(); ++i)
      std::printf("%s%s", i ? ", " : "", m.constraints[in.closed[i]].c_str());
    std::printf("}, restitution %s\n", fmt_vec(in.restitution).c_str());
    for (const auto& note : notes) std::printf("note: %s\n", note.c_str());
    std::printf("%-19s %-28s %-24s %-18s %-12s %-12s %-10s %s\n", "rule", "velocity after",
                "impulse", "mode", "T before", "T after", "worst Ev+", "note");
    for (const auto& [name, r] : results) {
      std::string note = r.ok() ? (r.admissible ? "" : "NOT ADMISSIBLE ") : "FAILED ";
      note += r.message;
      std::printf("%-19s %-28s %-24s %-18s %-12.6g %-12.6g %-10.3g %s\n", name.c_str(),
                  fmt_vec(r.v_after).c_str(), fmt_vec(r.impulse).c_str(),
                  mode_text(m, r.mode, ",").c_str(), r.energy_before, r.energy_after, r.worst_rate,
                  note.c_str());
      if (m.has_friction() && r.friction_impulse.size())  // frictionless output unchanged
        for (const auto& fc : m.friction)
          std::printf("%-19s friction at %s: P_T = %.6g, %s\n", "",
                      m.constraints[fc.contact].c_str(), r.friction_impulse(fc.contact),
                      impact::to_string(r.outcome[fc.contact]));
    }
  }
  std::cout.flush();
  if (!failures.empty()) throw NumericalError(failures);
}

// python/lcsim/plot.py impact-map (or $LCSIM_PLOT_IMPACT_MAP).
PlotScript impact_map_script() { return find_plot_script("impact-map", "LCSIM_PLOT_IMPACT_MAP"); }

void run_map(const ImpactsArgs& a, const mech::Model& model) {
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  const std::vector<std::string> ranges = io::split(a.map, ',');
  if (ranges.size() != 2) throw io::InputError("--map: expected v1range,v2range (lo:hi[:n] each)");
  app::ImpactMapSpec spec;
  spec.axis1 = app::parse_map_range(ranges[0], "--map");
  spec.axis2 = app::parse_map_range(ranges[1], "--map");
  if (!a.closed.empty()) spec.closed = app::parse_constraint_list(m, a.closed, "--closed");
  // Figure 3.5 is drawn at x1 = x2 = 0: q = 0 unless --x0 gives another q.
  // With --closed and no --x0, q is placed on the named contacts.
  const Eigen::VectorXd x0 = a.x0.empty() ? Eigen::VectorXd::Zero(2 * N) : initial_state(a, model);
  spec.q = x0.head(N);
  spec.v0 = x0.tail(N);
  if (a.x0.empty() && spec.closed.size() == 2)
    spec.q = app::close_contacts(m, spec.q, spec.closed, "--closed");
  spec.restitution = restitution(a, m);
  const app::ImpactMap map = app::impact_map(m, spec);
  if (!map.failure.empty()) throw NumericalError("--map: " + map.failure);
  const std::string csv = app::impact_map_csv(m, map);
  std::cout << csv;
  std::cout.flush();
  if (a.plot.empty()) return;
  const std::string title = spec.closed.empty()
                                ? model.name + ": Moreau impact map (Figure 3.5)"
                                : model.name + ": Moreau impact map, closed " + map.axes[0] +
                                      " (x), " + map.axes[1] + " (y) at q = " + fmt_vec(spec.q);
  draw_plot_of_text(csv, "lcsim_impact_map.csv", impact_map_script(), a.plot, title, "--plot");
  std::cerr << "impact map written to " << a.plot << "\n";
}

void run_impacts(const ImpactsArgs& a) {
  const mech::Model model = scene::load_model(a.model);
  if (!model.is_mechanical())
    throw io::InputError(a.model + ": impact rules need a mechanical model (M, E), not `lcs:`");
  if (!a.plot.empty() && a.map.empty()) throw io::InputError("--plot: only with --map");
  if (!a.closed.empty() && a.map.empty()) throw io::InputError("--closed: only with --map");
  if (!a.plot.empty()) {  // checked before the map is computed, not after
    check_writable(a.plot);
    (void)impact_map_script();
  }
  if (a.map.empty())
    run_compare(a, model);
  else
    run_map(a, model);
}

void setup(CLI::App& app) {
  auto a = std::make_shared<ImpactsArgs>();
  auto* cmd = app.add_subcommand("impacts", "Compare impact rules on one state, or map them");
  cmd->add_option("model", a->model, "Model file (YAML, mechanical)")->required();
  cmd->add_option("--x0", a->x0, "State a,b,... (q then v); default: the model's");
  cmd->add_option("--rules", a->rules,
                  "all, or a comma list of: " + name_list(impact::impact_law_names()));
  cmd->add_option(
      "--restitution", a->restitution,
      "One coefficient for all constraints or one per constraint (default: the model's)");
  cmd->add_flag("--json", a->json, "Print the results as JSON");
  cmd->add_option(
      "--map", a->map,
      "Impact map of a two-coordinate model over its pre-impact velocities: two ranges "
      "lo:hi[:n], v1 then v2 (lo < hi, n points from lo to hi, 2..2001, default 41), e.g. "
      "-2:0:81,-3:1 (CSV on stdout)");
  cmd->add_option("--closed", a->closed,
                  "With --map: the two contacts to close, by name or 0-based index (a,b); the "
                  "map is over their approach velocities");
  cmd->add_option("--plot", a->plot, "With --map: draw the map to this PNG (matplotlib)");
  cmd->callback([a] { run_impacts(*a); });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
