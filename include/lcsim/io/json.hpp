// JSON of runs, vectors and matrices (the keys of `simulate --json`).
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <nlohmann/json.hpp>

namespace lcsim::io {

using Eigen::VectorXd;

// JSON summary of a run (keys of the simulate command).
nlohmann::json trajectory_json(const mech::Model& model, const sim::Trajectory& traj);

nlohmann::json to_json(const VectorXd& v);
nlohmann::json to_json(const Eigen::MatrixXd& m);

}  // namespace lcsim::io
