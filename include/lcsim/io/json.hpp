// JSON of runs, vectors and matrices (the keys of `simulate --json`).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <nlohmann/json.hpp>

namespace lcsim::io {

using Eigen::VectorXd;

// JSON summary of a run (keys of the simulate command).
nlohmann::json trajectory_json(const mech::Model& model, const sim::Trajectory& traj);

nlohmann::json to_json(const VectorXd& v);
nlohmann::json to_json(const Eigen::MatrixXd& m);
// x, or null when it is not finite (JSON has no inf or nan): an error that
// could not be measured, a deviation of a run that failed.
inline nlohmann::json finite_or_null(double x) {
  return std::isfinite(x) ? nlohmann::json(x) : nlohmann::json(nullptr);
}

}  // namespace lcsim::io
