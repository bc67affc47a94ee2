// The work-precision sweep (`lcsim sweep`): each method at each step h,
// measured against an exact event-driven run of the same impact law, or of
// the nearest exact law where the method has none of its own (issue 13).
//
// Part of the public face of src/io (above sim: it runs integrators by name,
// so the Bullet layer's registered "bullet" takes part without io naming it).
#pragma once

#include <Eigen/Dense>
#include <functional>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/sim/sim.hpp>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace lcsim::app {

struct SweepOptions {
  std::vector<std::string> methods;  // integrator names (sim::make_integrator)
  std::vector<double> hs;            // step sizes (s), each in (0, t_end]
  int repeat = 3;                    // timing runs per point (median), >= 1
  sim::Options base;                 // t_end, impact, theta, force, lcp_solver, ...
  // base.sensitivity non-empty: each row also measures error_gradient, its
  // derivative dx(T)/dtheta against the exact one (docs/sensitivities.md);
  // empty (the default): no such column, the outputs as before.
  // Called after each row with "[i/n] method h = ..." (progress for a log).
  std::function<void(const std::string&)> progress;
};

// One exact reference run (one per distinct sim::ReferenceLaw).
struct ReferenceRun {
  sim::ReferenceLaw law;
  std::string status = "completed";  // or "failed: <message>"
  sim::Trajectory run;               // events only (dt_out = 0)
  long warnings = 0;
  std::string first_warning;  // "" when none
};

// A row: one method at one h (the event method has one row, h = 0).
//   error_final    max-abs difference of the final states,
//   error_events   at each event of the exact run, the max-abs difference of
//                  the run's state at the end of the step holding it and the
//                  exact state just before or after it (the nearer): the
//                  error where it is made, which a damped run at rest by
//                  t_end no longer shows,
//   error_max      the error over the whole run: the largest max-abs state
//                  difference over the comparison grid (the run's samples at
//                  multiples of dt_cmp, a multiple of h with at most ~2000
//                  points, against the reference sampled on the same grid; at
//                  a jump the reference has two samples and the nearer one
//                  counts), at least error_final and error_events,
//   error_floor    "" when the run integrates the model; else why its error
//                  stops falling with h (Bullet's multibody integrates the
//                  URDF's nonlinear dynamics, the exact run the model's
//                  linearisation: "the linearisation gap: ..."),
//   max_violation  the run's most negative gap,
//   energy_drift   (E_final - E_initial) of the run minus the reference's (J),
//   error_gradient only when base.sensitivity is asked: the max-abs
//                  difference of dx(T)/dtheta (every column) to the exact
//                  run's; +inf when either has no derivative there (a loss)
//                  or the method does not compute it.
// Errors are +inf when the run or its reference failed or was refused.
// kErrorMeasures says the same in one sentence (the JSON's "error_measures").
inline constexpr const char* kErrorMeasures =
    "max-abs state difference to the exact run of each row's reference law: error_max over the "
    "whole run (every sample of the comparison grid and every exact event), error_events at "
    "the exact events, error_final at t_end";
struct SweepRow {
  std::string method;
  double h = 0.0;  // 0 for event
  sim::ReferenceLaw reference;
  std::string status = "completed";  // "completed", "failed: ..." or "refused: ..."
  double error_final = 0.0, error_max = 0.0, max_violation = 0.0, energy_drift = 0.0;
  double error_events = 0.0;
  double error_gradient = 0.0;  // when SweepOptions::base.sensitivity is asked
  std::string error_floor;
  long steps = 0, lcp_solves = 0;
  // Median of `repeat` runs with their output (samples on the comparison
  // grid; the event row on the finest grid of the sweep); 0 if not completed.
  double wall_time_s = 0.0;
  long warnings = 0;  // the run's
  std::string first_warning;
  long reference_warnings = 0;  // the reference run's
  std::string reference_first_warning;
};

struct SweepResult {
  std::string model;
  double t_end = 0.0;
  std::string impact;                    // Options::impact of the sweep
  std::vector<std::string> sensitivity;  // the columns asked (empty: no error_gradient)
  std::vector<ReferenceRun> references;
  std::vector<SweepRow> rows;
  // True if some reference run failed (its rows carry the failure): the
  // caller reports numerical trouble after printing the table.
  bool reference_failed() const;
};

// Checks the options (io::InputError naming the option: --methods, --h,
// --repeat, --theta, --impact, --lcp), then every row with its method
// (sim::Integrator::refuse) before any runs: a refused row keeps its
// status ("refused: <why>") and the others run; when every row is refused,
// io::InputError with the first refusal. Runs that fail (a diverged run
// included) give rows with their status; nothing throws for numerical
// trouble.
SweepResult run_sweep(const mech::Model& model, const Eigen::VectorXd& x0, const SweepOptions& opt);

// {"model", "t_end", "impact", "references": [...], "rows": [...]}; rows as
// SweepRow with "h": null for event, non-finite numbers as null, and
// "reference_law", "reference_inelastic", "reference_reason".
nlohmann::json sweep_json(const SweepResult& r);

}  // namespace lcsim::app
