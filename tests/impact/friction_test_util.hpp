// Random planar friction impacts for the impact tests (friction_test.cpp)
// and the differential test against Siconos (tests/impact_siconos/).
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <random>

#include "impact/impact_test_util.hpp"

namespace lcsim::impact::testing {

// Random models: M SPD with masses over two decades, 1..4 contacts of which
// a random subset (or all) has friction, mu in [0, 1], all closed,
// restitution e.
struct RandomFriction {
  mech::MechanicalModel model;
  Eigen::VectorXd v;
  IndexSet closed;
};

inline RandomFriction random_friction(std::mt19937_64& rng, double e, bool all_frictional = false) {
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  // N >= 2k: the normal and tangent rows independent (G M^{-1} G' positive
  // definite), as for bodies in the plane (3 coordinates per body).
  const int k = std::uniform_int_distribution<int>(1, 4)(rng);
  const int N = std::uniform_int_distribution<int>(2 * k, 2 * k + 2)(rng);
  Eigen::MatrixXd A(N, N), E(k, N);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) A(i, j) = n01(rng);
  Eigen::VectorXd d(N);
  for (int i = 0; i < N; ++i) d(i) = std::pow(10.0, 2.0 * u01(rng) - 1.0);
  Eigen::MatrixXd M = A * A.transpose() * 0.1 + Eigen::MatrixXd(d.asDiagonal());
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < N; ++j) E(i, j) = n01(rng);
  RandomFriction r;
  r.model = make_model(M, E);
  r.model.restitution = Eigen::VectorXd::Constant(k, e);
  for (int i = 0; i < k; ++i) {
    if (!all_frictional && u01(rng) < 0.25) continue;
    Eigen::VectorXd t(N);
    for (int j = 0; j < N; ++j) t(j) = n01(rng);
    r.model.friction.push_back({i, t, u01(rng)});
  }
  if (r.model.friction.empty()) r.model.friction.push_back({0, Eigen::VectorXd::Ones(N), 0.5});
  r.v.resize(N);
  for (int j = 0; j < N; ++j) r.v(j) = n01(rng);
  for (int i = 0; i < k; ++i) r.closed.push_back(i);
  return r;
}

}  // namespace lcsim::impact::testing
