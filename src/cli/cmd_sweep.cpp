// `lcsim sweep MODEL`: the speed–accuracy trade, measured. Runs each method at
// each step h and compares it with the exact event-driven solution:
//   error_final    max-abs difference of the final states,
//   error_max      largest max-abs state difference over the comparison grid
//                  (the time-stepping samples at multiples of dt_cmp, a
//                  multiple of h with at most ~2000 points per run, against the
//                  event-driven run sampled exactly on the same grid; at a
//                  jump the exact run has two samples, before and after, and
//                  the nearer one counts),
//   max_violation  the run's most negative gap,
//   energy_drift   (E_final - E_initial) of the run minus that of the exact run,
//   steps, lcp_solves, wall_time_s (median of --repeat runs without samples).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>

#include "cli/command.hpp"
#include "cli/output.hpp"
#include "cli/run_inputs.hpp"
#include "io/io.hpp"
#include "sim/sim.hpp"

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
};

std::vector<std::string> split_list(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

struct Row {
  std::string method;
  double h = 0.0;  // 0 for event
  double error_final = 0.0, error_max = 0.0, max_violation = 0.0, energy_drift = 0.0;
  long steps = 0, lcp_solves = 0;
  double wall_time_s = 0.0;
  std::string status = "completed";
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

// Largest max-abs state error of the time-stepping samples against the exact
// samples on the same grid (both sorted by time).
double max_sample_error(const sim::Trajectory& ts, const sim::Trajectory& exact, double h) {
  double worst = 0.0;
  size_t e = 0;
  for (const auto& s : ts.samples) {
    const double tol = 1e-9 * std::max(h, std::abs(s.t) * 1e-6);
    while (e < exact.samples.size() && exact.samples[e].t < s.t - tol) ++e;
    double best = std::numeric_limits<double>::infinity();
    for (size_t j = e; j < exact.samples.size() && exact.samples[j].t <= s.t + tol; ++j)
      best = std::min(best, (s.x - exact.samples[j].x).cwiseAbs().maxCoeff());
    if (std::isfinite(best)) worst = std::max(worst, best);
  }
  return worst;
}

nlohmann::json rows_json(const std::string& model, const std::vector<Row>& rows) {
  nlohmann::json j;
  j["model"] = model;
  j["rows"] = nlohmann::json::array();
  for (const auto& r : rows) {
    nlohmann::json o;
    o["method"] = r.method;
    o["h"] = r.method == "event" ? nlohmann::json(nullptr) : nlohmann::json(r.h);
    o["error_final"] = r.error_final;
    o["error_max"] = r.error_max;
    o["max_violation"] = r.max_violation;
    o["energy_drift"] = r.energy_drift;
    o["steps"] = r.steps;
    o["lcp_solves"] = r.lcp_solves;
    o["wall_time_s"] = r.wall_time_s;
    o["status"] = r.status;
    j["rows"].push_back(o);
  }
  return j;
}

void run_sweep(const SweepArgs& a) {
  const mech::Model model = io::load_model(a.model);
  const std::vector<std::string> methods = split_list(a.methods);
  if (methods.empty()) throw io::InputError("--methods: empty list");
  std::vector<std::unique_ptr<sim::Integrator>> integrators;
  for (const auto& m : methods) {
    try {
      integrators.push_back(sim::make_integrator(m));
    } catch (const std::invalid_argument& e) {
      throw io::InputError(std::string("--methods: ") + e.what());
    }
  }
  (void)lcp::make_solver(a.lcp);
  std::vector<double> hs;
  for (const auto& tok : split_list(a.hs)) {
    const Eigen::VectorXd v = io::parse_vector(tok, "--h");
    hs.push_back(v(0));
  }
  if (hs.empty()) throw io::InputError("--h: empty list");

  const Eigen::VectorXd x0 = resolve_initial_state(model, a.model, a.x0);
  sim::Options base;
  base.t_end = resolve_horizon(model, a.model, a.t_end_given, a.t_end);
  for (double h : hs)
    if (!(h > 0.0) || !std::isfinite(h) || h > base.t_end)
      throw io::InputError("--h: every step must be finite, > 0 and <= the horizon (got " +
                           std::to_string(h) + ")");
  if (a.repeat < 1) throw io::InputError("--repeat: must be >= 1");
  if (!(a.theta >= 0.0 && a.theta <= 1.0)) throw io::InputError("--theta: must lie in [0, 1]");
  base.theta = a.theta;
  base.force = a.force;
  base.lcp_solver = a.lcp;
  // The plot's path and script are checked before the runs, not after.
  std::filesystem::path script;
  if (!a.plot.empty()) {
    check_writable(a.plot);
    script = find_plot_script("plot_work_precision.py", "LCSIM_PLOT_WORK_PRECISION");
  }

  // The exact reference: event-driven, final state and energy change.
  sim::Options ex_opt = base;
  ex_opt.dt_out = 0.0;
  const auto event = sim::make_integrator("event");
  const sim::Trajectory exact = event->run(model, x0, ex_opt);
  if (exact.status != sim::RunStatus::kCompleted)
    throw NumericalError("sweep: the exact event-driven run failed: " + exact.message);
  const double exact_drift = exact.energy_final - exact.energy_initial;

  auto timed = [&](const sim::Integrator& integ, sim::Options opt) {
    opt.record_samples = false;
    opt.dt_out = 0.0;
    std::vector<double> times;
    for (int r = 0; r < a.repeat; ++r) times.push_back(integ.run(model, x0, opt).wall_time_s);
    return median(times);
  };

  std::vector<Row> rows;
  const size_t total = integrators.size() * hs.size();
  size_t done = 0;
  for (size_t mi = 0; mi < integrators.size(); ++mi) {
    const sim::Integrator& integ = *integrators[mi];
    if (methods[mi] == "event") {
      Row r;
      r.method = "event";
      r.max_violation = exact.max_violation;
      r.steps = exact.steps;
      r.lcp_solves = exact.lcp_solves;
      r.wall_time_s = timed(integ, ex_opt);
      rows.push_back(r);
      done += hs.size();
      std::cerr << "sweep: [" << done << "/" << total << "] event done\n";
      continue;
    }
    for (double h : hs) {
      sim::Options opt = base;
      opt.h = h;
      // Comparison grid: a multiple of h, at most ~2000 points.
      const double m = std::max(1.0, std::round(base.t_end / (2000.0 * h)));
      opt.dt_out = m * h;
      Row r;
      r.method = methods[mi];
      r.h = h;
      const sim::Trajectory tr = integ.run(model, x0, opt);
      if (tr.status != sim::RunStatus::kCompleted) {
        r.status = "failed: " + tr.message;
        r.error_final = r.error_max = std::numeric_limits<double>::infinity();
      } else {
        sim::Options eo = ex_opt;
        eo.dt_out = opt.dt_out;
        const sim::Trajectory ex_grid = event->run(model, x0, eo);
        r.error_final = (tr.final_state - exact.final_state).cwiseAbs().maxCoeff();
        r.error_max = ex_grid.status == sim::RunStatus::kCompleted
                          ? max_sample_error(tr, ex_grid, h)
                          : std::numeric_limits<double>::quiet_NaN();
        r.error_max = std::max(r.error_max, r.error_final);
        r.energy_drift = (tr.energy_final - tr.energy_initial) - exact_drift;
        r.wall_time_s = timed(integ, opt);
      }
      r.max_violation = tr.max_violation;
      r.steps = tr.steps;
      r.lcp_solves = tr.lcp_solves;
      rows.push_back(r);
      ++done;
      std::cerr << "sweep: [" << done << "/" << total << "] " << r.method << " h = " << h
                << (r.status == "completed" ? "" : " (" + r.status + ")") << "\n";
    }
  }

  const nlohmann::json j = rows_json(model.name, rows);
  if (a.json) {
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("model %s, t_end %g, x0 from %s\n", model.name.c_str(), base.t_end,
                a.x0.empty() ? "the model" : "--x0");
    std::printf("%-12s %-8s %-11s %-11s %-11s %-11s %-9s %-9s %-10s\n", "method", "h", "err_final",
                "err_max", "violation", "E_drift", "steps", "lcp", "wall_s");
    for (const auto& r : rows) {
      char hbuf[32];
      if (r.method == "event")
        std::snprintf(hbuf, sizeof hbuf, "-");
      else
        std::snprintf(hbuf, sizeof hbuf, "%g", r.h);
      std::printf("%-12s %-8s %-11.3e %-11.3e %-11.3e %-11.3e %-9ld %-9ld %-10.3e%s\n",
                  r.method.c_str(), hbuf, r.error_final, r.error_max, r.max_violation,
                  r.energy_drift, r.steps, r.lcp_solves, r.wall_time_s,
                  r.status == "completed" ? "" : ("  " + r.status).c_str());
    }
  }
  std::cout.flush();
  if (!a.plot.empty()) {
    const std::filesystem::path tmp = std::filesystem::temp_directory_path() /
                                      ("lcsim_sweep_" + std::to_string(::getpid()) + ".json");
    io::write_file_atomic(tmp, j.dump(2));
    try {
      draw_plot(script, tmp, a.plot, model.name, "--plot");
    } catch (...) {
      std::filesystem::remove(tmp);
      throw;
    }
    std::filesystem::remove(tmp);
    std::cerr << "work-precision diagram written to " << a.plot << "\n";
  }
}

void setup(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  auto* cmd = app.add_subcommand(
      "sweep", "Work-precision sweep: methods x step sizes against the exact event-driven run");
  cmd->add_option("model", a->model, "Model file (YAML)")->required();
  cmd->add_option("--x0", a->x0, "Initial state a,b,... (q then v); default: the model's");
  auto* t_end = cmd->add_option("--t-end", a->t_end, "Horizon (s); default: the model's t_end");
  cmd->add_option("--methods", a->methods, "Comma-separated: event, euler, moreau-jean");
  cmd->add_option("--h", a->hs, "Comma-separated step sizes (s), e.g. 1e-2,1e-3,1e-4");
  cmd->add_option("--repeat", a->repeat, "Timing runs per point (median); default 3");
  cmd->add_option("--theta", a->theta, "Moreau–Jean theta in [0, 1]; default 0.5");
  cmd->add_flag("--force", a->force, "Run backward Euler even where it is not consistent");
  cmd->add_option("--lcp", a->lcp, "LCP solver: pivot, lemke, pgs, enum");
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
