// Issue 24 with Bullet: explicit dampers diverge above h = 2 / lambda_max(M^-1 D),
// the run stops as a numerical failure naming what diverged and the warning
// states that h (item 1); a sweep keeps the other methods' rows when Bullet
// refuses a model (item 4) and says when Bullet's error floor is the
// linearisation gap (item 9).
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/app/sweep.hpp>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::bullet {
namespace {

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Two bodies (rb6: M diagonal), a damper of 300 N s/m on a, one of 100 N s/m
// between a and b, springs of 10 N/m, a stop 1 m left of a.
const char* const kDamped =
    "name: damped_pair\nmechanical:\n  M: [[1, 0], [0, 2]]\n"
    "  D: [[300, -100], [-100, 100]]\n  K: [[10, 0], [0, 10]]\n  E: [[1, 0]]\n  g: [1]\n"
    "  constraints: [stop]\n  coordinates: [a, b]\ninitial: [0.1, 0, 0, 1]\nt_end: 2\n";

// lambda_max of M^-1 D = [[300, -100], [-50, 50]] in closed form: the larger
// root of lambda^2 - tr lambda + det, tr = 350, det = 300 * 50 - 100 * 50.
double largest_stable_h() {
  const double tr = 350.0, det = 300.0 * 50.0 - 100.0 * 50.0;
  return 2.0 / (0.5 * (tr + std::sqrt(tr * tr - 4.0 * det)));  // 6.27719e-3 s
}

// The warning's h, parsed from "... = <h> s ...".
double stated_h(const std::string& w) {
  const std::string key = "lambda_max(M^-1 D) = ";
  const auto at = w.find(key);
  return at == std::string::npos ? NAN : std::stod(w.substr(at + key.size()));
}

TEST(BulletDivergence, ExplicitDampersAboveTheStatedStepStopTheRun) {
  const mech::Model m = scene::parse_model(kDamped, "damped.yaml");
  sim::Options o;
  o.h = 1e-2;  // above 6.28e-3: the damping term multiplies v by up to |1 - 3.19| per step
  const sim::Trajectory tr = simulate_bullet(m, m.initial, o);
  EXPECT_EQ(tr.status, sim::RunStatus::kNumericalFailure) << tr.message;
  EXPECT_EQ(tr.message.rfind("bullet: diverged at t = ", 0), 0u) << tr.message;
  EXPECT_TRUE(has(tr.message, "energy")) << tr.message;
  EXPECT_LT(tr.steps, 200);                       // stopped early, not at t_end = 2 s
  EXPECT_NEAR(tr.t_end, tr.steps * 1e-2, 1e-12);  // the time reached
  EXPECT_TRUE(tr.final_state.allFinite());
  ASSERT_EQ(tr.warning_count("bullet-explicit-damping"), 1);
  const std::string w = tr.warnings.front().message;
  // Six significant digits are printed: 1e-5 relative.
  EXPECT_NEAR(stated_h(w), largest_stable_h(), 1e-5 * largest_stable_h()) << w;
  EXPECT_TRUE(has(w, "h = 0.01 is above it")) << w;
  // The same through the registry (Integrator::run, as the CLI and studies run it).
  EXPECT_EQ(sim::simulate(m, o, "bullet").status, sim::RunStatus::kNumericalFailure);
  // Below the bound: completes, and the warning says h is within it.
  o.h = 1e-3;
  const sim::Trajectory ok = simulate_bullet(m, m.initial, o);
  EXPECT_EQ(ok.status, sim::RunStatus::kCompleted) << ok.message;
  ASSERT_EQ(ok.warning_count("bullet-explicit-damping"), 1);
  EXPECT_TRUE(has(ok.warnings.front().message, "h = 0.001 is within it"))
      << ok.warnings.front().message;
}

// A model Bullet cannot express (M not diagonal, no URDF): refused by the
// method before any run, so the sweep keeps the other rows (it threw at the
// Bullet row after computing the others, losing the table).
TEST(BulletDivergence, SweepKeepsTheOtherRowsWhenBulletRefuses) {
  const mech::Model m = scene::parse_model(
      "name: nondiagonal\nmechanical:\n  M: [[1, 0.1], [0.1, 1]]\n  K: [[1, 0], [0, 1]]\n"
      "  E: [[1, 0]]\n  g: [0.5]\ninitial: [0.2, 0, 0, 0]\nt_end: 1\n",
      "nondiagonal.yaml");
  app::SweepOptions o;
  o.methods = {"event", "bullet", "moreau-jean"};
  o.hs = {1e-2};
  o.repeat = 1;
  o.base.t_end = 1.0;
  const app::SweepResult s = app::run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 3u);
  EXPECT_EQ(s.rows[0].status, "completed");
  EXPECT_EQ(s.rows[1].method, "bullet");
  EXPECT_EQ(s.rows[1].status.rfind("refused: ", 0), 0u) << s.rows[1].status;
  EXPECT_TRUE(has(s.rows[1].status, "M(1, 0) = 0.1")) << s.rows[1].status;
  EXPECT_TRUE(std::isinf(s.rows[1].error_max));
  EXPECT_EQ(s.rows[2].status, "completed");
  EXPECT_TRUE(std::isfinite(s.rows[2].error_max));
  // Bullet alone: nothing to measure, the refusal is the sweep's input error.
  o.methods = {"bullet"};
  EXPECT_THROW((void)app::run_sweep(m, m.initial, o), io::InputError);
}

// On a URDF scene Bullet integrates the nonlinear multibody, the exact run
// the linear model: the row says its error floor is the linearisation gap;
// Moreau-Jean's row (the same linear model) says nothing.
TEST(BulletDivergence, SweepNamesTheLinearisationGapOfBulletsMultibody) {
  const mech::Model m =
      scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/double_pendulum_scene.yaml");
  app::SweepOptions o;
  o.methods = {"bullet", "moreau-jean"};
  o.hs = {1e-2};
  o.repeat = 1;
  o.base.t_end = m.t_end;
  const app::SweepResult s = app::run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 2u);
  ASSERT_EQ(s.rows[0].status, "completed");
  EXPECT_EQ(s.rows[0].error_floor.rfind("the linearisation gap: ", 0), 0u) << s.rows[0].error_floor;
  EXPECT_TRUE(has(s.rows[0].error_floor, "nonlinear multibody")) << s.rows[0].error_floor;
  EXPECT_EQ(s.rows[1].error_floor, "");
  const auto j = app::sweep_json(s);
  EXPECT_TRUE(j["rows"][0]["error_floor"].is_string());
  EXPECT_TRUE(j["rows"][1]["error_floor"].is_null());
}

}  // namespace
}  // namespace lcsim::bullet
