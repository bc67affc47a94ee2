// Forward sensitivities in a model's parameters through planar stick / slip
// (docs/sensitivities.md, src/sim/exact/sensitivity_friction.cpp): f[i],
// K[i][j], D[i][j] move the free acceleration, the phase's forces
// lambda = -S^-1 H Av x and its closed loop; g[c] moves the gap monitors.
//
// A closed form (the block sliding to rest), then central differences of the
// exact method on the shipped friction files with the step and tolerance of
// tests/sim/test_sensitivity_events.cpp: h = 1e-4 max(1, |theta|), tolerance
// 4 |D(h) - D(h/2)| + 64e-13 max(1, |x|) / h; every perturbed run must have
// the run's events.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

#include "support/sensitivity_fd.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

mech::Model load(const std::string& path) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/" + path);
}

sim::Trajectory run(const mech::Model& m, double T, std::vector<std::string> sens = {}) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, m.initial, opt, "event");
}

struct Param {
  std::string column;
  double theta;
  std::function<void(mech::MechanicalModel&, double)> apply;
};

// Every present column of `ps` against central differences at x(T) and each
// event time (tests/support/sensitivity_fd.hpp); the number of entries
// compared.
int expect_matches_fd(const mech::Model& m, double T, const std::vector<Param>& ps) {
  std::vector<std::string> names;
  std::vector<test_support::FdColumn> cols;
  for (const Param& p : ps) {
    names.push_back(p.column);
    cols.push_back({p.column, p.theta,
                    [p](mech::Model& mm, VectorXd&, double d) { p.apply(*mm.mechanical, d); }});
  }
  const sim::Trajectory tr = run(m, T, names);
  EXPECT_TRUE(tr.ok()) << tr.message;
  if (!tr.ok()) return 0;
  return test_support::expect_columns_match_fd(m, m.initial, T, tr, cols);
}

Param force(int i, double f) {
  return {"f[" + std::to_string(i) + "]", f,
          [i](mech::MechanicalModel& m, double d) { m.f(i) += d; }};
}

// The block of robots/block_on_floor_friction.yaml (1 kg, mu = 0.4, weight
// N = -f_y = 9.81 N, sliding at v0 = 2 m/s along x) pushed by f_x = 0:
// decelerating at a = (mu N - f_x)/m, it stops at t* = v0/a after
// x* = v0^2/(2 a) and sticks (|f_x| <= mu N). With da/df_x = -1 and
// da/df_y = -mu: dx*/df_x = v0^2/(2 a^2), dx*/df_y = mu v0^2/(2 a^2),
// dt*/df_x = v0/a^2, dt*/df_y = mu v0/a^2, and the velocity's derivatives 0
// after the stop; before it (T = 0.3 s) x = v0 T - a T^2/2: dx/df_x =
// T^2/2, dx/df_y = mu T^2/2, dv/df_x = T, dv/df_y = mu T. The normal stays
// held: dy = 0. g[floor] is absent (a zero gap at the start). To 1e-12 (the
// run is exact to ~1e-15 here: nilpotent phases; margin ~100 on entries of
// size up to 0.26).
TEST(SensitivityFrictionParams, BlockSlidingToRestClosedForm) {
  const mech::Model m = load("robots/block_on_floor_friction.yaml");
  const double v0 = 2.0, mu = 0.4, a = mu * 9.81;
  const sim::Trajectory tr = run(m, 1.0, {"f[0]", "f[1]", "g[floor]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);  // slip -> stick
  ASSERT_TRUE(tr.dx_final_exists[0] && tr.dx_final_exists[1]);
  EXPECT_FALSE(tr.dx_final_exists[2]);
  const double dxs = v0 * v0 / (2 * a * a);
  EXPECT_NEAR(tr.dx_final(0, 0), dxs, 1e-12);
  EXPECT_NEAR(tr.dx_final(0, 1), mu * dxs, 1e-12);
  EXPECT_NEAR(tr.events[0].dt(0), v0 / (a * a), 1e-12);
  EXPECT_NEAR(tr.events[0].dt(1), mu * v0 / (a * a), 1e-12);
  for (int c = 0; c < 2; ++c)
    for (int r : {1, 2, 3}) EXPECT_NEAR(tr.dx_final(r, c), 0.0, 1e-12) << r << ", " << c;
  const double T = 0.3;
  const sim::Trajectory early = run(m, T, {"f[0]", "f[1]"});
  ASSERT_TRUE(early.ok()) << early.message;
  EXPECT_TRUE(early.events.empty());
  EXPECT_NEAR(early.dx_final(0, 0), T * T / 2, 1e-12);
  EXPECT_NEAR(early.dx_final(0, 1), mu * T * T / 2, 1e-12);
  EXPECT_NEAR(early.dx_final(2, 0), T, 1e-12);
  EXPECT_NEAR(early.dx_final(2, 1), mu * T, 1e-12);
}

// The shipped planar friction files against central differences at x(T)
// and every event time: the block sliding to rest (f[0], f[1]), the spring
// (K = 4) sliding, reversing and sticking (f[0], f[1], K[0][0], D[0][0]:
// a damping entry of 0 moved), the incline (f[0], f[1]) and the belt
// (stick then slip: the stick force's monitor mu u_N - u_T reaches zero,
// its dF terms; f[0], K[0][0]). g[c] is absent on each (they start on their
// floor: a zero gap). Counts asserted.
TEST(SensitivityFrictionParams, FrictionFilesAgainstFiniteDifferences) {
  struct File {
    const char* name;
    std::vector<Param> ps;
  };
  const Param k00{"K[0][0]", 4.0,
                  [](mech::MechanicalModel& m, double d) { m.K.coeffRef(0, 0) += d; }};
  const Param d00{"D[0][0]", 0.0,
                  [](mech::MechanicalModel& m, double d) { m.D.coeffRef(0, 0) += d; }};
  const Param gap{"g[0]", 0.0, [](mech::MechanicalModel& m, double d) { m.g(0) += d; }};
  const std::vector<File> files = {
      {"robots/block_on_floor_friction.yaml", {force(0, 0), force(1, -9.81), gap}},
      {"robots/mass_spring_friction.yaml", {force(0, 0), force(1, -9.81), k00, d00}},
      {"robots/incline_friction.yaml", {force(0, -2.9), force(1, -9.37)}},
      {"robots/belt_friction.yaml", {force(0, 0), k00}}};
  int total = 0;
  for (const File& f : files) {
    const mech::Model m = load(f.name);
    const sim::Trajectory plain = run(m, m.t_end);
    ASSERT_TRUE(plain.ok()) << plain.message;
    ASSERT_GE(plain.events.size(), 1u) << f.name;
    const int per = static_cast<int>(m.initial.size() + plain.events.size());
    const int present = static_cast<int>(f.ps.size()) - (f.ps.back().column == "g[0]");
    EXPECT_EQ(expect_matches_fd(m, m.t_end, f.ps), present * per) << f.name;
    total += present * per;
  }
  EXPECT_EQ(total, 2 * 5 + 4 * 6 + 2 * 5 + 2 * 6);
}

// mu[c], the friction coefficient (kind 'u'): it moves a sliding contact's
// force column -sigma mu t (the phase's dF and dAcl), a stick monitor by
// d(mu) u_N, and a sliding impact's tangential impulse. The block sliding
// to rest (v0 = 2, mu = 0.4, g = 9.81): x* = v0^2/(2 mu g), so dx*/dmu =
// -x*/mu and dt*/dmu = -t*/mu; before the stop (T = 0.3 s) x = v0 T - mu g
// T^2/2: dx/dmu = -g T^2/2, dv/dmu = -g T. The block dropped from y0 = 0.2
// m at vx0 = 2 m/s (w = sqrt(2 g y0) at the impact t1 = w/g, after which it
// slides: vx+ = vx0 - mu w, decelerating at mu g), at T = 0.4 s:
// dx/dmu = -w (T - t1) - g (T - t1)^2/2, dvx/dmu = -w - g (T - t1). To
// 1e-12 as above.
TEST(SensitivityFrictionParams, MuClosedForms) {
  mech::Model m = load("robots/block_on_floor_friction.yaml");
  const double v0 = 2.0, mu = 0.4, g = 9.81;
  const sim::Trajectory tr = run(m, 1.0, {"mu[floor]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);
  const double xs = v0 * v0 / (2 * mu * g), ts = v0 / (mu * g);
  EXPECT_NEAR(tr.dx_final(0, 0), -xs / mu, 1e-12);
  EXPECT_NEAR(tr.events[0].dt(0), -ts / mu, 1e-12);
  EXPECT_NEAR(tr.dx_final(2, 0), 0.0, 1e-12);
  const double T = 0.3;
  const sim::Trajectory early = run(m, T, {"mu[0]"});
  ASSERT_TRUE(early.ok()) << early.message;
  EXPECT_NEAR(early.dx_final(0, 0), -g * T * T / 2, 1e-12);
  EXPECT_NEAR(early.dx_final(2, 0), -g * T, 1e-12);
  m.initial << 0, 0.2, 2, 0;
  const double w = std::sqrt(2 * g * 0.2), t1 = w / g, Td = 0.4;
  const sim::Trajectory drop = run(m, Td, {"mu[floor]"});
  ASSERT_TRUE(drop.ok()) << drop.message;
  ASSERT_EQ(drop.events.size(), 1u);  // the impact, sliding after it
  ASSERT_TRUE(drop.dx_final_exists[0]);
  EXPECT_NEAR(drop.dx_final(0, 0), -w * (Td - t1) - g * (Td - t1) * (Td - t1) / 2, 1e-12);
  EXPECT_NEAR(drop.dx_final(2, 0), -w - g * (Td - t1), 1e-12);
  // Refused: a constraint without friction, and on a frictionless model.
  sim::Options o;
  o.t_end = 0.1;
  o.sensitivity = {"mu[nope]"};
  EXPECT_EQ(sim::simulate(m, m.initial, o, "event").status, Status::kInvalidInput);
  const mech::Model ball = load("robots/ball.yaml");
  o.sensitivity = {"mu[0]"};
  const sim::Trajectory nb = sim::simulate(ball, ball.initial, o, "event");
  EXPECT_EQ(nb.status, Status::kInvalidInput);
  EXPECT_NE(nb.message.find("has no friction"), std::string::npos) << nb.message;
}

// mu[0] on the four planar friction files against central differences (the
// belt: stick then slip, the stick force's monitor mu u_N - u_T reaching
// zero moves by d(mu) u_N; the spring: slip reversal and stick).
TEST(SensitivityFrictionParams, MuAgainstFiniteDifferences) {
  int total = 0;
  for (const char* name :
       {"robots/block_on_floor_friction.yaml", "robots/mass_spring_friction.yaml",
        "robots/incline_friction.yaml", "robots/belt_friction.yaml"}) {
    const mech::Model m = load(name);
    const Param mu{"mu[0]", m.mechanical->friction[0].mu,
                   [](mech::MechanicalModel& mm, double d) { mm.friction[0].mu += d; }};
    const sim::Trajectory plain = run(m, m.t_end);
    ASSERT_TRUE(plain.ok()) << plain.message;
    const int per = static_cast<int>(m.initial.size() + plain.events.size());
    EXPECT_EQ(expect_matches_fd(m, m.t_end, {mu}), per) << name;
    total += per;
  }
  EXPECT_EQ(total, 5 + 6 + 5 + 6);
}

}  // namespace
}  // namespace lcsim
