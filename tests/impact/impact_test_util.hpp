// Helpers for the impact-rule tests: small exact models and random ones.
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <lcsim/impact/impact.hpp>
#include <lcsim/mech/mech.hpp>
#include <random>
#include <string>

namespace lcsim::impact::testing {

inline mech::MechanicalModel make_model(const Eigen::MatrixXd& M, const Eigen::MatrixXd& E) {
  mech::MechanicalModel m;
  m.M = M.sparseView();
  m.E = E.sparseView();
  mech::fill_defaults(m);
  return m;
}

// Example 3.8.3, eq. (3.74): two carts, a stop (x1 >= 0) and a hook (x1 - x2 >= 0).
inline mech::MechanicalModel hook_model() { return *mech::two_carts_model(true).mechanical; }

// Example 1.4.1: three unit balls on a line, touching: x2 - x1 >= 0, x3 - x2 >= 0.
inline mech::MechanicalModel three_balls() {
  Eigen::MatrixXd E(2, 3);
  E << -1, 1, 0, 0, -1, 1;
  return make_model(Eigen::MatrixXd::Identity(3, 3), E);
}

inline ImpactInput input(const mech::MechanicalModel& m, const Eigen::VectorXd& v,
                         const IndexSet& closed, const Eigen::VectorXd& e = {}) {
  ImpactInput in;
  in.model = &m;
  in.q = Eigen::VectorXd::Zero(m.dofs());
  in.v = v;
  in.closed = closed;
  in.restitution = e.size() ? e : Eigen::VectorXd::Zero(m.num_constraints());
  return in;
}

// The pivoting LCP solver, made once.
inline const lcp::Solver& pivot() {
  static const auto s = lcp::make_solver("pivot");
  return *s;
}

// The impact law `rule` applied with the pivoting solver.
inline ImpactResult run(const std::string& rule, const ImpactInput& in) {
  return make_impact_law(rule)->apply(in, pivot());
}

inline void expect_near(const Eigen::VectorXd& a, const Eigen::VectorXd& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (int i = 0; i < a.size(); ++i) EXPECT_NEAR(a(i), b(i), tol) << "entry " << i;
}

inline Eigen::VectorXd vec(std::initializer_list<double> x) {
  Eigen::VectorXd v(x.size());
  int i = 0;
  for (double d : x) v(i++) = d;
  return v;
}

// A random impact: SPD M with masses over two decades, E of full row rank
// (k <= N) or rank deficient (some rows combinations of others), a random
// closed set and velocity.
struct RandomImpact {
  mech::MechanicalModel model;
  Eigen::VectorXd v;
  IndexSet closed;
  bool dependent = false;
};

inline RandomImpact random_impact(std::mt19937_64& rng, bool dependent) {
  std::normal_distribution<double> n01(0.0, 1.0);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  std::uniform_int_distribution<int> dofs(1, 6);
  RandomImpact r;
  const int N = dofs(rng);
  Eigen::MatrixXd A(N, N);
  for (int i = 0; i < N; ++i)
    for (int j = 0; j < N; ++j) A(i, j) = n01(rng);
  Eigen::VectorXd s(N);  // scales 10^-0.5 .. 10^0.5: masses over two decades
  for (int i = 0; i < N; ++i) s(i) = std::pow(10.0, u01(rng) - 0.5);
  const Eigen::MatrixXd M =
      s.asDiagonal() * (A * A.transpose() + 0.1 * Eigen::MatrixXd::Identity(N, N)) * s.asDiagonal();
  int k;
  Eigen::MatrixXd E;
  if (!dependent) {
    k = std::uniform_int_distribution<int>(1, N)(rng);
    E.resize(k, N);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < N; ++j) E(i, j) = n01(rng);
  } else {
    // rank r < k rows: k = r + extra, the extra rows nonnegative or mixed combinations.
    const int rank = std::uniform_int_distribution<int>(1, N)(rng);
    k = rank + std::uniform_int_distribution<int>(1, 3)(rng);
    Eigen::MatrixXd B(rank, N), C(k, rank);
    for (int i = 0; i < rank; ++i)
      for (int j = 0; j < N; ++j) B(i, j) = n01(rng);
    C.setZero();
    C.topRows(rank).setIdentity();
    for (int i = rank; i < k; ++i)
      for (int j = 0; j < rank; ++j) C(i, j) = n01(rng);
    E = C * B;
  }
  r.model = make_model(M, E);
  r.v.resize(N);
  for (int i = 0; i < N; ++i) r.v(i) = n01(rng) / s(i);  // velocities matched to the masses
  for (int i = 0; i < k; ++i)
    if (u01(rng) < 0.8) r.closed.push_back(i);
  r.dependent = dependent;
  return r;
}

// |E_i| |v|: the scale of the rate E_i v, for relative tolerances.
inline Eigen::VectorXd rate_scale(const Eigen::MatrixXd& E, const Eigen::VectorXd& v,
                                  const Eigen::VectorXd& w) {
  return E.cwiseAbs() * (v.cwiseAbs() + w.cwiseAbs());
}

}  // namespace lcsim::impact::testing
