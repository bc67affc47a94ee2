// `lcsim simulate MODEL`: run an integrator on a model and report the run.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <lcsim/app/run.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cli/command.hpp"
#include "cli/flag_names.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"

namespace lcsim::cli {
namespace {

// What the user gave. Options not given stay at a default-constructed
// sim::Options's values (the library's defaults; it refuses an option the
// chosen method ignores, so only given ones are passed).
struct SimulateArgs {
  std::string model;
  std::string x0;
  double t_end = std::nan("");  // NaN = the model's (when --t-end is not given)
  bool t_end_given = false;
  std::string method = "event";
  double dt_out = sim::Options{}.dt_out;
  std::string out;
  bool json = false;
  std::optional<std::string> impact;
  std::optional<std::string> lcp;
  std::optional<double> h;           // time-stepping step (s)
  std::optional<double> theta;       // Moreau–Jean theta
  std::optional<double> max_output;  // bytes
  bool force = false;                // backward Euler despite the consistency guard
  bool project = false;              // move an infeasible q0 onto E q + g >= 0 first
  std::string sensitivity;           // --sensitivity x0,f[1],e[stop] (Options::sensitivity)
  bool progress = false;     // --progress: progress lines on stderr even when not a terminal
  bool no_progress = false;  // --no-progress
  double linearisation_threshold = scene::kLinearisationThreshold;  // scenes: warn above it
};

std::string fmt_vec(const Eigen::VectorXd& v) { return "(" + number_list(v, 10) + ")"; }

// "{0 hook, 1 wall}": index and name of each constraint of a mechanical
// model or of an LCS that names its pairs (a circuit's diodes); "{0,1}" for
// an LCS without names.
std::string fmt_set(const mech::Model& model, const std::vector<int>& s) {
  const bool named = model.is_mechanical() || !model.pair_names.empty();
  std::string r = "{";
  for (size_t i = 0; i < s.size(); ++i) {
    r += (i ? (named ? ", " : ",") : "") + std::to_string(s[i]);
    if (model.is_mechanical()) r += " " + model.mechanical->constraints[s[i]];
    if (!model.is_mechanical() && named) r += " " + model.pair_names[s[i]];
  }
  return r + "}";
}

// Beside the trajectory's CSV: "run.csv" -> "run.sensitivity.csv".
std::string sensitivity_csv_path(const std::string& out) {
  const std::filesystem::path p(out);
  return (p.parent_path() / (p.stem().string() + ".sensitivity.csv")).string();
}

sim::Options run_options(const SimulateArgs& a, const mech::Model& model) {
  sim::Options opt;
  opt.t_end = resolve_horizon(model, a.model, a.t_end_given, a.t_end);
  // dt_out, h and theta are checked by the run (sim::check_run), whoever calls it.
  opt.dt_out = a.dt_out;
  if (a.h) opt.h = *a.h;
  if (a.theta) opt.theta = *a.theta;
  if (a.impact) opt.impact = *a.impact;
  if (a.lcp) opt.lcp_solver = *a.lcp;
  if (a.max_output) opt.max_output_bytes = *a.max_output;
  opt.force = a.force;
  for (size_t p = 0; !a.sensitivity.empty() && p != std::string::npos;) {
    const size_t comma = a.sensitivity.find(',', p);
    opt.sensitivity.push_back(
        a.sensitivity.substr(p, comma == std::string::npos ? comma : comma - p));
    p = comma == std::string::npos ? comma : comma + 1;
  }
  return opt;
}

// A circuit's conducting diodes after an event (a voltage-form diode is in
// the mode while it blocks, docs/circuits.md): "" for other models.
std::string conducting_note(const circuit::Circuit* c, const sim::Event& e) {
  if (!c) return "";
  std::string s;
  for (const std::string& d : c->conducting(e.mode_after)) s += (s.empty() ? "" : ", ") + d;
  return "      conducting: " + (s.empty() ? std::string("none") : s) + "\n";
}

void print_summary(const SimulateArgs& a, const mech::Model& model, const sim::Trajectory& tr,
                   const std::optional<scene::LinearisationCheck>& lin, bool written,
                   const circuit::Circuit* circuit) {
  std::printf("model %s, method %s, t_end %g\n", model.name.c_str(), tr.method.c_str(), tr.t_end);
  if (!tr.impact_law.empty()) std::printf("impact law %s\n", tr.impact_law.c_str());
  for (const auto& e : tr.events) {
    std::printf("  t = %-20.15g %-12s %s -> %s  mode %s\n", e.t,
                std::string(sim::to_string(e.type)).c_str(), fmt_vec(e.state_before).c_str(),
                fmt_vec(e.state_after).c_str(), fmt_set(model, e.mode_after).c_str());
    if (!e.note.empty()) std::printf("      (%s)\n", e.note.c_str());
    std::printf("%s", conducting_note(circuit, e).c_str());
  }
  if (tr.events_not_recorded > 0)
    std::printf("  ... and %ld more events, counted, not recorded\n", tr.events_not_recorded);
  std::printf("final state %s\n", fmt_vec(tr.final_state).c_str());
  if (model.is_mechanical())
    std::printf("energy %.12g -> %.12g\n", tr.energy_initial, tr.energy_final);
  std::printf("max violation %.3g, LCP solves %ld, warnings %ld, wall time %.3g s\n",
              tr.max_violation, tr.lcp_solves, tr.warning_count(), tr.wall_time_s);
  if (lin) {
    const std::string contact =
        lin->contact.empty()
            ? std::string()
            : lcsim::text(", contact '", lin->contact, "' ",
                          lcsim::format_number(100.0 * lin->contact_error, 3), " %");
    std::printf("linearisation error %.3g %% (mass %.3g %%, forces %.3g %%%s) over %zu states\n",
                100.0 * lin->error, 100.0 * lin->mass_error, 100.0 * lin->force_error,
                contact.c_str(), lin->states);
  }
  if (written) std::printf("trajectory written to %s\n", a.out.c_str());
}

// --project: an infeasible q0 moved onto E q + g >= 0 (documented in README:
// positions move to the nearest feasible ones in the kinetic metric;
// velocities are kept).
void project_start(const mech::Model& model, Eigen::VectorXd& x0) {
  if (!model.is_mechanical() || sim::infeasible_start(model, x0).empty()) return;
  const mech::MechanicalModel& m = *model.mechanical;
  const Eigen::VectorXd q = x0.head(m.dofs());
  const Eigen::VectorXd p = mech::project_feasible(m, q);
  const double moved = std::sqrt((p - q).dot(m.M * (p - q)));
  x0.head(m.dofs()) = p;
  std::cerr << "lcsim: note: --project moved the initial positions onto E q + g >= 0 "
            << "(kinetic-metric distance " << moved << ")\n";
}

// Where the run's sensitivities stopped existing, and their CSV.
void print_sensitivity(const sim::Trajectory& tr, const std::string& csv) {
  for (const auto& l : tr.sensitivity_losses)
    std::printf("sensitivity: no derivative from t = %.15g (%s%s%s)\n", l.t, l.contact.c_str(),
                l.contact.empty() ? "" : ": ", l.reason.c_str());
  if (!csv.empty()) std::printf("sensitivities written to %s\n", csv.c_str());
}

void run_simulate(const SimulateArgs& a) {
  try {  // checked first, before the model is read
    scene::check_linearisation_threshold(a.linearisation_threshold);
  } catch (const io::InputError& e) {
    throw io::InputError(with_flag_names(e.what()));
  }
  const scene::LoadedModel loaded = scene::load_model_and_scene(a.model);
  const mech::Model& model = loaded.model;
  if (loaded.scene)  // what loading repaired (balance_inertia)
    for (const auto& n : loaded.scene->notes) std::cerr << "lcsim: note: " << n << "\n";
  (void)sim::make_integrator(a.method);  // an unknown method before the state
  app::RunRequest req;
  req.method = a.method;
  req.x0 = resolve_initial_state(model, a.model, a.x0);
  if (a.project) project_start(model, *req.x0);
  req.options = run_options(a, model);
  req.csv_path = a.out;
  if (!a.out.empty() && !a.sensitivity.empty())
    req.sensitivity_csv_path = sensitivity_csv_path(a.out);
  req.linearisation_threshold = a.linearisation_threshold;
  std::optional<ProgressLine> progress;  // started with the run, once --out is open
  req.on_start = [&progress, &a, t_end = *req.options.t_end] {
    progress.emplace(t_end, a.no_progress ? ProgressLine::Mode::kNever
                            : a.progress  ? ProgressLine::Mode::kAlways
                                          : ProgressLine::Mode::kAuto);
  };
  req.options.progress = [&progress](double t) { progress->update(t); };
  const app::ModelRun run = app::run_model(loaded, req);
  const sim::Trajectory& tr = run.trajectory;
  if (!run.impact_note.empty()) std::cerr << "lcsim: note: " << run.impact_note << "\n";
  // A refused run integrated nothing: the error line is all there is to say.
  if (tr.status == sim::RunStatus::kInvalidInput) {
    if (!a.project && model.is_mechanical() && !sim::infeasible_start(model, *req.x0).empty())
      std::cerr << "lcsim: hint: --project starts from the nearest feasible positions\n";
    check_status(tr.status, with_flag_names(tr.message));
  }
  if (tr.status == sim::RunStatus::kCompleted) progress->done();
  if (a.json)
    std::cout << app::run_json(model, tr, run.linearisation).dump(2) << "\n";
  else
    print_summary(a, model, tr, run.linearisation, run.csv_written, loaded.circuit.get());
  if (!a.json) print_sensitivity(tr, run.csv_written ? req.sensitivity_csv_path : "");
  if (!run.linearisation_warning.empty())
    std::cerr << "lcsim: warning: " << run.linearisation_warning << "\n";
  print_warnings(tr);
  check_status(tr.status, with_flag_names(tr.message));
}

void setup(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  const sim::Options defaults;
  auto* cmd = app.add_subcommand("simulate", "Simulate a model (default: exact event-driven)");
  cmd->add_option("model", a->model, "Model file (YAML)")->required();
  cmd->add_option("--x0", a->x0, "Initial state a,b,... (q then v); default: the model's");
  auto* t_end = cmd->add_option("--t-end", a->t_end, "Horizon (s); default: the model's t_end");
  cmd->add_option("--method", a->method,
                  "Integrator (default event): " + name_list(sim::integrator_names()));
  cmd->add_option(
      "--h", a->h,
      "Time step of the time-stepping methods (s); default " + sim::short_number(defaults.h));
  cmd->add_option("--theta", a->theta,
                  "Moreau–Jean theta in [0, 1]; default " + sim::short_number(defaults.theta));
  cmd->add_flag("--project", a->project,
                "If the initial state violates a constraint, start from the nearest feasible "
                "positions (kinetic metric) instead of refusing it");
  auto* prog = cmd->add_flag("--progress", a->progress,
                             "Report progress on stderr, one line at most twice a second "
                             "(default: only on a terminal, after the first second)");
  cmd->add_flag("--no-progress", a->no_progress, "Never report progress")->excludes(prog);
  cmd->add_flag("--force", a->force,
                "Run backward Euler even where it is not consistent (rho_i >= 3, §7.3)");
  cmd->add_option("--dt-out", a->dt_out, "Output grid step (s); 0 = events only");
  cmd->add_option("--out", a->out, "Write the trajectory CSV here (streamed as the run goes)");
  cmd->add_option("--max-output", a->max_output,
                  "Refuse a run whose recorded output would exceed this many bytes (e.g. 1e9); "
                  "default " +
                      sim::short_number(defaults.max_output_bytes));
  cmd->add_flag("--json", a->json, "Print the run summary as JSON");
  cmd->add_option("--sensitivity", a->sensitivity,
                  "Forward sensitivities (euler and moreau-jean: of their step map), "
                  "comma-separated: x0, f[i], g[c], "
                  "e[c], K[i][j], D[i][j], M[i][j], amplitude[input]; a general LCS's A[i][j], "
                  "B[i][j], C[i][j], D[i][j] (docs/sensitivities.md); in --json, and with "
                  "--out in <out>.sensitivity.csv");
  cmd->add_option("--linearisation-threshold", a->linearisation_threshold,
                  "Scenes: warn when the linear model is off by more than this (relative; "
                  "default " +
                      sim::short_number(scene::kLinearisationThreshold) + ")");
  cmd->add_option("--impact", a->impact,
                  "Impact law (default " + defaults.impact +
                      ", with the model's restitution): " + name_list(impact::impact_law_names()));
  cmd->add_option(
      "--lcp", a->lcp,
      "LCP solver (default " + defaults.lcp_solver + "): " + name_list(lcp::solver_names()));
  cmd->callback([a, t_end] {
    // Given means given: --t-end nan is an error, not the model's horizon.
    a->t_end_given = t_end->count() > 0;
    run_simulate(*a);
  });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
