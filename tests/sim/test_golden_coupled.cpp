// The exact method on coupled multi-contact models against independent
// computations: closed forms where the model decouples, and (the
// differential check) lcsim's Moreau–Jean at decreasing h on random coupled
// models. tests/python/test_golden_coupled.py compares the same kind of
// models with Siconos 4.4. Every reference value is computed here, never
// taken from an event-driven run.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/sim/sim.hpp>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::RowVectorXd;
using Eigen::VectorXd;

// A coupled mass matrix (condition number ~30) for the closed-form cases.
MatrixXd coupled_mass() {
  MatrixXd M(3, 3);
  M << 4.0, 1.5, -0.7, 1.5, 2.0, 0.3, -0.7, 0.3, 0.5;
  return M;
}

// ---------------------------------------------------------------------------
// Rayleigh damping D = alpha M with no spring and no force: M q'' + alpha M q'
// = E' u, so in free flight v(t) = v0 e^{-alpha t} and
// q(t) = q0 + v0 (1 - e^{-alpha t}) / alpha, and the gap E q + g reaches zero
// at t* = -ln(1 + alpha (E q0 + g) / (E v0)) / alpha. The inelastic impact
// gives v+ = v- - M^{-1} E' (E v-) / (E M^{-1} E'); after it E v = 0 for ever
// (E v decays like v), the contact stays closed with u = 0, and
// v(T) = v+ e^{-alpha (T - t*)}, q(T) = q(t*) + v+ (1 - e^{-alpha (T - t*)}) / alpha.
//
// Regression: the closed loop's velocity block -M^{-1} D is alpha I up to
// 1e-17 residues of the product; balancing them against the identity block
// scaled the velocities by 1e-18, the monitors' noise bands became 1e4 wide,
// and the run went through the stop to a gap of -0.78 and "completed".
TEST(GoldenCoupled, RayleighDampingWithoutSpringsHitsTheStopOnTime) {
  const double alpha = 0.3, g = 0.3, T = 2.0;
  const MatrixXd M = coupled_mass();
  RowVectorXd E(3);
  E << 0.6, -0.8, 0.0;
  mech::MechanicalModel m;
  m.M = M.sparseView();
  m.D = (alpha * M).sparseView();
  m.E = MatrixXd(E).sparseView();
  m.g = VectorXd::Constant(1, g);
  const mech::Model model = mech::model_of(m, "rayleigh");
  VectorXd q0 = VectorXd::Zero(3), v0(3);
  v0 << -1.0, 0.5, 0.2;  // E v0 = -1, E q0 + g = 0.3: 1 + alpha g / (E v0) = 0.91
  VectorXd x0(6);
  x0 << q0, v0;

  const double Ev0 = E.dot(v0);
  const double t_star = -std::log(1.0 + alpha * (E.dot(q0) + g) / Ev0) / alpha;
  const VectorXd q_star = q0 + v0 * (1.0 - std::exp(-alpha * t_star)) / alpha;
  const VectorXd v_minus = v0 * std::exp(-alpha * t_star);
  const VectorXd Minv_Et = M.ldlt().solve(E.transpose());
  const VectorXd v_plus = v_minus - Minv_Et * E.dot(v_minus) / E.dot(Minv_Et);
  const double decay = std::exp(-alpha * (T - t_star));
  VectorXd x_T(6);
  x_T << q_star + v_plus * (1.0 - decay) / alpha, v_plus * decay;

  sim::Options opt;
  opt.t_end = T;
  opt.dt_out = 0.05;
  const sim::Trajectory tr = sim::simulate(model, x0, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kImpact);
  // Events are roots to a few ulp of t (Brent, 2 ulp); the closed form's own
  // rounding (log1p-free) is ~1e-16 relative: 1e-12 leaves a wide margin.
  EXPECT_NEAR(tr.events[0].t, t_star, 1e-12);
  // Exponentials and the impact are backward stable: the final state agrees
  // to ~1e-14 of its size (|x| ~ 1); 1e-11 is the margin for the event
  // time's error times the rates (|v| ~ 1).
  EXPECT_LT((tr.final_state - x_T).cwiseAbs().maxCoeff(), 1e-11);
  // Every sample is feasible up to rounding (the bug went to -0.78).
  EXPECT_GT(tr.max_violation, -1e-12);
}

// The livelock guard names the contact whose monitor stops each phase: events
// that re-select the same mode with no impulse (a monitor at rounding level
// giving a root at once, golden seed 176 before 5c95e8e) said "at contacts
// (none)". 64 such events 1e-9 s apart with no state change (rho = 1, so
// "quick" is 1e-4 s) must fail naming 'knee' and only it.
TEST(GoldenCoupled, LivelockNamesTheContactWhoseMonitorStopsThePhase) {
  sim::detail::LivelockGuard guard(64, 1.0, {"hip", "knee"});
  sim::detail::EventResult ev;
  ev.impulse = VectorXd::Zero(2);
  const VectorXd x = VectorXd::Ones(4);
  std::string why;
  // The first call only sets the clock (no event before it to be quick after).
  for (int i = 0; i < 65 && why.empty(); ++i)
    why = guard.after_event(0.2 + 1e-9 * i, x, x, {}, ev, {}, /*trigger=*/1);
  ASSERT_FALSE(why.empty());
  EXPECT_NE(why.find("at contacts 'knee'"), std::string::npos) << why;
  EXPECT_EQ(why.find("'hip'"), std::string::npos) << why;
  EXPECT_EQ(why.find("(none)"), std::string::npos) << why;
}

// The output grid of the time-stepping methods stays on multiples of dt_out:
// with h = 1e-6 and dt_out = 0.01 the sum of dt_out's drifted past the
// tolerance, and from t = 1.55 on every sample was recorded one step late
// (t = 1.550001), which the golden comparison took for a 1e-2 position
// error. Step times j h (as Moreau–Jean and backward Euler form them) are
// within an ulp or two of k dt_out; 1e-12 is the margin.
TEST(GoldenCoupled, OutputGridStaysOnMultiplesOfDtOut) {
  const double h = 1e-6, dt_out = 0.01;
  const long n = 2000000;  // t_end = 2
  sim::OutputSampler sampler(dt_out);
  long k = 0;
  for (long j = 1; j <= n; ++j) {
    const double t = static_cast<double>(j) * h;
    if (!sampler.want(t, h, j == n)) continue;
    ++k;
    EXPECT_NEAR(t, static_cast<double>(k) * dt_out, 1e-12) << "sample " << k;
    if (::testing::Test::HasFailure()) return;
  }
  EXPECT_EQ(k, 200);
}

}  // namespace
}  // namespace lcsim
