// The exact (event-driven) method with 3-D Coulomb friction on a polyhedral
// cone (issue 27, cone_phase.cpp and cone_modes.cpp): a point mass on the
// floor z >= 0 sliding from speed s0 at the angle psi from the first
// tangent, to rest, against the closed form mech::cone_slide (turning time,
// stop time, displacement and final heading, every d and heading given); at
// rest under a push inside the polygon it sticks exactly, and a push outside
// starts a slide in the direction of the cone's geometry (computed here
// from the polygon, against the run); d = 1 on a 3-D contact is the planar
// method's run; random models only dissipate and keep the Coulomb law.
//
// Tolerances. Each phase is a matrix exponential of a closed loop with
// entries O(1)-O(10) (a few eps relative per evaluation) and each event the
// root of a monitor found to a few ulp of t; the monitors cross zero at
// rates >= mu g sin(pi/(2d)) * (distance from the bisector) which here is
// >= 0.05 m/s^2, so a rounding of 1e-16 in a monitor moves an event by
// ~1e-15 s. We assert 1e-12 relative (the brief's "to rounding"): three
// orders of margin over the rounding of two events, while a wrong force
// column, a missed or spurious event shows at 1e-3 or more.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <random>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::VectorXd;
using sim::EventType;
using sim::FrictionMode;

constexpr double kG = 9.81, kMu = 0.3, kS0 = 1.0, kPi = std::numbers::pi;
constexpr double kRel = 1e-12;  // see the header

// A point mass m = 2 kg (x, y, z) on the floor z >= 0 under gravity and a
// horizontal push (px, py) (N); friction along x (t) and y (t2), mu = 0.3,
// d edge pairs; planar: the tangent x only.
mech::Model block(int d, double px = 0.0, double py = 0.0, bool planar = false) {
  mech::MechanicalModel m;
  const double mass = 2.0;
  m.M = (mass * Eigen::MatrixXd::Identity(3, 3)).sparseView();
  m.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  m.f = Eigen::Vector3d(px, py, -mass * kG);
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), kMu);
  if (!planar) {
    c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
    c.edges = d;
  }
  m.friction.push_back(c);
  return mech::model_of(m, "block3d");
}

sim::Trajectory run(const mech::Model& model, double psi, double s0, double t_end,
                    double dt_out = 0.0) {
  const VectorXd x0 =
      (VectorXd(6) << 0, 0, 0, s0 * std::cos(psi), s0 * std::sin(psi), 0).finished();
  sim::Options o;
  o.t_end = t_end;
  o.dt_out = dt_out;
  return sim::simulate(model, x0, o, "event");
}

// |a - b| as an angle (mod 2 pi).
double angle_gap(double a, double b) { return std::abs(std::remainder(a - b, 2.0 * kPi)); }

double rel(double got, double want) { return std::abs(got - want) / std::max(1.0, std::abs(want)); }

struct Case {
  int d;
  double psi;
};

// Edges, bisectors, between (a third, 0.7 of a sector, negative, past 2 pi).
std::vector<Case> slide_cases() {
  std::vector<Case> out;
  for (int d : {2, 3, 4, 5, 8, 16, 27})
    for (double a : {0.0, 1.0, 0.5, 1.0 / 3.0, 0.7, 2.5, -0.2, -1.5, 2.0 * d + 0.9, 0.999})
      out.push_back({d, a * kPi / d});
  for (double psi : {0.1234, 1.9, -2.7, 3.0})
    for (int d : {2, 4, 8}) out.push_back({d, psi});
  return out;
}

TEST(EventFriction3d, BlockSlidesToRestAsTheClosedForm) {
  double worst_t = 0, worst_x = 0, worst_h = 0;
  int n = 0;
  for (const Case& c : slide_cases()) {
    const mech::ConeSlide cf = mech::cone_slide(kS0, c.psi, kMu, kG, c.d);
    const sim::Trajectory tr = run(block(c.d), c.psi, kS0, cf.t_stop + 0.25);
    const std::string at = "d = " + std::to_string(c.d) + ", psi = " + std::to_string(c.psi);
    ASSERT_EQ(tr.status, Status::kCompleted) << at << ": " << tr.message;
    // Events: the turn onto the bisector (none when the slide starts on an
    // edge or a bisector), then the stop.
    ASSERT_FALSE(tr.events.empty()) << at;
    const sim::Event& stop = tr.events.back();
    ASSERT_EQ(stop.type, EventType::kStick) << at;
    ASSERT_EQ(stop.friction_mode_after.at(0), FrictionMode::kStick) << at;
    double heading = c.psi;
    if (tr.events.size() == 2) {
      const sim::Event& turn = tr.events[0];
      EXPECT_EQ(turn.type, EventType::kSlip) << at;
      EXPECT_LE(rel(turn.t, cf.t_turn), kRel) << at;
      heading = std::atan2(turn.state_after(4), turn.state_after(3));
    } else {
      ASSERT_EQ(tr.events.size(), 1u) << at;
      // No turn: straight along a bisector (t_turn = 0) or an edge (t_turn = t_stop).
      EXPECT_LE(std::min(cf.t_turn, cf.t_stop - cf.t_turn), 1e-12 * cf.t_stop) << at;
    }
    worst_t = std::max(worst_t, rel(stop.t, cf.t_stop));
    worst_x = std::max({worst_x, rel(tr.final_state(0), cf.x), rel(tr.final_state(1), cf.y)});
    worst_h = std::max(worst_h, angle_gap(heading, cf.heading));
    EXPECT_LE(rel(stop.t, cf.t_stop), kRel) << at;
    EXPECT_LE(rel(tr.final_state(0), cf.x), kRel) << at;
    EXPECT_LE(rel(tr.final_state(1), cf.y), kRel) << at;
    EXPECT_LE(angle_gap(heading, cf.heading), kRel) << at;
    // At rest, exactly, and still on the floor.
    // (the stick phase's acceleration is zero to the rounding of its forces)
    EXPECT_LE(tr.final_state.segment(3, 3).cwiseAbs().maxCoeff(), 1e-14) << at;
    EXPECT_LE(std::abs(tr.final_state(2)), 1e-14) << at;
    ++n;
  }
  std::printf("[  error   ] %d slides: stop time %.1e, position %.1e, heading %.1e rad\n", n,
              worst_t, worst_x, worst_h);
}

// The samples carry the modes: slip while moving, stick at rest; the
// energy falls at the rate of maximal dissipation mu m g |s|_* (the
// polygon's support function of the velocity).
TEST(EventFriction3d, SamplesSlipThenStickAndDissipateAtTheConeRate) {
  const int d = 4;
  const double psi = 0.3 * kPi / d;
  const mech::ConeSlide cf = mech::cone_slide(kS0, psi, kMu, kG, d);
  const sim::Trajectory tr = run(block(d), psi, kS0, cf.t_stop + 0.1, 0.01);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  for (const sim::Sample& s : tr.samples) {
    const double speed = std::hypot(s.x(3), s.x(4));
    ASSERT_EQ(s.friction_mode.size(), 1u);
    if (s.t > 1e-9 && s.t < cf.t_stop - 1e-9) {
      EXPECT_EQ(s.friction_mode[0], FrictionMode::kSlip);
    }
    if (s.t > cf.t_stop + 1e-9) {
      EXPECT_EQ(s.friction_mode[0], FrictionMode::kStick);
      EXPECT_LE(speed, 1e-14);  // zero to the stick forces' rounding
    }
    // The friction force along t: while sliding, -mu m g D_i.(x) on an edge
    // or the face force's x-component; |u_t| <= mu m g always.
    EXPECT_LE(std::abs(s.u_t(0)), kMu * 2.0 * kG * (1 + 1e-12));
  }
  EXPECT_LT(tr.energy_final, tr.energy_initial);
}

// A push inside the polygon: mu m g cos(pi/(2d)) * 0.999 in any direction,
// or 0.999 mu m g along an edge (the polygon reaches mu m g there): the
// block stays exactly at rest.
TEST(EventFriction3d, StaysAtRestUnderAPushInsideThePolygon) {
  const double mg = 2.0 * kG;
  for (int d : {2, 3, 4, 8}) {
    std::vector<std::pair<double, double>> pushes;  // magnitude, angle
    for (double a : {0.0, 0.5, 0.25, 1.7, -0.6})
      pushes.push_back({0.999 * kMu * mg * std::cos(kPi / (2 * d)), a * kPi / d});
    pushes.push_back({0.999 * kMu * mg, 3 * kPi / d});
    for (const auto& [p, phi] : pushes) {
      const sim::Trajectory tr =
          run(block(d, p * std::cos(phi), p * std::sin(phi)), 0.0, 0.0, 1.0, 0.25);
      ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
      EXPECT_TRUE(tr.events.empty()) << "d = " << d << ", phi = " << phi;
      for (const sim::Sample& s : tr.samples) {
        EXPECT_EQ(s.friction_mode.at(0), FrictionMode::kStick);
        EXPECT_LE(s.x.head(2).norm(), 1e-14);  // the stick forces' rounding over 1 s
        // The stick force balances the push.
        EXPECT_NEAR(s.u_t(0), -p * std::cos(phi), 1e-12 * mg);
      }
    }
  }
}

// The direction a push P e_phi (beyond the polygon) starts a block from
// rest: the acceleration a = P/m e_phi - mu g D with D of maximal
// dissipation along a itself. Edge i: a strictly within pi/(2d) of edge i;
// face j: a along its bisector n_j, the face force's offset |w| <= mu g
// sin(pi/(2d)). Found here by walking the 4d facets (the polygon's
// geometry); returns the acceleration (along t, t2).
std::pair<double, double> start_acceleration(double P_over_m, double phi, int d) {
  const double step = kPi / d, mug = kMu * kG;
  for (int i = 0; i < 2 * d; ++i) {
    const double ax = P_over_m * std::cos(phi) - mug * std::cos(i * step);
    const double ay = P_over_m * std::sin(phi) - mug * std::sin(i * step);
    if (angle_gap(std::atan2(ay, ax), i * step) < step / 2 - 1e-9) return {ax, ay};
  }
  for (int j = 0; j < 2 * d; ++j) {
    const double th = (j + 0.5) * step;
    const double along = P_over_m * std::cos(phi - th) - mug * std::cos(step / 2);
    const double w = P_over_m * std::sin(phi - th);  // the face force cancels it
    if (along > 0 && std::abs(w) <= mug * std::sin(step / 2))
      return {along * std::cos(th), along * std::sin(th)};
  }
  return {NAN, NAN};
}

TEST(EventFriction3d, APushBeyondThePolygonStartsTheSlideTheConeGives) {
  const double mass = 2.0, T = 0.5;
  int n = 0;
  for (int d : {2, 3, 4, 8})
    for (double a : {0.0, 0.5, 0.2, 0.45, 1.3, -0.8})
      for (double factor : {1.02, 1.5, 3.0}) {
        // Beyond the polygon in direction phi: past its support there.
        const double phi = a * kPi / d;
        const double reach = kMu * mass * kG * std::cos(kPi / (2 * d)) /
                             std::cos(std::remainder(phi - kPi / (2 * d), kPi / d));
        const double P = factor * reach;
        const auto [ax, ay] = start_acceleration(P / mass, phi, d);
        ASSERT_TRUE(std::isfinite(ax)) << d << " " << phi;
        const sim::Trajectory tr = run(block(d, P * std::cos(phi), P * std::sin(phi)), 0.0, 0.0, T);
        const std::string at = "d = " + std::to_string(d) + ", phi = " + std::to_string(phi) +
                               ", P = " + std::to_string(factor) + " x reach";
        ASSERT_EQ(tr.status, Status::kCompleted) << at << ": " << tr.message;
        EXPECT_TRUE(tr.events.empty()) << at;  // slides straight from the start
        EXPECT_NEAR(tr.final_state(0), 0.5 * ax * T * T, kRel * 10) << at;
        EXPECT_NEAR(tr.final_state(1), 0.5 * ay * T * T, kRel * 10) << at;
        EXPECT_NEAR(tr.final_state(3), ax * T, kRel * 10) << at;
        EXPECT_NEAR(tr.final_state(4), ay * T, kRel * 10) << at;
        ++n;
      }
  EXPECT_EQ(n, 72);
}

// d = 1 on a 3-D contact: the polygon is the segment [-t, t] (no friction
// along t2), the planar contact along t; the runs agree sample for sample.
TEST(EventFriction3d, DOneIsThePlanarMethod) {
  for (double psi : {0.0, 0.4, kPi, -2.0, kPi / 2}) {
    const sim::Trajectory a = run(block(1), psi, kS0, 0.6, 0.01);
    const sim::Trajectory b = run(block(1, 0, 0, true), psi, kS0, 0.6, 0.01);
    ASSERT_EQ(a.status, Status::kCompleted) << a.message;
    ASSERT_EQ(b.status, Status::kCompleted) << b.message;
    ASSERT_EQ(a.samples.size(), b.samples.size());
    ASSERT_EQ(a.events.size(), b.events.size());
    for (size_t i = 0; i < a.events.size(); ++i) EXPECT_LE(rel(a.events[i].t, b.events[i].t), kRel);
    for (size_t i = 0; i < a.samples.size(); ++i) {
      EXPECT_LE((a.samples[i].x - b.samples[i].x).cwiseAbs().maxCoeff(), kRel);
      EXPECT_EQ(a.samples[i].friction_mode, b.samples[i].friction_mode);
    }
  }
}

// A box (m = 4 kg, translating and tilting: q = x, y, z, rx, ry; no yaw,
// whose rows would not be orthogonal in these coordinates) on its four
// corners (+-a, +-b) with its centre of mass at the floor's level, so
// friction has no moment that tilts it: it slides as the single block
// (mech::cone_slide), the corners carrying m g in all and the block's
// friction, each corner on its own polygon with maximal dissipation. The four normal rows are
// dependent (rank 3): the split of the loads is indeterminate, the motion is not
// (resultant_determined).
mech::Model box4(int d) {
  const double m = 4.0, a = 0.3, b = 0.2;
  mech::MechanicalModel mm;
  mm.M = Eigen::Matrix<double, 5, 1>(m, m, m, 0.1, 0.2).asDiagonal().toDenseMatrix().sparseView();
  Eigen::MatrixXd E(4, 5);
  int r = 0;
  for (double cx : {-a, a})
    for (double cy : {-b, b}) E.row(r++) << 0, 0, 1, cy, -cx;
  mm.E = E.sparseView();
  mm.f = (Eigen::VectorXd(5) << 0, 0, -m * kG, 0, 0).finished();
  for (int c = 0; c < 4; ++c) {
    mech::FrictionalContact fc(c, (Eigen::VectorXd(5) << 1, 0, 0, 0, 0).finished(), kMu);
    fc.tangent2 = (Eigen::VectorXd(5) << 0, 1, 0, 0, 0).finished().sparseView();
    fc.edges = d;
    mm.friction.push_back(fc);
  }
  return mech::model_of(mm, "box4");
}

TEST(EventFriction3d, BoxOnFourCornersSlidesAsTheBlock) {
  for (int d : {2, 4, 8})
    for (double a : {0.0, 0.5, 0.3, 1.4}) {
      const double psi = a * kPi / d;
      const mech::ConeSlide cf = mech::cone_slide(kS0, psi, kMu, kG, d);
      const Eigen::VectorXd x0 =
          (Eigen::VectorXd(10) << 0, 0, 0, 0, 0, kS0 * std::cos(psi), kS0 * std::sin(psi), 0, 0, 0)
              .finished();
      sim::Options o;
      o.t_end = cf.t_stop + 0.25;
      o.dt_out = 0.05;
      const sim::Trajectory tr = sim::simulate(box4(d), x0, o, "event");
      const std::string at = "d = " + std::to_string(d) + ", psi = " + std::to_string(psi);
      ASSERT_EQ(tr.status, Status::kCompleted) << at << ": " << tr.message;
      ASSERT_FALSE(tr.events.empty()) << at;
      EXPECT_LE(rel(tr.events.back().t, cf.t_stop), kRel) << at;
      EXPECT_LE(rel(tr.final_state(0), cf.x), kRel) << at;
      EXPECT_LE(rel(tr.final_state(1), cf.y), kRel) << at;
      EXPECT_LE(tr.final_state.segment(2, 3).cwiseAbs().maxCoeff(), 1e-14) << at;  // flat
      for (const sim::Sample& s : tr.samples) {
        ASSERT_EQ(s.u_t2.size(), 4);
        const bool sliding = s.t > 1e-9 && s.t < cf.t_stop - 1e-9;
        const double vx = s.x(5), vy = s.x(6), sp = std::hypot(vx, vy);
        double support = -1e300;  // max_i D_i.s
        for (int i = 0; i < 2 * d; ++i)
          support = std::max(support, std::cos(i * kPi / d) * vx + std::sin(i * kPi / d) * vy);
        // The loads' split is indeterminate (the mode selection keeps an
        // independent set of corners: two diagonal ones here); their sum is
        // m g and the friction's resultant the block's, -mu m g D.
        double load = 0.0, work = 0.0;
        for (int c = 0; c < 4; ++c) {
          EXPECT_GE(s.u(c), 0.0) << at;
          load += s.u(c);
          work += s.u_t(c) * vx + s.u_t2(c) * vy;
          // Each corner: maximal dissipation F.s = -mu N max_i D_i.s.
          if (sliding) {
            EXPECT_NEAR(s.u_t(c) * vx + s.u_t2(c) * vy, -kMu * s.u(c) * support,
                        1e-12 * kMu * 4.0 * kG * sp)
                << at << " t = " << s.t;
          }
        }
        EXPECT_NEAR(load, 4.0 * kG, 1e-12 * 4.0 * kG) << at << " t = " << s.t;
        if (sliding) {
          EXPECT_NEAR(work, -kMu * 4.0 * kG * support, 1e-12 * kMu * 4.0 * kG * sp) << at;
        }
      }
    }
}

// Random models: k = 1..3 point masses on the floor, each with its own
// contact (tangents turned by a random angle, d in 2..6, mu in 0.1..0.8),
// coupled through a non-diagonal mass matrix and springs, pushed by random
// horizontal forces, starting on the floor with random tangential
// velocities. Every sample: the energy never rises (1e-9 of its scale: the
// rounding of the phases' exponentials), normal forces >= 0, the friction
// force in the polygon mu u_N conv{D_i} (each face, 1e-9 relative) and of
// maximal dissipation while sliding. Every run completes or is refused by
// name (a Painlevé-type phase, a selection without a consistent mode),
// never stalls.
TEST(EventFriction3d, RandomModelsDissipateAndKeepTheCoulombLaw) {
  std::mt19937 rng(2711);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int completed = 0, refused = 0, samples = 0;
  int face_to_edge = 0, edge_to_face = 0, stick_to_slip = 0, to_stick = 0, impacts = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int k = 1 + trial % 3, N = 3 * k;
    mech::MechanicalModel m;
    Eigen::MatrixXd R = Eigen::MatrixXd::NullaryExpr(N, N, [&] { return U(rng); });
    Eigen::MatrixXd M =
        Eigen::MatrixXd::Identity(N, N) * (1.0 + 0.5 * (U(rng) + 1)) + 0.3 * R * R.transpose() / N;
    m.M = M.sparseView();
    Eigen::MatrixXd L = Eigen::MatrixXd::Zero(N, N);
    for (int i = 0; i + 3 < N; ++i) L(i, i) = 1, L(i, i + 3) = -1;  // springs between masses
    m.K = (2.0 * (U(rng) + 1.0) * L.transpose() * L).sparseView();
    Eigen::MatrixXd E = Eigen::MatrixXd::Zero(k, N);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(N), x0 = Eigen::VectorXd::Zero(2 * N);
    std::vector<int> dd(static_cast<size_t>(k));
    for (int c = 0; c < k; ++c) {
      E(c, 3 * c + 2) = 1.0;
      f(3 * c) = 3.0 * U(rng), f(3 * c + 1) = 3.0 * U(rng), f(3 * c + 2) = -kG * 2.0;
      const double al = kPi * U(rng);
      Eigen::VectorXd t = Eigen::VectorXd::Zero(N), t2 = t;
      t(3 * c) = std::cos(al), t(3 * c + 1) = std::sin(al);
      t2(3 * c) = -std::sin(al), t2(3 * c + 1) = std::cos(al);
      mech::FrictionalContact fc(c, t, 0.1 + 0.35 * (U(rng) + 1.0));
      fc.tangent2 = t2.sparseView();
      fc.edges = dd[static_cast<size_t>(c)] = 2 + static_cast<int>(2.5 * (U(rng) + 1.0));
      m.friction.push_back(fc);
      x0(3 * c) = 0.2 * U(rng), x0(3 * c + 1) = 0.2 * U(rng);
      x0(N + 3 * c) = 2.0 * U(rng), x0(N + 3 * c + 1) = 2.0 * U(rng);
    }
    m.E = E.sparseView();
    m.f = f;
    const mech::Model model = mech::model_of(m, "random3d");
    sim::Options o;
    o.t_end = 1.5;
    o.dt_out = 0.01;
    const sim::Trajectory tr = sim::simulate(model, x0, o, "event");
    if (tr.status != Status::kCompleted) {
      ++refused;
      EXPECT_EQ(tr.status, Status::kNumericalFailure) << trial << ": " << tr.message;
      EXPECT_TRUE(tr.message.find("Painlev") != std::string::npos ||
                  tr.message.find("stick / slip selection") != std::string::npos)
          << trial << ": " << tr.message;
      continue;
    }
    ++completed;
    for (const sim::Event& e : tr.events) {  // which transitions the runs went through
      const auto has = [&](const char* a) { return e.note.find(a) != std::string::npos; };
      face_to_edge += has("slip-face") && has("-> slip-edge");
      edge_to_face += has("slip-edge") && has("-> slip-face");
      stick_to_slip += has("stick -> slip");
      to_stick += has("-> stick");
      impacts += e.type == EventType::kImpact;
    }
    double e_prev = tr.energy_initial;
    const double e_scale = 1.0 + std::abs(tr.energy_initial) + 0.5 * x0.tail(N).squaredNorm();
    for (const sim::Sample& s : tr.samples) {
      ++samples;
      const double e = mech::total_energy(*model.mechanical, s.x.head(N), s.x.tail(N));
      EXPECT_LE(e, e_prev + 1e-9 * e_scale) << trial << " t = " << s.t;
      e_prev = std::min(e_prev, e);
      for (int c = 0; c < k; ++c) {
        const mech::FrictionalContact& fc = model.mechanical->friction[static_cast<size_t>(c)];
        const double uN = s.u(c), Fx = s.u_t(c), Fy = s.u_t2(c);
        const double force = 1e-9 * (1.0 + std::abs(uN));  // rounding of a phase's forces
        EXPECT_GE(uN, -force) << trial;
        const int d = dd[static_cast<size_t>(c)];
        for (int j = 0; j < 2 * d; ++j) {
          const double th = (j + 0.5) * kPi / d;
          EXPECT_LE(std::cos(th) * Fx + std::sin(th) * Fy,
                    fc.mu * uN * std::cos(kPi / (2 * d)) + force)
              << trial << " t = " << s.t;
        }
        const Eigen::VectorXd v = s.x.tail(N);
        const double s1 = Eigen::VectorXd(fc.tangent).dot(v);
        const double s2 = Eigen::VectorXd(fc.tangent2).dot(v);
        if (std::hypot(s1, s2) > 1e-6) {
          double support = -1e300;
          for (int i = 0; i < 2 * d; ++i)
            support = std::max(support, std::cos(i * kPi / d) * s1 + std::sin(i * kPi / d) * s2);
          EXPECT_NEAR(Fx * s1 + Fy * s2, -fc.mu * uN * support, force * std::hypot(s1, s2))
              << trial << " t = " << s.t;
        }
      }
    }
  }
  std::printf("[  counts  ] 200 random 3-D models: %d completed, %d refused by name, %d samples\n",
              completed, refused, samples);
  std::printf(
      "[  counts  ] events: %d edge -> face, %d face -> edge, %d stick -> slip, %d -> stick, "
      "%d impacts\n",
      edge_to_face, face_to_edge, stick_to_slip, to_stick, impacts);
  EXPECT_EQ(completed + refused, 200);
}

// A point mass dropped from 0.05 m with a tangential velocity: it lands
// (the cone's impact law at e = 0 removes the normal velocity and takes at
// most mu P_N off the sliding, on the polygon), then slides to rest as
// mech::cone_slide from the velocity the impact left, where it left it.
// The block dropped from 0.05 m while sliding at 2 m/s along psi, run by the
// exact method to t_end (the two tests below).
sim::Trajectory sliding_landing(int d, double psi, double t_end) {
  const double s0 = 2.0;
  const VectorXd x0 =
      (VectorXd(6) << 0, 0, 0.05, s0 * std::cos(psi), s0 * std::sin(psi), 0).finished();
  sim::Options o;
  o.t_end = t_end;
  return sim::simulate(block(d), x0, o, "event");
}

TEST(EventFriction3d, AfterAnImpactSlidesToRestAsTheClosedForm) {
  for (int d : {2, 4})
    for (double a : {0.0, 0.5, 0.3}) {
      const double psi = a * kPi / d;
      const sim::Trajectory tr = sliding_landing(d, psi, 1.5);
      const std::string at = "d = " + std::to_string(d) + ", psi = " + std::to_string(psi);
      ASSERT_EQ(tr.status, Status::kCompleted) << at << ": " << tr.message;
      ASSERT_GE(tr.events.size(), 2u) << at;
      const sim::Event& hit = tr.events.front();
      ASSERT_EQ(hit.type, EventType::kImpact) << at;
      EXPECT_NEAR(hit.t, std::sqrt(2 * 0.05 / kG), 1e-12) << at;
      const VectorXd& xp = hit.state_after;
      EXPECT_LE(std::abs(xp(5)), 1e-12) << at;  // inelastic
      const double u = std::hypot(xp(3), xp(4));
      ASSERT_GT(u, 0.1) << at;  // still sliding after the impact
      const mech::ConeSlide cf = mech::cone_slide(u, std::atan2(xp(4), xp(3)), kMu, kG, d);
      EXPECT_EQ(tr.events.back().type, EventType::kStick) << at;
      EXPECT_LE(rel(tr.events.back().t, hit.t + cf.t_stop), kRel) << at;
      EXPECT_LE(rel(tr.final_state(0), xp(0) + cf.x), kRel) << at;
      EXPECT_LE(rel(tr.final_state(1), xp(1) + cf.y), kRel) << at;
    }
}

// The same landing's impulses as the event reports them, along both
// tangents (Event::friction_impulse2 was left empty by the exact method,
// found on bullet3's r2d2, docs/contacts.md). Closed forms for the point
// mass m = 2 landing at w = sqrt(2 g 0.05) while sliding at s0 = 2 m/s
// along psi: P_N = m w; the law's friction impulse is the projection of
// -m s onto the polygon mu P_N conv{D_i} (m s0 = 4 is far outside it,
// mu P_N = 0.59): on an edge's region (psi = 0, and 0.3 pi/d, whose offset
// from the vertex stays in its normal cone) the vertex -mu P_N D_0; on the
// bisector psi = pi/(2d) the middle of face 0, -mu cos(pi/(2d)) P_N
// (cos psi, sin psi). The velocity jump is P / m on each axis (M = m I,
// t = x, t2 = y). Tolerance 1e-12: the law's LCP on 2d + 2 unknowns of
// size O(1) rounds at ~1e-15; a missing or misattributed impulse is O(0.1).
TEST(EventFriction3d, TheLandingsFrictionImpulseIsReportedAlongBothTangents) {
  const double mass = 2.0, w = std::sqrt(2 * kG * 0.05), pn = mass * w;
  for (int d : {2, 4})
    for (double a : {0.0, 0.5, 0.3}) {
      const double psi = a * kPi / d;
      const sim::Trajectory tr = sliding_landing(d, psi, 0.2);
      const std::string at = "d = " + std::to_string(d) + ", psi = " + std::to_string(psi);
      ASSERT_EQ(tr.status, Status::kCompleted) << at << ": " << tr.message;
      ASSERT_FALSE(tr.events.empty()) << at;
      const sim::Event& hit = tr.events.front();
      ASSERT_EQ(hit.type, EventType::kImpact) << at;
      ASSERT_EQ(hit.impulse.size(), 1) << at;
      ASSERT_EQ(hit.friction_impulse.size(), 1) << at;
      ASSERT_EQ(hit.friction_impulse2.size(), 1) << at;
      EXPECT_NEAR(hit.impulse(0), pn, 1e-12) << at;
      const double reach = a == 0.5 ? kMu * std::cos(kPi / (2 * d)) * pn : kMu * pn;
      const double want1 = a == 0.5 ? -reach * std::cos(psi) : -reach;
      const double want2 = a == 0.5 ? -reach * std::sin(psi) : 0.0;
      EXPECT_NEAR(hit.friction_impulse(0), want1, 1e-12) << at;
      EXPECT_NEAR(hit.friction_impulse2(0), want2, 1e-12) << at;
      const VectorXd dv = hit.state_after.tail(3) - hit.state_before.tail(3);
      EXPECT_NEAR(mass * dv(0), hit.friction_impulse(0), 1e-12) << at;
      EXPECT_NEAR(mass * dv(1), hit.friction_impulse2(0), 1e-12) << at;
    }
}

}  // namespace
}  // namespace lcsim
