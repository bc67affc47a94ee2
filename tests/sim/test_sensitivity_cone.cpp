// Forward sensitivities through 3-D friction on a polyhedral cone in the
// exact method (docs/sensitivities.md, "3-D friction";
// src/sim/exact/sensitivity_cone.cpp).
//
// The closed form: a point mass on the floor sliding from (vx0, vy0) with a
// cone of 2d edges (mech::cone_slide). In the frame of the edge k nearest
// the velocity (p0 along it, r across, a = mu g, h = pi/(2d)) the turn onto
// the face's bisector comes at t1 = (p0 - |r| / tan h) / a and, summing the
// edge phase and the face phase of mech::cone_slide's derivation, the stop
// at t* = (p0 + |r| tan h) / a at P* = (p0^2 + r^2) / (2 a) along the edge
// and Q* = (r p0 - r |r| cot(2h)) / a across it (checked here against
// cone_slide itself). Differentiated by hand: dt*/dp0 = 1/a, dt*/dr =
// sign(r) tan h / a, dt1/dp0 = 1/a, dt1/dr = -sign(r) / (a tan h),
// dP*/dp0 = p0/a, dP*/dr = r/a, dQ*/dp0 = r/a, dQ*/dr = (p0 - 2 |r|
// cot(2h)) / a, with dp0/dvx0 = cos(k pi/d), dp0/dvy0 = sin(k pi/d), dr/dvx0
// = -sin(k pi/d), dr/dvy0 = cos(k pi/d); every time and distance is
// proportional to 1/mu: d/dmu = -value/mu.
//
// Central differences of the exact method (tests/support/sensitivity_fd.hpp:
// h = 1e-4 max(1, |theta|), tolerance 4 |D(h) - D(h/2)| + 64e-13 max(1,
// |x|) / h, every perturbed run with the run's events) at x(T) and every
// event time on the point at several headings, a point on an incline
// pushed sideways, and the box of robots/box_slide_scene.yaml sliding on its
// four corners to rest.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <lcsim/io/model_file.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <string>
#include <vector>

#include "support/sensitivity_fd.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81, kMu = 0.3, kPi = std::numbers::pi;

// A point mass of 2 kg (x, y, z) on the floor z >= 0 under gravity and a
// push (px, py); friction along x (t) and y (t2), mu = 0.3, d edge pairs;
// planar: the tangent x only.
mech::Model point(int d, double px = 0.0, double py = 0.0, bool planar = false) {
  mech::MechanicalModel m;
  m.M = (2.0 * Eigen::MatrixXd::Identity(3, 3)).sparseView();
  m.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  m.f = Eigen::Vector3d(px, py, -2.0 * kG);
  m.constraints = {"floor"};
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), kMu);
  if (!planar) {
    c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
    c.edges = d;
  }
  m.friction.push_back(c);
  return mech::model_of(m, "point3d");
}

VectorXd sliding(double s0, double psi) {
  return (VectorXd(6) << 0, 0, 0, s0 * std::cos(psi), s0 * std::sin(psi), 0).finished();
}

sim::Trajectory run(const mech::Model& m, const VectorXd& x0, double T,
                    std::vector<std::string> sens) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, x0, opt, "event");
}

// The closed form's stop and its derivatives in (vx0, vy0) and mu.
struct Stop {
  double t1, t, x, y;
  double dt1[2], dt[2], dx[2], dy[2];  // d/dvx0, d/dvy0
};

Stop closed_form(double s0, double psi, int d) {
  const double delta = kPi / d, h = delta / 2, a = kMu * kG;
  const double k = std::round(psi / delta), ek = k * delta, alpha = psi - ek;
  const double p0 = s0 * std::cos(alpha), r = s0 * std::sin(alpha), sg = r > 0 ? 1.0 : -1.0;
  const double cot2h = std::cos(2 * h) / std::sin(2 * h);
  const double P = (p0 * p0 + r * r) / (2 * a), Q = (r * p0 - r * std::abs(r) * cot2h) / a;
  Stop s{};
  s.t1 = (p0 - std::abs(r) / std::tan(h)) / a;
  s.t = (p0 + std::abs(r) * std::tan(h)) / a;
  s.x = P * std::cos(ek) - Q * std::sin(ek);
  s.y = P * std::sin(ek) + Q * std::cos(ek);
  const double dp0[2] = {std::cos(ek), std::sin(ek)}, dr[2] = {-std::sin(ek), std::cos(ek)};
  for (int c = 0; c < 2; ++c) {
    const double dP = (p0 * dp0[c] + r * dr[c]) / a;
    const double dQ = (r * dp0[c] + (p0 - 2 * std::abs(r) * cot2h) * dr[c]) / a;
    s.dt1[c] = (dp0[c] - sg * dr[c] / std::tan(h)) / a;
    s.dt[c] = (dp0[c] + sg * dr[c] * std::tan(h)) / a;
    s.dx[c] = dP * std::cos(ek) - dQ * std::sin(ek);
    s.dy[c] = dP * std::sin(ek) + dQ * std::cos(ek);
  }
  return s;
}

// The closed form above is mech::cone_slide's (which the exact method
// matches to 1e-12, tests/sim/test_event_friction3d.cpp), to rounding.
TEST(SensitivityCone, ClosedFormIsConeSlides) {
  for (int d : {2, 3, 4, 8})
    for (double a : {0.3, -0.7, 0.5, 1.25, 0.999})
      for (double s0 : {0.5, 1.7}) {
        const double psi = a * kPi / d;
        const mech::ConeSlide cs = mech::cone_slide(s0, psi, kMu, kG, d);
        const Stop s = closed_form(s0, psi, d);
        EXPECT_NEAR(s.t, cs.t_stop, 1e-14) << d << " " << a;
        EXPECT_NEAR(s.t1, cs.t_turn, 1e-14) << d << " " << a;
        EXPECT_NEAR(s.x, cs.x, 1e-14) << d << " " << a;
        EXPECT_NEAR(s.y, cs.y, 1e-14) << d << " " << a;
      }
}

// Tolerance of the closed-form checks: each phase is exact to a few eps and
// each event's dt divides the monitor's w S by its rate (>= mu g sin(pi/(2d))
// times the velocity's distance to the bisector here, ~0.1 m/s^2): ~1e-15
// per event, amplified ~100 at most; 1e-12 leaves a margin of ten while a
// wrong row, column or saltation shows at 1e-2 or more.
constexpr double kTol = 1e-12;

struct Case {
  int d;
  double a;  // psi in units of pi/d
};

// Sliding to rest at headings between an edge and a bisector, on either side
// of the edge, and from a bisector (a face from the start: mode selection
// sets the velocity on it, and S is projected there, sensitivity_cone.cpp).
TEST(SensitivityCone, SlideToRestAgainstClosedForm) {
  const double s0 = 1.0;
  int checked = 0;
  for (const Case& c : {Case{2, 0.3}, Case{2, -0.7}, Case{2, 0.5}, Case{4, 0.3}, Case{4, -0.2},
                        Case{4, 0.5}, Case{4, 1.5}, Case{8, 0.3}, Case{3, -0.45}}) {
    const double psi = c.a * kPi / c.d;
    const Stop cf = closed_form(s0, psi, c.d);
    const std::string at =
        "d = " + std::to_string(c.d) + ", psi = " + std::to_string(c.a) + " pi/d";
    const sim::Trajectory tr = run(point(c.d), sliding(s0, psi), cf.t + 0.2, {"x0", "mu[floor]"});
    ASSERT_TRUE(tr.ok()) << at << ": " << tr.message;
    const bool turns = cf.t1 > 1e-9;
    ASSERT_EQ(tr.events.size(), turns ? 2u : 1u) << at;
    for (int v = 0; v < 2; ++v) {  // x0[3] = vx0, x0[4] = vy0
      ASSERT_TRUE(tr.dx_final_exists[static_cast<size_t>(3 + v)]) << at;
      EXPECT_NEAR(tr.dx_final(0, 3 + v), cf.dx[v], kTol) << at << " dx*/dv" << v;
      EXPECT_NEAR(tr.dx_final(1, 3 + v), cf.dy[v], kTol) << at << " dy*/dv" << v;
      EXPECT_NEAR(tr.dx_final(3, 3 + v), 0.0, kTol) << at;  // at rest
      EXPECT_NEAR(tr.dx_final(4, 3 + v), 0.0, kTol) << at;
      EXPECT_NEAR(tr.events.back().dt(3 + v), cf.dt[v], kTol) << at << " dt*/dv" << v;
      if (turns) {
        EXPECT_NEAR(tr.events.front().dt(3 + v), cf.dt1[v], kTol) << at;
      }
      checked += turns ? 5 : 4;
    }
    for (int q = 0; q < 2; ++q) {  // a shift of the start: the same shift at rest
      EXPECT_NEAR(tr.dx_final(q, q), 1.0, kTol) << at;
      EXPECT_NEAR(tr.dx_final(1 - q, q), 0.0, kTol) << at;
    }
    // mu[floor] (column 6): every time and distance is proportional to 1/mu.
    EXPECT_NEAR(tr.dx_final(0, 6), -cf.x / kMu, kTol) << at;
    EXPECT_NEAR(tr.dx_final(1, 6), -cf.y / kMu, kTol) << at;
    EXPECT_NEAR(tr.events.back().dt(6), -cf.t / kMu, kTol) << at;
    if (turns) {
      EXPECT_NEAR(tr.events.front().dt(6), -cf.t1 / kMu, kTol) << at;
    }
    checked += turns ? 4 : 3;
  }
  EXPECT_EQ(checked, 117);
}

// d = 1 on a 3-D contact is the planar method's (friction along t only): its
// derivatives are the planar model's, and the block sliding along t stops at
// t* = s0/a after s0^2/(2a) (dt*/dvx0 = 1/a, dx*/dvx0 = s0/a, dx*/dmu =
// -x*/mu), while y moves freely (dy(T)/dvy0 = T).
TEST(SensitivityCone, OneEdgePairIsPlanar) {
  const double s0 = 1.0, a = kMu * kG, T = s0 / a + 0.2;
  const std::vector<std::string> cols = {"x0", "mu[floor]", "f[0]"};
  const sim::Trajectory tr = run(point(1), sliding(s0, 0.0), T, cols);
  const sim::Trajectory pl = run(point(1, 0, 0, true), sliding(s0, 0.0), T, cols);
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_TRUE(pl.ok()) << pl.message;
  ASSERT_EQ(tr.events.size(), 1u);
  EXPECT_EQ(tr.dx_final, pl.dx_final);
  EXPECT_EQ(tr.events[0].dt, pl.events[0].dt);
  EXPECT_NEAR(tr.events[0].dt(3), 1 / a, kTol);
  EXPECT_NEAR(tr.dx_final(0, 3), s0 / a, kTol);
  EXPECT_NEAR(tr.dx_final(1, 4), T, kTol);
  EXPECT_NEAR(tr.dx_final(0, 6), -s0 * s0 / (2 * a) / kMu, kTol);
}

// Every x0 entry and parameter of `cols` against central differences at
// x(T) and every event time; the number of entries compared.
int expect_fd(const mech::Model& m, const VectorXd& x0, double T,
              const std::vector<test_support::FdColumn>& cols) {
  std::vector<std::string> names;
  for (const auto& c : cols) names.push_back(c.column);
  bool x0s = false;
  for (const auto& c : cols) x0s = x0s || c.column.rfind("x0[", 0) == 0;
  std::vector<std::string> asked;
  if (x0s) asked.push_back("x0");
  for (const auto& c : cols)
    if (c.column.rfind("x0[", 0) != 0) asked.push_back(c.column);
  const sim::Trajectory tr = run(m, x0, T, asked);
  EXPECT_TRUE(tr.ok()) << tr.message;
  if (!tr.ok()) return 0;
  return test_support::expect_columns_match_fd(m, x0, T, tr, cols);
}

std::vector<test_support::FdColumn> x0_columns(const VectorXd& x0) {
  std::vector<test_support::FdColumn> cols;
  for (Eigen::Index i = 0; i < x0.size(); ++i)
    cols.push_back({"x0[" + std::to_string(i) + "]", x0(i),
                    [i](mech::Model&, VectorXd& x, double d) { x(i) += d; }});
  return cols;
}

test_support::FdColumn param(const std::string& name, double theta,
                             std::function<void(mech::MechanicalModel&, double)> f) {
  return {name, theta, [f](mech::Model& m, VectorXd&, double d) { f(*m.mechanical, d); }};
}

// The point with springs k = 1 N/m on x and y (so K and D have entries to
// move), sliding to rest at headings between an edge and a bisector (a
// turn, then the stop; the spring's pull stays inside the polygon: it
// sticks): x0, f, K, D, mu. z, vz (which move the floor's gap) and g[floor]
// are absent (a zero gap at the start).
TEST(SensitivityCone, PointSlidingToRestAgainstCentralDifferences) {
  int compared = 0;
  for (const Case& c : {Case{2, 0.3}, Case{4, -0.35}, Case{8, 0.7}}) {
    mech::Model m = point(c.d, 0.4, -0.3);
    m.mechanical->K = Eigen::Vector3d(1, 1, 0).asDiagonal().toDenseMatrix().sparseView();
    m.mechanical->D = Eigen::SparseMatrix<double>(3, 3);
    m = mech::model_of(*m.mechanical, "point3d");
    const VectorXd x0 = sliding(1.0, c.a * kPi / c.d);
    std::vector<test_support::FdColumn> cols = x0_columns(x0);
    cols.push_back(param("f[0]", 0.4, [](mech::MechanicalModel& mm, double d) { mm.f(0) += d; }));
    cols.push_back(param("f[1]", 0.3, [](mech::MechanicalModel& mm, double d) { mm.f(1) += d; }));
    cols.push_back(param("f[2]", kG, [](mech::MechanicalModel& mm, double d) { mm.f(2) += d; }));
    cols.push_back(param("K[0][0]", 1.0,
                         [](mech::MechanicalModel& mm, double d) { mm.K.coeffRef(0, 0) += d; }));
    cols.push_back(param("K[1][0]", 0.0,
                         [](mech::MechanicalModel& mm, double d) { mm.K.coeffRef(1, 0) += d; }));
    cols.push_back(param("D[1][1]", 0.0,
                         [](mech::MechanicalModel& mm, double d) { mm.D.coeffRef(1, 1) += d; }));
    cols.push_back(param("mu[floor]", kMu,
                         [](mech::MechanicalModel& mm, double d) { mm.friction[0].mu += d; }));
    cols.push_back(
        param("g[floor]", 0.0, [](mech::MechanicalModel& mm, double d) { mm.g(0) += d; }));
    compared += expect_fd(m, x0, 0.5, cols);
  }
  // Per case: 14 columns less the absent z, vz, g[floor] = 11, each on 6
  // states and 2 events.
  EXPECT_EQ(compared, 3 * 11 * 8);
}

// A point on an incline steeper than its friction angle (the floor's
// gravity tilted by beta = 0.5 rad, tan(beta) = 0.55 > mu = 0.3), pushed
// sideways at 1 m/s along the first tangent: it never stops, its velocity
// turning down the slope through the cone's edges and faces (edge -> face ->
// edge events), d = 4 and 3. x0, f, mu against central differences.
TEST(SensitivityCone, InclinePushedSidewaysAgainstCentralDifferences) {
  const double beta = 0.5;
  int compared = 0;
  for (int d : {3, 4}) {
    mech::Model m = point(d, 0.0, -2.0 * kG * std::sin(beta));
    m.mechanical->f(2) = -2.0 * kG * std::cos(beta);
    m = mech::model_of(*m.mechanical, "incline3d");
    const VectorXd x0 = sliding(1.0, 0.0);
    std::vector<test_support::FdColumn> cols = x0_columns(x0);
    cols.push_back(param("f[0]", 0.0, [](mech::MechanicalModel& mm, double dd) { mm.f(0) += dd; }));
    cols.push_back(param("f[1]", 2 * kG * std::sin(beta),
                         [](mech::MechanicalModel& mm, double dd) { mm.f(1) += dd; }));
    cols.push_back(param("mu[floor]", kMu,
                         [](mech::MechanicalModel& mm, double dd) { mm.friction[0].mu += dd; }));
    const sim::Trajectory tr = run(m, x0, 1.0, {});
    ASSERT_TRUE(tr.ok()) << tr.message;
    EXPECT_GE(tr.events.size(), 2u) << "d = " << d;  // turns through edges and faces
    compared += expect_fd(m, x0, 1.0, cols);
  }
  // Per d: x0's 6 entries less z, vz (a zero gap at the start) and f[0],
  // f[1], mu: 7 columns on 6 states and 2 events (the edge -> edge
  // crossings of a bisector: the face's force would leave the face).
  EXPECT_EQ(compared, 2 * 7 * 8);
}

// The box of robots/box_slide_scene.yaml (four corners on the floor, mu =
// 0.3, d = 4) put on the floor sliding at (1, 0.4) m/s: it turns onto a
// face and stops on its four corners (their normals dependent: the phase's
// forces are the resultant's, so its parameter columns are not computed;
// x0 is). Every x0 entry against central differences; those moving the
// corners' gaps (z, roll, pitch and their rates) are absent.
TEST(SensitivityCone, BoxSlidingToRestAgainstCentralDifferences) {
  mech::Model m = scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/box_slide_scene.yaml");
  const mech::MechanicalModel& mm = *m.mechanical;
  const Eigen::Index N = mm.dofs();
  VectorXd x0 = m.initial;
  for (Eigen::Index i = 0; i < N; ++i) {
    const std::string& name = mm.coordinates[static_cast<size_t>(i)];
    if (name == "box.z") x0(i) = 0.05;  // on the floor (the base's pose: 0.05 m up)
  }
  const sim::Trajectory plain = run(m, x0, 0.6, {});
  ASSERT_TRUE(plain.ok()) << plain.message;
  ASSERT_EQ(plain.events.size(), 2u);  // the turn onto a face, the stop
  const int compared = expect_fd(m, x0, 0.6, x0_columns(x0));
  // 12 x0 entries less the 6 that move the gaps, on 12 states and 2 events;
  // the yaw rate parts the corners' turns (they turn together only by
  // symmetry): reported absent at the turn, the rest kept.
  EXPECT_EQ(compared, 5 * 14);
}

// At rest under a push inside the polygon, the point sticks. A perturbed
// start slides and stops again within a time proportional to the
// perturbation, so its velocity's derivative is zero and its position's
// moves by O(perturbation^2): dx(T)/dv0 = 0, dv(T)/dv0 = 0, dx(T)/dx0 = 1,
// and a push's or mu's derivative is zero while it sticks (the velocity
// rows of S projected at t = 0, sensitivity_cone.cpp; d = 1 and the planar
// model too). To 1e-12 (the phase is exact to rounding).
TEST(SensitivityCone, StickAtRestStart) {
  for (int d : {2, 4}) {
    const sim::Trajectory tr =
        run(point(d, 1.0, -2.0), VectorXd::Zero(6), 0.5, {"x0", "f[0]", "mu[floor]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    ASSERT_TRUE(tr.events.empty());
    for (int c : {0, 1, 3, 4, 6, 7}) {
      ASSERT_TRUE(tr.dx_final_exists[static_cast<size_t>(c)]) << c;
      for (int r = 0; r < 6; ++r)
        EXPECT_NEAR(tr.dx_final(r, c), (c == r && c < 2) ? 1.0 : 0.0, 1e-12) << r << ", " << c;
    }
  }
  // Planar (one tangent, x; the planar model and a 3-D contact with d = 1)
  // pushed along x: the same along x, while y (no friction) moves freely:
  // dy(T)/dvy0 = T, dvy/dvy0 = 1.
  for (const bool planar : {true, false}) {
    const sim::Trajectory tr =
        run(point(1, 1.0, 0.0, planar), VectorXd::Zero(6), 0.5, {"x0", "f[0]", "mu[floor]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    ASSERT_TRUE(tr.events.empty());
    for (int c : {0, 3, 6, 7})
      for (int r : {0, 1, 3, 4})
        EXPECT_NEAR(tr.dx_final(r, c), c == r && c == 0 ? 1.0 : 0.0, 1e-12) << r << ", " << c;
    EXPECT_NEAR(tr.dx_final(1, 4), 0.5, 1e-12);
    EXPECT_NEAR(tr.dx_final(4, 4), 1.0, 1e-12);
    EXPECT_NEAR(tr.dx_final(0, 4), 0.0, 1e-12);
  }
}

// Where the derivative does not exist the run says so, naming the contact:
// a slide started exactly along an edge (its stop coincides with the turn
// onto a face), and a push exactly on the polygon's face (the stick force
// at the cone's boundary from the start).
TEST(SensitivityCone, LossesNameTheContact) {
  const double s0 = 1.0;
  const double a = kMu * kG;
  const sim::Trajectory edge = run(point(4), sliding(s0, 0.0), 0.5, {"x0", "mu[floor]"});
  ASSERT_TRUE(edge.ok()) << edge.message;
  ASSERT_EQ(edge.sensitivity_losses.size(), 2u);  // the zero gap's, then the stop's
  const sim::SensitivityLoss& stop = edge.sensitivity_losses.back();
  EXPECT_EQ(stop.contact, "floor");
  EXPECT_NE(stop.reason.find("stops on an edge"), std::string::npos) << stop.reason;
  EXPECT_EQ(stop.columns, std::vector<int>{4});  // vy0 parts the turn from the stop
  EXPECT_FALSE(edge.dx_final_exists[4]);
  EXPECT_EQ(edge.dx_final.col(4).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_FALSE(edge.events.back().dt_exists[4]);
  // Along the edge the slide stays on it: t* = s0/a, x* = s0^2/(2a).
  ASSERT_TRUE(edge.dx_final_exists[3]);
  EXPECT_NEAR(edge.events.back().dt(3), 1 / a, kTol);
  EXPECT_NEAR(edge.dx_final(0, 3), s0 / a, kTol);
  EXPECT_NEAR(edge.dx_final(1, 3), 0.0, kTol);
  EXPECT_NEAR(edge.dx_final(0, 6), -s0 * s0 / (2 * a) / kMu, kTol);
  const int d = 4;
  const double th = 0.5 * kPi / d, push = kMu * 2.0 * kG * std::cos(kPi / (2 * d));
  const sim::Trajectory face = run(point(d, push * std::cos(th), push * std::sin(th)),
                                   VectorXd::Zero(6), 0.3, {"x0", "f[0]"});
  ASSERT_TRUE(face.ok()) << face.message;
  ASSERT_FALSE(face.sensitivity_losses.empty());
  EXPECT_EQ(face.sensitivity_losses.front().contact, "floor");
  EXPECT_EQ(face.sensitivity_losses.back().t, 0.0);
  EXPECT_NE(face.sensitivity_losses.back().reason.find("polygon's boundary"), std::string::npos)
      << face.sensitivity_losses.back().reason;
  for (size_t c = 0; c < face.dx_final_exists.size(); ++c) EXPECT_FALSE(face.dx_final_exists[c]);
}

// Landings with 3-D friction (Stewart–Trinkle at the impact's outcome,
// sensitivity_cone_impact.cpp): the point dropped from 0.2 m (w = 1.98 m/s,
// the impulse's polygon mu w = 0.59 m/s) sliding at 1 m/s (it slides on
// after the impact, on an edge's region or a face) or at 0.3 m/s (it
// sticks at the impact), d = 2, 4; x0, f, mu against central differences
// at x(T) and every event (the landing, the turn, the stop).
TEST(SensitivityCone, LandingAgainstCentralDifferences) {
  int compared = 0;
  for (int d : {2, 4})
    for (const double s0 : {3.0, 1.0, 0.3}) {
      VectorXd x0 = sliding(s0, 0.3 * kPi / d);
      x0(2) = 0.2;
      const mech::Model m = point(d, 0.3, -0.2);
      std::vector<test_support::FdColumn> cols = x0_columns(x0);
      cols.push_back(
          param("f[0]", 0.3, [](mech::MechanicalModel& mm, double dd) { mm.f(0) += dd; }));
      cols.push_back(param("mu[floor]", kMu,
                           [](mech::MechanicalModel& mm, double dd) { mm.friction[0].mu += dd; }));
      const sim::Trajectory tr = run(m, x0, 0.8, {"x0", "f[0]", "mu[floor]"});
      ASSERT_TRUE(tr.ok()) << tr.message;
      EXPECT_TRUE(tr.sensitivity_losses.empty()) << tr.sensitivity_losses.front().reason;
      EXPECT_EQ(tr.events.front().type, sim::EventType::kImpact);
      compared += expect_fd(m, x0, 0.8, cols);
    }
  // 8 columns on 6 states and the events: the landing (at 3 m/s the slide
  // goes on in an edge's region, at 1 m/s along a face, at 0.3 m/s it
  // sticks), then the turn or the stop: 10 events over the six runs.
  EXPECT_EQ(compared, 8 * (6 * 6 + 10));
}

// A landing whose tangential velocity is exactly what the polygon's face
// can stop (s0 = mu cos(pi/(2d)) w along the face's normal): stick and slip
// meet at the impact; every column is lost there, naming the floor.
TEST(SensitivityCone, LandingOnThePolygonsBoundaryIsALoss) {
  const int d = 4;
  const double w = std::sqrt(2 * kG * 0.2), s0 = kMu * std::cos(kPi / (2 * d)) * w;
  VectorXd x0 = sliding(s0, 0.5 * kPi / d);
  x0(2) = 0.2;
  const sim::Trajectory tr = run(point(d), x0, 0.4, {"x0", "mu[floor]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  const sim::SensitivityLoss& l = tr.sensitivity_losses.front();
  EXPECT_EQ(l.contact, "floor");
  EXPECT_EQ(l.t, tr.events.front().t);
  EXPECT_NE(l.reason.find("boundary of its outcome"), std::string::npos) << l.reason;
  for (size_t c = 0; c < tr.dx_final_exists.size(); ++c) EXPECT_FALSE(tr.dx_final_exists[c]);
}

// The box of robots/box_slide_scene.yaml from its own start lands on its
// four corners together: the first loss is the coincidence, naming a corner.
TEST(SensitivityCone, BoxLandingOnFourCornersIsACoincidence) {
  const mech::Model box =
      scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/box_slide_scene.yaml");
  const sim::Trajectory bt = run(box, box.initial, 0.25, {"x0"});
  ASSERT_TRUE(bt.ok()) << bt.message;
  ASSERT_FALSE(bt.sensitivity_losses.empty());
  EXPECT_EQ(bt.sensitivity_losses.front().contact.rfind("box", 0), 0u);
  for (size_t c = 0; c < bt.dx_final_exists.size(); ++c) EXPECT_FALSE(bt.dx_final_exists[c]);
}

// The point (2 kg) on the floor pulled by springs k = 20 N/m on x and y from
// a free 1 kg mass (x2, y2), d edge pairs (SpringPulledStickSlip...).
mech::Model pulled(int d) {
  mech::MechanicalModel m;
  m.M = Eigen::VectorXd((Eigen::VectorXd(5) << 2, 2, 2, 1, 1).finished())
            .asDiagonal()
            .toDenseMatrix()
            .sparseView();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(5, 5);
  for (const auto& [a, b] : {std::pair{0, 3}, std::pair{1, 4}}) {
    K(a, a) = K(b, b) = 20.0;
    K(a, b) = K(b, a) = -20.0;
  }
  m.K = K.sparseView();
  m.D = Eigen::SparseMatrix<double>(5, 5);
  m.E = (Eigen::RowVectorXd(5) << 0, 0, 1, 0, 0).finished().sparseView();
  m.f = (VectorXd(5) << 0, 0, -2.0 * kG, 0, 0).finished();
  m.constraints = {"floor"};
  mech::FrictionalContact c(0, (VectorXd(5) << 1, 0, 0, 0, 0).finished(), kMu);
  c.tangent2 = (VectorXd(5) << 0, 1, 0, 0, 0).finished().sparseView();
  c.edges = d;
  m.friction.push_back(c);
  return mech::model_of(m, "pulled3d");
}

// Stick -> slip at the polygon's boundary and back: the point (2 kg, at
// rest on the floor) pulled by springs k = 20 N/m on x and y from a free
// 1 kg mass (x2, y2) launched at (3, 1) m/s: the spring force grows past mu
// m g = 5.9 N, the stick force leaves the polygon (a
// slip from rest, its sliding monitor starting at order 2), the slide turns
// through edges and faces and sticks again as the spring swings back. x0,
// f, K, mu against central differences at x(T) and every event.
TEST(SensitivityCone, SpringPulledStickSlipAgainstCentralDifferences) {
  int compared = 0;
  for (int d : {2, 4}) {
    const mech::Model model = pulled(d);
    std::vector<test_support::FdColumn> params;
    params.push_back(
        param("f[3]", 0.0, [](mech::MechanicalModel& mm, double dd) { mm.f(3) += dd; }));
    params.push_back(param(
        "K[0][3]", -20.0, [](mech::MechanicalModel& mm, double dd) { mm.K.coeffRef(0, 3) += dd; }));
    params.push_back(param("mu[floor]", kMu,
                           [](mech::MechanicalModel& mm, double dd) { mm.friction[0].mu += dd; }));
    // From rest (stuck; the first event is stick -> slip): the parameters
    // (a perturbed velocity would slide and stick again: StickAtRestStart).
    const VectorXd rest = (VectorXd(10) << 0, 0, 0, 0, 0, 0, 0, 0, 3, 1).finished();
    const sim::Trajectory tr = run(model, rest, 1.0, {});
    ASSERT_TRUE(tr.ok()) << tr.message;
    EXPECT_EQ(tr.events.size(), d == 2 ? 5u : 2u);
    compared += expect_fd(model, rest, 1.0, params);
    // Sliding at the start (0.5, -0.3) m/s: x0 and the parameters.
    const VectorXd x0 = (VectorXd(10) << 0, 0, 0, 0, 0, 0.5, -0.3, 0, 3, 1).finished();
    std::vector<test_support::FdColumn> cols = x0_columns(x0);
    cols.insert(cols.end(), params.begin(), params.end());
    const sim::Trajectory ts = run(model, x0, 1.0, {});
    ASSERT_TRUE(ts.ok()) << ts.message;
    EXPECT_EQ(ts.events.size(), d == 2 ? 2u : 4u);
    compared += expect_fd(model, x0, 1.0, cols);
  }
  // From rest: 3 columns on 10 states and 5 (d = 2) or 2 events; sliding:
  // x0's 10 entries less z, vz (a zero gap at the start) and the 3
  // parameters, on 10 states and 2 (d = 2) or 4 events.
  EXPECT_EQ(compared, 3 * 15 + 3 * 12 + 11 * 12 + 11 * 14);
}

// M[i][j] through 3-D phases (sensitivity_cone.cpp: dG = -G dM G moves the
// free acceleration, the forces and the loop). Gravity is the fixed force
// f_z = -2 g (not m g): the normal force stays 2 g, the deceleration is a =
// 2 mu g / m, and every time and distance of the closed form is
// proportional to 1/a, so to m: in the direction dM = I (the sum of the
// columns M[0][0], M[1][1], M[2][2]) d(value)/dm = value/m, m = 2. The
// velocity at rest and z stay 0. kTol as above (the same events).
TEST(SensitivityCone, MassOfSlideToRestAgainstClosedForm) {
  const double s0 = 1.0, mass = 2.0;
  int checked = 0;
  for (const Case& c : {Case{2, 0.3}, Case{2, -0.7}, Case{4, 0.3}, Case{4, -0.2}}) {
    const double psi = c.a * kPi / c.d;
    const Stop cf = closed_form(s0, psi, c.d);
    const std::string at =
        "d = " + std::to_string(c.d) + ", psi = " + std::to_string(c.a) + " pi/d";
    const sim::Trajectory tr =
        run(point(c.d), sliding(s0, psi), cf.t + 0.2, {"M[0][0]", "M[1][1]", "M[2][2]"});
    ASSERT_TRUE(tr.ok()) << at << ": " << tr.message;
    // (The zero gap's loss at the start names x0's z, vz only.)
    for (size_t c = 0; c < 3; ++c) ASSERT_TRUE(tr.dx_final_exists[c]) << at;
    ASSERT_EQ(tr.events.size(), 2u) << at;
    const VectorXd dx = tr.dx_final.rowwise().sum();
    Eigen::VectorXd dt(2);
    for (size_t k = 0; k < 2; ++k) dt(static_cast<Eigen::Index>(k)) = tr.events[k].dt.sum();
    EXPECT_NEAR(dx(0), cf.x / mass, kTol) << at << " dx*/dm";
    EXPECT_NEAR(dx(1), cf.y / mass, kTol) << at << " dy*/dm";
    for (int i : {2, 3, 4, 5}) EXPECT_NEAR(dx(i), 0.0, kTol) << at << " state " << i;
    EXPECT_NEAR(dt(0), cf.t1 / mass, kTol) << at << " dt1/dm";
    EXPECT_NEAR(dt(1), cf.t / mass, kTol) << at << " dt*/dm";
    checked += 8;
  }
  EXPECT_EQ(checked, 32);
}

// A point (2 kg) dropped from z0 = 0.5 m (w = sqrt(2 g z0)) sliding at s0 =
// 3 m/s along the cone's edge 1 (psi = pi/d: the slide's impulse is -mu P_N
// along it, its velocity inside edge 1's region), restitution e = 0.5: it
// lands at t1 = w/g, leaves at e w with s+ = s0 - mu (1 + e) w, lands again
// at t2 = t1 + 2 e w/g with s++ = s+ - mu (1 + e) e w = s0 - mu w (1 +
// e)^2, and at T in (t2, t3) it is in flight: along psi p(T) = s0 t1 + s+
// (t2 - t1) + s++ (T - t2), z(T) = e^2 w (T - t2) - g (T - t2)^2 / 2. So
// dt1/de = 0, dt2/de = 2 w/g, ds+/de = -mu w, ds++/de = -2 mu w (1 + e),
// dp/de = -mu w (t2 - t1) + (s+ - s++) 2 w/g - 2 mu w (1 + e) (T - t2),
// dz/de = 2 e w (T - t2) - e^2 w 2 w/g + 2 w (T - t2), dvz/de = 2 w (1 + e).
// To 1e-12 (two impacts, each exact to rounding; no event has a small rate).
TEST(SensitivityCone, BouncingLandingRestitutionAgainstClosedForm) {
  const double z0 = 0.5, s0 = 3.0, e = 0.5, w = std::sqrt(2 * kG * z0), T = 0.72;
  const double t1 = w / kG, t2 = t1 + 2 * e * w / kG, t3 = t2 + 2 * e * e * w / kG;
  ASSERT_TRUE(t2 < T && T < t3);
  const double sp = s0 - kMu * (1 + e) * w, spp = s0 - kMu * w * (1 + e) * (1 + e);
  ASSERT_GT(spp, 0.5);  // sliding on after both impacts
  const double dp =
      -kMu * w * (t2 - t1) + (sp - spp) * 2 * w / kG - 2 * kMu * w * (1 + e) * (T - t2);
  const double dz = 2 * e * w * (T - t2) - e * e * w * 2 * w / kG + 2 * w * (T - t2);
  int checked = 0;
  for (int d : {3, 4}) {
    mech::Model m = point(d);
    m.mechanical->restitution = VectorXd::Constant(1, e);
    m = mech::model_of(*m.mechanical, "point3d");
    const double psi = kPi / d;
    VectorXd x0 = sliding(s0, psi);
    x0(2) = z0;
    const sim::Trajectory tr = run(m, x0, T, {"e[floor]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    ASSERT_TRUE(tr.sensitivity_losses.empty()) << tr.sensitivity_losses[0].reason;
    ASSERT_EQ(tr.events.size(), 2u);
    EXPECT_NEAR(tr.events[0].t, t1, 1e-12);
    EXPECT_NEAR(tr.events[1].t, t2, 1e-12);
    EXPECT_NEAR(tr.events[0].dt(0), 0.0, kTol);
    EXPECT_NEAR(tr.events[1].dt(0), 2 * w / kG, kTol) << "dt2/de, d = " << d;
    EXPECT_NEAR(tr.dx_final(0, 0), dp * std::cos(psi), kTol) << "dx/de, d = " << d;
    EXPECT_NEAR(tr.dx_final(1, 0), dp * std::sin(psi), kTol) << "dy/de, d = " << d;
    EXPECT_NEAR(tr.dx_final(2, 0), dz, kTol) << "dz/de, d = " << d;
    const double dspp = -2 * kMu * w * (1 + e);
    EXPECT_NEAR(tr.dx_final(3, 0), dspp * std::cos(psi), kTol) << "dvx/de, d = " << d;
    EXPECT_NEAR(tr.dx_final(4, 0), dspp * std::sin(psi), kTol) << "dvy/de, d = " << d;
    EXPECT_NEAR(tr.dx_final(5, 0), 2 * w * (1 + e), kTol) << "dvz/de, d = " << d;
    checked += 8;
  }
  EXPECT_EQ(checked, 16);
}

// The plastic landing (e = 0: the floor is then held, any e > 0 bounces):
// only a one-sided derivative in e exists, the column is lost at the
// landing naming the floor (sensitivity.cpp's plastic_restitution); M's
// columns are computed.
TEST(SensitivityCone, PlasticLandingLosesRestitution) {
  VectorXd x0 = sliding(3.0, 0.3 * kPi / 4);
  x0(2) = 0.2;
  const sim::Trajectory tr = run(point(4), x0, 0.5, {"e[floor]", "M[0][0]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_EQ(tr.sensitivity_losses.size(), 1u);
  const sim::SensitivityLoss& l = tr.sensitivity_losses.front();
  EXPECT_EQ(l.contact, "floor");
  EXPECT_EQ(l.t, tr.events.front().t);
  EXPECT_EQ(l.columns, std::vector<int>{0});
  EXPECT_NE(l.reason.find("plastic impact"), std::string::npos) << l.reason;
  EXPECT_FALSE(tr.dx_final_exists[0]);
  EXPECT_TRUE(tr.dx_final_exists[1]);
}

test_support::FdColumn mass_entry(int i, int j, double theta) {
  return param("M[" + std::to_string(i) + "][" + std::to_string(j) + "]", theta,
               [i, j](mech::MechanicalModel& mm, double d) {
                 mm.M.coeffRef(i, j) += d;
                 if (i != j) mm.M.coeffRef(j, i) += d;
               });
}

// M[i][j] and e[c] against central differences: the point sliding to rest
// with springs (phases: edge, face, stick), the landings of
// LandingAgainstCentralDifferences with e = 0.5 at 3 m/s (bouncing: two
// impacts, the slide after each on an edge's region or a face) and at 0.3
// m/s (stuck at the first impact, leaving without sliding velocity) and the spring-pulled
// point from rest (SpringPulledStickSlip...: stick -> slip, turns, stick;
// the stick and slip forces moved by G).
TEST(SensitivityCone, MassAndRestitutionAgainstCentralDifferences) {
  int compared = 0;
  for (const Case& c : {Case{2, 0.3}, Case{4, -0.35}}) {
    mech::Model m = point(c.d, 0.4, -0.3);
    m.mechanical->K = Eigen::Vector3d(1, 1, 0).asDiagonal().toDenseMatrix().sparseView();
    m = mech::model_of(*m.mechanical, "point3d");
    const VectorXd x0 = sliding(1.0, c.a * kPi / c.d);
    compared += expect_fd(m, x0, 0.5,
                          {mass_entry(0, 0, 2.0), mass_entry(1, 1, 2.0), mass_entry(2, 2, 2.0),
                           mass_entry(0, 1, 0.0)});
  }
  for (int d : {2, 4})
    for (const double s0 : {3.0, 0.3}) {
      mech::Model m = point(d, 0.3, -0.2);
      m.mechanical->restitution = VectorXd::Constant(1, 0.5);
      m = mech::model_of(*m.mechanical, "point3d");
      VectorXd x0 = sliding(s0, 0.3 * kPi / d);
      x0(2) = 0.2;
      compared += expect_fd(m, x0, 0.45,
                            {mass_entry(0, 0, 2.0), mass_entry(2, 2, 2.0), mass_entry(0, 2, 0.0),
                             param("e[floor]", 0.5, [](mech::MechanicalModel& mm, double dd) {
                               mm.restitution(0) += dd;
                             })});
    }
  for (int d : {2, 4})
    compared += expect_fd(pulled(d), (VectorXd(10) << 0, 0, 0, 0, 0, 0, 0, 0, 3, 1).finished(), 1.0,
                          {mass_entry(0, 0, 2.0), mass_entry(2, 2, 2.0), mass_entry(3, 3, 1.0),
                           mass_entry(0, 3, 0.0)});
  // 4 columns on 6 states and 2 events: the turn and the stop; the two
  // landings (T = 0.45 s between the second and the third), four runs;
  // pulled from rest, 10 states and 5 (d = 2) or 2 events.
  EXPECT_EQ(compared, 2 * 4 * 8 + 4 * 4 * 8 + 4 * 15 + 4 * 12);
}

// A unit point at rest on the floor (mu = 0.4, N = 9.81 N, d edge pairs)
// pushed along a face's normal n_0 (angle pi/(2d)) by a force input `push`.
mech::Model pushed_point(int d, const std::string& input, double angle) {
  char gain[96];
  std::snprintf(gain, sizeof gain, "[%.17g, %.17g, 0]", std::cos(angle), std::sin(angle));
  return io::parse_matrix_model(
      "name: pushed_point\ninputs:\n  - " + input +
          "\nmechanical:\n  M: [[1, 0, 0], [0, 1, 0], [0, 0, 1]]\n  E: [[0, 0, 1]]\n"
          "  f: [0, 0, -9.81]\n  coordinates: [x, y, z]\n  constraints: [floor]\n"
          "  force_inputs: [{input: push, gain: " +
          gain + "}]\n  friction:\n    - {contact: floor, tangents: [[1, 0, 0], [0, 1, 0]], d: " +
          std::to_string(d) + ", mu: 0.4}\ninitial: [0, 0, 0, 0, 0, 0]\nt_end: 1.8\n",
      "pushed_point.yaml");
}

// An input's own parameters through 3-D phases (sensitivity_cone.cpp: the
// force column of the free acceleration moves as f[i]'s, the exosystem's
// rows as they are). The ramp P t / t1 (pwl points (0, 0), (t1, P), P = 6
// N, t1 = 2 s) along the face normal n_0: the point sticks until the push
// reaches the polygon's face, P t / t1 = mu c N (c = cos(pi/(2d))), ts = mu
// c N t1 / P, then slides along n_0 (the face: its cross force zero) with
// x'' = P s / t1 - mu c N, the planar block's closed form with mu c for mu
// (test_sensitivity_friction_params.cpp): at T = 1.8 s along n_0 dp/dP =
// (T^3/6 - T ts^2/2 + ts^3/3) / t1, dv/dP = (T^2 - ts^2) / (2 t1), dts/dP =
// -ts/P, and d/dt1 = -(P / t1) d/dP. To 1e-12 (as there).
TEST(SensitivityCone, InputParametersAgainstClosedForm) {
  int checked = 0;
  for (int d : {2, 4}) {
    const double th = kPi / (2 * d), c = std::cos(th);
    const mech::Model m = pushed_point(d, "{name: push, kind: pwl, points: [[0, 0], [2, 6]]}", th);
    const double P = 6, t1 = 2, muN = 0.4 * 9.81 * c, ts = muN * t1 / P, T = 1.8;
    const sim::Trajectory tr = run(m, VectorXd::Zero(6), T, {"pwl_v[push][1]", "pwl_t[push][1]"});
    ASSERT_TRUE(tr.ok()) << tr.message;
    ASSERT_TRUE(tr.dx_final_exists[0] && tr.dx_final_exists[1]);  // (the zero gap's loss: x0's)
    ASSERT_EQ(tr.events.size(), 1u);                              // stick -> slip on the face
    ASSERT_NEAR(tr.events[0].t, ts, 1e-12);
    const double dp = (T * T * T / 6 - T * ts * ts / 2 + ts * ts * ts / 3) / t1;
    const double dv = (T * T - ts * ts) / (2 * t1);
    for (int col = 0; col < 2; ++col) {
      const double k = col == 0 ? 1.0 : -P / t1;  // d/dt1 = -(P / t1) d/dP
      EXPECT_NEAR(tr.dx_final(0, col), k * dp * std::cos(th), 1e-12) << d << " " << col;
      EXPECT_NEAR(tr.dx_final(1, col), k * dp * std::sin(th), 1e-12) << d << " " << col;
      EXPECT_NEAR(tr.dx_final(3, col), k * dv * std::cos(th), 1e-12) << d << " " << col;
      EXPECT_NEAR(tr.dx_final(4, col), k * dv * std::sin(th), 1e-12) << d << " " << col;
      EXPECT_NEAR(tr.events[0].dt(col), k * -ts / P, 1e-12) << d << " " << col;
      EXPECT_NEAR(tr.dx_final(2, col), 0.0, 1e-12);
      EXPECT_NEAR(tr.dx_final(5, col), 0.0, 1e-12);
      checked += 7;
    }
  }
  EXPECT_EQ(checked, 28);
}

// A damped sine push (amplitude 8 N, 0.4 Hz, damping 0.1 1/s, phase 0.3,
// offset 0.5 N) at 0.3 rad from the first tangent, d = 4: stick -> slip,
// turns through the cone's edges and faces as the push swings, stick again;
// its parameters against central differences.
TEST(SensitivityCone, InputParametersAgainstCentralDifferences) {
  const mech::Model m = pushed_point(
      4,
      "{name: push, kind: damped_sine, amplitude: 8, frequency: 0.4, damping: 0.1, phase: 0.3, "
      "offset: 0.5}",
      0.3);
  auto input = [](const char* column, double theta, double mech::Input::*field) {
    return test_support::FdColumn{column, theta, [field](mech::Model& mm, VectorXd&, double dd) {
                                    mm.mechanical->inputs[0].*field += dd;
                                  }};
  };
  const int n = expect_fd(m, VectorXd::Zero(6), 3.0,
                          {input("amplitude[push]", 8, &mech::Input::amplitude),
                           input("frequency[push]", 0.4, &mech::Input::frequency),
                           input("damping[push]", 0.1, &mech::Input::damping),
                           input("phase[push]", 0.3, &mech::Input::phase),
                           input("offset[push]", 0.5, &mech::Input::offset)});
  // 5 columns on 6 states and 4 events (stick -> slip, turns, stick).
  EXPECT_EQ(n, 5 * (6 + 4));
}

}  // namespace
}  // namespace lcsim
