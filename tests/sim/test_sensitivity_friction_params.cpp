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
#include <lcsim/io/model_file.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

#include "support/coupled_bar.hpp"
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

Param mass(int i, int j, double theta) {
  return {"M[" + std::to_string(i) + "][" + std::to_string(j) + "]", theta,
          [i, j](mech::MechanicalModel& m, double d) {
            m.M.coeffRef(i, j) += d;
            if (i != j) m.M.coeffRef(j, i) += d;
          }};
}

Param restitution(int c, double e) {
  return {"e[" + std::to_string(c) + "]", e,
          [c](mech::MechanicalModel& m, double d) { m.restitution(c) += d; }};
}

// M[i][j] (the mass matrix moves G = M^-1: the phase's free acceleration,
// its forces through S = H M^-1 G' and the stick / slip columns). The block
// of robots/block_on_floor_friction.yaml, whose weight is the file's force
// f_y = -9.81 N (not m g: it does not scale with the mass), sliding at v0 =
// 2 m/s and pushed by f_x: the normal force N = 9.81 N holds y (M[1][1]
// moves nothing: N does not depend on it), and along x m vx' = f_x - mu N,
// so a = (mu N - f_x)/m, t* = v0/a = m v0/(mu N - f_x), x* = v0^2/(2 a) = m
// v0^2/(2 (mu N - f_x)), after which it sticks (|f_x| <= mu N). At m = 1:
// dx*/dm = x*, dt*/dm = t*, dv/dm = 0 after the stop; before it (T = 0.3 s)
// x = v0 T - a T^2/2: dx/dm = a T^2/2, dv/dm = a T. With f_x = 0 and with a
// push f_x = 1 N (the stop moves with m either way: the weight is a force).
// To 1e-12 as above.
TEST(SensitivityFrictionParams, MassClosedForms) {
  const double v0 = 2.0, mu = 0.4, N = 9.81;
  for (const double fx : {0.0, 1.0}) {
    mech::Model m = load("robots/block_on_floor_friction.yaml");
    m.mechanical->f(0) = fx;
    const double a = mu * N - fx, ts = v0 / a, xs = v0 * v0 / (2 * a);
    const sim::Trajectory tr = run(m, 1.0, {"M[0][0]", "M[1][1]", "M[x][y]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    ASSERT_EQ(tr.events.size(), 1u);  // slip -> stick
    ASSERT_NEAR(tr.final_state(0), xs, 1e-12);
    for (int c = 0; c < 3; ++c) ASSERT_TRUE(tr.dx_final_exists[static_cast<size_t>(c)]);
    EXPECT_NEAR(tr.dx_final(0, 0), xs, 1e-12) << fx;
    EXPECT_NEAR(tr.events[0].dt(0), ts, 1e-12) << fx;
    for (int r : {1, 2, 3}) EXPECT_NEAR(tr.dx_final(r, 0), 0.0, 1e-12) << r;
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(tr.dx_final(r, 1), 0.0, 1e-12) << r;
    EXPECT_NEAR(tr.events[0].dt(1), 0.0, 1e-12);
    const double T = 0.3;
    const sim::Trajectory early = run(m, T, {"M[0][0]", "M[1][1]"});
    ASSERT_TRUE(early.ok()) << early.message;
    EXPECT_NEAR(early.dx_final(0, 0), a * T * T / 2, 1e-12) << fx;
    EXPECT_NEAR(early.dx_final(2, 0), a * T, 1e-12) << fx;
    for (int r = 0; r < 4; ++r) EXPECT_NEAR(early.dx_final(r, 1), 0.0, 1e-12) << r;
  }
  // Through a sliding impact: dropped from y0 = 0.2 m at vx0 = 2 m/s,
  // plastic, mass m along x (M[0][0]): the floor's impulse P_N = w (w =
  // sqrt(2 g y0), M[1][1] = 1) at t1 = w/g, the tangential -mu P_N, so vx+ =
  // vx0 - mu w/m, then sliding at mu N/m: at T = 0.4 s, s = T - t1, dvx/dm =
  // mu w + mu N s and dx/dm = mu w s + mu N s^2/2 (m = 1).
  mech::Model m = load("robots/block_on_floor_friction.yaml");
  m.initial << 0, 0.2, 2, 0;
  const double g = 9.81, w = std::sqrt(2 * g * 0.2), s = 0.4 - w / g;
  const sim::Trajectory drop = run(m, 0.4, {"M[0][0]"});
  ASSERT_TRUE(drop.ok()) << drop.message;
  ASSERT_EQ(drop.events.size(), 1u);
  ASSERT_TRUE(drop.dx_final_exists[0]);
  EXPECT_NEAR(drop.dx_final(0, 0), mu * w * s + mu * N * s * s / 2, 1e-12);
  EXPECT_NEAR(drop.dx_final(2, 0), mu * w + mu * N * s, 1e-12);
  EXPECT_NEAR(drop.events[0].dt(0), 0.0, 1e-12);
}

// e[c] through impacts with friction: R = [(1 + e) E_A; T_S], e on where the
// contact approaches. The block dropped from y0 = 0.2 m (w = sqrt(2 g y0),
// t1 = w/g) on the floor with restitution e = 0.5: P_N = (1 + e) w, it leaves
// at vy+ = e w, lands again at t2 = t1 + 2 e w/g (dt2/de = 2 w/g) at -e w,
// leaves at e^2 w. Sliding (vx0 = 2 > mu (1 + e) w: vx+ = vx0 - mu (1 + e)
// w, vx++ = vx+ - mu (1 + e) e w > 0, still sliding), in flight vx is
// constant: at T = 0.3 s (between the impacts, s1 = T - t1) dx/de = -mu w
// s1, dvx/de = -mu w, dy/de = w s1, dvy/de = w; at T = 0.45 s (s = T - t2,
// before the third impact at 0.505 s) dx/de = -mu w (t2 - t1) + (vx+ -
// vx++) 2w/g - mu w (2 + 2e) s, dvx/de = -mu w (2 + 2e), y = e^2 w s - g
// s^2/2: dy/de = 2 e w s - (e^2 w - g s) 2w/g, dvy/de = 2 e w + 2 w.
// Sticking (vx0 = 0.5 <= mu (1 + e) w): vx+ = 0 and x = vx0 t1 whatever e,
// the same y derivatives. dt1/de = 0. To 1e-12 as above.
TEST(SensitivityFrictionParams, RestitutionClosedForms) {
  const double mu = 0.4, g = 9.81, e = 0.5, w = std::sqrt(2 * g * 0.2);
  const double t1 = w / g, t2 = t1 + 2 * e * w / g;
  for (const double vx0 : {2.0, 0.5}) {
    mech::Model m = load("robots/block_on_floor_friction.yaml");
    m.mechanical->restitution = VectorXd::Constant(1, e);
    m.initial << 0, 0.2, vx0, 0;
    const bool slides = vx0 > mu * (1 + e) * w;
    const sim::Trajectory one = run(m, 0.3, {"e[floor]"});
    ASSERT_TRUE(one.ok()) << one.message;
    ASSERT_EQ(one.events.size(), 1u);
    ASSERT_TRUE(one.dx_final_exists[0]);
    const double s1 = 0.3 - t1;
    EXPECT_NEAR(one.dx_final(0, 0), slides ? -mu * w * s1 : 0.0, 1e-12) << vx0;
    EXPECT_NEAR(one.dx_final(2, 0), slides ? -mu * w : 0.0, 1e-12) << vx0;
    EXPECT_NEAR(one.dx_final(1, 0), w * s1, 1e-12) << vx0;
    EXPECT_NEAR(one.dx_final(3, 0), w, 1e-12) << vx0;
    EXPECT_NEAR(one.events[0].dt(0), 0.0, 1e-12);
    const double T = 0.45, s = T - t2;
    const sim::Trajectory two = run(m, T, {"e[floor]"});
    ASSERT_TRUE(two.ok()) << two.message;
    ASSERT_EQ(two.events.size(), 2u);
    ASSERT_TRUE(two.dx_final_exists[0]);
    ASSERT_NEAR(two.events[1].t, t2, 1e-12);
    EXPECT_NEAR(two.events[1].dt(0), 2 * w / g, 1e-12) << vx0;
    const double dx =
        -mu * w * (t2 - t1) + mu * (1 + e) * e * w * 2 * w / g - mu * w * (2 + 2 * e) * s;
    EXPECT_NEAR(two.dx_final(0, 0), slides ? dx : 0.0, 1e-12) << vx0;
    EXPECT_NEAR(two.dx_final(2, 0), slides ? -mu * w * (2 + 2 * e) : 0.0, 1e-12) << vx0;
    EXPECT_NEAR(two.dx_final(1, 0), 2 * e * w * s - (e * e * w - g * s) * 2 * w / g, 1e-12);
    EXPECT_NEAR(two.dx_final(3, 0), 2 * e * w + 2 * w, 1e-12) << vx0;
  }
}

// M[i][j] and e[c] against central differences (tests/support/
// sensitivity_fd.hpp: x(T) and every event time): the coupled bar landing
// with mu = 1.5 (stick) and mu = 0.2 (slip), plastic, to 0.6 s, and with mu
// = 0.2, e = 0.5 (two bouncing impacts) to 0.55 s (M[0][0], M[1][1],
// M[2][2], M[1][2], M[0][2], e[0]; at e = 0, e[0] is reported absent at the
// impact: any e > 0 bounces); the four planar friction files, which start
// on their floor and have no impact (M[0][0], M[1][1], M[0][1] at t_end),
// and the spinning disk (impacts with e = 0.5 and stick at 0, 0.306 and
// 0.459 s, to 0.5 s, before its accumulation, whose limit's derivative is
// that of the limit as the run takes it, off by the order of its tail:
// docs/sensitivities.md; M and e[0]). Counts asserted.
TEST(SensitivityFrictionParams, MassAndRestitutionAgainstFiniteDifferences) {
  int total = 0;
  struct Bar {
    double mu, e, T;
  };
  for (const auto& [mu, e, T] : {Bar{1.5, 0.0, 0.6}, Bar{0.2, 0.0, 0.6}, Bar{0.2, 0.5, 0.55}}) {
    const mech::Model m = test_support::coupled_bar(mu, e);
    const sim::Trajectory plain = run(m, T);
    ASSERT_TRUE(plain.ok()) << plain.message;
    const int per = static_cast<int>(6 + plain.events.size());
    const std::vector<Param> ps = {mass(0, 0, 1), mass(1, 1, 1), mass(2, 2, 0.1),
                                   mass(1, 2, 0), mass(0, 2, 0), restitution(0, e)};
    const int n = expect_matches_fd(m, T, ps);
    EXPECT_EQ(n, (e > 0 ? 6 : 5) * per) << "bar, mu = " << mu << ", e = " << e;
    if (e == 0) {
      const sim::Trajectory tr = run(m, T, {"e[corner]"});
      ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
      EXPECT_EQ(tr.sensitivity_losses[0].contact, "corner");
      EXPECT_EQ(tr.sensitivity_losses[0].t, plain.events[0].t);
      EXPECT_NE(tr.sensitivity_losses[0].reason.find("one-sided"), std::string::npos);
    }
    total += n;
  }
  struct File {
    const char* name;
    double T;
  };
  for (const auto& [name, T_file] :
       {File{"robots/block_on_floor_friction.yaml", 0}, File{"robots/mass_spring_friction.yaml", 0},
        File{"robots/incline_friction.yaml", 0}, File{"robots/belt_friction.yaml", 0},
        File{"robots/spinning_disk_friction.yaml", 0.5}}) {  // 0: the file's t_end
    const mech::Model m = load(name);
    const double T = T_file > 0 ? T_file : m.t_end;
    const sim::Trajectory plain = run(m, T);
    ASSERT_TRUE(plain.ok()) << plain.message;
    const int per = static_cast<int>(m.initial.size() + plain.events.size());
    std::vector<Param> ps = {mass(0, 0, 1), mass(1, 1, 1), mass(0, 1, 0)};
    const double e = m.mechanical->restitution(0);
    if (e > 0.0) ps.push_back(restitution(0, e));
    const int n = expect_matches_fd(m, T, ps);
    EXPECT_EQ(n, static_cast<int>(ps.size()) * per) << name;
    std::cout << name << " to " << T << " s: " << plain.events.size() << " events, " << n
              << " entries\n";
    total += n;
  }
  EXPECT_EQ(total, 5 * 7 + 5 * 7 + 6 * 8 + 3 * 5 + 3 * 6 + 3 * 5 + 3 * 6 + 4 * 9);
}

// The block of robots/block_on_floor_friction.yaml at rest on its floor
// (mu = 0.4, N = 9.81 N), pushed along x by a force input `push`.
mech::Model pushed_block(const std::string& input) {
  return io::parse_matrix_model(
      "name: pushed_block\ninputs:\n  - " + input +
          "\nmechanical:\n  M: [[1, 0], [0, 1]]\n  E: [[0, 1]]\n  f: [0, -9.81]\n"
          "  coordinates: [x, y]\n  constraints: [floor]\n"
          "  force_inputs: [{input: push, gain: [1, 0]}]\n"
          "  friction:\n    - {contact: floor, tangent: [1, 0], mu: 0.4}\n"
          "initial: [0, 0, 0, 0]\nt_end: 1.8\n",
      "pushed_block.yaml");
}

// An input's own parameters through the friction phase: they move the force
// column of the free acceleration (and the exosystem), so the forces' dF =
// -S^-1 H dAv as f[i]'s. The block at rest pushed by the ramp f_x = P t /
// t1 (pwl points (0, 0), (t1, P), P = 6 N, t1 = 2 s): it sticks until P t /
// t1 = mu N, ts = mu N t1 / P (the stick force's monitor reaching the
// cone's edge), then slides with x'' = P s / t1 - mu N, the integrand zero
// at ts, so at T = 1.8 s: dx(T)/dP = int_ts^T (T - s) s / t1 ds = (T^3/6 -
// T ts^2/2 + ts^3/3) / t1, dv/dP = (T^2 - ts^2) / (2 t1), dts/dP = -ts/P;
// t1 enters through P / t1 only, so d/dt1 = -(P / t1) d/dP. To 1e-12 (a
// margin ~100 over the run's rounding on entries up to 0.6).
TEST(SensitivityFrictionParams, InputParametersClosedForms) {
  const mech::Model m = pushed_block("{name: push, kind: pwl, points: [[0, 0], [2, 6]]}");
  const double P = 6, t1 = 2, muN = 0.4 * 9.81, ts = muN * t1 / P, T = 1.8;
  const sim::Trajectory tr = run(m, T, {"pwl_v[push][1]", "pwl_t[push][1]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 1u);  // stick -> slip
  ASSERT_NEAR(tr.events[0].t, ts, 1e-12);
  ASSERT_TRUE(tr.dx_final_exists[0] && tr.dx_final_exists[1]);
  const double dx = (T * T * T / 6 - T * ts * ts / 2 + ts * ts * ts / 3) / t1;
  const double dv = (T * T - ts * ts) / (2 * t1);
  EXPECT_NEAR(tr.dx_final(0, 0), dx, 1e-12);
  EXPECT_NEAR(tr.dx_final(2, 0), dv, 1e-12);
  EXPECT_NEAR(tr.events[0].dt(0), -ts / P, 1e-12);
  EXPECT_NEAR(tr.dx_final(0, 1), -P / t1 * dx, 1e-12);
  EXPECT_NEAR(tr.dx_final(2, 1), -P / t1 * dv, 1e-12);
  EXPECT_NEAR(tr.events[0].dt(1), P / t1 * ts / P, 1e-12);
  for (int c = 0; c < 2; ++c)
    for (int r : {1, 3}) EXPECT_NEAR(tr.dx_final(r, c), 0.0, 1e-12);
}

// A damped sine push (amplitude 8 N, 0.4 Hz, damping 0.1 1/s, phase 0.3,
// offset 0.5 N), to 4.5 s through six stick / slip events (stick -> slip+
// at 0.058 s, a reversal slip+ -> slip- at 1.465 s, stick at 2.454 s, slip+
// at 2.615 s, stick at 3.808 s, slip- at 4.018 s): its five parameters
// against central differences (counts asserted).
TEST(SensitivityFrictionParams, InputParametersAgainstFiniteDifferences) {
  const mech::Model m = pushed_block(
      "{name: push, kind: damped_sine, amplitude: 8, frequency: 0.4, damping: 0.1, phase: 0.3, "
      "offset: 0.5}");
  const double T = 4.5;
  const sim::Trajectory plain = run(m, T);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 6u);
  auto input = [](const char* column, double theta, double mech::Input::*field) {
    return Param{column, theta,
                 [field](mech::MechanicalModel& mm, double d) { mm.inputs[0].*field += d; }};
  };
  const std::vector<Param> ps = {input("amplitude[push]", 8, &mech::Input::amplitude),
                                 input("frequency[push]", 0.4, &mech::Input::frequency),
                                 input("damping[push]", 0.1, &mech::Input::damping),
                                 input("phase[push]", 0.3, &mech::Input::phase),
                                 input("offset[push]", 0.5, &mech::Input::offset)};
  EXPECT_EQ(expect_matches_fd(m, T, ps), 5 * (4 + 6));
}

// e[c] at a plastic impact (e = 0) has only one side (e >= 0); where the
// contact is then held, any e > 0 bounces (another event sequence), so the
// column is reported absent, with or without friction (the ball dropped on
// its ground from 1 m, resting from t1 = 0.4515 s: the loss names `ground`
// at t1, no number); where the contact leaves at once, e > 0 only adds a
// small rate, the same sequence, and the right derivative is given: a unit
// mass under a ceiling z <= 1, thrown up at 5 m/s from 0.5 m, reaches it at
// t1 = (5 - v_a)/g with v_a = sqrt(25 - g), leaves at -e v_a, so at T = 0.4
// s (s = T - t1) z = 1 - e v_a s - g s^2/2: dz/de = -v_a s, dv/de = -v_a, to
// 1e-12.
TEST(SensitivityFrictionParams, PlasticImpactRestitutionIsOneSided) {
  const mech::Model ball = mech::ball_model(0.0);
  const sim::Trajectory rest = sim::simulate(
      ball, Eigen::Vector2d(1.0, 0.0),
      [] {
        sim::Options o;
        o.t_end = 1.0;
        o.sensitivity = {"x0", "e[0]"};
        return o;
      }(),
      "event");
  ASSERT_TRUE(rest.ok()) << rest.message;
  ASSERT_EQ(rest.sensitivity_losses.size(), 1u);
  EXPECT_NEAR(rest.sensitivity_losses[0].t, std::sqrt(2 / 9.81), 1e-12);
  EXPECT_EQ(rest.sensitivity_losses[0].contact, ball.mechanical->constraints[0]);
  EXPECT_TRUE(rest.dx_final_exists[0] && rest.dx_final_exists[1]);
  EXPECT_FALSE(rest.dx_final_exists[2]);
  EXPECT_EQ(rest.dx_final.col(2).cwiseAbs().maxCoeff(), 0.0);
  const mech::Model ceiling = io::parse_matrix_model(
      "name: ceiling\nmechanical:\n  M: [[1]]\n  E: [[-1]]\n  g: [1]\n  f: [-9.81]\n"
      "  restitution: [0]\n  coordinates: [z]\n  constraints: [ceiling]\n"
      "initial: [0.5, 5]\nt_end: 0.4\n",
      "ceiling.yaml");
  const double g = 9.81, va = std::sqrt(25 - g), s = 0.4 - (5 - va) / g;
  const sim::Trajectory up = run(ceiling, 0.4, {"e[ceiling]"});
  ASSERT_TRUE(up.ok()) << up.message;
  ASSERT_EQ(up.events.size(), 1u);
  ASSERT_TRUE(up.sensitivity_losses.empty()) << up.sensitivity_losses[0].reason;
  EXPECT_NEAR(up.dx_final(0, 0), -va * s, 1e-12);
  EXPECT_NEAR(up.dx_final(1, 0), -va, 1e-12);
}

}  // namespace
}  // namespace lcsim
