// Backward Euler with Coulomb friction, planar and 3-D (issue 27,
// src/sim/stepping/euler_friction.cpp): a block sliding to rest on a floor
// (planar, and 3-D at several headings with d = 4) against the closed forms,
// first order in h; a block on an incline stuck (mu > tan alpha) and sliding
// (mu < tan alpha); the energy never rising over seeded random models; the
// samples' stick / slip labels; the refusal of asymmetric D or K.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>
#include <string>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kG = 9.81;

sim::Trajectory run_euler(const mech::Model& model, const VectorXd& x0, double t_end, double h) {
  sim::Options o;
  o.t_end = t_end;
  o.h = h;
  return sim::make_integrator("euler")->run(model, x0, o);
}

// A unit mass on a plane inclined by alpha, coordinates (s, n) along and
// normal to it: f = g (-sin alpha, -cos alpha), contact n >= 0, friction
// along s with mu (alpha = 0: the floor).
mech::Model incline(double alpha, double mu) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  m.E = Eigen::RowVector2d(0, 1).sparseView();
  m.f = Eigen::Vector2d(-kG * std::sin(alpha), -kG * std::cos(alpha));
  mech::fill_defaults(m);
  m.friction.emplace_back(0, Eigen::Vector2d(1, 0), mu);
  return mech::model_of(m, "incline");
}

// Where a run first has zero sliding velocity (below 1e-12 of the initial
// speed: a stuck velocity is v_free + W^-1 t' lambda_T, a cancellation of
// terms of the initial speed's size, exact to a few eps of it, and far
// below the last sliding step's speed, a fraction of mu g h >= 1e-3 m/s).
struct Stop {
  double t = -1.0, s = 0.0;
};
Stop first_stop(const sim::Trajectory& tr, double v0) {
  for (const sim::Sample& s : tr.samples)
    if (s.t > 0.0 && std::abs(s.x(2)) <= 1e-12 * std::abs(v0)) return {s.t, s.x(0)};
  return {};
}

// The discrete motion of a block decelerating at a from v0 (|v0| > 0,
// a > 0 against it). Backward Euler takes a off the speed per step (the
// normal impulse is m g cos(alpha) h exactly: the gap stays 0; the friction
// impulse mu times it) and moves by h times the step's end speed. With
// t* = |v0|/a = (n + phi) h, 0 <= phi < 1, it slides n steps and stops in
// step n + 1 (at t* when phi = 0), so 0 <= t_stop - t* <= h, and it has
// moved h sum_{i=1..n} (v0 - sign(v0) a i h) = s* - h v0/2 + sign(v0) a h^2
// phi (1 - phi)/2 with s* = v0 t*/2: the error is -h v0/2 + r,
// |r| <= a h^2/8, first order with constant v0/2.
void expect_stop_first_order(const mech::Model& model, double v0, double a) {
  const double t_star = std::abs(v0) / a, s_star = v0 * t_star / 2;
  const VectorXd x0 = (VectorXd(4) << 0, 0, v0, 0).finished();
  double err_prev = 0.0;
  for (double h : {1e-3, 5e-4}) {
    const sim::Trajectory tr = run_euler(model, x0, t_star + 0.05, h);
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    const Stop st = first_stop(tr, v0);
    ASSERT_GT(st.t, 0.0) << "h = " << h;
    // 1e-9 s: the rounding of t* and of the step count's times.
    EXPECT_GE(st.t - t_star, -1e-9) << "h = " << h;
    EXPECT_LE(st.t - t_star, h + 1e-9) << "h = " << h;
    // a h^2/8 (the remainder above) plus 1e-12 m, the rounding of ~10^3
    // sums of terms below 2 m.
    const double err = st.s - s_star;
    EXPECT_NEAR(err, -h * v0 / 2, a * h * h / 8 + 1e-12) << "h = " << h;
    std::printf("[ euler    ] v0 = %g, a = %g, h = %g: t_stop - t* = %.3e, s - s* = %.6e\n", v0, a,
                h, st.t - t_star, err);
    // First order: halving h halves the error. The remainder is at most
    // a h/(4 |v0|) of it (2.5e-3 here), so the ratio is 2 within 0.02.
    if (err_prev != 0.0) {
      EXPECT_NEAR(err_prev / err, 2.0, 0.02) << "h = " << h;
    }
    err_prev = err;
    // While it slides the mean friction force is -sign(v0) mu m g cos(alpha),
    // and the contact is labelled slip in the direction of v0; at rest stick.
    for (const sim::Sample& s : tr.samples) {
      if (s.t == 0.0 || std::abs(s.t - st.t) <= h) continue;  // the stopping step
      ASSERT_EQ(s.friction_mode.size(), 1u);
      const sim::FrictionMode slip =
          v0 > 0 ? sim::FrictionMode::kSlipPositive : sim::FrictionMode::kSlipNegative;
      EXPECT_EQ(s.friction_mode[0], s.t < st.t ? slip : sim::FrictionMode::kStick) << s.t;
    }
  }
}

// The block on the floor (alpha = 0): mu = 0.4, v0 = 2 m/s, a = mu g
// (robots/block_on_floor_friction.yaml's closed form: t* = 0.509684 s).
TEST(EulerFriction, BlockOnFloorStopsAtTheClosedFormFirstOrder) {
  expect_stop_first_order(incline(0.0, 0.4), 2.0, 0.4 * kG);
  expect_stop_first_order(incline(0.0, 0.4), -2.0, 0.4 * kG);
}

// The incline, mu = 0.5 > tan(0.3) (robots/incline_friction.yaml): sliding
// down at v0 = -1.5 m/s it decelerates at a = g (mu cos - sin) and sticks;
// then it stays (next test).
TEST(EulerFriction, InclineMuAboveTanSticksAtTheClosedForm) {
  const double alpha = 0.3, mu = 0.5;
  expect_stop_first_order(incline(alpha, mu), -1.5, kG * (mu * std::cos(alpha) - std::sin(alpha)));
}

// At rest on the incline with mu > tan alpha the block stays: the stick
// impulse cancels gravity's along-slope impulse exactly (W = I), so its
// position and speed stay at zero to 1e-15 (the rounding of one LU solve
// of terms of size g h), every step labelled stick, with the friction force
// m g sin(alpha) up the slope (1e-12 N: rounding of the 3 x 3 LCP).
TEST(EulerFriction, InclineMuAboveTanStaysAtRest) {
  const double alpha = 0.3, mu = 0.5;
  const sim::Trajectory tr = run_euler(incline(alpha, mu), VectorXd::Zero(4), 1.0, 1e-3);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  ASSERT_GT(tr.samples.size(), 1000u);
  for (const sim::Sample& s : tr.samples) {
    EXPECT_NEAR(s.x(0), 0.0, 1e-15) << s.t;
    EXPECT_NEAR(s.x(2), 0.0, 1e-15) << s.t;
    if (s.t == 0.0) continue;
    EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kStick) << s.t;
    EXPECT_NEAR(s.u_t(0), kG * std::sin(alpha), 1e-12) << s.t;
    EXPECT_NEAR(s.u(0), kG * std::cos(alpha), 1e-12) << s.t;
  }
}

// mu = 0.3 < tan(0.5) = 0.546: from rest it slides down at a = g (sin -
// mu cos) and never sticks. Backward Euler: v_n = -a n h exactly and s_n =
// -a h^2 n (n + 1)/2 = s(t) - a h t/2 with s(t) = -a t^2/2: the error at T
// is -a h T/2 to rounding (1e-12 m over 10^3 to 2 10^3 steps of terms below
// 1 m), first order with ratio 2 (within 1e-6: the same rounding over an
// error of 1e-3 m).
TEST(EulerFriction, InclineMuBelowTanSlidesAtTheClosedFormFirstOrder) {
  const double alpha = 0.5, mu = 0.3, T = 1.0;
  const double a = kG * (std::sin(alpha) - mu * std::cos(alpha));
  double err_prev = 0.0;
  for (double h : {1e-3, 5e-4}) {
    const sim::Trajectory tr = run_euler(incline(alpha, mu), VectorXd::Zero(4), T, h);
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    const double err = tr.final_state(0) - (-a * T * T / 2);
    EXPECT_NEAR(err, -a * h * T / 2, 1e-12) << "h = " << h;
    EXPECT_NEAR(tr.final_state(2), -a * T, 1e-12) << "h = " << h;
    if (err_prev != 0.0) {
      EXPECT_NEAR(err / err_prev, 0.5, 1e-6);
    }
    err_prev = err;
    for (const sim::Sample& s : tr.samples) {
      if (s.t == 0.0) continue;
      EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kSlipNegative) << s.t;
      EXPECT_NEAR(s.u_t(0), mu * kG * std::cos(alpha), 1e-12) << s.t;  // up the slope
    }
  }
}

// A point mass on the floor z >= 0, friction on the cone of 2d edges (t = x,
// t2 = y), mu = 0.3, sliding at 1 m/s at the angle psi from x.
mech::Model block3d(int d) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(3, 3).sparseView();
  m.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  m.f = Eigen::Vector3d(0, 0, -kG);
  mech::fill_defaults(m);
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), 0.3);
  c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
  c.edges = d;
  m.friction.push_back(c);
  return mech::model_of(m, "block3d");
}

// Against mech::cone_slide at d = 4, headings on an edge, on a bisector and
// between. Why the bounds hold (the argument of test_mj_friction3d.cpp's
// theta = 1 case, which is this step: the normal row at the position level
// reads E v+ + 0/h >= 0 on the floor): along the bisector b of the face the
// velocity ends on, v.b falls at mu g cos(pi/(2d)) per unit time in the
// closed form and in every step, so the discrete stop is within [0, h) after
// the closed form's; the implicit step ends on the bisector (or stays on the
// edge) as the closed form does: the final heading to 1e-9 rad; the
// positions are right rectangles of a velocity that equals the closed form's
// at every step but the turn's and the last moving one (each off by at most
// mu g h): displacement error -h v0/2 + r per component, |r| <= 2 mu g h^2,
// first order with the error halving with h (ratio 2 within 0.1: r is at
// most 1.2% of the error at h = 1e-3).
TEST(EulerFriction, Block3dSlidesAsConeSlideFirstOrder) {
  const double pi = std::acos(-1.0), mu = 0.3;
  const int d = 4;
  for (double psi : {0.0, pi / 8, pi / 12, pi / 2 + 0.7 * pi / d, 2.0}) {
    const mech::ConeSlide cs = mech::cone_slide(1.0, psi, mu, kG, d);
    const VectorXd x0 = (VectorXd(6) << 0, 0, 0, std::cos(psi), std::sin(psi), 0).finished();
    double err_prev = 0.0;
    for (double h : {1e-3, 5e-4}) {
      const std::string at = "psi = " + std::to_string(psi) + ", h = " + std::to_string(h);
      sim::Options o;
      o.t_end = cs.t_stop + 0.05;
      o.h = h;
      const sim::Trajectory tr = sim::make_integrator("euler")->run(block3d(d), x0, o);
      ASSERT_EQ(tr.status, Status::kOk) << tr.message;
      double t_stop = -1.0, x = 0.0, y = 0.0, heading = 0.0;
      for (const sim::Sample& s : tr.samples) {
        const bool rest = std::hypot(s.x(3), s.x(4)) <= 1e-12;
        if (rest && s.t > 0.0) {
          t_stop = s.t;
          x = s.x(0);
          y = s.x(1);
          EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kStick) << at;
          break;
        }
        heading = std::atan2(s.x(4), s.x(3));
        if (s.t > 0.0) {
          EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kSlip) << at << ", t = " << s.t;
        }
      }
      ASSERT_GT(t_stop, 0.0) << at;
      EXPECT_GE(t_stop - cs.t_stop, -1e-9) << at;
      EXPECT_LT(t_stop - cs.t_stop, h + 1e-9) << at;
      EXPECT_NEAR(std::remainder(heading - cs.heading, 2 * pi), 0.0, 1e-9) << at;
      const double rem = 2 * mu * kG * h * h;
      EXPECT_NEAR(x - cs.x, -h * std::cos(psi) / 2, rem) << at;
      EXPECT_NEAR(y - cs.y, -h * std::sin(psi) / 2, rem) << at;
      const double err = std::hypot(x - cs.x, y - cs.y);
      std::printf("[ euler 3d ] psi = %.4f, h = %g: t_stop - t* = %.3e, |error| = %.6e\n", psi, h,
                  t_stop - cs.t_stop, err);
      if (err_prev != 0.0) {
        EXPECT_NEAR(err_prev / err, 2.0, 0.1) << at;
      }
      err_prev = err;
    }
  }
}

// A vector orthogonal to the rows of B (Gram–Schmidt on a random one).
VectorXd orthogonal_to(const MatrixXd& B, std::mt19937& rng) {
  std::normal_distribution<double> n01;
  VectorXd t(B.cols());
  for (Eigen::Index i = 0; i < t.size(); ++i) t(i) = n01(rng);
  for (Eigen::Index r = 0; r < B.rows(); ++r)
    t -= (B.row(r).dot(t) / B.row(r).squaredNorm()) * B.row(r).transpose();
  return t;
}

// A random model: N = 3..5 coordinates, SPD M, PSD K and D (symmetric),
// a constant force, 1..3 contacts each with friction (mu in [0, 1]; planar or
// 3-D with d in 1..4), a start on or above every constraint.
struct Random {
  mech::Model model;
  VectorXd x0;
};
Random random_model(std::mt19937& rng) {
  std::normal_distribution<double> n01;
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  const int N = 3 + static_cast<int>(rng() % 3), k = 1 + static_cast<int>(rng() % 3);
  auto rand_mat = [&](int r, int c) {
    MatrixXd A(r, c);
    for (int i = 0; i < r; ++i)
      for (int j = 0; j < c; ++j) A(i, j) = n01(rng);
    return A;
  };
  mech::MechanicalModel m;
  const MatrixXd A = rand_mat(N, N), B = rand_mat(N, N), C = rand_mat(N, N);
  m.M = (A * A.transpose() + N * MatrixXd::Identity(N, N)).sparseView();
  m.K = (5.0 * u01(rng) * B * B.transpose()).sparseView();
  m.D = (0.5 * u01(rng) * C * C.transpose()).sparseView();
  m.f = 5.0 * rand_mat(N, 1);
  const MatrixXd E = rand_mat(k, N);
  m.E = E.sparseView();
  const VectorXd q0 = rand_mat(N, 1), v0 = rand_mat(N, 1);
  m.g = -E * q0;
  for (int i = 0; i < k; ++i)
    if (u01(rng) < 0.5) m.g(i) += 0.3 * u01(rng);  // half the contacts open at the start
  mech::fill_defaults(m);
  for (int i = 0; i < k; ++i) {
    const VectorXd t = orthogonal_to(E.row(i), rng);
    mech::FrictionalContact fc(i, t, u01(rng));
    if (u01(rng) < 0.5) {  // 3-D
      MatrixXd nt(2, N);
      nt << E.row(i), t.transpose();
      const VectorXd t2 = orthogonal_to(nt, rng);
      fc.tangent2 = (t2 * (t.norm() / t2.norm())).sparseView();
      fc.edges = 1 + static_cast<int>(rng() % 4);
    }
    m.friction.push_back(fc);
  }
  Random r{mech::model_of(m, "random"), VectorXd(2 * N)};
  r.x0 << q0, v0;
  return r;
}

// Backward Euler dissipates: with q+ = q + h v+ and M (v+ - v) = h (f - D v+
// - K q+) + E' lambda_N + T' lambda_T, the energy T + V (f in the potential)
// changes by
//   -|v+ - v|_M^2/2 - h |v+|_D^2 - h^2 |v+|_K^2/2 + lambda_N' E v+
//   + lambda_T' T v+,
// where lambda_N' E v+ = -lambda_N' (E q + g)/h <= 0 (a positive impulse
// closes its gap at the step's end from a gap >= 0) and the friction term is
// <= 0 (maximal dissipation: stick has T v+ = 0, slip opposes it). So the
// energy never rises from one step to the next; the tolerance 1e-9 of the
// energy's scale (|E| + the kinetic energy at the start + 1 J) covers the
// rounding of the step's LCP (solved to 1e-12 relative) over the scale.
// A run may end on a step LCP that no solver solves (a Painlevé-type
// coupling: numerical trouble, never a false "completed"); most complete.
TEST(EulerFriction, EnergyNeverRisesOnRandomModels) {
  std::mt19937 rng(20261127);
  int completed = 0, failed = 0;
  long steps = 0, solves = 0, sticks = 0, slips = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Random r = random_model(rng);
    ASSERT_FALSE(mech::check_model(r.model)) << trial;
    sim::Options o;
    o.t_end = 1.0;
    o.h = 2e-3;
    const sim::Trajectory tr = sim::make_integrator("euler")->run(r.model, r.x0, o);
    if (tr.status != Status::kOk) {
      EXPECT_EQ(tr.status, Status::kNumericalFailure) << trial << ": " << tr.message;
      ++failed;
      continue;
    }
    ++completed;
    steps += tr.steps;
    solves += tr.lcp_solves;
    const mech::MechanicalModel& m = *r.model.mechanical;
    const int N = m.dofs();
    const double scale =
        std::abs(tr.energy_initial) + 0.5 * r.x0.tail(N).dot(m.M * r.x0.tail(N)) + 1.0;
    double prev = tr.energy_initial;
    for (const sim::Sample& s : tr.samples) {
      const double e = mech::total_energy(m, s.x.head(N), s.x.tail(N));
      EXPECT_LE(e, prev + 1e-9 * scale) << "trial " << trial << ", t = " << s.t;
      prev = e;
      // The step's LCP over every constraint, though solved on an active
      // set: each gap at the step's end >= 0 and a positive force only on a
      // closed gap, to 1e-9 m (rounding of gaps formed from terms of a few
      // metres, and of an LCP solved to 1e-12 relative, divided by h).
      for (sim::FrictionMode fm : s.friction_mode) {
        sticks += fm == sim::FrictionMode::kStick;
        slips += fm != sim::FrictionMode::kStick && fm != sim::FrictionMode::kOpen;
      }
      for (int i = 0; i < m.num_constraints(); ++i) {
        EXPECT_GE(s.y(i), -1e-9) << "trial " << trial << ", t = " << s.t;
        if (s.u(i) > 0.0) {
          EXPECT_LE(s.y(i), 1e-9) << "trial " << trial << ", t = " << s.t;
        }
      }
    }
    EXPECT_LE(tr.energy_final, tr.energy_initial + 1e-9 * scale) << trial;
  }
  std::printf(
      "[ random   ] %d completed (%ld steps, %ld LCP solves), %d failed as numerical "
      "trouble\n",
      completed, steps, solves, failed);
  EXPECT_GE(completed, 180);
  // The runs exercise both branches of Coulomb's law (counted over samples
  // and contacts): bounds well below what these seeds give (6829 stick,
  // 44074 slip).
  std::printf("[ random   ] contact samples: %ld stick, %ld slip\n", sticks, slips);
  EXPECT_GE(sticks, 1000);
  EXPECT_GE(slips, 1000);
}

// A Painlevé-type contact (W_NN - mu W_NT = 1 - 3 < 0: M = I, normal
// (0, 1), tangent (1, 3), mu = 1) sliding along +t: no slipping motion
// keeps the block on the floor, and the exact method refuses the phase
// (docs/friction.md). The step's LCP has a solution (Stewart and Trinkle's
// step is solvable by Lemke's method): the slide stops in the first step,
// a tangential impact, as Moreau–Jean's step (theta = 1) does. With the
// gap at zero the position-level normal row E v+ + (E q + g)/h reads
// E v+ + 0, Moreau–Jean's, so the two runs agree to the rounding of that
// gap (1e-12 on states of size 2).
TEST(EulerFriction, PainleveTypeSlideStopsInOneStepAsMoreauJeans) {
  mech::MechanicalModel m = *incline(0.0, 1.0).mechanical;
  m.friction[0] = mech::FrictionalContact(0, Eigen::Vector2d(1, 3), 1.0);
  const mech::Model model = mech::model_of(m, "painleve");
  const VectorXd x0 = (VectorXd(4) << 0, 0, 2, 0).finished();
  const sim::Trajectory e = run_euler(model, x0, 0.1, 1e-3);
  sim::Options o;
  o.t_end = 0.1;
  o.h = 1e-3;
  o.theta = 1.0;
  const sim::Trajectory mj = sim::make_integrator("moreau-jean")->run(model, x0, o);
  ASSERT_EQ(e.status, Status::kOk) << e.message;
  ASSERT_EQ(mj.status, Status::kOk) << mj.message;
  ASSERT_EQ(e.samples.size(), mj.samples.size());
  for (size_t i = 0; i < e.samples.size(); ++i)
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(e.samples[i].x(j), mj.samples[i].x(j), 1e-12) << i;
  // Stopped after the first step: sliding speed t'v = v_x + 3 v_y zero.
  EXPECT_NEAR(e.samples[1].x(2) + 3 * e.samples[1].x(3), 0.0, 1e-12);
  EXPECT_LE(e.energy_final, 1e-12);
}

// A force input (docs/inputs.md) pushing the block on the floor along x,
// push(t) = 10 t N (m = 1 kg, mu = 0.4): it sticks while push <= mu m g,
// i.e. up to t_s = mu g/10, then v(t) = 5 (t - t_s)^2. Backward Euler takes
// the push at the step's end, as on euler's LCS path: the block sticks (at
// rest to 1e-15: the stick impulse cancels h push, below 4e-3 m/s, to a few
// ulp) while push(t_{n+1}) <= mu g and then gains
// h (push(t_{n+1}) - mu g) per step, a right Riemann sum of the linear
// 10 (t - t_s): with t_s = (m - phi) h (m the first sliding step), the
// error at T is 5 h (T - t_s) + 5 phi (1 - phi) h^2, so within 5 h^2/4 of
// 5 h (T - t_s) (plus 1e-12 m/s, the rounding of 10^3 sums of terms below
// 2 m/s). The same as Moreau–Jean at theta = 1 (its step force is f(t0 + h)
// there, the gap stays at zero) to 1e-12.
TEST(EulerFriction, ForceInputStartsTheSlideAtTheClosedForm) {
  const mech::Model model = io::parse_matrix_model(R"(
name: pushed_block
inputs:
  - {name: push, kind: pwl, points: [[0, 0], [1, 10]]}
mechanical:
  M: [[1, 0], [0, 1]]
  E: [[0, 1]]
  f: [0, -9.81]
  force_inputs: [{input: push, gain: [1, 0]}]
  friction:
    - {contact: 0, tangent: [1, 0], mu: 0.4}
initial: [0, 0, 0, 0]
)",
                                                   "pushed.yaml");
  const double t_s = 0.4 * kG / 10, T = 1.0;
  for (double h : {1e-3, 5e-4}) {
    const sim::Trajectory tr = run_euler(model, model.initial, T, h);
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    for (const sim::Sample& s : tr.samples) {
      if (s.t == 0.0 || s.t > t_s) continue;
      EXPECT_NEAR(s.x(0), 0.0, 1e-15) << s.t;
      EXPECT_NEAR(s.x(2), 0.0, 1e-15) << s.t;
      EXPECT_EQ(s.friction_mode[0], sim::FrictionMode::kStick) << s.t;
    }
    const double err = tr.final_state(2) - 5 * (T - t_s) * (T - t_s);
    EXPECT_NEAR(err, 5 * h * (T - t_s), 5 * h * h / 4 + 1e-12) << "h = " << h;
    std::printf("[ euler    ] pushed block, h = %g: v(T) error %.6e (5 h (T - t_s) = %.6e)\n", h,
                err, 5 * h * (T - t_s));
    sim::Options o;
    o.t_end = T;
    o.h = h;
    o.theta = 1.0;
    const sim::Trajectory mj = sim::make_integrator("moreau-jean")->run(model, model.initial, o);
    ASSERT_EQ(mj.status, Status::kOk) << mj.message;
    for (int j = 0; j < 4; ++j) EXPECT_NEAR(tr.final_state(j), mj.final_state(j), 1e-12) << j;
  }
}

// Euler's LCS path takes asymmetric D or K; with friction the step factors
// W = M + h D + h^2 K by Cholesky, so such a model is refused by one line.
TEST(EulerFriction, AsymmetricDampingIsRefusedByName) {
  mech::MechanicalModel m = *incline(0.0, 0.4).mechanical;
  MatrixXd D = MatrixXd::Zero(2, 2);
  D(0, 1) = 1.0;
  m.D = D.sparseView();
  const sim::Trajectory tr =
      run_euler(mech::model_of(m, "gyro"), (VectorXd(4) << 0, 0, 1, 0).finished(), 0.1, 1e-3);
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_EQ(tr.message.rfind("method 'euler' with friction factors M + h D + h^2 K", 0), 0u)
      << tr.message;
  EXPECT_NE(tr.message.find("model 'gyro' has D"), std::string::npos) << tr.message;
}

}  // namespace
}  // namespace lcsim
