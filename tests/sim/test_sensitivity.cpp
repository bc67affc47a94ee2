// Forward sensitivities of the exact method (Options::sensitivity,
// docs/sensitivities.md) against closed forms and against central finite
// differences of the exact method itself.
//
// Finite differences: D(h) = (x(T; theta + h) - x(T; theta - h)) / 2h has
// error c h^2 + rounding; with D(h) and D(h/2) the truncation of D(h/2) is
// |D(h) - D(h/2)| / 3 (Richardson), and the exact method's states are good
// to ~1e-13 of their size (tests/sim/test_event_driven.cpp), so the rounding
// of D(h/2) is at most 2e-13 |x| / h. Each entry is asserted to
// 4 |D(h) - D(h/2)| + 64e-13 max(1, |x|) / h: the Richardson estimate with a
// factor 12 of margin, and the rounding bound with a factor 32.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

sim::Trajectory run(const mech::Model& m, const VectorXd& x0, double T,
                    std::vector<std::string> sens = {}, std::string law = "moreau-restitution") {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  opt.impact = std::move(law);
  return sim::simulate(m, x0, opt, "event");
}

mech::Model load(const std::string& name) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
}

// The ball z'' = -g from (z0, v0) with restitution e, after its k-th bounce
// at T (moreau-restitution = Newton's law for one contact): with the impact
// speed w = sqrt(v0^2 + 2 g z0), t1 = (v0 + w) / g and
// t_k = t1 + (2 w / g) sum_{j=1}^{k-1} e^j; after bounce k the ball leaves
// at c = e^k w, so with s = T - t_k: z = c s - g s^2 / 2, v = c - g s.
// Derivatives by the chain rule in (z0, v0, e).
struct BallClosed {
  double z, v;
  Eigen::RowVector3d dz, dv;           // d/d(z0, v0, e)
  std::vector<Eigen::RowVector3d> dt;  // of each impact time
};
BallClosed ball_closed(double z0, double v0, double e, double g, double T) {
  const double w = std::sqrt(v0 * v0 + 2 * g * z0);
  const Eigen::RowVector3d dw(g / w, v0 / w, 0.0);
  const double t1 = (v0 + w) / g;
  const Eigen::RowVector3d dt1 = (Eigen::RowVector3d(0, 1, 0) + dw) / g;
  BallClosed out;
  double tk = t1;
  Eigen::RowVector3d dtk = dt1;
  int k = 0;
  double sum = 0.0, dsum = 0.0;  // sum_{j=1}^{k-1} e^j and its e-derivative
  while (tk < T) {
    ++k;
    out.dt.push_back(dtk);
    const double t_next = t1 + 2 * w / g * (sum + std::pow(e, k));
    if (t_next >= T) break;
    sum += std::pow(e, k);
    dsum += k * std::pow(e, k - 1);
    tk = t_next;
    dtk = dt1 + 2.0 / g * (dw * sum) + Eigen::RowVector3d(0, 0, 2 * w / g * dsum);
  }
  const double c = std::pow(e, k) * w;
  const Eigen::RowVector3d dc =
      std::pow(e, k) * dw + Eigen::RowVector3d(0, 0, k * std::pow(e, k - 1) * w);
  const double s = T - tk;
  out.z = c * s - g * s * s / 2;
  out.v = c - g * s;
  out.dz = dc * s - (c - g * s) * dtk;
  out.dv = dc + g * dtk;
  return out;
}

// Through two and three bounces: rounding-level agreement. The flights are
// polynomials (the Taylor series of the nilpotent phase is exact), the
// impact map is linear, and the event times are Brent roots to a few ulp:
// every quantity is O(1..10) and computed in a few dozen operations, so
// 1e-11 is four orders above the rounding and far below any error of the
// saltation (which would be O(1)).
TEST(Sensitivity, BallThroughTwoAndThreeBounces) {
  const double g = 9.81, e = 0.5, z0 = 1.0, v0 = 0.5;
  const mech::Model m = mech::ball_model(e, g);
  for (const double T : {1.1, 1.25}) {  // t2 = 0.960, t3 = 1.187, t4 = 1.301
    const sim::Trajectory tr = run(m, Eigen::Vector2d(z0, v0), T, {"x0", "e[0]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    const BallClosed c = ball_closed(z0, v0, e, g, T);
    ASSERT_EQ(tr.events.size(), c.dt.size()) << "T = " << T;
    EXPECT_EQ(c.dt.size(), T < 1.187 ? 2u : 3u);
    ASSERT_EQ(tr.sensitivity_columns, (std::vector<std::string>{"x0[0]", "x0[1]", "e[0]"}));
    EXPECT_TRUE(tr.sensitivity_losses.empty());
    EXPECT_NEAR(tr.final_state(0), c.z, 1e-12);
    for (int j = 0; j < 3; ++j) {
      EXPECT_TRUE(tr.dx_final_exists[j]);
      EXPECT_NEAR(tr.dx_final(0, j), c.dz(j), 1e-11) << "dz/d" << tr.sensitivity_columns[j];
      EXPECT_NEAR(tr.dx_final(1, j), c.dv(j), 1e-11) << "dv/d" << tr.sensitivity_columns[j];
      for (size_t k = 0; k < c.dt.size(); ++k)
        EXPECT_NEAR(tr.events[k].dt(j), c.dt[k](j), 1e-11) << "dt" << k + 1 << "/d" << j;
    }
  }
}

// Central differences of x(T) in each column of a run, as the header says.
struct Perturbation {
  std::string column;
  double step;
  std::function<void(mech::Model&, VectorXd&, double)> apply;  // theta += delta
};

void expect_matches_fd(const mech::Model& m, const VectorXd& x0, double T,
                       const std::vector<Perturbation>& ps, bool x0_columns,
                       const std::string& law = "moreau-restitution") {
  std::vector<std::string> names;
  if (x0_columns) names.push_back("x0");
  for (const auto& p : ps) names.push_back(p.column);
  const sim::Trajectory tr = run(m, x0, T, names, law);
  ASSERT_TRUE(tr.ok()) << tr.message;
  if (!tr.sensitivity_losses.empty()) {
    const auto& l = tr.sensitivity_losses.front();
    for (const auto& e : tr.events)
      std::cout << e.t << " " << sim::to_string(e.type) << " " << e.state_before.transpose()
                << " -> " << e.state_after.transpose() << "\n";
    FAIL() << "t = " << l.t << " '" << l.contact << "': " << l.reason;
  }
  std::vector<Perturbation> all;
  if (x0_columns)
    for (int i = 0; i < x0.size(); ++i)
      all.push_back({"x0[" + std::to_string(i) + "]", 1e-4 * std::max(1.0, std::abs(x0(i))),
                     [i](mech::Model&, VectorXd& x, double d) { x(i) += d; }});
  all.insert(all.end(), ps.begin(), ps.end());
  const double xs = std::max(1.0, tr.final_state.cwiseAbs().maxCoeff());
  for (size_t c = 0; c < all.size(); ++c) {
    auto fd = [&](double h) {
      VectorXd out[2];
      for (int s = 0; s < 2; ++s) {
        mech::Model mm = m;
        VectorXd xx = x0;
        all[c].apply(mm, xx, s == 0 ? h : -h);
        const sim::Trajectory t2 = run(mm, xx, T, {}, law);
        EXPECT_TRUE(t2.ok()) << t2.message;
        EXPECT_EQ(t2.events.size(), tr.events.size()) << all[c].column << ": events differ";
        out[s] = t2.final_state;
      }
      return VectorXd((out[0] - out[1]) / (2 * h));
    };
    const double h = all[c].step;
    const VectorXd d1 = fd(h), d2 = fd(h / 2);
    ASSERT_EQ(tr.sensitivity_columns[c], all[c].column);
    EXPECT_TRUE(tr.dx_final_exists[c]);
    for (int i = 0; i < d2.size(); ++i) {
      const double tol = 4 * std::abs(d1(i) - d2(i)) + 64e-13 * xs / h;
      EXPECT_NEAR(tr.dx_final(i, static_cast<Eigen::Index>(c)), d2(i), tol)
          << "dx[" << i << "]/d" << all[c].column;
    }
  }
}

Perturbation sparse_entry(const std::string& name, char which, int i, int j, double step) {
  return {name, step, [which, i, j](mech::Model& m, VectorXd&, double d) {
            auto& mm = *m.mechanical;
            auto& A = which == 'K' ? mm.K : which == 'D' ? mm.D : mm.M;
            A.coeffRef(i, j) += d;
            if (which == 'M' && i != j) A.coeffRef(j, i) += d;
          }};
}

// Thesis §3.7: impact at t = 1, a constrained phase, release, to T = 3.
TEST(Sensitivity, TwoCartsAgainstFiniteDifferences) {
  const mech::Model m = load("two_carts.yaml");
  std::vector<Perturbation> ps = {
      sparse_entry("K[0][1]", 'K', 0, 1, 1e-4),
      sparse_entry("D[1][1]", 'D', 1, 1, 1e-4),
      sparse_entry("M[0][1]", 'M', 0, 1, 1e-4),
      sparse_entry("M[x2][x2]", 'M', 1, 1, 1e-4),
      {"f[1]", 1e-4, [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->f(1) += d; }},
      {"g[stop]", 1e-4, [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->g(0) += d; }},
  };
  expect_matches_fd(m, m.initial, 3.0, ps, true);
}

// The hook model from an open start (the file's start is a simultaneous
// impact, below). Plastic (the model's e = 0) to T = 3: an impact on the
// hook, which then stays closed, and an impact on the stop with the hook
// held (an impact LCP on two closed contacts, impulse on one). With e = 0.5
// to T = 2: hook, stop, stop (before the stop's impacts accumulate at 2.73).
// Pushes f = (-0.2, 0.5) N on the carts: without them the hook's force vanishes
// exactly as the stop is hit (x1 = x2 = 0 relaxes both springs), a
// coincidence (CoincidingReleaseAndImpactHaveNoDerivative).
TEST(Sensitivity, HookAgainstFiniteDifferences) {
  mech::Model m = load("two_carts_hook.yaml");
  m.mechanical->f << -0.2, 0.5;
  VectorXd x0(4);
  x0 << 0.3, 0.1, -1.0, 0.4;
  const sim::Trajectory plastic = run(m, x0, 3.0);
  ASSERT_TRUE(plastic.ok()) << plastic.message;
  ASSERT_GE(plastic.events.size(), 2u);
  EXPECT_GT(plastic.events[0].impulse(1), 0.0);  // the hook
  EXPECT_GT(plastic.events[1].impulse(0), 0.0);  // the stop
  expect_matches_fd(
      m, x0, 3.0,
      {sparse_entry("M[0][0]", 'M', 0, 0, 1e-4),
       sparse_entry("K[1][0]", 'K', 1, 0, 1e-4),
       {"f[x1]", 1e-4, [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->f(0) += d; }},
       {"g[hook]", 1e-4, [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->g(1) += d; }}},
      true);
  m.mechanical->restitution << 0.5, 0.5;
  const sim::Trajectory elastic = run(m, x0, 2.0);
  ASSERT_TRUE(elastic.ok()) << elastic.message;
  ASSERT_EQ(elastic.events.size(), 3u);
  std::vector<Perturbation> ps = {
      {"e[hook]", 1e-4,
       [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->restitution(1) += d; }},
      {"e[stop]", 1e-4,
       [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->restitution(0) += d; }},
      sparse_entry("M[0][1]", 'M', 0, 1, 1e-4),
  };
  expect_matches_fd(m, x0, 2.0, ps, true);
  // Newton's law (its restitution outside the LCP: dv+/de = G E' lambda).
  expect_matches_fd(m, x0, 2.0, ps, false, "newton");
}

// A URDF scene: the double pendulum swinging against its shoulder stop.
TEST(Sensitivity, DoublePendulumSceneAgainstFiniteDifferences) {
  const mech::Model m = load("double_pendulum_scene.yaml");
  const sim::Trajectory plain = run(m, m.initial, 2.0);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_GE(plain.events.size(), 1u);
  std::vector<Perturbation> ps = {
      {"e[0]", 1e-4,
       [](mech::Model& mm, VectorXd&, double d) { mm.mechanical->restitution(0) += d; }},
      sparse_entry("K[1][1]", 'K', 1, 1, 1e-4),
  };
  expect_matches_fd(m, m.initial, 2.0, ps, true);
}

// A general LCS without jumps (D = 1 > 0): an oscillator whose spring
// stiffens for x1 < 0; each crossing of x1 = 0 is a mode change.
TEST(Sensitivity, LcsModeChangesAgainstFiniteDifferences) {
  mech::Model m;
  m.name = "stiffening";
  lcs::Lcs s;
  s.A = MatrixXd{{0, 1}, {-1, 0}};
  s.B = MatrixXd{{0}, {1}};
  s.C = MatrixXd{{1, 0}};
  s.D = MatrixXd{{1}};
  m.lcs = s;
  const VectorXd x0 = Eigen::Vector2d(0.5, 0.2);
  const sim::Trajectory plain = run(m, x0, 6.0);
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_GE(plain.events.size(), 2u);
  expect_matches_fd(m, x0, 6.0, {}, true);
}

bool lost(const sim::Trajectory& tr, const std::string& contact, const std::string& word) {
  for (const auto& l : tr.sensitivity_losses)
    if (l.contact == contact && l.reason.find(word) != std::string::npos) return true;
  return false;
}

// The hook's own start: both gaps zero and closing at t = 0 (a
// simultaneous impact on the boundary of the admissible set): dx/dx0 does
// not exist, and the run names both contacts.
TEST(Sensitivity, SimultaneousImpactStartHasNoDerivative) {
  const mech::Model m = load("two_carts_hook.yaml");
  const sim::Trajectory tr = run(m, m.initial, 1.0, {"x0", "f[0]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  EXPECT_TRUE(lost(tr, "stop", "zero gap at the start"));
  EXPECT_TRUE(lost(tr, "hook", "zero gap at the start"));
  for (int c = 0; c < 4; ++c) {
    EXPECT_FALSE(tr.dx_final_exists[c]);
    EXPECT_EQ(tr.dx_final.col(c).cwiseAbs().maxCoeff(), 0.0);  // absent, not a number
  }
}

// A grazing start: the ball at rest on the ground (gap and rate zero).
TEST(Sensitivity, GrazingStartHasNoDerivative) {
  const sim::Trajectory tr = run(mech::ball_model(0.5), Eigen::Vector2d(0.0, 0.0), 1.0, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  EXPECT_EQ(tr.sensitivity_losses[0].contact, "c1");
  EXPECT_EQ(tr.sensitivity_losses[0].t, 0.0);
  EXPECT_FALSE(tr.dx_final_exists[0]);
}

// A grazing contact during the run: x'' = -x from (1, 0) touches the stop
// x >= -1 at t = pi with a zero rate.
TEST(Sensitivity, GrazingContactHasNoDerivative) {
  const mech::Model m = mech::spring_stop_model(1.0, 1.0);
  const sim::Trajectory tr = run(m, Eigen::Vector2d(1.0, 0.0), 4.0, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_FALSE(tr.sensitivity_losses.empty());
  EXPECT_EQ(tr.sensitivity_losses[0].contact, "c1");
  EXPECT_NEAR(tr.sensitivity_losses[0].t, std::numbers::pi, 1e-6);
  EXPECT_FALSE(tr.dx_final_exists[0]);
}

// Two balls dropped from one height hit the ground together: coinciding
// events, no derivative from then on.
TEST(Sensitivity, CoincidingImpactsHaveNoDerivative) {
  mech::MechanicalModel mm;
  mm.M = mech::SparseMatrix(2, 2);
  mm.M.setIdentity();
  mm.E = mm.M;
  mm.f = VectorXd::Constant(2, -9.81);
  mm.restitution = VectorXd::Constant(2, 0.5);
  mm.constraints = {"left", "right"};
  const mech::Model m = mech::model_of(mm, "two_balls");
  const sim::Trajectory tr = run(m, Eigen::Vector4d(1, 1, 0, 0), 0.6, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_FALSE(tr.sensitivity_losses.empty());
  EXPECT_NE(tr.sensitivity_losses[0].reason.find("coinciding"), std::string::npos);
  EXPECT_NEAR(tr.sensitivity_losses[0].t, std::sqrt(2 / 9.81), 1e-12);
  EXPECT_FALSE(tr.dx_final_exists[0]);
  // Samples before the impact still carry the derivative.
  EXPECT_TRUE(tr.samples.front().dx_exists[0]);
}

// The hook model without a push from the same start: the hook, held since
// its impact, loses its force exactly when the stop is hit.
TEST(Sensitivity, CoincidingReleaseAndImpactHaveNoDerivative) {
  const mech::Model m = load("two_carts_hook.yaml");
  VectorXd x0(4);
  x0 << 0.3, 0.1, -1.0, 0.4;
  const sim::Trajectory tr = run(m, x0, 3.0, {"x0"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.events.size(), 2u);
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  EXPECT_EQ(tr.sensitivity_losses[0].contact, "hook");
  EXPECT_EQ(tr.sensitivity_losses[0].t, tr.events[1].t);
  EXPECT_NE(tr.sensitivity_losses[0].reason.find("coinciding"), std::string::npos);
  EXPECT_TRUE(tr.events[0].dt_exists[0]);
  EXPECT_FALSE(tr.events[1].dt_exists[0]);
}

// What the run refuses (input error, one line).
TEST(Sensitivity, RefusesWhatItDoesNotCover) {
  const mech::Model m = load("two_carts.yaml");
  sim::Options opt;
  opt.t_end = 1.0;
  opt.sensitivity = {"e[stop]"};  // backward Euler ignores restitution (x0 it computes)
  EXPECT_EQ(sim::simulate(m, m.initial, opt, "euler").status, Status::kInvalidInput);
  opt.sensitivity = {"g[stop]"};  // Moreau-Jean's map depends on g only through its active set
  EXPECT_EQ(sim::simulate(m, m.initial, opt, "moreau-jean").status, Status::kInvalidInput);
  for (const std::string bad : {"f[9]", "K[0]", "e[nope]", "z[0]", "x0,x0"}) {
    opt.sensitivity = {bad};
    if (bad == "x0,x0") opt.sensitivity = {"x0", "x0"};
    const sim::Trajectory tr = sim::simulate(m, m.initial, opt, "event");
    EXPECT_EQ(tr.status, Status::kInvalidInput) << bad;
    EXPECT_EQ(tr.message.find('\n'), std::string::npos);
  }
  opt.sensitivity = {"x0"};
  opt.impact = "sequential";
  EXPECT_EQ(sim::simulate(m, m.initial, opt, "event").status, Status::kInvalidInput);
}

// Asking for sensitivities changes nothing else in the run.
TEST(Sensitivity, PlainRunUnchanged) {
  const mech::Model m = load("two_carts.yaml");
  sim::Options opt;
  opt.t_end = 3.0;
  opt.dt_out = 0.1;
  const sim::Trajectory a = sim::simulate(m, m.initial, opt, "event");
  opt.sensitivity = {"x0", "f[0]"};
  const sim::Trajectory b = sim::simulate(m, m.initial, opt, "event");
  ASSERT_EQ(a.samples.size(), b.samples.size());
  for (size_t i = 0; i < a.samples.size(); ++i) {
    EXPECT_EQ(a.samples[i].t, b.samples[i].t);
    EXPECT_EQ(a.samples[i].x, b.samples[i].x);
    EXPECT_EQ(b.samples[i].dx.cols(), 5);
  }
  EXPECT_EQ(a.final_state, b.final_state);
}

}  // namespace
}  // namespace lcsim
