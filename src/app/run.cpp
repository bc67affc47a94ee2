// Running a model to its outputs (run.hpp): the run's options, where its
// samples go, the run, and what is said after it.
#include <algorithm>
#include <cmath>
#include <lcsim/app/run.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/csv.hpp>
#include <lcsim/io/json.hpp>
#include <lcsim/io/sensitivity.hpp>
#include <utility>
#include <vector>

namespace lcsim::app {
namespace {

bool checks_linearisation(const scene::LoadedModel& loaded, const RunRequest& r) {
  return loaded.scene.has_value() && r.check_linearisation;
}

// The request's options with the samples it asks for. Samples feed only the
// CSV, the caller's sink, the kept samples and a scene's check: when none but
// the check wants them, they are taken on a grid of kLinearisationStates
// points unless an output grid was asked for.
sim::Options run_options(const scene::LoadedModel& loaded, const RunRequest& r) {
  sim::Options opt = r.options;
  const bool asked =
      !r.csv_path.empty() || r.sample_sink || r.keep_samples || !r.sensitivity_csv_path.empty();
  const bool check = checks_linearisation(loaded, r);
  opt.record_samples = asked || check;
  const double horizon = opt.t_end.value_or(loaded.model.t_end);
  if (check && !asked && opt.dt_out == 0.0 && std::isfinite(horizon) && horizon > 0.0)
    opt.dt_out = horizon / static_cast<double>(scene::kLinearisationStates);
  return opt;
}

// Where the samples go as the run streams them (sim::Options::sample_sink):
// the CSV, the caller's sink, the kept samples and the visited states.
struct SampleRoute {
  std::optional<io::TrajectoryCsvWriter> csv;
  std::optional<io::SensitivityCsvWriter> sensitivity_csv;
  std::function<void(const sim::Sample&)> caller;
  std::vector<sim::Sample> kept;
  bool keep = false, visit = false;
  scene::LinearisationStates visited;

  SampleRoute(const scene::LoadedModel& loaded, const RunRequest& r)
      : caller(r.sample_sink), keep(r.keep_samples), visit(checks_linearisation(loaded, r)) {
    if (!r.csv_path.empty()) csv.emplace(r.csv_path, loaded.model);  // fails now, not after
    if (!r.sensitivity_csv_path.empty())
      sensitivity_csv.emplace(r.sensitivity_csv_path, loaded.model);
  }
  void add(const sim::Sample& s) {
    if (csv) csv->write(s);
    if (sensitivity_csv) sensitivity_csv->write(s);
    if (caller) caller(s);
    if (visit) visited.add(s.x);
    if (keep) kept.push_back(s);
  }
};

sim::Trajectory run(const mech::Model& model, const RunRequest& r, const sim::Options& opt) {
  if (r.runner) return r.runner(model, r.x0.value_or(model.initial), opt);
  return r.x0 ? sim::simulate(model, *r.x0, opt, r.method) : sim::simulate(model, opt, r.method);
}

// After the run: the CSV committed when it completed, the scene's check and
// its warning, the impact law's alias note.
void finish(const scene::LoadedModel& loaded, const RunRequest& r, const sim::Options& opt,
            SampleRoute& route, ModelRun& out) {
  sim::Trajectory& tr = out.trajectory;
  if (route.keep) tr.samples = std::move(route.kept);
  if (!tr.impact_law.empty()) out.impact_note = impact::laws().alias_note(opt.impact);
  if (tr.status == sim::RunStatus::kInvalidInput) return;  // nothing was integrated
  if (tr.status == sim::RunStatus::kCompleted && route.csv) {
    route.csv->commit();
    out.csv_written = true;
  }
  if (tr.status == sim::RunStatus::kCompleted && route.sensitivity_csv)
    route.sensitivity_csv->commit(tr.sensitivity_columns);
  if (route.visit) {
    out.linearisation = scene::check_linearisation(*loaded.scene, route.visited.states());
    out.linearisation_warning =
        scene::linearisation_warning(*out.linearisation, r.linearisation_threshold);
  }
}

}  // namespace

Runner reference_runner(const sim::ReferenceLaw& law) {
  return [law](const mech::Model& model, const Eigen::VectorXd& x0, const sim::Options& opt) {
    return sim::run_reference(model, x0, law, opt);
  };
}

ModelRun run_model(const scene::LoadedModel& loaded, const RunRequest& request) {
  scene::check_linearisation_threshold(request.linearisation_threshold);
  sim::Options opt = run_options(loaded, request);
  SampleRoute route(loaded, request);
  if (opt.record_samples) opt.sample_sink = [&route](const sim::Sample& s) { route.add(s); };
  ModelRun out;
  if (request.on_start) request.on_start();
  out.trajectory = run(loaded.model, request, opt);
  finish(loaded, request, opt, route, out);
  return out;
}

nlohmann::json run_json(const mech::Model& model, const sim::Trajectory& trajectory,
                        const std::optional<scene::LinearisationCheck>& linearisation) {
  nlohmann::json j = io::trajectory_json(model, trajectory);
  const auto& lin = linearisation;
  j["linearisation_error"] = lin ? nlohmann::json(lin->error) : nlohmann::json(nullptr);
  j["linearisation_check"] = lin ? scene::to_json(*lin) : nlohmann::json(nullptr);
  if (!trajectory.sensitivity_columns.empty())
    j["sensitivity"] = io::sensitivity_json(model, trajectory);
  return j;
}

double comparison_grid(double t_end, double h) {
  return std::max(1.0, std::round(t_end / (2000.0 * h))) * h;
}

}  // namespace lcsim::app
