// Running a model to its outputs, said once for `lcsim simulate`, `lcsim
// compare` and Python's lcsim.simulate: the run's samples routed as it goes
// (a streamed CSV, the caller's own sink, or kept), a scene's linearisation
// checked at the states it visited, and the JSON of `simulate --json`.
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/sim/sim.hpp>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

namespace lcsim::app {

// A way to run a model other than an integrator by name: an exact reference
// run (reference_runner), Bullet with its world settings (the CLI's compare).
using Runner = std::function<sim::Trajectory(const mech::Model& model, const Eigen::VectorXd& x0,
                                             const sim::Options& opt)>;

// sim::run_reference of `law` as a Runner.
Runner reference_runner(const sim::ReferenceLaw& law);

struct RunRequest {
  std::string method = "event";  // an integrator's name (sim::integrators())
  Runner runner;                 // when set, runs instead of `method`
  // Unset: the model's initial state (with `method`, sim::simulate refuses a
  // model without one; a runner is given model.initial as it is).
  std::optional<Eigen::VectorXd> x0;
  // Passed to the run as given (progress included), except record_samples
  // and sample_sink, which run_model sets, and dt_out (see run_model).
  sim::Options options;
  // Where the samples go, any of:
  std::string csv_path;              // "" = none (io::TrajectoryCsvWriter)
  std::string sensitivity_csv_path;  // "" = none; the samples' dx (io::SensitivityCsvWriter)
  std::function<void(const sim::Sample&)> sample_sink;  // the caller's own (must not throw)
  bool keep_samples = false;                            // in the returned trajectory
  // A scene's run checks its linear model at the visited states
  // (scene::check_linearisation) and warns above this (relative, > 0).
  bool check_linearisation = true;
  double linearisation_threshold = scene::kLinearisationThreshold;
  // Called once the outputs are open, just before the run (a progress line's start).
  std::function<void()> on_start;
};

struct ModelRun {
  sim::Trajectory trajectory;  // samples only when RunRequest::keep_samples
  // Scenes (and check_linearisation) only; unset for a refused run.
  std::optional<scene::LinearisationCheck> linearisation;
  std::string linearisation_warning;  // "" when within the threshold or not checked
  // The note of an aliased impact law (impact::laws().alias_note), "" when
  // Options::impact is no alias or the run applied no law.
  std::string impact_note;
  bool csv_written = false;  // the CSV is in place (the run completed)
};

// Runs the request on a loaded model. The CSV file is created before the run
// (an unwritable path fails at once, io::InputError) and appears only when
// the run completes. When no sample is asked for (no CSV, no sink, not kept),
// a scene's run still records samples for its check, on a grid of
// scene::kLinearisationStates points over the horizon unless dt_out > 0.
// Throws io::InputError ("linearisation_threshold must be ...") for a bad
// threshold; every other bad input is the trajectory's status
// (kInvalidInput, nothing integrated) and message, naming fields.
ModelRun run_model(const scene::LoadedModel& loaded, const RunRequest& request);

// What `lcsim simulate --json` prints (less its final newline):
// io::trajectory_json with linearisation_error and linearisation_check (null
// when the run was not checked), and "sensitivity" (io::sensitivity_json)
// when the run computed sensitivities.
nlohmann::json run_json(const mech::Model& model, const sim::Trajectory& trajectory,
                        const std::optional<scene::LinearisationCheck>& linearisation);

// The grid on which a step-h run is compared with its exact reference: a
// multiple of h with at most ~2000 points over t_end (s).
double comparison_grid(double t_end, double h);

}  // namespace lcsim::app
