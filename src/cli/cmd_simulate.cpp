// `lcsim simulate MODEL`: run an integrator on a model and report the run.
#include <cmath>
#include <cstdio>
#include <iostream>
#include <lcsim/io/io.hpp>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <optional>
#include <vector>

#include "cli/command.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"

namespace lcsim::cli {
namespace {

struct SimulateArgs {
  std::string model;
  std::string x0;
  double t_end = std::nan("");  // NaN = the model's (when --t-end is not given)
  bool t_end_given = false;
  std::string method = "event";
  double dt_out = 0.0;
  std::string out;
  bool json = false;
  std::string impact = sim::Options{}.impact;  // the library's default
  std::string lcp = "pivot";
  double h = std::nan("");  // time-stepping step (s); NaN = sim::Options default
  bool h_given = false;
  double theta = 0.5;        // Moreau–Jean theta
  bool force = false;        // backward Euler despite the consistency guard
  bool project = false;      // move an infeasible q0 onto E q + g >= 0 first
  bool progress = false;     // --progress: progress lines on stderr even when not a terminal
  bool no_progress = false;  // --no-progress
  double linearisation_threshold = io::kLinearisationThreshold;  // scenes: warn above it
};

std::string fmt_vec(const Eigen::VectorXd& v) {
  std::string s = "(";
  char buf[64];
  for (int i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%s%.10g", i ? ", " : "", v(i));
    s += buf;
  }
  return s + ")";
}

std::string fmt_set(const std::vector<int>& s) {
  std::string r = "{";
  for (size_t i = 0; i < s.size(); ++i) r += (i ? "," : "") + std::to_string(s[i]);
  return r + "}";
}

void run_simulate(const SimulateArgs& a) {
  io::check_linearisation_threshold(a.linearisation_threshold);
  const io::LoadedModel loaded = io::load_model_and_scene(a.model);
  const std::optional<io::Scene>& scene = loaded.scene;
  const mech::Model& model = loaded.model;
  // Names are checked before anything runs, so a typo fails at once.
  auto integrator = sim::make_integrator(a.method);
  (void)impact::make_impact_law(a.impact);
  (void)lcp::make_solver(a.lcp);

  Eigen::VectorXd x0 = resolve_initial_state(model, a.model, a.x0);
  if (a.project && model.is_mechanical() && !sim::infeasible_start(model, x0).empty()) {
    // Documented in README: positions move to the nearest feasible ones in
    // the kinetic metric; velocities are kept.
    const mech::MechanicalModel& m = *model.mechanical;
    const Eigen::VectorXd q = x0.head(m.dofs());
    const Eigen::VectorXd p = mech::project_feasible(m, q);
    const double moved = std::sqrt((p - q).dot(m.M * (p - q)));
    x0.head(m.dofs()) = p;
    std::cerr << "lcsim: note: --project moved the initial positions onto E q + g >= 0 "
              << "(kinetic-metric distance " << moved << ")\n";
  }
  sim::Options opt;
  opt.t_end = resolve_horizon(model, a.model, a.t_end_given, a.t_end);
  if (!(a.dt_out >= 0.0) || !std::isfinite(a.dt_out))
    throw io::InputError("--dt-out: must be a finite number >= 0 (got " + std::to_string(a.dt_out) +
                         ")");
  opt.dt_out = a.dt_out;
  if (a.h_given || a.method != "event") {
    const double h = a.h_given ? a.h : opt.h;
    if (!(h > 0.0) || !std::isfinite(h))
      throw io::InputError("--h: must be a finite number > 0 (got " + std::to_string(h) + ")");
    if (h > *opt.t_end)
      throw io::InputError("--h: must not exceed the horizon " + std::to_string(*opt.t_end) +
                           " (got " + std::to_string(h) + ")");
    opt.h = h;
  }
  if (!(a.theta >= 0.0 && a.theta <= 1.0))
    throw io::InputError("--theta: must lie in [0, 1] (got " + std::to_string(a.theta) + ")");
  opt.theta = a.theta;
  opt.force = a.force;
  opt.impact = a.impact;
  opt.lcp_solver = a.lcp;
  // Samples feed only the CSV; a run without --out keeps none (at N = 10000
  // they were 64 MB of a 140 MB process).
  opt.record_samples = !a.out.empty();
  // A scene's linear model is checked at the visited states
  // (io::check_linearisation): keep the samples, on a grid of
  // io::kLinearisationStates points when no output grid was asked for and no
  // CSV is written (the CSV keeps the grid the user chose).
  if (scene) {
    opt.record_samples = true;
    if (opt.dt_out == 0.0 && a.out.empty())
      opt.dt_out = *opt.t_end / static_cast<double>(io::kLinearisationStates);
  }
  // An unwritable --out fails now, not after the run.
  if (!a.out.empty()) check_writable(a.out);

  ProgressLine progress(*opt.t_end, a.no_progress ? ProgressLine::Mode::kNever
                                    : a.progress  ? ProgressLine::Mode::kAlways
                                                  : ProgressLine::Mode::kAuto);
  opt.progress = [&progress](double t) { progress.update(t); };
  const sim::Trajectory tr = integrator->run(model, x0, opt);
  if (tr.status == sim::RunStatus::kCompleted) progress.done();
  const bool failed = tr.status != sim::RunStatus::kCompleted;
  if (!failed && !a.out.empty()) io::write_file_atomic(a.out, io::trajectory_csv(model, tr));
  std::optional<io::LinearisationCheck> lin;
  if (scene) {
    std::vector<Eigen::VectorXd> states;
    for (const auto& s : tr.samples) states.push_back(s.x);
    lin = io::check_linearisation(*scene, states);
  }
  if (a.json) {
    nlohmann::json j = io::trajectory_json(model, tr);
    j["linearisation_error"] = lin ? nlohmann::json(lin->error) : nlohmann::json(nullptr);
    j["linearisation_check"] = lin ? io::to_json(*lin) : nlohmann::json(nullptr);
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("model %s, method %s, t_end %g\n", model.name.c_str(), tr.method.c_str(), tr.t_end);
    if (!tr.impact_law.empty()) std::printf("impact law %s\n", tr.impact_law.c_str());
    for (const auto& e : tr.events) {
      std::printf("  t = %-20.15g %-12s %s -> %s  mode %s\n", e.t,
                  std::string(sim::to_string(e.type)).c_str(), fmt_vec(e.state_before).c_str(),
                  fmt_vec(e.state_after).c_str(), fmt_set(e.mode_after).c_str());
      if (!e.note.empty()) std::printf("      (%s)\n", e.note.c_str());
    }
    if (tr.events_not_recorded > 0)
      std::printf("  ... and %ld more events, counted, not recorded\n", tr.events_not_recorded);
    std::printf("final state %s\n", fmt_vec(tr.final_state).c_str());
    if (model.is_mechanical())
      std::printf("energy %.12g -> %.12g\n", tr.energy_initial, tr.energy_final);
    std::printf("max violation %.3g, LCP solves %ld, warnings %d, wall time %.3g s\n",
                tr.max_violation, tr.lcp_solves, tr.warnings, tr.wall_time_s);
    if (lin)
      std::printf("linearisation error %.3g %% (mass %.3g %%, forces %.3g %%) over %zu states\n",
                  100.0 * lin->error, 100.0 * lin->mass_error, 100.0 * lin->force_error,
                  lin->states);
    if (!a.out.empty() && !failed) std::printf("trajectory written to %s\n", a.out.c_str());
  }
  if (lin) {
    const std::string w = io::linearisation_warning(*lin, a.linearisation_threshold);
    if (!w.empty()) std::cerr << "lcsim: warning: " << w << "\n";
  }
  for (const auto& w : tr.warning_messages) std::cerr << "lcsim: warning: " << w << "\n";
  if (failed) throw NumericalError(tr.message);
}

void setup(CLI::App& app) {
  auto a = std::make_shared<SimulateArgs>();
  auto* cmd = app.add_subcommand("simulate", "Simulate a model (default: exact event-driven)");
  cmd->add_option("model", a->model, "Model file (YAML)")->required();
  cmd->add_option("--x0", a->x0, "Initial state a,b,... (q then v); default: the model's");
  auto* t_end = cmd->add_option("--t-end", a->t_end, "Horizon (s); default: the model's t_end");
  cmd->add_option("--method", a->method, "Integrator: event, euler, moreau-jean");
  auto* h = cmd->add_option("--h", a->h, "Time step of euler and moreau-jean (s); default 1e-3");
  cmd->add_option("--theta", a->theta, "Moreau–Jean theta in [0, 1]; default 0.5");
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
  cmd->add_option("--out", a->out, "Write the trajectory CSV here");
  cmd->add_flag("--json", a->json, "Print the run summary as JSON");
  cmd->add_option("--linearisation-threshold", a->linearisation_threshold,
                  "Scenes: warn when the linear model is off by more than this (relative; "
                  "default 0.01)");
  cmd->add_option("--impact", a->impact,
                  "Impact law (default moreau-restitution, with the model's restitution)");
  cmd->add_option("--lcp", a->lcp, "LCP solver: pivot, lemke, pgs, enum");
  cmd->callback([a, t_end, h] {
    // Given means given: --t-end nan is an error, not the model's horizon.
    a->t_end_given = t_end->count() > 0;
    a->h_given = h->count() > 0;
    run_simulate(*a);
  });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
