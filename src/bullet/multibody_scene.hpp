// Internal to src/bullet: the multibody scene of multibody_world.cpp, chosen
// by simulate_bullet (world.cpp) for models from URDF scenes.
#pragma once

#include <Eigen/Dense>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>
#include <vector>

namespace lcsim::bullet {

// Row `row` of E, c q_j + g >= 0 with j = coordinate: the bound -g/c on q_j
// from below (c > 0) or above (c < 0).
struct JointLimit {
  int row = 0;
  int coordinate = 0;
  double c = 1.0;
  double bound = 0.0;
  bool lower = true;
};

// One JointLimit per row of E; std::invalid_argument naming the file
// `source` (the scene's path; omitted when empty) and the first row that
// involves more or fewer than one coordinate (0-based).
std::vector<JointLimit> joint_limits_of(const mech::MechanicalModel& m, const std::string& source);

// "btMultiBody from the URDF, btMultiBodyConstraintSolver (100 iterations), ..."
std::string multibody_description(const WorldSettings& s);

// The scene run as a btMultiBody (multibody_world.cpp); `limits` from
// joint_limits_of. Never throws.
sim::Trajectory simulate_multibody(const mech::Model& model, const scene::Scene& setup,
                                   const std::vector<JointLimit>& limits, const Eigen::VectorXd& x0,
                                   const sim::Options& opt, const WorldSettings& s);

}  // namespace lcsim::bullet
