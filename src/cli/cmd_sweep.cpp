// `lcsim sweep MODEL`: the speed–accuracy trade, measured. Runs each method at
// each step h and compares it with an exact event-driven run of the same
// impact law, or of the nearest exact law where the method has none (the
// computation, the reference laws and the row's fields: src/app/sweep.hpp).
// Each row names its reference law and carries its run's warnings and the
// reference's (count and first message).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <lcsim/app/sweep.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/command.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"

namespace lcsim::cli {
namespace {

struct SweepArgs {
  std::string model;
  std::string x0;
  double t_end = std::nan("");
  bool t_end_given = false;  // --t-end nan is an error, not the model's horizon
  std::string methods = "event,euler,moreau-jean";
  std::string hs = "1e-2,1e-3,1e-4";
  int repeat = 3;
  double theta = 0.5;
  bool force = false;
  bool json = false;
  std::string plot;
  std::string lcp = "pivot";
  std::string impact = sim::Options{}.impact;
  std::string sensitivity;  // "x0,f[1]": the err_grad column (docs/sensitivities.md)
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string warning_text(long count, const std::string& first) {
  if (count == 0) return "0";
  return std::to_string(count) + " (" + first + ")";
}

void print_text(const app::SweepResult& s, const std::string& x0_from) {
  std::printf("model %s, t_end %g, --impact %s, x0 from %s\n", s.model.c_str(), s.t_end,
              s.impact.c_str(), x0_from.c_str());
  const bool grad = !s.sensitivity.empty();  // the column only when asked
  std::printf("%-12s %-8s %-24s %-11s %-11s %-11s %-11s %-9s %-9s %-10s%s\n", "method", "h",
              "reference law", "err_final", "err_max", "violation", "E_drift", "steps", "lcp",
              "wall_s", grad ? " err_grad" : "");
  for (const auto& r : s.rows) {
    char hbuf[32];
    if (r.method == "event")
      std::snprintf(hbuf, sizeof hbuf, "-");
    else
      std::snprintf(hbuf, sizeof hbuf, "%g", r.h);
    char gbuf[32] = "";
    if (grad) std::snprintf(gbuf, sizeof gbuf, " %-10.3e", r.error_gradient);
    std::printf("%-12s %-8s %-24s %-11.3e %-11.3e %-11.3e %-11.3e %-9ld %-9ld %-10.3e%s%s\n",
                r.method.c_str(), hbuf, r.reference.label().c_str(), r.error_final, r.error_max,
                r.max_violation, r.energy_drift, r.steps, r.lcp_solves, r.wall_time_s, gbuf,
                r.status == "completed" ? "" : ("  " + r.status).c_str());
    if (!r.error_floor.empty()) std::printf("    error floor: %s\n", r.error_floor.c_str());
    if (r.warnings > 0)
      std::printf("    warnings: %s\n", warning_text(r.warnings, r.first_warning).c_str());
    if (r.method != "event" && r.reference_warnings > 0)
      std::printf("    reference warnings: %s\n",
                  warning_text(r.reference_warnings, r.reference_first_warning).c_str());
  }
  std::printf("errors: %s\n", app::kErrorMeasures);
  std::printf("reference laws:\n");
  std::vector<std::string> seen;
  for (const auto& r : s.rows) {
    const std::string line = r.method + ": " + r.reference.label() + " -- " + r.reference.reason;
    if (std::find(seen.begin(), seen.end(), line) != seen.end()) continue;
    seen.push_back(line);
    std::printf("  %s\n", line.c_str());
  }
}

void run_sweep(const SweepArgs& a) {
  const mech::Model model = scene::load_model(a.model);
  app::SweepOptions o;
  o.methods = split_list(a.methods);
  for (const auto& tok : split_list(a.hs)) o.hs.push_back(io::parse_vector(tok, "--h")(0));
  o.repeat = a.repeat;
  const Eigen::VectorXd x0 = resolve_initial_state(model, a.model, a.x0);
  o.base.t_end = resolve_horizon(model, a.model, a.t_end_given, a.t_end);
  o.base.theta = a.theta;
  o.base.force = a.force;
  o.base.lcp_solver = a.lcp;
  o.base.impact = a.impact;
  o.base.sensitivity = split_list(a.sensitivity);
  o.progress = [](const std::string& line) { std::cerr << "sweep: " << line << "\n"; };
  // The plot's path and script are checked before the runs, not after.
  PlotScript script;
  if (!a.plot.empty()) {
    check_writable(a.plot);
    script = find_plot_script("work-precision", "LCSIM_PLOT_WORK_PRECISION");
  }
  const app::SweepResult s = app::run_sweep(model, x0, o);
  const nlohmann::json j = app::sweep_json(s);
  if (a.json)
    std::cout << j.dump(2) << "\n";
  else
    print_text(s, a.x0.empty() ? "the model" : "--x0");
  std::cout.flush();
  if (!a.plot.empty()) {
    draw_plot_of_text(j.dump(2), "lcsim_sweep.json", script, a.plot, model.name, "--plot");
    std::cerr << "work-precision diagram written to " << a.plot << "\n";
  }
  // A refused reference (bad input) exits 2, a failed one 3: its own status.
  for (const auto& ref : s.references)
    check_status(ref.run.status,
                 "sweep: the exact reference run (" + ref.law.label() + ") " + ref.status);
}

void setup(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep", "Work-precision sweep: methods x step sizes against the exact event-driven run");
  cmd->add_option("model", a->model, "Model file (YAML)")->required();
  cmd->add_option("--x0", a->x0, "Initial state a,b,... (q then v); default: the model's");
  auto* t_end = cmd->add_option("--t-end", a->t_end, "Horizon (s); default: the model's t_end");
  cmd->add_option("--methods", a->methods,
                  "Comma-separated: " + name_list(sim::integrator_names()));
  cmd->add_option("--h", a->hs, "Comma-separated step sizes (s), e.g. 1e-2,1e-3,1e-4");
  cmd->add_option("--repeat", a->repeat, "Timing runs per point (median); default 3");
  cmd->add_option("--theta", a->theta, "Moreau–Jean theta in [0, 1]; default 0.5");
  cmd->add_option("--impact", a->impact,
                  "Impact law of the event method (and of the reference of methods without "
                  "a law of their own); default " +
                      sim::Options{}.impact + ": " + name_list(impact::impact_law_names()));
  cmd->add_flag("--force", a->force, "Run backward Euler even where it is not consistent");
  cmd->add_option("--lcp", a->lcp, "LCP solver: " + name_list(lcp::solver_names()));
  cmd->add_option("--sensitivity", a->sensitivity,
                  "Comma-separated columns (x0, f[i], g[c], e[c], K[i][j], D[i][j], M[i][j]): "
                  "each row also gives err_grad, the error of its dx(T)/dtheta against the "
                  "exact one");
  cmd->add_flag("--json", a->json, "Print {\"rows\": [...]} as JSON");
  cmd->add_option("--plot", a->plot, "Draw the work-precision diagram (PNG) here");
  cmd->callback([a, t_end] {
    a->t_end_given = t_end->count() > 0;
    run_sweep(*a);
  });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
