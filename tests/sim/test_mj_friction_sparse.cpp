// Moreau–Jean with friction on its sparse path (src/sim/stepping/mj_friction.cpp,
// src/sim/stepping/friction_gs.cpp): one step against an independent dense
// computation of the same friction LCP on random coupled models, and the
// planar cart chain against closed forms and against the dense path.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdio>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kG = 9.81;

// A random coupled model: N = 6, k = 3 contacts, all closed at q0, the first
// two frictional, M and K dense SPD (so W_NT != 0), gravity-like f pressing
// the contacts shut, restitution 0.5 on contact 1.
struct Random {
  mech::Model model;
  VectorXd x0;
};

Random random_model(unsigned seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int N = 6, k = 3;
  auto rnd = [&](int r, int c) {
    MatrixXd x(r, c);
    for (Eigen::Index i = 0; i < x.size(); ++i) x.data()[i] = u(gen);
    return x;
  };
  const MatrixXd A = rnd(N, N), B = rnd(N, N);
  mech::MechanicalModel m;
  m.M = (A * A.transpose() + N * MatrixXd::Identity(N, N)).sparseView();
  m.K = (0.1 * B * B.transpose()).sparseView();
  const MatrixXd E = rnd(k, N);
  m.E = E.sparseView();
  // The velocity's scale picks the regime: 1 slips at every contact in one
  // step, the smaller ones put the stick force near the cone's edge, inside
  // or out (the friction impulse of a step is about mu |f| h ~ 0.02).
  const double scale = std::array<double, 6>{1.0, 0.3, 0.1, 0.03, 0.01, 0.003}[seed % 6];
  const VectorXd q0 = rnd(N, 1), v = scale * rnd(N, 1);
  m.g = -E * q0;  // every contact closed at q0
  // f = -E' (1 + |noise|) pushes each contact shut.
  m.f = -E.transpose() * (VectorXd::Ones(k) + rnd(k, 1).cwiseAbs()) * 5.0;
  mech::fill_defaults(m);
  m.restitution = VectorXd::Zero(k);
  m.restitution(1) = 0.5;
  for (int c = 0; c < 2; ++c)
    m.friction.push_back({c, VectorXd(rnd(N, 1)), 0.1 + 0.15 * (u(gen) + 1.0)});
  // v approaching every contact: E v = -0.1 (1 + noise), by the least-norm
  // correction of a random v.
  const VectorXd target = -0.1 * scale * (VectorXd::Ones(k) + rnd(k, 1).cwiseAbs());
  const VectorXd vv = v + E.transpose() * (E * E.transpose()).ldlt().solve(target - E * v);
  Random r{mech::model_of(m, "random" + std::to_string(seed)), VectorXd(2 * N)};
  r.x0 << q0, vv;
  return r;
}

sim::Trajectory one_step(const mech::Model& model, const VectorXd& x0, double h, int pivot_max,
                         int sparse_dofs) {
  sim::Options o;
  o.t_end = h;
  o.h = h;
  o.theta = 0.5;
  o.pivot_max_active = pivot_max;
  o.sparse_dofs_threshold = sparse_dofs;
  return sim::make_integrator("moreau-jean")->run(model, x0, o);
}

// The step computed densely from its definition (moreau_jean.cpp's header):
// W = M + h theta D + h^2 theta^2 K, v_free = v + h W^{-1}(f - D v - K(q + h
// theta v)), G = [E; T], the friction LCP of impact::friction_lcp on
// G W^{-1} G' solved by enumeration (the oracle), v+ = v_free + W^{-1} G' lambda.
struct DenseStep {
  VectorXd v_next, lambda_N, lambda_T, u_T;
};
DenseStep dense_step(const mech::MechanicalModel& m, const VectorXd& x0, double h) {
  const int N = m.dofs(), k = m.num_constraints(), nf = static_cast<int>(m.friction.size());
  const double th = 0.5;
  const MatrixXd M = m.M, D = m.D, K = m.K, E = m.E;
  const VectorXd q = x0.head(N), v = x0.tail(N);
  const MatrixXd W = M + h * th * D + h * h * th * th * K;
  const Eigen::LLT<MatrixXd> llt(W);
  const VectorXd v_free = v + h * llt.solve(m.f - D * v - K * (q + h * th * v));
  MatrixXd G(k + nf, N);
  G.topRows(k) = E;
  VectorXd mu(nf), belt(nf);
  std::vector<int> normal_of;
  for (int f = 0; f < nf; ++f) {
    G.row(k + f) = m.friction[f].tangent.transpose();
    mu(f) = m.friction[f].mu;
    belt(f) = m.friction[f].velocity;
    normal_of.push_back(m.friction[f].contact);
  }
  const MatrixXd WGt = llt.solve(G.transpose());
  const VectorXd rate = G * v_free;
  const VectorXd rate_N = rate.head(k) + m.restitution.cwiseProduct(E * v);
  const impact::FrictionLcp p =
      impact::friction_lcp(G * WGt, rate_N, rate.tail(nf) - belt, normal_of, mu);
  const lcp::Result r = lcp::make_solver("enum")->solve(p.M, p.q, {});
  EXPECT_TRUE(r.ok()) << r.message;
  DenseStep d;
  impact::friction_impulses(r.z, k, normal_of, mu, d.lambda_N, d.lambda_T);
  VectorXd lam(k + nf);
  lam << d.lambda_N, d.lambda_T;
  d.v_next = v_free + WGt * lam;
  d.u_T = G.bottomRows(nf) * d.v_next - belt;
  return d;
}

TEST(MjFrictionSparse, StepEqualsDenseFrictionLcpOnRandomCoupledModels) {
  const double h = 1e-2;
  int sticks = 0, slips = 0;
  for (unsigned seed = 1; seed <= 36; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Random rm = random_model(seed);
    const mech::MechanicalModel& m = *rm.model.mechanical;
    const DenseStep d = dense_step(m, rm.x0, h);
    for (int f = 0; f < 2; ++f) {
      if (!(d.lambda_N(f) > 1e-9)) continue;
      if (std::abs(d.u_T(f)) <= 1e-9)
        ++sticks;
      else
        ++slips;
    }
    // pivot_max_active 0: block Gauss–Seidel on the sparse Delassus matrix;
    // 32: the dense friction LCP by the pivoting solver. Dense LLT (64) and
    // sparse LDLT (0) of W alike.
    for (const int pivot_max : {0, 32})
      for (const int sparse_dofs : {0, 64}) {
        const sim::Trajectory tr = one_step(rm.model, rm.x0, h, pivot_max, sparse_dofs);
        ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
        // The sweep itself converged: one solve. A sweep that does not meet
        // its residual test falls back to the dense LCP, whose solves count
        // too, and would hide a wrong sweep behind a right answer.
        if (pivot_max == 0) {
          EXPECT_EQ(tr.lcp_solves, 1);
        }
        const VectorXd v = tr.final_state.tail(m.dofs());
        // Velocities O(1): the sweeps stop at a natural residual of 1e-13 (1 +
        // |b|) on a Delassus matrix with eigenvalues in [1e-2, 1] here, so
        // lambda and v are within ~1e-11 of the LCP's solution; the pivoting
        // path is exact to rounding. 1e-9 leaves two digits of margin.
        EXPECT_LE((v - d.v_next).cwiseAbs().maxCoeff(), 1e-9)
            << "pivot_max_active " << pivot_max << ", sparse_dofs " << sparse_dofs;
        // The impulses (mean forces times h), to the same relative level.
        const sim::Sample& last = tr.samples.back();
        for (int i = 0; i < 3; ++i)
          EXPECT_NEAR(last.u(i) * h, d.lambda_N(i), 1e-9 * (1 + std::abs(d.lambda_N(i))));
        for (int f = 0; f < 2; ++f)
          EXPECT_NEAR(last.u_t(f) * h, d.lambda_T(f), 1e-9 * (1 + std::abs(d.lambda_T(f))));
      }
  }
  // The models cover both friction modes.
  std::printf("random models: %d sticking, %d slipping frictional contacts\n", sticks, slips);
  EXPECT_GT(sticks, 0);
  EXPECT_GT(slips, 0);
}

// The planar cart chain (bench/bench_mj_friction.cpp): n carts with (x_i,
// y_i), unit masses, springs k_s between neighbours in x, floors y_i >= 0,
// gravity, friction mu along x_i.
mech::Model planar_chain(int n, double k_s, double mu, const VectorXd& vx0, double vy0 = 0.0) {
  const int N = 2 * n;
  MatrixXd K = MatrixXd::Zero(N, N), E = MatrixXd::Zero(n, N);
  for (int i = 0; i + 1 < n; ++i) {
    K(2 * i, 2 * i) += k_s;
    K(2 * i + 2, 2 * i + 2) += k_s;
    K(2 * i, 2 * i + 2) -= k_s;
    K(2 * i + 2, 2 * i) -= k_s;
  }
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(N, N).sparseView();
  m.K = K.sparseView();
  for (int i = 0; i < n; ++i) E(i, 2 * i + 1) = 1.0;
  m.E = E.sparseView();
  m.g = VectorXd::Zero(n);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < n; ++i) m.f(2 * i + 1) = -kG;
  mech::fill_defaults(m);
  for (int i = 0; i < n; ++i) m.friction.push_back({i, VectorXd::Unit(N, 2 * i), mu});
  mech::Model model = mech::model_of(m, "planar_chain");
  model.initial = VectorXd::Zero(2 * N);
  for (int i = 0; i < n; ++i) {
    model.initial(2 * i) = 0.1 * (i % 3);
    model.initial(N + 2 * i) = vx0(i);
    model.initial(N + 2 * i + 1) = vy0;
  }
  return model;
}

sim::Trajectory run_chain(const mech::Model& model, double t_end, double h, int pivot_max) {
  sim::Options o;
  o.t_end = t_end;
  o.h = h;
  o.pivot_max_active = pivot_max;
  return sim::make_integrator("moreau-jean")->run(model, model.initial, o);
}

TEST(MjFrictionSparse, PlanarChainWithoutSpringsStopsEachCartAtV0OverMuG) {
  // Each cart slides alone: every step takes mu g h off its speed (normal
  // impulse g h) until less is left, then it sticks at exactly 0: stick
  // time within h of t*_i = v0_i / (mu g) (tests/sim/test_friction.cpp).
  const int n = 5;
  const double mu = 0.4, h = 1e-3;
  const VectorXd v0 = (VectorXd(n) << 2.0, -1.0, 0.5, 1.5, -0.25).finished();
  const mech::Model model = planar_chain(n, 0.0, mu, v0);
  for (const int pivot_max : {0, 32}) {  // block Gauss–Seidel; dense friction LCP
    SCOPED_TRACE("pivot_max_active " + std::to_string(pivot_max));
    const sim::Trajectory tr = run_chain(model, 0.6, h, pivot_max);
    ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
    for (int i = 0; i < n; ++i) {
      const double t_star = std::abs(v0(i)) / (mu * kG);
      double ts = NAN;
      for (const sim::Sample& s : tr.samples)
        if (std::isnan(ts) && std::abs(s.x(2 * n + 2 * i)) <= 1e-12 * std::abs(v0(i))) ts = s.t;
      EXPECT_LE(std::abs(ts - t_star), h) << "cart " << i;
      // Distance v0 t* / 2 to O(h), as in test_friction.cpp.
      EXPECT_NEAR(tr.final_state(2 * i) - model.initial(2 * i), v0(i) * t_star / 2,
                  2 * std::abs(v0(i)) * h)
          << "cart " << i;
    }
  }
}

TEST(MjFrictionSparse, PlanarChainWithSpringsDissipatesAndKeepsForcesInTheCone) {
  // Springs couple the carts: stick and slip mixed. No closed form; the
  // energy cannot rise (friction and e = 0 contacts dissipate, theta = 1/2
  // adds none), the mean forces lie in the cone |u_t| <= mu u_N, and the
  // sparse sweep agrees with the dense friction LCP (both solve the same LCP,
  // whose solution is unique here: W_NT = 0 and W_TT > 0). The carts start
  // moving down at 1e-3 m/s: the first step ends them 5e-7 m inside the
  // floor (q+ = q + h (v + v+) / 2 with v+ = 0), so every contact stays in
  // the active set at every step on both paths. At zero gap a normal rate of
  // +1e-17 left by rounding opens a contact for one step (moreau_jean.cpp's
  // activation), and which path rounds which way is not part of the LCP.
  const int n = 5;
  const double mu = 0.3, h = 1e-3;
  const VectorXd v0 = (VectorXd(n) << 1.0, -0.5, 0.8, 0.0, -1.2).finished();
  const mech::Model model = planar_chain(n, 20.0, mu, v0, -1e-3);
  const sim::Trajectory gs = run_chain(model, 1.0, h, 0);
  const sim::Trajectory dense = run_chain(model, 1.0, h, 32);
  ASSERT_EQ(gs.status, Status::kCompleted) << gs.message;
  ASSERT_EQ(dense.status, Status::kCompleted) << dense.message;
  EXPECT_EQ(gs.lcp_solves, gs.steps);  // every sweep converged (no dense fallback)
  // Rounding over 1000 steps of O(1) energy: 1e-9 J.
  EXPECT_LE(gs.energy_final, gs.energy_initial + 1e-9);
  EXPECT_LT(gs.energy_final, gs.energy_initial - 0.1);  // friction did work
  int sticking = 0, slipping = 0;
  for (const sim::Sample& s : gs.samples)
    for (int i = 0; i < n; ++i) {
      // Cone to rounding of forces of size g (1e-9 N).
      EXPECT_LE(std::abs(s.u_t(i)), mu * s.u(i) + 1e-9) << "t = " << s.t << ", cart " << i;
      if (s.u(i) <= 1.0) continue;
      (std::abs(s.u_t(i)) < mu * s.u(i) * (1 - 1e-6) ? sticking : slipping)++;
    }
  EXPECT_GT(sticking, 0);
  EXPECT_GT(slipping, 0);
  // Same LCP per step, each solved to 1e-13 relative: the trajectories agree
  // to far below the step's own error (1e-9 on O(1) states after 1000 steps).
  EXPECT_LE((gs.final_state - dense.final_state).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace lcsim
