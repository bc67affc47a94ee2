// Moreau–Jean with 3-D Coulomb friction (issue 27, mj_friction.hpp): a point
// mass (x, y, z) on the floor z >= 0 under gravity, friction along x (t) and
// y (t2) on the polyhedral cone of 2d edges, against the closed form
// mech::cone_slide; a block at rest stays at rest; d = 1 on a 3-D contact is
// the planar step along t.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim {
namespace {

constexpr double kG = 9.81, kMu = 0.3, kS0 = 1.0;

mech::Model block3d(int d) {
  mech::MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(3, 3).sparseView();
  m.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  m.f = Eigen::Vector3d(0, 0, -kG);
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), kMu);
  c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
  c.edges = d;
  m.friction.push_back(c);
  return mech::model_of(m, "block3d");
}

sim::Trajectory slide(const mech::Model& model, double psi, double h, double t_end,
                      double theta = 0.5) {
  const Eigen::VectorXd x0 =
      (Eigen::VectorXd(6) << 0, 0, 0, kS0 * std::cos(psi), kS0 * std::sin(psi), 0).finished();
  sim::Options o;
  o.t_end = t_end;
  o.h = h;
  o.theta = theta;
  return sim::make_integrator("moreau-jean")->run(model, x0, o);
}

// What a run gives to compare with the closed form: the first sample time
// with zero tangential velocity (below 1e-12 s0: the stuck step's velocity is
// v + W^{-1} D' beta, zero to rounding of terms of size s0), the
// displacement there, the heading of the last sample still moving.
struct Measured {
  double t_stop = -1.0, x = 0.0, y = 0.0, heading = 0.0;
};
Measured measure(const sim::Trajectory& tr) {
  Measured r;
  for (const sim::Sample& s : tr.samples) {
    const double vx = s.x(3), vy = s.x(4);
    const bool rest = std::hypot(vx, vy) <= 1e-12 * kS0;
    if (rest && s.t > 0.0) {
      r.t_stop = s.t;
      r.x = s.x(0);
      r.y = s.x(1);
      return r;
    }
    if (!rest) r.heading = std::atan2(vy, vx);
  }
  return r;
}

// The headings of the brief: on an edge, on a bisector, between (a third
// of the way from edge 0 to edge 1, and past the first quadrant).
struct Case {
  int d;
  double psi;
};
std::vector<Case> cases() {
  const double pi = std::acos(-1.0);
  std::vector<Case> out;
  for (int d : {2, 4, 8}) {
    out.push_back({d, 0.0});                    // on edge 0
    out.push_back({d, pi / d});                 // on edge 1
    out.push_back({d, pi / (2 * d)});           // on the bisector of face 0
    out.push_back({d, pi / (3 * d)});           // between, nearer edge 0
    out.push_back({d, pi / 2 + 0.7 * pi / d});  // between, second quadrant
  }
  return out;
}

// Why the bounds hold. The step's velocity is the backward Euler of the
// cone law with the normal impulse m g h exactly (K = D = 0). Along the
// bisector b of the face the velocity ends on, v.b falls at mu g cos(pi/(2d))
// in both phases of the closed form (the edge force has that component
// along b, so has every force on the face) and in every step alike, so the
// discrete velocity is zero from the first step after the closed form's
// stop: 0 <= t_stop_h - t_stop < h (C = 1; 1e-9 for the rounding of the
// step count). It is not smooth in h (where the stop falls in a step), so
// first order is shown on the displacement. The implicit step puts the
// velocity exactly on the bisector (or keeps it on the edge) where the
// closed form's goes: the final heading agrees to rounding (1e-9 rad). The
// discrete velocity equals the closed form's at every step but the one that
// crosses the turn (off by at most mu g h) and the last moving one (at most
// mu g h from zero); the positions are theta's quadrature of it. theta = 1
// (right rectangles) errs on each linear phase by -h/2 times the velocity
// lost, so by -h v0/2 in all: x_h - x = -h v0/2 + r, |r| <= 2 mu g h^2 per
// component (the two odd steps), first order with C = s0/2 exactly, and the
// error halves when h halves (ratio 2 within 0.1: the remainder is at most
// 2 mu g h / (s0/2) = 1.2% of the error at h = 1e-3). theta = 0.5 (the
// default, trapezoids) is exact on the linear phases: |x_h - x| <= 2 mu g
// h^2, second order in the displacement.
double rounding_free_heading_error(double a, double b) {
  return std::remainder(a - b, 2 * std::acos(-1.0));
}

TEST(MjFriction3d, BlockSlideAgainstConeSlideFirstOrder) {
  for (const Case& c : cases()) {
    const mech::Model model = block3d(c.d);
    const mech::ConeSlide cs = mech::cone_slide(kS0, c.psi, kMu, kG, c.d);
    const double v0x = kS0 * std::cos(c.psi), v0y = kS0 * std::sin(c.psi);
    double err_prev = -1.0;
    for (double h : {1e-3, 5e-4, 2.5e-4}) {
      const std::string at = "d = " + std::to_string(c.d) + ", psi = " + std::to_string(c.psi) +
                             ", h = " + std::to_string(h);
      const sim::Trajectory tr = slide(model, c.psi, h, cs.t_stop + 0.05, 1.0);
      ASSERT_EQ(tr.status, Status::kOk) << tr.message;
      const Measured r = measure(tr);
      ASSERT_GT(r.t_stop, 0.0) << at;
      EXPECT_GE(r.t_stop - cs.t_stop, -1e-9) << at;
      EXPECT_LT(r.t_stop - cs.t_stop, h + 1e-9) << at;
      EXPECT_NEAR(rounding_free_heading_error(r.heading, cs.heading), 0.0, 1e-9) << at;
      const double rem = 2 * kMu * kG * h * h;
      EXPECT_NEAR(r.x - cs.x, -h * v0x / 2, rem) << at;
      EXPECT_NEAR(r.y - cs.y, -h * v0y / 2, rem) << at;
      const double err = std::hypot(r.x - cs.x, r.y - cs.y);
      if (err_prev > 0.0) {
        EXPECT_NEAR(err_prev / err, 2.0, 0.1) << at;
      }
      err_prev = err;
      // theta = 0.5: second order in the displacement, the same stop and heading.
      const Measured t = measure(slide(model, c.psi, h, cs.t_stop + 0.05));
      EXPECT_EQ(t.t_stop, r.t_stop) << at;
      EXPECT_NEAR(rounding_free_heading_error(t.heading, cs.heading), 0.0, 1e-9) << at;
      EXPECT_NEAR(t.x, cs.x, rem) << at;
      EXPECT_NEAR(t.y, cs.y, rem) << at;
    }
  }
}

// A block at rest on the floor stays at rest: every sample's tangential
// position and velocity exactly zero, the contact sticking.
TEST(MjFriction3d, BlockAtRestSticksExactly) {
  for (int d : {2, 4, 8}) {
    const sim::Trajectory tr =
        sim::make_integrator("moreau-jean")->run(block3d(d), Eigen::VectorXd::Zero(6), [] {
          sim::Options o;
          o.t_end = 0.2;
          return o;
        }());
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    ASSERT_GT(tr.samples.size(), 100u);
    for (const sim::Sample& s : tr.samples) {
      EXPECT_EQ(s.x(0), 0.0);
      EXPECT_EQ(s.x(1), 0.0);
      EXPECT_EQ(s.x(3), 0.0);
      EXPECT_EQ(s.x(4), 0.0);
      if (s.t > 0.0) {
        ASSERT_EQ(s.friction_mode.size(), 1u);
        EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kStick) << "t = " << s.t;
      }
    }
  }
}

// d = 1 on a 3-D contact (edges +t, -t: friction along t alone) is the planar
// step along t: the same trajectory, x and y, as the planar model (the y
// velocity is free in both) to rounding of the two LCPs' different unknowns
// (1e-12 relative to s0 and the distance s0^2/(mu g) = 0.34 m).
TEST(MjFriction3d, OneEdgePairIsThePlanarStep) {
  mech::MechanicalModel planar = *block3d(1).mechanical;
  planar.friction[0].tangent2 = Eigen::SparseVector<double>();
  planar.friction[0].edges = 0;
  const mech::Model planar_model = mech::model_of(planar, "block2d");
  for (double psi : {0.0, 0.5, 2.0}) {
    const sim::Trajectory a = slide(block3d(1), psi, 1e-3, 0.5);
    const sim::Trajectory b = slide(planar_model, psi, 1e-3, 0.5);
    ASSERT_EQ(a.status, Status::kOk) << a.message;
    ASSERT_EQ(b.status, Status::kOk) << b.message;
    ASSERT_EQ(a.samples.size(), b.samples.size());
    for (size_t i = 0; i < a.samples.size(); ++i) {
      EXPECT_EQ(a.samples[i].t, b.samples[i].t);
      for (int j = 0; j < 6; ++j) EXPECT_NEAR(a.samples[i].x(j), b.samples[i].x(j), 1e-12) << i;
    }
  }
}

// A model with a 3-D and a planar contact (the planar one's second-tangent
// column is empty): two uncoupled blocks, the 3-D one at psi = 0.4 (d = 4),
// the planar one along t, each stopping as its closed form says:
// cone_slide, and s0/(mu g) for the planar block. Bound [0, 2h): the step
// bound above, plus one step: a step may end with the gap at +1e-21 (the
// normal impulse m g h to rounding) and the active-set rule (the
// frictionless step's too) then leaves the contact out for one step, which
// costs that step's friction, mu g h of speed, one step of stop time.
TEST(MjFriction3d, MixedPlanarAnd3dContacts) {
  mech::MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(6, 6).sparseView();
  Eigen::MatrixXd E = Eigen::MatrixXd::Zero(2, 6);
  E(0, 2) = E(1, 5) = 1.0;
  m.E = E.sparseView();
  m.f = (Eigen::VectorXd(6) << 0, 0, -kG, 0, 0, -kG).finished();
  Eigen::VectorXd t = Eigen::VectorXd::Zero(6), t2 = t, tp = t;
  t(0) = t2(1) = tp(3) = 1.0;
  mech::FrictionalContact c3(0, t, kMu);
  c3.tangent2 = t2.sparseView();
  c3.edges = 4;
  m.friction = {c3, mech::FrictionalContact(1, tp, kMu)};
  const double psi = 0.4, h = 1e-3;
  const mech::ConeSlide cs = mech::cone_slide(kS0, psi, kMu, kG, 4);
  const double planar_stop = kS0 / (kMu * kG);
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(12);
  x0(6) = kS0 * std::cos(psi);
  x0(7) = kS0 * std::sin(psi);
  x0(9) = kS0;
  sim::Options o;
  o.t_end = std::max(cs.t_stop, planar_stop) + 0.05;
  o.h = h;
  const sim::Trajectory a =
      sim::make_integrator("moreau-jean")->run(mech::model_of(m, "mixed"), x0, o);
  ASSERT_EQ(a.status, Status::kOk) << a.message;
  double stop3 = -1.0, stop2 = -1.0, heading = 0.0;
  for (const sim::Sample& s : a.samples) {
    const bool rest3 = std::hypot(s.x(6), s.x(7)) <= 1e-12 * kS0;
    if (!rest3) heading = std::atan2(s.x(7), s.x(6));
    if (rest3 && stop3 < 0.0 && s.t > 0.0) stop3 = s.t;
    if (std::abs(s.x(9)) <= 1e-12 * kS0 && stop2 < 0.0 && s.t > 0.0) stop2 = s.t;
    EXPECT_EQ(s.x(10), 0.0);  // no friction across the planar block's t
  }
  EXPECT_GE(stop3 - cs.t_stop, -1e-9);
  EXPECT_LT(stop3 - cs.t_stop, 2 * h);
  EXPECT_NEAR(rounding_free_heading_error(heading, cs.heading), 0.0, 1e-9);
  EXPECT_GE(stop2 - planar_stop, -1e-9);
  EXPECT_LT(stop2 - planar_stop, 2 * h);
}

}  // namespace
}  // namespace lcsim
