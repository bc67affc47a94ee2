// The time-stepping methods at the extremes: Moreau–Jean (theta = 1/2 and 1),
// backward Euler (Algorithm 7.3.1) where it applies, and Bullet (src/bullet,
// the "rb6" scene: diagonal M, stops and hooks). The cases of issue 8 §1 --
// stiff and soft springs, a stiffness ratio 1e12, a mass ratio 1e8, steps from
// 1e-8 to 1, 10^6-step horizons, grazing, simultaneous and accumulating
// impacts, dependent constraints, nearly singular M, infeasible starts -- each
// against a closed form. Tolerances are C h (or C (omega h)) with C the
// measured constant of the first-order scheme times a stated margin, so an
// O(1) or O(sqrt h) mistake fails. Measured numbers: docs/extremes.md,
// printed by build/bench/table_extremes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <sstream>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>

#include "support/run_lcsim.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
constexpr double kPi = std::numbers::pi;
constexpr double kG = 9.81;

struct Scheme {
  const char* method;
  double theta;  // Moreau–Jean only
};
constexpr Scheme kMj05{"moreau-jean", 0.5}, kMj1{"moreau-jean", 1.0}, kEuler{"euler", 1.0};

std::string label(const Scheme& s) {
  return std::string(s.method) + (s.method[0] == 'm' ? " theta " + std::to_string(s.theta) : "");
}

mech::Model wrap(mech::MechanicalModel m) { return mech::model_of(std::move(m), "extreme"); }

mech::Model spring_stop(double k, double s, double e = 0.0) {
  return mech::spring_stop_model(k, s, e);
}

mech::Model ball(double e) { return mech::ball_model(e, kG); }

sim::Trajectory step(const Scheme& s, const mech::Model& model, const VectorXd& x0, double T,
                     double h, bool samples = false, const char* lcp_solver = "pivot") {
  sim::Options o;
  o.lcp_solver = lcp_solver;
  o.t_end = T;
  o.h = h;
  o.theta = s.theta;
  o.record_samples = samples;
  // One option set for every scheme: each keeps what it reads (Euler has no
  // theta, and the library refuses an option a method would ignore).
  const auto integ = sim::make_integrator(s.method);
  return integ->run(model, x0, sim::keep_used(o, integ->options_used()));
}

double maxabs(const VectorXd& x) { return x.cwiseAbs().maxCoeff(); }

// ---- Bullet, through the lcsim executable ---------------------------------
// test_extremes links the layers up to io (tests/CMakeLists.txt), not
// lcsim_bullet, so Bullet runs as `lcsim simulate FILE --method bullet --json`
// on the model written by io::model_yaml (17 significant digits).
struct BulletRun {
  int exit_code = -1;
  nlohmann::json out;  // the --json summary (final_state, max_violation, ...)
  std::string err;
  VectorXd final_state() const {
    VectorXd x(static_cast<Eigen::Index>(out.at("final_state").size()));
    for (Eigen::Index i = 0; i < x.size(); ++i) x(i) = out.at("final_state")[i].get<double>();
    return x;
  }
};

bool have_lcsim_binary() { return std::filesystem::exists(LCSIM_BINARY); }

BulletRun bullet(mech::Model model, const VectorXd& x0, double T, double h) {
  model.initial = x0;
  model.t_end = T;
  const std::filesystem::path file = cli_test::private_temp("extreme_bullet_model", ".yaml");
  std::ofstream(file) << io::model_yaml(model);
  std::ostringstream args;
  args.precision(17);
  args << "simulate '" << file.string() << "' --method bullet --h " << h << " --json";
  const cli_test::CliRun run =
      cli_test::run_lcsim(args.str(), cli_test::private_temp("extreme_bullet_err", ".txt"));
  std::filesystem::remove(file);
  BulletRun r;
  r.exit_code = run.exit_code;
  r.err = run.err;
  r.out = nlohmann::json::parse(run.out, nullptr, /*allow_exceptions=*/false);
  return r;
}

#define REQUIRE_LCSIM_BINARY()                            \
  if (!have_lcsim_binary())                               \
  GTEST_SKIP() << "build the lcsim target to run Bullet " \
                  "(" LCSIM_BINARY " is missing)"

// ---- Stiff and soft springs ------------------------------------------------
// The spring of test_event_driven_extremes.cpp: released from q = 1 onto a
// stop at q = -1/2, impact at omega t1 = 2 pi / 3, then -1/2 cos(omega (t -
// t1)) grazing the stop twice (mid-phase grazes) before T = t1 + 2.3 periods.
// Step h = period / 1000 (omega h = 6.3e-3) at every k: the error relative to
// the amplitude must not depend on k. Errors (q and v/omega) are first order
// in omega h through the impact step; measured max over k (table_extremes):
// MJ 1/2 2.5e-2, MJ 1 2.5e-2, Euler 2.0e-2 (the same at every k: the
// schemes are scale-invariant in omega h). Bounds: twice that.
struct SpringCase {
  Scheme scheme;
  double bound;  // on |q - q_exact| and |v/omega - v_exact/omega| (amplitude 1)
};
class StiffSpringStepping : public ::testing::TestWithParam<std::tuple<double, int>> {};

TEST_P(StiffSpringStepping, ImpactThenGrazingOscillation) {
  const auto [k, which] = GetParam();
  const SpringCase cases[] = {{kMj05, 0.05}, {kMj1, 0.05}, {kEuler, 0.04}};
  const SpringCase& c = cases[which];
  const double w = std::sqrt(k), P = 2 * kPi / w, t1 = P / 3, T = t1 + 2.3 * P;
  const auto tr = step(c.scheme, spring_stop(k, 0.5), Eigen::Vector2d(1, 0), T, P / 1000);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double tau = w * (T - t1);
  EXPECT_NEAR(tr.final_state(0), -0.5 * std::cos(tau), c.bound) << label(c.scheme) << " k " << k;
  EXPECT_NEAR(tr.final_state(1) / w, 0.5 * std::sin(tau), c.bound) << label(c.scheme) << " k " << k;
  // Feasibility: Moreau–Jean crosses by at most h (1 - theta) |v| + O(h^2)
  // per step (time_stepping.cpp); |v| <= omega here, so (1 - theta) omega h
  // plus a margin of 2; Euler solves at position level: no crossing.
  EXPECT_GE(tr.max_violation, -2 * ((1 - c.scheme.theta) * w * P / 1000 + 1e-12))
      << label(c.scheme) << " k " << k;
}

INSTANTIATE_TEST_SUITE_P(Stiffness, StiffSpringStepping,
                         ::testing::Combine(::testing::Values(1e-6, 1e-2, 1.0, 1e3, 1e6, 1e9),
                                            ::testing::Values(0, 1, 2)));

// Stiffness ratio 1e12 in one model: k = 1e-3 (stop far away at -10) and
// k = 1e9 (stop at -1/2), uncoupled. (a) Step resolving the fast mode
// (h = 1e-7, omega_f h = 3.2e-3, 10^4 steps): both as the closed form, bound
// as the resolved spring above (first order in omega_f h). (b) Step 1e-2,
// omega_f h = 316, 1000 steps: the slow mode is still right -- measured
// 8.2e-10 for theta = 1/2 (trapezoidal, O((omega_s h)^2)), 4.8e-5 for theta =
// 1 and Euler (numerical damping, O(omega_s^2 h T)); bounds 10x -- and the
// unresolved fast mode stays bounded by its initial amplitude (the energy
// balance of time_stepping.cpp has no positive term for theta >= 1/2, e = 0),
// nothing non-finite. Resolved case measured: fast error 2.3e-2 (MJ 1/2),
// 6.8e-3 (MJ 1), 4.6e-3 (Euler); slow 5e-14; bounds about 2x.
TEST(SteppingExtremes, StiffnessRatio1e12) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  m.K = MatrixXd(Eigen::Vector2d(1e-3, 1e9).asDiagonal()).sparseView();
  m.E = MatrixXd::Identity(2, 2).sparseView();
  m.g = Eigen::Vector2d(10.0, 0.5);
  const auto model = wrap(m);
  const double ws = std::sqrt(1e-3), wf = std::sqrt(1e9), t1 = 2 * kPi / (3 * wf);
  for (const auto& [s, bound] : {std::pair{kMj05, 0.05}, {kMj1, 0.015}, {kEuler, 0.01}}) {
    const double T = 1e-3;
    const auto tr = step(s, model, Eigen::Vector4d(1, 1, 0, 0), T, 1e-7);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    EXPECT_NEAR(tr.final_state(0), std::cos(ws * T), 1e-12) << label(s);
    EXPECT_NEAR(tr.final_state(1), -0.5 * std::cos(wf * (T - t1)), bound) << label(s);
  }
  for (const auto& [s, bound] : {std::pair{kMj05, 1e-8}, {kMj1, 5e-4}, {kEuler, 5e-4}}) {
    const auto tr = step(s, model, Eigen::Vector4d(1, 1, 0, 0), 10.0, 1e-2);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    ASSERT_TRUE(tr.final_state.allFinite());
    EXPECT_NEAR(tr.final_state(0), std::cos(ws * 10.0), bound) << label(s);
    EXPECT_LE(std::abs(tr.final_state(1)), 1.0 + 1e-12) << label(s);
    EXPECT_LE(tr.energy_final, tr.energy_initial * (1 + 1e-12)) << label(s);
  }
}

// Mass ratio 1e8 through a hook (x1 - x2 >= 0), both orderings, from
// (0, 0, -1, 2): the hook closes at t = 0 and the first step's LCP is
// Moreau's rule itself (Moreau–Jean with e = 0; Euler's position-level LCP
// gives the same velocity when no force acts), so both carts move at
// (m1 v1 + m2 v2)/(m1 + m2) from then on; velocities to 1e-11 (1000 steps
// of rounding, 1000 x 2 eps x |v| ~ 1e-12, times 10). Positions: theta = 1
// and Euler exact to the same 1e-11 (measured 9e-16); theta = 1/2 moves the
// positions in the impact step with the mean of v and v+, so the light cart
// crosses the hook by (1 - theta) h |v1 - vc| = 1.5e-3 (measured 1.5e-3,
// the scheme's documented crossing) and the gap stays there (no force).
TEST(SteppingExtremes, MassRatio1e8PlasticHook) {
  for (const auto& [m1, m2] : {std::pair{1e-4, 1e4}, std::pair{1e4, 1e-4}}) {
    mech::MechanicalModel m;
    m.M = MatrixXd(Eigen::Vector2d(m1, m2).asDiagonal()).sparseView();
    m.E = Eigen::RowVector2d(1, -1).sparseView();
    const auto model = wrap(m);
    const double vc = (-m1 + 2 * m2) / (m1 + m2);
    for (const Scheme& s : {kMj05, kMj1, kEuler}) {
      const auto tr = step(s, model, Eigen::Vector4d(0, 0, -1, 2), 1.0, 1e-3);
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
      EXPECT_LE(maxabs(tr.final_state.tail(2) - Eigen::Vector2d(vc, vc)), 1e-11)
          << label(s) << " m1 " << m1;
      const double cross = (1 - s.theta) * 1e-3 * 3.0 * 1.001 + 1e-11;
      EXPECT_LE(maxabs(tr.final_state.head(2) - Eigen::Vector2d(vc, vc)), cross)
          << label(s) << " m1 " << m1;
      EXPECT_GE(tr.max_violation, -cross) << label(s) << " m1 " << m1;
    }
  }
}

// Step sizes 1e-8 ... 1 on the k = 1 spring of the stiff-spring case. For h
// >= 1e-3 the run is the whole case to T = 10 (h = 1: 10 steps of one-sixth
// of a period); below, it starts 5000 steps before the impact from the exact
// state and lasts 10^4 steps, so the impact is in every run. Errors are
// first order through the impact step, ~C h; measured C (table_extremes):
// theta = 1: 0.5 to 2.0; Euler: 0.9 to 1.9 for h >= 1e-6; theta = 1/2: 0.5
// to 1.4, except 8.8 at h = 1e-3, where the run to T = 10 crosses the stop
// by h/2 at the impact and then turns the mid-phase grazes into small
// impacts. Bounds: 4 h (theta = 1, Euler), 20 h (theta = 1/2), and at most
// the amplitude 1 (h = 1: finite and bounded, errors 0.5-0.8). Euler at h =
// 1e-8 is a separate test (StepSizeTinyEuler, the run that found the scaling defect).
TEST(SteppingExtremes, StepSizes1e8To1) {
  const auto model = spring_stop(1.0, 0.5);
  const double t1 = 2 * kPi / 3;
  auto exact = [&](double t) -> Eigen::Vector2d {
    if (t < t1) return {std::cos(t), -std::sin(t)};
    return {-0.5 * std::cos(t - t1), 0.5 * std::sin(t - t1)};
  };
  for (double h : {1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8}) {
    const double t0 = h >= 1e-3 ? 0.0 : t1 - 5000 * h, T = h >= 1e-3 ? 10.0 : 1e4 * h;
    for (const auto& [s, C] : {std::pair{kMj05, 20.0}, {kMj1, 4.0}, {kEuler, 4.0}}) {
      if (s.method[0] == 'e' && h < 1e-7) continue;  // StepSizeTinyEuler
      const auto tr = step(s, model, exact(t0), T, h);
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << label(s) << " h " << h << tr.message;
      ASSERT_TRUE(tr.final_state.allFinite());
      EXPECT_LE(maxabs(tr.final_state - exact(t0 + T)), std::min(C * h, 1.0))
          << label(s) << " h " << h;
      EXPECT_LE(tr.energy_final, tr.energy_initial * (1 + 1e-12)) << label(s) << " h " << h;
    }
  }
}

// 10^6 steps (h = 1e-3, T = 1000, ~160 periods, ~320 impacts) on the k = 1
// spring with an elastic stop (e = 1) at -1/2. The exact motion conserves
// the energy 1/2. Moreau–Jean theta = 1/2 conserves it too: the trapezoidal
// free step conserves the quadratic energy, and at an impact lambda E v_t =
// lambda E v ((1 - theta) - theta e) = 0 (energy balance in
// time_stepping.cpp), so only rounding drifts: measured 4.7e-15, bound
// 1e-10 (a random walk of 1e6 roundings of 1e-16 stays below 1e-12; a
// systematic O(h^2) per-step drift would give 1e0). theta = 1 dissipates
// (numerical damping + the impact term): bounded, falls by 70 %. Feasibility: a crossing is at most
// (1 - theta) h |v| + theta h^2 |K q| <= 0.5e-3 + 1e-6 with |v| <= 1, |q| <= 1 (energy 1/2);
// margin 1.5. Backward Euler ignores the restitution (warned), so its energy is only required to
// stay bounded.
TEST(SteppingExtremes, MillionStepsEnergyAndFeasibility) {
  const auto model = spring_stop(1.0, 0.5, 1.0);
  for (const Scheme& s : {kMj05, kMj1, kEuler}) {
    const auto tr = step(s, model, Eigen::Vector2d(1, 0), 1000.0, 1e-3);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    EXPECT_EQ(tr.steps, 1000000);
    EXPECT_LE(tr.energy_final, tr.energy_initial * (1 + 1e-9)) << label(s);
    EXPECT_GE(tr.max_violation, -1.5 * ((1 - s.theta) * 1e-3 + s.theta * 1e-6)) << label(s);
    if (s.method[0] == 'm' && s.theta == 0.5) {
      EXPECT_NEAR(tr.energy_final / tr.energy_initial, 1.0, 1e-10);
    }
    if (s.method[0] == 'e') {
      EXPECT_EQ(tr.warning_count("restitution-ignored"), 1);
      EXPECT_NE(tr.first_warning().find("ignores restitution"), std::string::npos);
    }
  }
}

// Grazing at the start. A ball at rest on the ground under gravity (gap 0,
// rate 0): the first step's LCP carries the weight, u = m g exactly, nothing
// moves (bound: rounding of g h / h, 1e-12). A mass at its stop with a spring
// pulling it away: released at once, then free motion -cos t, whose error is
// that of the free scheme: trapezoidal O(h^2) for theta = 1/2, O(h) for
// theta = 1 and Euler; measured 7.0e-8 and 4.2e-4 at h = 1e-3; bounds 2e-7
// and 1e-3.
TEST(SteppingExtremes, GrazingAtStart) {
  for (const auto& [s, bound] : {std::pair{kMj05, 2e-7}, {kMj1, 1e-3}, {kEuler, 1e-3}}) {
    const auto tr = step(s, ball(0.0), Eigen::Vector2d(0, 0), 1.0, 1e-3, true);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    EXPECT_LE(maxabs(tr.final_state), 1e-15) << label(s);
    EXPECT_NEAR(tr.samples.back().u(0), kG, 1e-12) << label(s);
    EXPECT_GE(tr.max_violation, -1e-15) << label(s);  // Euler: -1.7e-21
    const auto tr2 = step(s, spring_stop(1.0, 1.0), Eigen::Vector2d(-1, 0), 1.0, 1e-3);
    ASSERT_EQ(tr2.status, sim::RunStatus::kCompleted) << tr2.message;
    EXPECT_LE(maxabs(tr2.final_state - Eigen::Vector2d(-std::cos(1.0), std::sin(1.0))), bound)
        << label(s);
  }
}

// N carts on unstretched neighbour springs, all moving at -1 toward stops at
// distance 1: every cart hits at t = 1 and then rests at q = -1 (closed form
// as in test_event_driven_extremes.cpp). N = 1000 runs the sparse path with
// an active set of 1000 > pivot_max_active, i.e. sparse PGS. The motion is a
// rigid translation (K q = 0), so the only error is where the step lands the
// impact: theta = 1/2 activates a stop when the predicted gap y - h/2 <= 0,
// one step too late and, moving with the mean of v and v+ = 0, crosses by
// (1 - theta) h = h/2 (and stays there: nothing pushes back); theta = 1
// stops one step early (gap h left open); Euler's position-level LCP lands
// on y = 0. Measured at every N: 5.0e-4, 1.0e-3, 2.3e-10. Bounds: 1.01 h/2,
// 1.01 h, 1e-9. Backward Euler is dense: refused at N = 1000.
class SimultaneousImpactsStepping : public ::testing::TestWithParam<int> {};

TEST_P(SimultaneousImpactsStepping, ChainStopsAtOnce) {
  const int N = GetParam();
  const mech::Model model = wrap(*mech::chain_model({N, true, false, false}).mechanical);
  VectorXd x0(2 * N), rest(2 * N);
  x0 << VectorXd::Zero(N), -VectorXd::Ones(N);
  rest << -VectorXd::Ones(N), VectorXd::Zero(N);
  const double h = 1e-3;
  for (const auto& [s, bound] :
       {std::pair{kMj05, 1.01 * h / 2}, {kMj1, 1.01 * h}, {kEuler, 1e-9}}) {
    const auto tr = step(s, model, x0, 2.0, h);
    if (s.method[0] == 'e' && N == 1000) {
      EXPECT_EQ(tr.status, sim::RunStatus::kInvalidInput);
      EXPECT_NE(tr.message.find("more than the 1001"), std::string::npos) << tr.message;
      continue;
    }
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << label(s) << ": " << tr.message;
    EXPECT_LE(maxabs(tr.final_state - rest), bound) << label(s) << " N " << N;
    EXPECT_GE(tr.max_violation, -(s.theta == 0.5 ? bound : 1e-12)) << label(s) << " N " << N;
    EXPECT_EQ(tr.warning_count(), 0) << label(s) << " N " << N;
  }
}

INSTANTIATE_TEST_SUITE_P(Chains, SimultaneousImpactsStepping, ::testing::Values(10, 100, 1000));

// Accumulating impacts: a ball dropped from 1 with e = 0.5 and 0.9. Exact:
// rebound to e^2 after the first impact, rest after t* = t1 (1 + e)/(1 - e).
// Moreau–Jean puts the Newton law in its velocity LCP: the rebound height is
// first order in h, measured 2.7e-3 / 6.2e-4 (theta = 1/2, e = 0.5 / 0.9)
// and 6.3e-4 / 2.2e-4 (theta = 1) at h = 1e-3; bounds 5 h and 2 h. The
// bounces below the step's resolution are absorbed: at T = t* + 1 the ball
// rests within one step's fall, |x| <= 2 g h^2 (measured 1.2e-6, 7.4e-6). Backward Euler ignores
// restitution and says so (warning); it lands and stays: no rebound.
TEST(SteppingExtremes, AccumulatingImpacts) {
  const double t1 = std::sqrt(2 / kG), h = 1e-3;
  for (double e : {0.5, 0.9}) {
    const double ts = t1 * (1 + e) / (1 - e);
    for (const auto& [s, bound] : {std::pair{kMj05, 5 * h}, {kMj1, 2 * h}}) {
      const auto tr = step(s, ball(e), Eigen::Vector2d(1, 0), ts + 1, h, true);
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
      double top = 0.0;
      for (const auto& smp : tr.samples)
        if (smp.t > t1 + 0.01 && smp.t < t1 * (1 + 2 * e)) top = std::max(top, smp.x(0));
      EXPECT_NEAR(top, e * e, bound) << label(s) << " e " << e;
      EXPECT_LE(maxabs(tr.final_state), 2 * kG * h * h) << label(s) << " e " << e;
    }
    const auto be = step(kEuler, ball(e), Eigen::Vector2d(1, 0), ts + 1, h);
    ASSERT_EQ(be.status, sim::RunStatus::kCompleted) << be.message;
    ASSERT_EQ(be.warning_count("restitution-ignored"), 1);
    EXPECT_NE(be.first_warning().find("ignores restitution"), std::string::npos);
  }
}

// Dependent constraints (Theorem 4.6.5): the §3.7 stop given twice (c = 1)
// or as x1 >= 0 and 2 x1 >= 0 (c = 2). The Delassus matrix is singular; the
// impulse split is not unique, the motion is: each scheme must give the
// motion of its own single-stop run -- measured 0 for theta = 1/2 and Euler
// but 1.4e-6 for theta = 1 (Lemke on the singular LCP; unexplained, far
// below the scheme's own error), bound 1e-5 -- and hence the exact
// §3.7 final state to its first-order error (measured 7.1e-4 for theta =
// 1/2, 8.9e-4 for theta = 1 and Euler at h = 1e-3; bound 2 h). The
// two-row runs use Lemke: the default "pivot" fails on the singular
// Delassus matrix (DependentConstraintsDefaultSolver, a defect).
TEST(SteppingExtremes, DependentConstraintsSameMotion) {
  MatrixXd A(4, 4);
  A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  const VectorXd xT = (A * (2.0 - kPi / 2)).exp() * Eigen::Vector4d(0, 0, 0, 1);
  const VectorXd x0 = Eigen::Vector4d(0, -1, -1, 0);
  const auto carts = [](const MatrixXd& E) { return mech::two_carts_model(E); };
  for (const auto& [s, bound] : {std::pair{kMj05, 2e-3}, {kMj1, 2e-3}, {kEuler, 2e-3}}) {
    const auto one = step(s, carts(Eigen::RowVector2d(1, 0)), x0, 2.0, 1e-3);
    ASSERT_EQ(one.status, sim::RunStatus::kCompleted) << one.message;
    EXPECT_LE(maxabs(one.final_state - xT), bound) << label(s);
    for (double c : {1.0, 2.0}) {
      const auto tr = step(s, carts(MatrixXd{{1, 0}, {c, 0}}), x0, 2.0, 1e-3, false, "lemke");
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << label(s) << " c " << c << tr.message;
      EXPECT_LE(maxabs(tr.final_state - one.final_state), 1e-5) << label(s) << " c " << c;
    }
  }
}

// Nearly dependent constraints: x1 >= 0 and x1 + d (x2 + 1) >= 0, both closed
// at the §3.7 impact (the event-driven test of the same name has the
// derivation). Each step's LCP has the Delassus matrix [[1, 1], [1, 1 + d^2]]
// (condition ~4/d^2), so a scheme's run may differ from its own single-stop
// run by up to min(d, eps/d) per unit impulse; measured (table_extremes):
// bitwise equal for theta = 1/2, theta = 1 and Euler at every d from 1e-2 to
// 1e-14 (Euler and theta = 1 pay up to 2x the LCP solves below d = 1e-8:
// pivoting stops on the numerically singular W and Lemke takes over). Bound
// 2 min(d, eps/d) + 1e-14 against the single-stop run, and that run's own
// first-order error (2 h) against the exact state.
TEST(SteppingExtremes, NearlyDependentConstraints) {
  const double eps = std::numeric_limits<double>::epsilon();
  const VectorXd x0 = Eigen::Vector4d(0, -1, -1, 0);
  const mech::Model single = mech::two_carts_model(Eigen::RowVector2d(1, 0));
  for (const Scheme& s : {kMj05, kMj1, kEuler}) {
    const auto ref = step(s, single, x0, 2.0, 1e-3);
    ASSERT_EQ(ref.status, sim::RunStatus::kCompleted) << label(s) << ": " << ref.message;
    for (double d : {1e-2, 1e-4, 1e-6, 3e-8, 1e-8, 3e-9, 1e-11, 1e-14}) {
      const auto tr =
          step(s, mech::two_carts_model(Eigen::Matrix2d{{1, 0}, {1, d}}, Eigen::Vector2d(0, d)), x0,
               2.0, 1e-3);
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << label(s) << " d " << d << tr.message;
      EXPECT_LE(maxabs(tr.final_state - ref.final_state), 2 * std::min(d, eps / d) + 1e-14)
          << label(s) << " d " << d;
    }
  }
}

// Nearly singular M (condition number 2e8), one stop, no force: free motion
// reaches the stop at t = 1 and the step's LCP applies Moreau's rule, v+ = v
// - M^{-1} E'(E M^{-1} E')^{-1} E v, as in the event-driven test; tolerance
// 10 eps cond. Backward Euler gets the same velocity from its position-level
// LCP (no force acts).
TEST(SteppingExtremes, NearlySingularMass) {
  const double d = 1e-8;
  mech::MechanicalModel m;
  m.M = Eigen::Matrix2d{{1, 1 - d}, {1 - d, 1}}.sparseView();
  m.E = Eigen::RowVector2d(1, 0).sparseView();
  m.g = VectorXd::Constant(1, 1.0);
  const auto model = wrap(m);
  const MatrixXd Mi = m.M.toDense().inverse(), E = m.E.toDense();
  const Eigen::Vector2d v(-1, 0.5);
  const VectorXd vp = v - Mi * E.transpose() * (E * Mi * E.transpose()).inverse() * (E * v);
  for (const Scheme& s : {kMj05, kMj1, kEuler}) {
    const auto tr = step(s, model, Eigen::Vector4d(0, 0, v(0), v(1)), 2.0, 1e-3);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    EXPECT_LE(maxabs(tr.final_state.tail(2) - vp), 10 * 1e-15 * 2 / d) << label(s);
  }
}

// Dependent rows with the default lcp_solver "pivot" (principal pivoting,
// for P-matrices): the step's Delassus matrix is singular and pivoting stops
// on a singular block ("M is not a P-matrix"). Found by helper-12 (Moreau–Jean
// theta = 1 and backward Euler failed at t = 0); the step now falls back to
// Lemke, PGS and enumeration (lcp::solve_with_fallbacks) as impacts and mode
// selection do, and gives the single-stop motion (Theorem 4.6.5): the final
// state of the single-stop run to 1e-5 (the theta = 1 Lemke difference of
// 1.4e-6 measured above).
TEST(SteppingExtremes, DependentConstraintsDefaultSolver) {
  const mech::Model single = mech::two_carts_model(Eigen::RowVector2d(1, 0));
  for (const Eigen::Matrix2d& E :
       {Eigen::Matrix2d{{1, 0}, {1, 0}}, Eigen::Matrix2d{{1, 0}, {2, 0}}}) {
    for (const Scheme& s : {kMj05, kMj1, kEuler}) {
      const auto tr = step(s, mech::two_carts_model(E), Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
      ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << label(s) << ": " << tr.message;
      const auto ref = step(s, single, Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
      EXPECT_LE(maxabs(tr.final_state - ref.final_state), 1e-5) << label(s) << " E " << E;
    }
  }
}

// Backward Euler at tiny steps. The k = 1 spring run of StepSizes1e8To1
// (impact mid-run, 10^4 steps) had error 1.5e-5 at h = 1e-8 (1500 h; found by
// helper-12): the step's LCP matrix G = h C (I - hA)^{-1} B is h^2 E M^-1 E' =
// 1e-16, and the solver's acceptance (1e-12 (1 + |q|)) then admitted any
// multiplier within 1e4 of the solution. The LCP is now solved diagonally
// scaled (lcp::solve_scaled). Bound 4 h, as at every other step size.
TEST(SteppingExtremes, StepSizeTinyEuler) {
  const auto model = spring_stop(1.0, 0.5);
  const double t1 = 2 * kPi / 3, h = 1e-8, t0 = t1 - 5000 * h, T = t0 + 1e4 * h;
  const auto tr = step(kEuler, model, Eigen::Vector2d(std::cos(t0), -std::sin(t0)), 1e4 * h, h);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  EXPECT_LE(
      maxabs(tr.final_state - Eigen::Vector2d(-0.5 * std::cos(T - t1), 0.5 * std::sin(T - t1))),
      4 * h);
}

// An infeasible start (E q0 + g < 0) is refused naming the constraint and the
// gap, as the event-driven method does (issue 8 §1, thesis §3.8), through
// sim::infeasible_start. Before (found by helper-12) Moreau–Jean held the ball
// 0.1 below the ground for the whole run and Euler's position-level LCP
// launched it at 0.1 / h = 100 m/s, both with status completed.
TEST(SteppingExtremes, InfeasibleStartIsRefused) {
  mech::MechanicalModel b;
  b.M = MatrixXd::Identity(1, 1).sparseView();
  b.E = MatrixXd::Identity(1, 1).sparseView();
  b.constraints = {"floor"};
  for (const Scheme& s : {kMj05, kMj1, kEuler}) {
    const auto tr = step(s, wrap(b), Eigen::Vector2d(-0.1, 0), 1.0, 1e-3);
    EXPECT_EQ(tr.status, sim::RunStatus::kInvalidInput) << label(s);
    EXPECT_NE(tr.message.find("floor"), std::string::npos) << label(s) << ": " << tr.message;
  }
}

// ---- Bullet (rb6 scene: diagonal M, stops and hooks) ------------------------
// Measured (table_extremes): resolved stiff springs k = 1e-6 ... 1e9 at h =
// period / 1000: error 5.5e-2 at every k (speculative limits engage early,
// docs/bullet-comparison.md), bound 0.1; the mass-ratio-1e8 hook: 8.9e-16,
// bound 1e-11 as above; chains of 10 and 100 carts at h = 1e-3: 4.4e-14
// (the limit rows cap the approach speed, then ERP closes the gap
// geometrically), bound 1e-9; never a crossing (round-off, 1e-12).
TEST(BulletExtremes, StiffSpringsMassRatioChains) {
  REQUIRE_LCSIM_BINARY();
  for (double k : {1e-6, 1.0, 1e9}) {
    const double w = std::sqrt(k), P = 2 * kPi / w, t1 = P / 3, T = t1 + 2.3 * P;
    const BulletRun r = bullet(spring_stop(k, 0.5), Eigen::Vector2d(1, 0), T, P / 1000);
    ASSERT_EQ(r.exit_code, 0) << r.err;
    const VectorXd x = r.final_state();
    const double tau = w * (T - t1);
    EXPECT_NEAR(x(0), -0.5 * std::cos(tau), 0.1) << "k " << k;
    EXPECT_NEAR(x(1) / w, 0.5 * std::sin(tau), 0.1) << "k " << k;
    EXPECT_GE(r.out.at("max_violation").get<double>(), -1e-12) << "k " << k;
  }
  mech::MechanicalModel m;
  m.M = MatrixXd(Eigen::Vector2d(1e-4, 1e4).asDiagonal()).sparseView();
  m.E = Eigen::RowVector2d(1, -1).sparseView();
  const BulletRun r = bullet(wrap(m), Eigen::Vector4d(0, 0, -1, 2), 1.0, 1e-3);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const double vc = (-1e-4 + 2e4) / (1e4 + 1e-4);
  EXPECT_LE(maxabs(r.final_state() - Eigen::Vector4d(vc, vc, vc, vc)), 1e-11);
  for (int N : {10, 100}) {
    VectorXd x0(2 * N), rest(2 * N);
    x0 << VectorXd::Zero(N), -VectorXd::Ones(N);
    rest << -VectorXd::Ones(N), VectorXd::Zero(N);
    const BulletRun c =
        bullet(wrap(*mech::chain_model({N, true, false, false}).mechanical), x0, 2.0, 1e-3);
    ASSERT_EQ(c.exit_code, 0) << c.err;
    EXPECT_LE(maxabs(c.final_state() - rest), 1e-9) << "N " << N;
    EXPECT_GE(c.out.at("max_violation").get<double>(), -1e-12) << "N " << N;
  }
}

// What Bullet's scene cannot express is refused, naming it: a non-diagonal
// (here nearly singular) M. Dependent stop rows (x1 >= 0 twice, or x1 >= 0
// and 2 x1 >= 0) are two limits on one body: the §3.7 final state to 4.6e-4
// at h = 1e-3 (measured; bound 2 h as the other schemes).
TEST(BulletExtremes, NearlySingularMassRefusedDependentRowsRun) {
  REQUIRE_LCSIM_BINARY();
  mech::MechanicalModel m;
  m.M = Eigen::Matrix2d{{1, 1 - 1e-8}, {1 - 1e-8, 1}}.sparseView();
  m.E = Eigen::RowVector2d(1, 0).sparseView();
  m.g = VectorXd::Constant(1, 1.0);
  const BulletRun r = bullet(wrap(m), Eigen::Vector4d(0, 0, -1, 0.5), 2.0, 1e-3);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("diagonal M"), std::string::npos) << r.err;
  MatrixXd A(4, 4);
  A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  const VectorXd xT = (A * (2.0 - kPi / 2)).exp() * Eigen::Vector4d(0, 0, 0, 1);
  for (double c : {1.0, 2.0}) {
    const BulletRun b = bullet(mech::two_carts_model(Eigen::Matrix2d{{1, 0}, {c, 0}}),
                               Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
    ASSERT_EQ(b.exit_code, 0) << b.err;
    EXPECT_LE(maxabs(b.final_state() - xT), 2e-3) << "c " << c;
  }
  // A nearly dependent row x1 + d x2 + d >= 0 is no limit of one body nor a
  // hook between two: refused, naming the row and its coefficients.
  mech::MechanicalModel nd;
  nd.M = MatrixXd::Identity(2, 2).sparseView();
  nd.E = Eigen::Matrix2d{{1, 0}, {1, 1e-8}}.sparseView();
  nd.g = Eigen::Vector2d(0, 1e-8);
  const BulletRun n = bullet(wrap(nd), Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
  EXPECT_NE(n.exit_code, 0);
  EXPECT_NE(n.err.find("row 1 of E) has coefficients 1 and 1e-08"), std::string::npos) << n.err;
}

// Where the Bullet scene cannot do what the model asks it says so (these
// were silent wrong results until helper-12's run, fixed in world.cpp):
// (1) restitution: a 6DOF2 limit's bounce never applies at the pinned stop
//     ERP 0.2 (measured on a bare Bullet 3.24 scene): the ball dropped from
//     1 m with e = 0.5 does not rebound (exact: 0.1875 m going up at 1.5 t1)
//     and the run warns "restitution is lost or reduced";
// (2) explicit springs past omega h = 2 (k = 1e9, h = 1e-3: omega h = 32;
//     energy x18 within a second) warn with the Gershgorin bound on omega;
// (3) an infeasible start (ball 0.1 below the ground) is refused, exit 3,
//     naming the constraint, as the event-driven method does.
TEST(BulletExtremes, RestitutionStabilityInfeasibleStart) {
  REQUIRE_LCSIM_BINARY();
  const double t1 = std::sqrt(2 / kG);
  const BulletRun b = bullet(ball(0.5), Eigen::Vector2d(1, 0), 1.5 * t1, 1e-3);
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_LE(b.final_state()(0), 1e-6);  // no rebound: the limitation is real
  EXPECT_NE(b.err.find("restitution is lost or reduced"), std::string::npos) << b.err;
  const BulletRun s = bullet(spring_stop(1e9, 0.5), Eigen::Vector2d(1, 0), 1.0, 1e-3);
  ASSERT_EQ(s.exit_code, 0) << s.err;
  EXPECT_NE(s.err.find("omega h up to"), std::string::npos) << s.err;
  const BulletRun i = bullet(ball(0.0), Eigen::Vector2d(-0.1, 0), 1.0, 1e-3);
  EXPECT_EQ(i.exit_code, 2);  // an infeasible start is input
  EXPECT_NE(i.err.find("is violated at t = 0 (gap = -0.1)"), std::string::npos) << i.err;
}

}  // namespace
}  // namespace lcsim
