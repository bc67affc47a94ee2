// A bar on one corner with planar friction whose normal and tangent rows
// couple (W_NT != 0), for the sensitivity tests through friction impacts
// (tests/sim/test_sensitivity_events.cpp, test_sensitivity_friction_params.cpp).
#pragma once

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <lcsim/mech/mech.hpp>

namespace lcsim::test_support {

// The bar (x, y, theta; M =
// diag(1, 1, 0.1); gap y - 0.5 theta, tangent x' + 0.2 y' + 0.4 theta':
// W_NT = -1.8) from (0, 0.3, 0, 1, 0, 0.4).
inline mech::Model coupled_bar(double mu, double e) {
  mech::Model m;
  m.name = "bar";
  mech::MechanicalModel& b = m.mechanical.emplace();
  Eigen::SparseMatrix<double> M(3, 3), E(1, 3);
  M.insert(0, 0) = 1, M.insert(1, 1) = 1, M.insert(2, 2) = 0.1;
  E.insert(0, 1) = 1, E.insert(0, 2) = -0.5;
  b.M = M;
  b.D = Eigen::SparseMatrix<double>(3, 3);
  b.K = Eigen::SparseMatrix<double>(3, 3);
  b.E = E;
  b.f = Eigen::VectorXd::Zero(3);
  b.f(1) = -9.81;
  b.g = Eigen::VectorXd::Zero(1);
  b.coordinates = {"x", "y", "theta"};
  b.constraints = {"corner"};
  b.restitution = Eigen::VectorXd::Constant(1, e);
  mech::FrictionalContact fc;
  fc.contact = 0;
  fc.tangent = Eigen::SparseVector<double>(3);
  fc.tangent.insert(0) = 1;
  fc.tangent.insert(1) = 0.2;
  fc.tangent.insert(2) = 0.4;
  fc.mu = mu;
  b.friction = {fc};
  m.initial = Eigen::VectorXd(6);
  m.initial << 0, 0.3, 0, 1, 0, 0.4;
  return m;
}

}  // namespace lcsim::test_support
