// Event-driven simulation against the thesis's exact solutions.
//
// Tolerances: the phases are matrix exponentials (relative error ~1e-15 per
// evaluation) and events are roots found by Brent's method to 1e-14 s, so
// event times and states are good to ~1e-13; we assert 1e-10, which leaves
// three orders of margin for the conditioning of the root (|y'| >= 0.5 at
// the events below) while still failing on any modelling error, which would
// show at O(1e-3) or more.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <random>
#include <unsupported/Eigen/MatrixFunctions>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector4d;
using Eigen::VectorXd;
constexpr double kTol = 1e-10;

mech::Model two_carts(bool hook) { return mech::two_carts_model(hook); }

// A of (3.1) on (x1, x2, x3, x4).
MatrixXd free_A() {
  MatrixXd A(4, 4);
  A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  return A;
}

sim::Trajectory run(const mech::Model& model, const VectorXd& x0, double t_end,
                    double dt_out = 0.0) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  return sim::simulate_event_driven(model, x0, opt);
}

void expect_near(const VectorXd& a, const VectorXd& b, double tol, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol)
      << what << "\n got " << a.transpose() << "\n want " << b.transpose();
}

// §3.7: impact at t = 1, constrained phase x2 = -cos(t-1), u = cos(t-1),
// release at 1 + pi/2 at (0,0,0,1), free motion to T = 3.
TEST(EventDriven, TwoCartsSection37) {
  const MatrixXd A = free_A();
  const VectorXd x0 = (-A).exp() * Vector4d(0, -1, -1, 0);
  const auto tr = run(two_carts(false), x0, 3.0, 0.01);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 2u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  EXPECT_NEAR(tr.events[0].t, 1.0, kTol);
  expect_near(tr.events[0].state_before, Vector4d(0, -1, -1, 0), kTol, "before impact");
  expect_near(tr.events[0].state_after, Vector4d(0, -1, 0, 0), kTol, "after impact");
  EXPECT_EQ(tr.events[0].mode_after, (std::vector<int>{0}));
  // Impulse of the stop: the velocity jump of cart 1, u^0 = -x3 = 1.
  EXPECT_NEAR(tr.events[0].impulse(0), 1.0, kTol);
  EXPECT_EQ(tr.events[1].type, sim::EventType::kRelease);
  EXPECT_NEAR(tr.events[1].t, 1.0 + std::numbers::pi / 2, kTol);
  expect_near(tr.events[1].state_after, Vector4d(0, 0, 0, 1), kTol, "at release");
  EXPECT_TRUE(tr.events[1].mode_after.empty());
  const VectorXd xT = (A * (3.0 - 1.0 - std::numbers::pi / 2)).exp() * Vector4d(0, 0, 0, 1);
  expect_near(tr.final_state, xT, kTol, "final state");
  // The constrained phase, sampled exactly on the output grid.
  int checked = 0;
  for (const auto& s : tr.samples) {
    if (s.t > 1.0 + 1e-9 && s.t < 1.0 + std::numbers::pi / 2 - 1e-9) {
      EXPECT_NEAR(s.x(1), -std::cos(s.t - 1.0), kTol) << "x2 at t = " << s.t;
      EXPECT_NEAR(s.u(0), std::cos(s.t - 1.0), kTol) << "u at t = " << s.t;
      EXPECT_NEAR(s.x(0), 0.0, kTol);
      ++checked;
    }
  }
  EXPECT_GE(checked, 150);  // pi/2 / 0.01 = 157 grid points
  EXPECT_GE(tr.max_violation, -1e-12);
  // Inelastic impact: energy drops by ½ x3² = ½ at t = 1, nothing else.
  EXPECT_NEAR(tr.energy_initial - tr.energy_final, 0.5, kTol);
}

// The shipped model file gives the same run.
TEST(EventDriven, ShippedTwoCartsModel) {
  const auto model = scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/two_carts.yaml");
  ASSERT_EQ(model.initial.size(), 4);
  const auto tr = run(model, model.initial, model.t_end);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 2u);
  EXPECT_NEAR(tr.events[0].t, 1.0, kTol);
  EXPECT_NEAR(tr.events[1].t, 1.0 + std::numbers::pi / 2, kTol);
}

// Example 3.4.5: from (0,1,-1,0) a jump to (0,1,0,0) and immediate release.
TEST(EventDriven, Example345JumpAndImmediateRelease) {
  const auto tr = run(two_carts(false), Vector4d(0, 1, -1, 0), 0.5);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].t, 0.0);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  expect_near(tr.events[0].state_after, Vector4d(0, 1, 0, 0), kTol, "after jump");
  EXPECT_TRUE(tr.events[0].mode_after.empty()) << "smooth continuation must be unconstrained";
  // Free motion from (0,1,0,0): the cart leaves the stop (x1 > 0 at once).
  const VectorXd x = (free_A() * 0.5).exp() * Vector4d(0, 1, 0, 0);
  expect_near(tr.final_state, x, kTol, "final");
}

// Example 3.8.3: from (0,0,-1,2) the hook alone is selected: jump to (0,0,½,½).
TEST(EventDriven, Example383HookOnly) {
  const auto tr = run(two_carts(true), Vector4d(0, 0, -1, 2), 0.1);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].t, 0.0);
  expect_near(tr.events[0].state_after, Vector4d(0, 0, 0.5, 0.5), kTol, "after jump");
  EXPECT_EQ(tr.events[0].mode_after, (std::vector<int>{1})) << "hook only, not the stop";
  EXPECT_NEAR(tr.events[0].impulse(0), 0.0, kTol);
  EXPECT_NEAR(tr.events[0].impulse(1), 1.5, kTol);  // x4 drops by 3/2
}

// Example 3.8.3: discontinuous dependence on x0(eps) = (eps, eps, -2, 1).
// eps = 0: both constraints at once, a jump to rest. eps > 0: hook first, then
// the stop hits with v = (-½ + g(eps)) and the state converges to (0,0,0,-½).
TEST(EventDriven, Example383DiscontinuousDependence) {
  const auto tr0 = run(two_carts(true), Vector4d(0, 0, -2, 1), 1.0);
  ASSERT_EQ(tr0.status, sim::RunStatus::kCompleted) << tr0.message;
  expect_near(tr0.events.at(0).state_after, Vector4d(0, 0, 0, 0), kTol, "eps = 0");
  expect_near(tr0.final_state, Vector4d(0, 0, 0, 0), kTol, "rest at equilibrium");
  for (double eps : {1e-3, 1e-5}) {
    const auto tr = run(two_carts(true), Vector4d(eps, eps, -2, 1), 0.1);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_GE(tr.events.size(), 2u);
    expect_near(tr.events[0].state_after, Vector4d(eps, eps, -0.5, -0.5), kTol, "hook jump");
    // The stop impact: cart 1 stops, cart 2 keeps its velocity -½ + g(eps);
    // g(eps) = O(eps) (the hook phase lasts ~2 eps), so 10 eps bounds it.
    const VectorXd after = tr.events[1].state_after;
    EXPECT_NEAR(after(0), 0.0, kTol);
    EXPECT_NEAR(after(2), 0.0, kTol);
    EXPECT_NEAR(after(3), -0.5, 10 * eps);
  }
}

// Example 7.3.3: the triple integrator from (0,-1,0) needs a delta' impulse;
// the consistent state of the constrained mode is V = {0}, so it jumps to 0
// and stays there.
TEST(EventDriven, TripleIntegratorReinitialises) {
  mech::Model model;
  model.name = "triple";
  lcs::Lcs s;
  s.A = MatrixXd::Zero(3, 3);
  s.A(0, 1) = 1;
  s.A(1, 2) = 1;
  s.B = MatrixXd::Zero(3, 1);
  s.B(2, 0) = 1;
  s.C = MatrixXd::Zero(1, 3);
  s.C(0, 0) = 1;
  s.D = MatrixXd::Zero(1, 1);
  model.lcs = s;
  const auto tr = run(model, Eigen::Vector3d(0, -1, 0), 1.0);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  expect_near(tr.events[0].state_after, Eigen::Vector3d(0, 0, 0), kTol, "after jump");
  expect_near(tr.final_state, Eigen::Vector3d(0, 0, 0), kTol, "final");
}

mech::Model ball(double e) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(1, 1).sparseView();
  m.E = MatrixXd::Identity(1, 1).sparseView();
  m.f = VectorXd::Constant(1, -9.81);
  m.restitution = VectorXd::Constant(1, e);
  mech::fill_defaults(m);
  mech::Model model;
  model.name = "ball";
  model.mechanical = m;
  return model;
}

// A ball dropped from 1 m: e = 0 sticks at t1 = sqrt(2/g) with u = g after.
TEST(EventDriven, BallInelasticSticks) {
  const double g = 9.81, t1 = std::sqrt(2.0 / g);
  const auto tr = run(ball(0.0), Eigen::Vector2d(1.0, 0.0), 2.0);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_NEAR(tr.events[0].t, t1, kTol);
  EXPECT_NEAR(tr.events[0].state_before(1), -g * t1, kTol);
  expect_near(tr.final_state, Eigen::Vector2d(0, 0), kTol, "rests on the ground");
  EXPECT_NEAR(tr.samples.back().u(0), g, kTol);  // the ground carries the weight
}

// e = 0.5: impacts at t1, t1 + 2e t1, ... accumulating at t* = t1 (1+e)/(1-e).
// The accumulation is taken when a flight is shorter than 1e-10 s; the
// geometric tail left out is 1e-10 e/(1-e) = 1e-10, so t* holds to 1e-9.
TEST(EventDriven, BallAccumulation) {
  const double g = 9.81, e = 0.5, t1 = std::sqrt(2.0 / g);
  const auto tr = run(ball(e), Eigen::Vector2d(1.0, 0.0), 2.0);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 6u);
  double tk = t1, flight = 2 * e * t1;
  for (int i = 0; i < 5; ++i) {
    EXPECT_EQ(tr.events[i].type, sim::EventType::kImpact);
    EXPECT_NEAR(tr.events[i].t, tk, kTol) << "impact " << i;
    tk += flight;
    flight *= e;
  }
  const auto& last = tr.events.back();
  EXPECT_EQ(last.type, sim::EventType::kAccumulation);
  EXPECT_NEAR(last.t, t1 * (1 + e) / (1 - e), 1e-9);
  expect_near(tr.final_state, Eigen::Vector2d(0, 0), 1e-9, "at rest");
}

// Invariants on random models: feasibility, complementarity, energy never
// rising (D >= 0, e = 0, f = 0). Tolerances: 1e-9 relative to the energy and
// state scale, far above rounding (1e-15) and far below any violation a
// wrong mode or impulse would cause (O(1e-2) for these random data).
TEST(EventDriven, RandomModelInvariants) {
  std::mt19937 gen(1234);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int runs = 0;
  for (int trial = 0; trial < 20; ++trial) {
    const int N = 3, k = 2;
    MatrixXd R(N, N), S(N, N), P(N, N);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) {
        R(i, j) = U(gen);
        S(i, j) = U(gen);
        P(i, j) = U(gen);
      }
    mech::MechanicalModel m;
    m.M = (R * R.transpose() + MatrixXd::Identity(N, N)).sparseView();
    m.K = (S * S.transpose()).sparseView();
    m.D = (0.1 * P * P.transpose()).sparseView();
    m.E.resize(k, N);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < N; ++j) m.E.coeffRef(i, j) = U(gen);
    m.g = VectorXd(k);
    for (int i = 0; i < k; ++i) m.g(i) = 0.25 * (U(gen) + 1.0);
    mech::fill_defaults(m);
    mech::Model model;
    model.name = "random";
    model.mechanical = m;
    VectorXd x0 = VectorXd::Zero(2 * N);
    for (int i = 0; i < N; ++i) x0(N + i) = 2.0 * U(gen);
    const auto tr = run(model, x0, 5.0, 0.01);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << "trial " << trial << ": " << tr.message;
    const double E0 = tr.energy_initial;
    for (const auto& s : tr.samples) {
      const double scale = 1.0 + s.x.cwiseAbs().maxCoeff();
      EXPECT_GE(s.y.minCoeff(), -1e-9 * scale) << "feasibility, trial " << trial << " t " << s.t;
      EXPECT_GE(s.u.minCoeff(), -1e-9 * scale) << "u >= 0, trial " << trial << " t " << s.t;
      EXPECT_LE(std::abs(s.u.dot(s.y)), 1e-9 * scale * scale) << "complementarity";
      const double Es = mech::total_energy(m, s.x.head(N), s.x.tail(N));
      EXPECT_LE(Es, E0 + 1e-9 * (1.0 + std::abs(E0))) << "energy rose, trial " << trial;
    }
    ++runs;
  }
  EXPECT_EQ(runs, 20);
}

}  // namespace
}  // namespace lcsim
