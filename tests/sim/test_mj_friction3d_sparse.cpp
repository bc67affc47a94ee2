// Moreau–Jean with 3-D Coulomb friction above the dense limit (issue 27,
// src/sim/stepping/cone_gs.cpp: block Gauss–Seidel over the contacts), and
// the outputs of the second tangent (Sample::u_t2, Sample::friction_facet):
// - many uncoupled blocks (more than 600 LCP unknowns, so the sparse path)
//   give each block's dense-path trajectory, itself checked against
//   mech::cone_slide (test_mj_friction3d.cpp);
// - a coupled 3-D cart chain: one step against the Stewart–Trinkle LCP
//   computed densely here from the step's definition and solved by Lemke;
// - a block on an incline steeper than its friction angle, pushed sideways,
//   against the closed form derived below (dense and sparse paths).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

constexpr double kG = 9.81, kMu = 0.3;
const double kPi = std::acos(-1.0);

// n uncoupled point masses (x, y, z) each on its floor z >= 0 under gravity,
// friction along x (t) and y (t2) with d[i] edge pairs; block i starts at
// speed s0 at the heading psi[i].
mech::Model blocks(const std::vector<int>& d, const std::vector<double>& psi, double s0) {
  const int n = static_cast<int>(d.size()), N = 3 * n;
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(N, N).sparseView();
  MatrixXd E = MatrixXd::Zero(n, N);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < n; ++i) {
    E(i, 3 * i + 2) = 1.0;
    m.f(3 * i + 2) = -kG;
  }
  m.E = E.sparseView();
  mech::fill_defaults(m);
  for (int i = 0; i < n; ++i) {
    mech::FrictionalContact c(i, VectorXd::Unit(N, 3 * i), kMu);
    c.tangent2 = VectorXd::Unit(N, 3 * i + 1).sparseView();
    c.edges = d[static_cast<size_t>(i)];
    m.friction.push_back(c);
  }
  mech::Model model = mech::model_of(m, "blocks");
  model.initial = VectorXd::Zero(2 * N);
  for (int i = 0; i < n; ++i) {
    model.initial(N + 3 * i) = s0 * std::cos(psi[static_cast<size_t>(i)]);
    model.initial(N + 3 * i + 1) = s0 * std::sin(psi[static_cast<size_t>(i)]);
  }
  return model;
}

sim::Trajectory run_mj(const mech::Model& model, const VectorXd& x0, double h, double t_end) {
  sim::Options o;
  o.t_end = t_end;
  o.h = h;
  return sim::make_integrator("moreau-jean")->run(model, x0, o);
}

// 70 blocks, d = 2, 3, 4, 8 and 1 in turn (LCP unknowns sum (2d + 2) = 14
// (6 + 8 + 10 + 18 + 4) = 644 > 600: the sparse path), at headings on
// each d's edges, bisectors and between, against mech::cone_slide with the
// bounds of test_mj_friction3d.cpp (MixedPlanarAnd3dContacts): the stop
// within [0, 2h) after the closed form's (a step may end with a gap of
// +1e-21, rounding of the normal impulse m g h, and the frictionless step's
// active-set rule then leaves the contact out for one step, costing that
// step's friction: one step of stop time), the heading at rest to 1e-9 rad,
// the displacement within 2 mu g h^2 (trapezoids on the linear phases) plus,
// for such a skipped step, the speed mu g h it leaves for at most t_stop.
// d = 1 blocks off their edge never stop (no friction along t2): their
// velocity along t2 stays s0 sin(psi) exactly.
TEST(MjFriction3dSparse, ManyBlocksStopAsConeSlideSays) {
  std::vector<int> d;
  std::vector<double> psi;
  const int ds[] = {2, 3, 4, 8, 1};
  for (int i = 0; i < 70; ++i) {
    const int di = ds[i % 5];
    d.push_back(di);
    psi.push_back(kPi / di * (0.25 * (i / 5)) + (i % 2 ? 0.0 : 0.1));
  }
  const double h = 1e-3, t_end = 0.55;  // past every stop of d >= 2 (<= 0.48 s at d = 2)
  const mech::Model all = blocks(d, psi, 1.0);
  const sim::Trajectory tr = run_mj(all, all.initial, h, t_end);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  const int N = 3 * 70;
  int checked = 0;
  for (int i = 0; i < 70; ++i) {
    const int di = d[static_cast<size_t>(i)];
    const double pi = psi[static_cast<size_t>(i)];
    const std::string at = "block " + std::to_string(i) + ", d = " + std::to_string(di);
    if (di == 1) {
      EXPECT_EQ(tr.samples.back().x(N + 3 * i + 1), std::sin(pi)) << at;
      continue;
    }
    const mech::ConeSlide cs = mech::cone_slide(1.0, pi, kMu, kG, di);
    double t_stop = -1.0, x = 0.0, y = 0.0, heading = 0.0;
    for (const sim::Sample& s : tr.samples) {
      const double vx = s.x(N + 3 * i), vy = s.x(N + 3 * i + 1);
      if (s.t > 0.0 && std::hypot(vx, vy) <= 1e-12) {
        t_stop = s.t, x = s.x(3 * i), y = s.x(3 * i + 1);
        break;
      }
      if (std::hypot(vx, vy) > 1e-12) heading = std::atan2(vy, vx);
    }
    ASSERT_GT(t_stop, 0.0) << at;
    EXPECT_GE(t_stop - cs.t_stop, -1e-9) << at;
    EXPECT_LT(t_stop - cs.t_stop, 2 * h + 1e-9) << at;
    EXPECT_NEAR(std::remainder(heading - cs.heading, 2 * kPi), 0.0, 1e-9) << at;
    const double rem = 2 * kMu * kG * h * h + kMu * kG * h * cs.t_stop;
    EXPECT_NEAR(x, cs.x, rem) << at;
    EXPECT_NEAR(y, cs.y, rem) << at;
    ++checked;
  }
  EXPECT_EQ(checked, 56);
}

// The outputs of a slide on a bisector (d = 4, psi = pi/8): the force on the
// opposite face (between edges 4 and 5), of size mu g cos(pi/8) against the
// velocity: u_t = -mu g cos(pi/8) cos(pi/8), u_t2 = -mu g cos(pi/8) sin(pi/8)
// (N, unit mass), each to rounding (1e-12 relative) of the step's implicit
// solve, and the facet face 4 ("slip-face-4") while it slides.
TEST(MjFriction3dSparse, SecondTangentAndFacetInTheSamples) {
  const double a = kPi / 8;
  const mech::Model one = blocks({4}, {a}, 1.0);
  const sim::Trajectory tr = run_mj(one, one.initial, 1e-3, 0.2);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  int sliding = 0;
  for (const sim::Sample& s : tr.samples) {
    if (s.t == 0.0) continue;
    ASSERT_EQ(s.u_t2.size(), 1);
    ASSERT_EQ(s.friction_facet.size(), 1u);
    ASSERT_EQ(s.friction_mode[0], sim::FrictionMode::kSlip) << s.t;
    ++sliding;
    const double F = kMu * kG * std::cos(a);
    EXPECT_NEAR(s.u_t(0), -F * std::cos(a), 1e-12 * F);
    EXPECT_NEAR(s.u_t2(0), -F * std::sin(a), 1e-12 * F);
    EXPECT_EQ(sim::friction_mode_text(s.friction_mode[0], s.friction_facet[0]), "slip-face-4");
  }
  EXPECT_GT(sliding, 100);
  // A planar model has neither (its outputs stay as they were).
  mech::MechanicalModel planar = *one.mechanical;
  planar.friction[0].tangent2 = Eigen::SparseVector<double>();
  planar.friction[0].edges = 0;
  const sim::Trajectory p = run_mj(mech::model_of(planar, "planar"), one.initial, 1e-3, 0.01);
  ASSERT_EQ(p.status, Status::kOk) << p.message;
  EXPECT_EQ(p.samples.back().u_t2.size(), 0);
  EXPECT_TRUE(p.samples.back().friction_facet.empty());
}

// The 3-D cart chain (bench/bench_mj_friction3d.cpp): cart i has (x_i, y_i,
// z_i), unit masses, springs k_s between neighbours in x and in y, floors
// z_i >= 0, gravity, friction along x_i and y_i with d edge pairs.
mech::Model chain3d(int n, double k_s, int d) {
  const int N = 3 * n;
  std::vector<Eigen::Triplet<double>> k;
  for (int i = 0; i + 1 < n; ++i)
    for (int c = 0; c < 2; ++c) {
      const int a = 3 * i + c, b = 3 * i + 3 + c;
      k.emplace_back(a, a, k_s);
      k.emplace_back(b, b, k_s);
      k.emplace_back(a, b, -k_s);
      k.emplace_back(b, a, -k_s);
    }
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(N, N).sparseView();
  m.K.resize(N, N);
  m.K.setFromTriplets(k.begin(), k.end());
  MatrixXd E = MatrixXd::Zero(n, N);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < n; ++i) E(i, 3 * i + 2) = 1.0, m.f(3 * i + 2) = -kG;
  m.E = E.sparseView();
  mech::fill_defaults(m);
  for (int i = 0; i < n; ++i) {
    mech::FrictionalContact c(i, VectorXd::Unit(N, 3 * i), kMu);
    c.tangent2 = VectorXd::Unit(N, 3 * i + 1).sparseView();
    c.edges = d;
    m.friction.push_back(c);
  }
  return mech::model_of(m, "chain3d");
}

// The step from its definition (moreau_jean.cpp, theta = 0.5): W = M +
// h^2 theta^2 K, v_free = v + h W^{-1}(f - K(q + h theta v)), G = [E; T;
// T2], the edges' Delassus matrix P (G W^{-1} G') P' and Stewart–Trinkle's
// LCP (impact::friction_cone_lcp) solved by Lemke, v+ = v_free + W^{-1} G'
// (lambda_N, P' beta).
VectorXd dense_cone_step(const mech::MechanicalModel& m, const VectorXd& x0, double h, int d) {
  const int N = m.dofs(), n = m.num_constraints();
  const double th = 0.5;
  const MatrixXd M = m.M, K = m.K, E = m.E;
  const VectorXd q = x0.head(N), v = x0.tail(N);
  const Eigen::LLT<MatrixXd> llt(MatrixXd(M + h * h * th * th * K));
  const VectorXd v_free = v + h * llt.solve(m.f - K * (q + h * th * v));
  MatrixXd G(3 * n, N);
  G.topRows(n) = E;
  for (int f = 0; f < n; ++f) {
    G.row(n + f) = VectorXd(m.friction[f].tangent).transpose();
    G.row(2 * n + f) = VectorXd(m.friction[f].tangent2).transpose();
  }
  MatrixXd P = MatrixXd::Zero(n + 2 * d * n, 3 * n);
  P.topLeftCorner(n, n).setIdentity();
  std::vector<int> normal_of, first, ds;
  for (int f = 0; f < n; ++f) {
    normal_of.push_back(f);
    first.push_back(2 * d * f);
    ds.push_back(d);
    for (int i = 0; i < 2 * d; ++i) {
      P(n + 2 * d * f + i, n + f) = std::cos(kPi * i / d);
      P(n + 2 * d * f + i, 2 * n + f) = std::sin(kPi * i / d);
    }
  }
  const MatrixXd WGt = llt.solve(G.transpose());
  const MatrixXd Wb = P * (G * WGt) * P.transpose();
  const VectorXd rate = P * (G * v_free);
  const impact::FrictionLcp p = impact::friction_cone_lcp(
      Wb, rate.head(n), rate.tail(2 * d * n), normal_of, first, ds, VectorXd::Constant(n, kMu));
  const lcp::Result r =
      impact::solve_friction_cone_lcp(p, *lcp::make_solver("lemke"), nullptr, nullptr);
  EXPECT_TRUE(r.ok()) << r.message;
  return v_free + WGt * (P.transpose() * r.z.head(n + 2 * d * n));
}

// 61 carts at d = 4: 61 (1 + 8 + 1) = 610 unknowns, above the dense limit.
// Velocities random in the plane with speeds from 0 to 0.06 m/s around the
// step's friction impulse mu g h = 0.029 m/s (h = 1e-2), so some carts stick
// and some slide, on edges and faces; the springs (k_s = 50) couple them.
// The sweeps stop at a natural residual of 1e-13 (1 + |b|) with |b| ~ 0.1 on
// a Delassus matrix with eigenvalues in [0.99, 1.01], so v+ is within ~1e-12
// of the LCP's; 1e-9 leaves the margin of the pivoting solver's rounding.
TEST(MjFriction3dSparse, CoupledChainStepEqualsTheDenseConeLcp) {
  const int n = 61, d = 4;
  const double h = 1e-2;
  const mech::Model model = chain3d(n, 50.0, d);
  const int N = 3 * n;
  int sticks = 0, slips = 0;
  for (unsigned seed = 1; seed <= 4; ++seed) {
    std::mt19937 gen(seed);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    VectorXd x0 = VectorXd::Zero(2 * N);
    for (int i = 0; i < n; ++i) {
      x0(3 * i) = 0.01 * (u(gen) - 0.5);  // springs stretched a little
      const double s = 0.06 * u(gen), a = 2 * kPi * u(gen);
      x0(N + 3 * i) = s * std::cos(a);
      x0(N + 3 * i + 1) = s * std::sin(a);
    }
    const VectorXd want = dense_cone_step(*model.mechanical, x0, h, d);
    const sim::Trajectory tr = run_mj(model, x0, h, h);
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    EXPECT_EQ(tr.lcp_solves, 1);  // the sweeps converged, no other solve
    const VectorXd v = tr.final_state.tail(N);
    EXPECT_LE((v - want).cwiseAbs().maxCoeff(), 1e-9) << "seed " << seed;
    for (int i = 0; i < n; ++i)
      (std::hypot(want(3 * i), want(3 * i + 1)) <= 1e-12 ? sticks : slips)++;
  }
  std::printf("coupled chain: %d sticking, %d sliding carts\n", sticks, slips);
  EXPECT_GT(sticks, 0);
  EXPECT_GT(slips, 0);
}

// ---- A block on an incline steeper than its friction angle, pushed sideways.
//
// The closed form. A point mass on a plane inclined at alpha (tan alpha >
// mu) pressed by m g cos(alpha); in the contact's frame (t, t2) gravity's
// tangential part is a constant drive a_g (|a_g| = g sin alpha) and the
// friction force per unit mass is c F, c = mu g cos(alpha), F in the polygon
// P_d of maximal dissipation: F = D_i, the vertex most opposed to the
// sliding velocity u, while u stays strictly inside vertex i's region (its
// angle within pi/(2d) of theta_i + pi). So, phase by phase, u is linear in
// time with the acceleration a_g + c D_i, the heading turning; the phase ends
// where u reaches a region's boundary (the direction b at theta_i + pi +-
// pi/(2d): a linear equation in time). There, with D_j the neighbour's
// vertex, either a_g + c D_j carries u on into region j (the next phase,
// force on edge j), or both sides push u back onto b, and u slides along b
// with the force on face (i, j): every point of that face has the component
// -c cos(pi/(2d)) along b, so u.b grows at a_g.b - c cos(pi/(2d)) and u
// stays on b (the face's weights take the component across b). The
// position is the integral of u, exact per phase.
struct InclineMotion {
  Eigen::Vector2d u, p;   // velocity and displacement along (t, t2) at T (m/s, m)
  int facet = -1;         // at T: 2i on edge i, 2i + 1 on face i
  Eigen::Vector2d accel;  // of the last phase (m/s^2)
  int phases = 0;
};

Eigen::Vector2d edge(int i, int d) { return {std::cos(kPi * i / d), std::sin(kPi * i / d)}; }
double cross(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  return a(0) * b(1) - a(1) * b(0);
}

// At a region boundary b (a velocity direction at pi (k + 1/2)/d, between
// vertex lo's region below it in angle and hi = lo + 1's above): the side
// whose acceleration carries u away from b (+1 into hi's, -1 into lo's), or
// 0 when both push u onto b (the face (lo, hi)).
int leave_boundary(const Eigen::Vector2d& ag, double c, int d, const Eigen::Vector2d& b, int lo,
                   int hi) {
  if (cross(b, ag + c * edge(hi, d)) > 0.0) return 1;
  if (cross(b, ag + c * edge(lo, d)) < 0.0) return -1;
  return 0;
}

InclineMotion incline_closed_form(const Eigen::Vector2d& ag, double c, int d,
                                  const Eigen::Vector2d& u0, double T) {
  const int n = 2 * d;
  auto wrap = [n](int i) { return ((i % n) + n) % n; };
  InclineMotion m;
  m.u = u0;
  m.p.setZero();
  double t = 0.0;
  int i = 0;  // the vertex most opposed to u0
  for (int k = 1; k < n; ++k)
    if (edge(k, d).dot(u0) < edge(i, d).dot(u0)) i = k;
  // u0 on a boundary (a tie with a neighbour, to rounding): the boundary's rule.
  int lo = -1;
  if (edge(wrap(i + 1), d).dot(u0) - edge(i, d).dot(u0) <= 1e-12 * u0.norm()) lo = i;
  if (edge(wrap(i - 1), d).dot(u0) - edge(i, d).dot(u0) <= 1e-12 * u0.norm()) lo = wrap(i - 1);
  int entered = 0;  // the side of region i whose boundary u is on (0: none)
  for (m.phases = 1; m.phases < 64; ++m.phases) {
    if (lo >= 0) {  // at a boundary: on into a region, or along the face
      const Eigen::Vector2d b = m.u.normalized();
      const int side = leave_boundary(ag, c, d, b, lo, wrap(lo + 1));
      if (side != 0) {
        i = side > 0 ? wrap(lo + 1) : lo;
        entered = -side;  // hi's lower boundary, or lo's upper one
        lo = -1;
        continue;
      }
      const double along = ag.dot(b) - c * std::cos(kPi / (2 * d)), rest = T - t;
      EXPECT_GT(m.u.dot(b) + along * rest, 0.0);  // it does not stop before T
      m.p += m.u * rest + 0.5 * along * rest * rest * b;
      m.u += along * rest * b;
      m.accel = along * b;
      m.facet = 2 * lo + 1;
      return m;
    }
    const Eigen::Vector2d a = ag + c * edge(i, d);
    double tau = T - t;
    int side = 0;  // -1: reaches the boundary toward vertex i - 1, +1 toward i + 1
    for (int sgn : {-1, 1}) {
      if (sgn == entered) continue;  // the boundary u is on (it leaves it)
      const double ang = kPi * i / d + kPi + sgn * kPi / (2 * d);
      const Eigen::Vector2d b(std::cos(ang), std::sin(ang));
      const double den = cross(a, b);
      if (den == 0.0) continue;
      const double when = -cross(m.u, b) / den;
      if (when > 0.0 && when < tau && (m.u + a * when).dot(b) > 0.0) tau = when, side = sgn;
    }
    m.p += m.u * tau + 0.5 * a * tau * tau;
    m.u += a * tau;
    t += tau;
    m.accel = a;
    m.facet = 2 * i;
    entered = 0;
    if (side == 0) return m;
    const double ang = kPi * i / d + kPi + side * kPi / (2 * d);
    const Eigen::Vector2d b(std::cos(ang), std::sin(ang));
    m.u = m.u.dot(b) * b;  // on the boundary
    lo = side > 0 ? i : wrap(i - 1);
  }
  ADD_FAILURE() << "more than 64 phases";
  return m;
}

struct InclineCase {
  int d;
  double gamma;  // the frame's turn: t at gamma from the downhill direction (rad)
};

// Blocks i on planes at alpha with normal n = (sin a, 0, cos a), downhill
// direction s = (cos a, 0, -sin a), across h = (0, 1, 0); the frame t = cos
// gamma s + sin gamma h, t2 = -sin gamma s + cos gamma h (orthonormal, so
// a_g = g sin(alpha) (cos gamma, -sin gamma)); each starts on its plane
// pushed across the slope at v0 h.
constexpr double kAlpha = 0.5, kV0 = 1.0;  // tan 0.5 = 0.546 > mu = 0.3

mech::Model inclines(const std::vector<InclineCase>& cases) {
  const int nb = static_cast<int>(cases.size()), N = 3 * nb;
  const Eigen::Vector3d nrm(std::sin(kAlpha), 0, std::cos(kAlpha)),
      down(std::cos(kAlpha), 0, -std::sin(kAlpha)), across(0, 1, 0);
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(N, N).sparseView();
  MatrixXd E = MatrixXd::Zero(nb, N);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < nb; ++i) E.block(i, 3 * i, 1, 3) = nrm.transpose(), m.f(3 * i + 2) = -kG;
  m.E = E.sparseView();
  mech::fill_defaults(m);
  for (int i = 0; i < nb; ++i) {
    const double g = cases[static_cast<size_t>(i)].gamma;
    VectorXd t = VectorXd::Zero(N), t2 = VectorXd::Zero(N);
    t.segment<3>(3 * i) = std::cos(g) * down + std::sin(g) * across;
    t2.segment<3>(3 * i) = -std::sin(g) * down + std::cos(g) * across;
    mech::FrictionalContact c(i, t, kMu);
    c.tangent2 = t2.sparseView();
    c.edges = cases[static_cast<size_t>(i)].d;
    m.friction.push_back(c);
  }
  mech::Model model = mech::model_of(m, "inclines");
  model.initial = VectorXd::Zero(2 * N);
  for (int i = 0; i < nb; ++i) model.initial(N + 3 * i + 1) = kV0;
  return model;
}

// Each block of a run against the closed form at T. Why the bounds hold:
// Moreau–Jean's step is the implicit (backward Euler) velocity update with
// the force of maximal dissipation for the step's end velocity, the normal
// impulse m g cos(alpha) h exactly; inside a phase its acceleration is the
// closed form's exactly, and the velocity lands on a region's boundary when
// the closed form's does (the implicit step cannot cross it with a force
// pushing back). So the velocities differ only by the steps holding a phase
// change, each by at most c |D_i - D_j| h <= 2 c h: |u_h - u| <= 2 c h per
// phase. The positions (theta = 1/2: trapezoids, exact on linear phases)
// then differ by at most T times that plus the change steps' 2 c h^2. The
// last phase's acceleration is exact to rounding of the step's solve (1e-9
// of g), and the facet at T is the closed form's.
void check_inclines(const std::vector<InclineCase>& cases, double h, double T) {
  const mech::Model model = inclines(cases);
  sim::Options o;
  o.t_end = T;
  o.h = h;
  o.dt_out = h;
  const sim::Trajectory tr = sim::make_integrator("moreau-jean")->run(model, model.initial, o);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  const int nb = static_cast<int>(cases.size()), N = 3 * nb;
  const sim::Sample &last = tr.samples.back(), &before = tr.samples[tr.samples.size() - 2];
  const double c = kMu * kG * std::cos(kAlpha);
  for (int i = 0; i < nb; ++i) {
    const InclineCase& k = cases[static_cast<size_t>(i)];
    const std::string at = "d = " + std::to_string(k.d) + ", gamma = " + std::to_string(k.gamma) +
                           ", h = " + std::to_string(h);
    const mech::FrictionalContact& fc = model.mechanical->friction[static_cast<size_t>(i)];
    const Eigen::Vector2d ag =
        kG * std::sin(kAlpha) * Eigen::Vector2d(std::cos(k.gamma), -std::sin(k.gamma));
    const Eigen::Vector2d u0(std::sin(k.gamma) * kV0, std::cos(k.gamma) * kV0);
    const InclineMotion cf = incline_closed_form(ag, c, k.d, u0, T);
    auto frame = [&](const VectorXd& x) {
      return Eigen::Vector2d(fc.tangent.dot(x), fc.tangent2.dot(x));
    };
    const Eigen::Vector2d u = frame(last.x.tail(N)), p = frame(last.x.head(N));
    const double bound = 2 * c * h * cf.phases;
    EXPECT_LE((u - cf.u).norm(), bound) << at;
    EXPECT_LE((p - cf.p).norm(), T * bound + 2 * c * h * h * cf.phases) << at;
    const Eigen::Vector2d acc = (u - frame(before.x.tail(N))) / (last.t - before.t);
    EXPECT_LE((acc - cf.accel).norm(), 1e-9 * kG) << at;
    const impact::ConeFacet f = last.friction_facet[static_cast<size_t>(i)];
    EXPECT_EQ(2 * f.edge + (f.face ? 1 : 0), cf.facet) << at;
    if (h == 1e-3)
      std::printf("%s: %d phases, facet %s, |du| = %.2e (bound %.2e), heading %.6f rad\n",
                  at.c_str(), cf.phases,
                  sim::friction_mode_text(last.friction_mode[static_cast<size_t>(i)], f).c_str(),
                  (u - cf.u).norm(), bound, std::atan2(cf.u(1), cf.u(0)));
  }
}

// The frame turned so that the downhill direction is on an edge (gamma = 0:
// it ends sliding with the force on edge d, keeping its sideways speed), on
// a bisector (gamma = -pi/(2d): it ends along face d, the sideways speed
// gone), and between; d = 2, 3, 4, 8. One block per run: the dense path.
std::vector<InclineCase> incline_cases() {
  std::vector<InclineCase> out;
  for (int d : {2, 3, 4, 8})
    for (double g : {0.0, -kPi / (2 * d), 0.3, -1.1}) out.push_back({d, g});
  return out;
}

TEST(MjFriction3dIncline, PushedSidewaysSlidesAsTheConeGivesDense) {
  for (const InclineCase& k : incline_cases())
    for (double h : {1e-3, 2.5e-4}) check_inclines({k}, h, 0.6);
}

// All 16 blocks in one model four times over (64 contacts, sum (2d + 2) =
// 4 (6 + 8 + 10 + 18) 4 = 672 unknowns > 600): the sparse path, the same
// bounds.
TEST(MjFriction3dIncline, PushedSidewaysSlidesAsTheConeGivesSparse) {
  std::vector<InclineCase> all;
  for (int r = 0; r < 4; ++r)
    for (const InclineCase& k : incline_cases()) all.push_back(k);
  check_inclines(all, 1e-3, 0.6);
}

}  // namespace
}  // namespace lcsim
