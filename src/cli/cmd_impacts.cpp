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
#include <lcsim/app/impacts.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <sstream>

#include "cli/command.hpp"
#include "cli/flag_names.hpp"
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

std::string fmt_vec(const Eigen::VectorXd& v) { return "(" + number_list(v, 6) + ")"; }

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

// --restitution: one coefficient for every constraint, or one per constraint
// (checked by the library, app::resolve_restitution); empty: the model's.
Eigen::VectorXd restitution(const ImpactsArgs& a, const mech::MechanicalModel& m) {
  if (a.restitution.empty()) return Eigen::VectorXd();
  Eigen::VectorXd e = io::parse_vector(a.restitution, "--restitution");
  if (e.size() == 1) e = Eigen::VectorXd::Constant(m.num_constraints(), e(0));
  return e;
}

// --rules: "all" (the library's choice: every law, with friction every law
// that handles it) or a comma list of names.
std::vector<std::string> rule_list(const std::string& text) {
  if (text == "all") return {};
  std::vector<std::string> out = io::split(text, ',');
  if (out.empty()) throw io::InputError("--rules: empty list (give all or a,b,...)");
  return out;
}

// `f()`, its input errors naming the command's flags where the library's
// name the request's fields.
template <class F>
auto with_flags(F f) {
  try {
    return f();
  } catch (const io::InputError& e) {
    throw io::InputError(with_flag_names(e.what(), impacts_flags()));
  }
}

void print_table(const mech::Model& model, const app::ImpactsAtState& r) {
  const mech::MechanicalModel& m = *model.mechanical;
  std::printf("model %s at state %s, closed {", model.name.c_str(), fmt_vec(r.x0).c_str());
  for (size_t i = 0; i < r.closed.size(); ++i)
    std::printf("%s%s", i ? ", " : "", m.constraints[r.closed[i]].c_str());
  std::printf("}, restitution %s\n", fmt_vec(r.restitution).c_str());
  for (const auto& note : r.notes) std::printf("note: %s\n", note.c_str());
  std::printf("%-19s %-28s %-24s %-18s %-12s %-12s %-10s %s\n", "rule", "velocity after", "impulse",
              "mode", "T before", "T after", "worst Ev+", "note");
  for (const auto& [name, res] : r.results) {
    std::string note = res.ok() ? (res.admissible ? "" : "NOT ADMISSIBLE ") : "FAILED ";
    note += res.message;
    std::printf("%-19s %-28s %-24s %-18s %-12.6g %-12.6g %-10.3g %s\n", name.c_str(),
                fmt_vec(res.v_after).c_str(), fmt_vec(res.impulse).c_str(),
                mode_text(m, res.mode, ",").c_str(), res.energy_before, res.energy_after,
                res.worst_rate, note.c_str());
    if (m.has_friction_3d() && res.friction_impulse2.size())  // planar output unchanged
      for (const auto& fc : m.friction)
        std::printf("%-19s friction at %s: P_T = (%.6g, %.6g), %s\n", "",
                    m.constraints[fc.contact].c_str(), res.friction_impulse(fc.contact),
                    res.friction_impulse2(fc.contact),
                    impact::cone_mode_text(res.outcome[fc.contact], res.facet[fc.contact]).c_str());
    else if (m.has_friction() && res.friction_impulse.size())  // frictionless output unchanged
      for (const auto& fc : m.friction)
        std::printf("%-19s friction at %s: P_T = %.6g, %s\n", "", m.constraints[fc.contact].c_str(),
                    res.friction_impulse(fc.contact), impact::to_string(res.outcome[fc.contact]));
  }
}

void run_compare(const ImpactsArgs& a, const mech::Model& model) {
  app::ImpactsRequest request;
  request.x0 = initial_state(a, model);
  request.rules = rule_list(a.rules);
  request.restitution = restitution(a, *model.mechanical);
  const app::ImpactsAtState r = with_flags([&] { return app::impacts_at_state(model, request); });
  if (a.json)
    std::cout << app::impacts_json(model, r).dump(2) << "\n";
  else
    print_table(model, r);
  std::cout.flush();
  if (const std::string failures = r.failures(); !failures.empty()) throw NumericalError(failures);
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
  spec.restitution = with_flags([&] { return app::resolve_restitution(m, restitution(a, m)); });
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
