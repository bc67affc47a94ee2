// Issue 24, item 1: a diverged run is never "completed". One guard
// (sim::DivergenceGuard, src/sim/divergence.cpp) for every method: the
// time-stepping loops stop at the first diverged step, Integrator::run checks
// what any method (the exact one included) reports at its end.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <string>

namespace lcsim::sim {
namespace {

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// An undamped oscillator, omega = 10 rad/s, from q = 1 at rest: energy 50 J.
mech::Model oscillator(double k) {
  return scene::parse_model("name: osc\nmechanical:\n  M: [[1]]\n  K: [[" + std::to_string(k) +
                                "]]\n  coordinates: [a]\ninitial: [1, 0]\nt_end: 100\n",
                            "osc.yaml");
}

// Moreau-Jean with theta < 1/2 gains energy every step: E+ - E =
// -(theta - 1/2)(|v+ - v|_M^2 + h^2 |v_t|_K^2) (moreau_jean.cpp's balance);
// here about 0.8 % a step (h omega = 0.1), e^80 over the 10^4 steps, finite
// all the way (before the guard the run said "completed" at E ~ 1e36 J). The
// guard stops it once E - E0 exceeds 1e6 times the energy scale (50 J, the
// start's): ln(1e6) / 0.008 ~ 1700 steps, well before the 10^4.
TEST(Divergence, MoreauJeanBelowHalfThetaStopsWithTheEnergyNamed) {
  const mech::Model m = oscillator(100.0);
  Options o;
  o.h = 1e-2;
  o.theta = 0.1;
  const Trajectory tr = simulate(m, o, "moreau-jean");
  EXPECT_EQ(tr.status, RunStatus::kNumericalFailure) << tr.message;
  EXPECT_EQ(tr.message.rfind("moreau-jean: diverged at t = ", 0), 0u) << tr.message;
  EXPECT_TRUE(has(tr.message, "energy")) << tr.message;
  EXPECT_TRUE(has(tr.message, "energy scale 50 J")) << tr.message;
  EXPECT_LT(tr.steps, 5000);                    // stopped early, not at t_end
  EXPECT_DOUBLE_EQ(tr.t_end, tr.steps * 1e-2);  // the time reached: the last sane step's
  EXPECT_TRUE(tr.final_state.allFinite());
  // The state kept is the one before the diverged step; the energy test runs
  // every DivergenceGuard::kStride = 16 steps, so it is at most 16 steps of
  // growth (1.008^16 = 1.14) past the bound of 1e6 * 50 J.
  EXPECT_LE(tr.energy_final - 50.0, 1.2 * 1e6 * 50.0);
  // theta = 1/2 conserves the quadratic energy of a linear oscillator: no
  // false alarm over the same 10^4 steps.
  o.theta = 0.5;
  const Trajectory ok = simulate(m, o, "moreau-jean");
  EXPECT_EQ(ok.status, RunStatus::kCompleted) << ok.message;
}

// A negative spring (k = -1e4) grows like e^{100 t}: over 100 s the exact
// method's state overflows. Energy is conserved (the potential falls as the
// kinetic energy rises), so it is the non-finite test that fires, here in
// Integrator::run's check of the final state: the exact method had reported
// "completed" with a NaN final state.
TEST(Divergence, ExactMethodWithANonFiniteFinalStateIsAFailure) {
  const Trajectory tr = simulate(oscillator(-1e4), Options{}, "event");
  EXPECT_EQ(tr.status, RunStatus::kNumericalFailure);
  EXPECT_EQ(tr.message.rfind("event: diverged at t = 100: q 'a' = ", 0), 0u) << tr.message;
  EXPECT_TRUE(has(tr.message, "(not finite)")) << tr.message;
  // Backward Euler on the same model: its step is stable for this growth
  // (|(1 - h A)^{-1}| stays finite), the run completes.
  Options o;
  o.t_end = 0.1;
  EXPECT_EQ(simulate(oscillator(-1e4), o, "euler").status, RunStatus::kCompleted);
}

// Two free carts, a stop on the first: M = diag(1, 2), f = (0, -1) N,
// t_end 2 s (no spring, so a far position costs no energy and the gap test
// is seen alone).
mech::Model carts() {
  return scene::parse_model(
      "name: carts\nmechanical:\n  M: [[1, 0], [0, 2]]\n"
      "  E: [[1, 0]]\n  g: [0.5]\n  f: [0, -1]\n  coordinates: [a, b]\n  constraints: [stop]\n"
      "initial: [0, 0, 1, 0]\nt_end: 2\n",
      "carts.yaml");
}

// The guard's three tests and their messages, on hand-made states.
TEST(Divergence, GuardNamesWhatDiverged) {
  const mech::Model m = carts();
  DivergenceGuard g(m, m.initial, 2.0);
  // Energy scale: T0 = 1/2, |V0| = 0, forces: (f_b T)^2 / (2 M_bb) = 4 / 4 = 1.
  EXPECT_DOUBLE_EQ(g.energy_scale(), 1.5);
  // Length scale: |g| + |E|_1 (|q0| + T sqrt(2 E_s / m_min)) = 0.5 + 2 sqrt(3).
  EXPECT_NEAR(g.length_scale(), 0.5 + 2.0 * std::sqrt(3.0), 1e-12);
  Eigen::VectorXd x = m.initial;
  EXPECT_EQ(g.check(0.1, x, true), "");
  x(3) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(g.check(0.25, x), "diverged at t = 0.25: v 'b' = nan (not finite)");
  // Kinetic energy 1/2 * 2 * 2000^2 = 4e6 J > 1e6 * 1.5 J.
  x = m.initial;
  x(3) = 2000.0;
  const std::string energy = g.check(0.5, x, true);
  EXPECT_EQ(energy.rfind("diverged at t = 0.5: energy 4e+06 J from 0.5 J at the start", 0), 0u)
      << energy;
  EXPECT_TRUE(has(energy, "v 'b' = 2000")) << energy;
  // Just below the energy bound (1000 m/s: 1e6 J): sane; the gap test then
  // fires only a thousand length scales past the stop.
  x(3) = 1000.0;
  EXPECT_EQ(g.check(0.5, x, true), "");
  x(3) = 0.0;
  x(0) = -0.5 - 1e3 * g.length_scale() * 1.01;
  const std::string gap = g.check(0.75, x, true);
  EXPECT_EQ(gap.rfind("diverged at t = 0.75: constraint 'stop' violated by ", 0), 0u) << gap;
  EXPECT_TRUE(has(gap, "far past any stop")) << gap;
  // A penetration of a whole length scale is not divergence.
  x(0) = -0.5 - g.length_scale();
  EXPECT_EQ(g.check(0.75, x, true), "");
}

// No false alarm on the shipped models with every method that takes them
// (the golden and extremes suites run the rest).
TEST(Divergence, ShippedModelsStillComplete) {
  for (const char* name : {"two_carts.yaml", "two_carts_hook.yaml", "ball.yaml",
                           "belt_friction.yaml", "mass_spring_friction.yaml"}) {
    const mech::Model m = scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
    for (const char* method : {"event", "moreau-jean", "euler"}) {
      auto integ = make_integrator(method);
      if (integ->refuse(m, m.initial, Options{})) continue;  // a model it does not take
      const Trajectory tr = integ->run(m, m.initial, Options{});
      EXPECT_EQ(tr.status, RunStatus::kCompleted) << name << " " << method << ": " << tr.message;
    }
  }
}

}  // namespace
}  // namespace lcsim::sim
