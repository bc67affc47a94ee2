// The exact event-driven method on coupled contacts (issue 12): inelastic
// impacts that accumulate through a non-diagonal Delassus matrix, coupled
// stops coming to rest, a lift-off of 1e-10 and its landing, stiff
// oscillators against stops at omega = 1e3 ... 1e9, the NAO legs, and the
// default impact law with a resting contact. Every reference value is
// computed here independently of lcsim's phases (closed forms, or long-double
// recurrences with closed-form flights), never taken from an lcsim run.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <numbers>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::Vector4d;
using Eigen::VectorXd;
using ld = long double;

sim::Trajectory run(const mech::Model& model, const VectorXd& x0, double t_end,
                    double dt_out = 0.0) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  return sim::simulate_event_driven(model, x0, opt);
}

// ---------------------------------------------------------------------------
// A unit point mass in a wedge: two stops with unit normals nA = (1, 0) and
// nB = (cos 120°, sin 120°), so W = E M^-1 E' = [[1, -1/2], [-1/2, 1]], under
// a constant force a (a pulls away from both faces: nA.a > 0, nB.a > 0),
// every impact inelastic. An impact on one face leaves the mass sliding away
// from it (its gap opens like (n.a) s^2 / 2), the other face is hit, and its
// impulse drives the first face's rate negative through W_AB < 0: the impacts
// alternate, each halving the normal velocity, with intervals that shrink
// super-geometrically, to an accumulation at the corner at t*. From there the
// mass starts from rest: q(t) = a (t - t*)^2 / 2.
struct Wedge {
  double v0, angle_deg;  // initial state q = (0, 1), v = (0, -v0); a at angle
};

mech::Model wedge_model(double angle_deg) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  const double c = std::cos(2 * std::numbers::pi / 3), s = std::sin(2 * std::numbers::pi / 3);
  MatrixXd E(2, 2);
  E << 1, 0, c, s;
  m.E = E.sparseView();
  const double a = angle_deg * std::numbers::pi / 180;
  m.f = Vector2d(std::cos(a), std::sin(a));
  return mech::model_of(m, "wedge");
}

// The recurrence in long double: flights in closed form (quadratics), the
// inelastic impact v+ = v - (n.v) n. Returns t* (or -1 if the mass escapes
// before t_end) and counts the impacts resolved.
ld wedge_accumulation_time(const Wedge& w, double t_end, int* impacts) {
  const ld c = std::cos(2 * std::numbers::pi_v<ld> / 3),
           s = std::sin(2 * std::numbers::pi_v<ld> / 3);
  const ld n[2][2] = {{1, 0}, {c, s}};
  const ld ang = w.angle_deg * std::numbers::pi_v<ld> / 180;
  const ld a[2] = {std::cos(ang), std::sin(ang)};
  ld q[2] = {0, 1}, v[2] = {0, -static_cast<ld>(w.v0)}, t = 0;
  *impacts = 0;
  for (int iter = 0; iter < 200; ++iter) {
    ld best = -1;
    int hit = -1;
    const ld speed = std::hypot(v[0], v[1]);
    for (int i = 0; i < 2; ++i) {
      const ld c0 = std::max<ld>(n[i][0] * q[0] + n[i][1] * q[1], 0);
      const ld c1 = n[i][0] * v[0] + n[i][1] * v[1];
      const ld c2 = (n[i][0] * a[0] + n[i][1] * a[1]) / 2;  // > 0 for these angles
      // Opening, and c2 > 0 keeps it open; the face just hit has c1 = 0 up to
      // rounding (1e-18 of the speed in long double).
      if (c1 >= -1e-15L * speed) continue;
      const ld disc = c1 * c1 - 4 * c2 * c0;
      if (disc < 0) continue;
      const ld root = 2 * c0 / (-c1 + std::sqrt(disc));  // smallest positive root
      if (hit < 0 || root < best) {
        best = root;
        hit = i;
      }
    }
    if (hit < 0 || t + best > t_end) return -1;
    for (int d = 0; d < 2; ++d) {
      q[d] += v[d] * best + a[d] * best * best / 2;
      v[d] += a[d] * best;
    }
    t += best;
    const ld vn = n[hit][0] * v[0] + n[hit][1] * v[1];
    for (int d = 0; d < 2; ++d) v[d] -= vn * n[hit][d];
    ++*impacts;
    // Converged: the next interval is below long double's resolution of t.
    if (best < 1e-22L) return t;
  }
  return t;
}

// lcsim's final state at t = 1 against a (1 - t*)^2 / 2 and a (1 - t*).
// Tolerance 1e-12: the impacts lcsim resolves carry event-time errors of a
// few ulp (1e-16 s), and where the next interval falls below double's
// resolution it closes both faces in one inelastic impact; the motion left
// out there is at most the normal speed (<= 3) times the unresolved time
// (< 1e-15 s). 1e-12 leaves three orders of margin; a missed lift-off or a
// wrong impulse shows at 1e-3 or more (the constraint was violated outright
// before lift-offs were followed from their derivatives).
TEST(CoupledContacts, InelasticImpactsAccumulateInAWedge) {
  for (const Wedge w :
       {Wedge{3, 80}, Wedge{3, 70}, Wedge{2, 80}, Wedge{2, 70}, Wedge{1.8, 80}, Wedge{2.5, 70}}) {
    int impacts = 0;
    const ld t_star = wedge_accumulation_time(w, 1.0, &impacts);
    ASSERT_GT(t_star, 0) << "the reference escapes: v0 " << w.v0 << ", angle " << w.angle_deg;
    ASSERT_GE(impacts, 5);
    const mech::Model model = wedge_model(w.angle_deg);
    const auto tr = run(model, Vector4d(0, 1, 0, -w.v0), 1.0);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    const Vector2d a = model.mechanical->f;
    const double r = static_cast<double>(1 - t_star);
    const Vector4d want(a(0) * r * r / 2, a(1) * r * r / 2, a(0) * r, a(1) * r);
    EXPECT_LE((tr.final_state - want).cwiseAbs().maxCoeff(), 1e-12)
        << "v0 " << w.v0 << ", angle " << w.angle_deg << "\n got " << tr.final_state.transpose()
        << "\n want " << want.transpose();
    // Energy never rises: kinetic plus the potential -f.q of the force.
    double E_prev = tr.energy_initial;
    for (const auto& e : tr.events) {
      const double Eb =
          mech::total_energy(*model.mechanical, e.state_before.head(2), e.state_before.tail(2));
      const double Ea =
          mech::total_energy(*model.mechanical, e.state_after.head(2), e.state_after.tail(2));
      EXPECT_NEAR(Eb, E_prev, 1e-12 * (1 + std::abs(E_prev))) << "phases conserve energy";
      EXPECT_LE(Ea, Eb + 1e-12 * (1 + std::abs(Eb))) << "an inelastic impact gained energy";
      E_prev = Ea;
    }
  }
}

// Gravity into the corner (both faces pushed): the mass hits face B, slides
// along it (mode {B}, no event), reaches the corner and stops there in one
// inelastic impact on both faces; it then rests with both contact forces
// positive, and no event follows (no ping-pong between {A} and {B}).
// Closed form: after the B impact at t1 the motion along B is uniformly
// accelerated by the tangential part of a; the corner is reached at t2.
TEST(CoupledContacts, CoupledStopsComeToRestWithoutPingPong) {
  const double ang = 240 * std::numbers::pi / 180;  // into the corner
  mech::Model model = wedge_model(0);
  model.mechanical->f = Vector2d(std::cos(ang), std::sin(ang));
  const Vector2d a = model.mechanical->f;
  const Vector2d nB(std::cos(2 * std::numbers::pi / 3), std::sin(2 * std::numbers::pi / 3));
  ASSERT_LT(a.dot(nB), 0.0);
  ASSERT_LT(a(0), 0.0);
  // From q = (2, 1.5) at rest the mass falls under a onto face B first
  // (n_B.q0 + n_B.a t^2/2 = 0 at t1 = 1.095; face A only at 2.83).
  const Vector2d q0(2.0, 1.5);
  const double t1 = std::sqrt(-2 * nB.dot(q0) / nB.dot(a));
  ASSERT_LT(t1, std::sqrt(-2 * q0(0) / a(0)));
  const Vector2d q1 = q0 + a * t1 * t1 / 2, v1 = a * t1 - nB.dot(a * t1) * nB;
  // Along face B, s = d.q with d = (sin 60°, cos 60°) the face's direction
  // from the corner; s'' = d.a < 0, so s(tau) = s1 + u1 tau + d.a tau^2/2
  // reaches the corner s = 0 at the positive root.
  const Vector2d d(std::sin(std::numbers::pi / 3), std::cos(std::numbers::pi / 3));
  const double s1 = d.dot(q1), u1 = d.dot(v1), at = d.dot(a);
  ASSERT_LT(at, 0.0);
  const double t2 = t1 + (-u1 - std::sqrt(u1 * u1 - 2 * at * s1)) / at;
  const auto tr = run(model, Vector4d(q0(0), q0(1), 0, 0), 5.0, 0.05);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.events.size(), 2u) << "expected the B impact and the corner impact only";
  EXPECT_NEAR(tr.events[0].t, t1, 1e-12);  // a root of a quadratic, conditioning ~1
  EXPECT_EQ(tr.events[0].mode_after, (sim::IndexSet{1}));
  EXPECT_NEAR(tr.events[1].t, t2, 1e-10);
  EXPECT_EQ(tr.events[1].mode_after, (sim::IndexSet{0, 1}));
  EXPECT_LE(tr.final_state.cwiseAbs().maxCoeff(), 1e-10) << "rests in the corner";
  // Both forces positive at rest: u = -W^-1 E M^-1 f for the corner mode.
  const Eigen::Matrix2d W{{1, -0.5}, {-0.5, 1}};
  const Vector2d u_rest = -W.inverse() * Vector2d(a(0), nB.dot(a));
  ASSERT_GT(u_rest.minCoeff(), 0.0);
  EXPECT_LE((tr.samples.back().u - u_rest).cwiseAbs().maxCoeff(), 1e-10);
}

// ---------------------------------------------------------------------------
// A lift-off of about 1e-10 and its landing. Two unit masses: mass 1 rests
// on the stop q1 >= 0, pressed by F = 1; mass 2 is tied to it by a unit
// spring (K = [[2, -1], [-1, 1]], f = (-1, 0)). While mass 1 rests,
// q2 = A sin t and the contact force is u = 1 - A sin t: with A = 1 + delta
// the force reaches zero at t_l = asin(1/A) and mass 1 lifts off by a height
// of order delta^2. The flight is the free 2-DOF oscillator from the
// lift-off state, solved here in modal closed form in long double; its
// landing is a root found by bisection.
struct Flight {
  ld t_l, t_land, peak;
};

Flight lift_off_flight(ld A) {
  const ld t_l = std::asin(1 / A);
  // Free motion about the static equilibrium q_s = K^-1 f = (-1, -1).
  const ld s5 = std::sqrt(5.0L);
  const ld w2[2] = {(3 - s5) / 2, (3 + s5) / 2};  // eigenvalues of K
  // Eigenvectors of K: (K - w2 I)(x, y) = 0 gives y = (2 - w2) x.
  ld V[2][2];
  for (int i = 0; i < 2; ++i) {
    const ld x = 1, y = 2 - w2[i], nrm = std::sqrt(x * x + y * y);
    V[0][i] = x / nrm;
    V[1][i] = y / nrm;
  }
  const ld d0[2] = {0 - (-1), A * std::sin(t_l) - (-1)};  // q - q_s at lift-off
  const ld dv[2] = {0, A * std::cos(t_l)};
  ld c[2], s[2];  // modal amplitudes: eta_i = c_i cos(w t) + s_i sin(w t)
  for (int i = 0; i < 2; ++i) {
    const ld w = std::sqrt(w2[i]);
    c[i] = V[0][i] * d0[0] + V[1][i] * d0[1];
    s[i] = (V[0][i] * dv[0] + V[1][i] * dv[1]) / w;
  }
  auto q1 = [&](ld tau) {
    ld r = -1;
    for (int i = 0; i < 2; ++i) {
      const ld w = std::sqrt(w2[i]);
      r += V[0][i] * (c[i] * std::cos(w * tau) + s[i] * std::sin(w * tau));
    }
    return r;
  };
  // March to the first sign change after the opening, then bisect.
  ld lo = 0, peak = 0;
  const ld step = 1e-5L;
  ld hi = step;
  while (q1(hi) >= 0 || hi < 100 * step) {
    peak = std::max(peak, q1(hi));
    lo = hi;
    hi += step;
  }
  for (int i = 0; i < 200; ++i) {
    const ld mid = (lo + hi) / 2;
    (q1(mid) > 0 ? lo : hi) = mid;
  }
  return {t_l, t_l + lo, peak};
}

mech::Model lift_off_model() {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  m.K = (MatrixXd(2, 2) << 2, -1, -1, 1).finished().sparseView();
  m.f = Vector2d(-1, 0);
  m.E = (MatrixXd(1, 2) << 1, 0).finished().sparseView();
  return mech::model_of(m, "lift_off");
}

// Release and landing times to 1e-9 s: both are simple roots (the force
// crosses zero with rate A cos t_l ~ 4e-3, the gap lands with a rate of
// ~1e-7 m/s against a time error of Brent's 1e-16 s), so 1e-9 leaves a wide
// margin, and a landing missed by the old noise band (1.6e-9 in gap) would
// not be an event at all.
TEST(CoupledContacts, LiftOffOf1e10AndItsLanding) {
  const ld A = 1 + 6e-6L;
  const Flight fl = lift_off_flight(A);
  ASSERT_GT(fl.peak, 5e-11L);  // the lift-off is about 1e-10 m
  ASSERT_LT(fl.peak, 5e-10L);
  const auto tr = run(lift_off_model(), Vector4d(0, 0, 0, static_cast<double>(A)), 2.5);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 2u);
  EXPECT_EQ(tr.events[0].type, sim::EventType::kRelease);
  EXPECT_NEAR(tr.events[0].t, static_cast<double>(fl.t_l), 1e-9);
  EXPECT_NEAR(tr.events[1].t, static_cast<double>(fl.t_land), 1e-9);
  EXPECT_EQ(tr.events[1].mode_after, (sim::IndexSet{0}));
}

// ---------------------------------------------------------------------------
// Stiff oscillators against a stop, omega = 1e3, 1e6, 1e9 (M = 1, K = w^2,
// and M = 1e-6, K = 1e6 for w = 1e6). From q = 0 with v = -v0 the mass
// reaches the stop q = -s (s = v0/(2w)) at t1 = asin(1/2)/w with speed
// v0 cos(pi/6), rebounds with e = 1/2, and returns to the stop after
// (pi + 2 phi)/w with phi = asin(s/R), R = sqrt(s^2 + (v+/w)^2).
// Tolerances relative to the time scale 1/w and the amplitude s: 1e-9,
// set by the root finder's relative accuracy (Brent to ~1e-15 of t) and the
// exponential's backward error; the index was misclassified (infinite) from
// w ~ 1e6 on before, and the run refused.
TEST(CoupledContacts, StiffOscillatorsAgainstAStop) {
  struct Case {
    double mass, omega;
  };
  for (const Case c : {Case{1, 1e3}, Case{1, 1e6}, Case{1e-6, 1e6}, Case{1, 1e9}}) {
    const double w = c.omega, v0 = 1.0, s = v0 / (2 * w), e = 0.5;
    mech::MechanicalModel m;
    m.M = (MatrixXd(1, 1) << c.mass).finished().sparseView();
    m.K = (MatrixXd(1, 1) << c.mass * w * w).finished().sparseView();
    m.E = (MatrixXd(1, 1) << 1).finished().sparseView();
    m.g = VectorXd::Constant(1, s);
    m.restitution = VectorXd::Constant(1, e);
    const mech::Model model = mech::model_of(m, "stiff");
    const lcs::Lcs sys = model.as_lcs();
    EXPECT_EQ(lcs::leading_row_indices(sys)[0], 2) << "omega " << w;
    const double t1 = std::asin(0.5) / w, v_imp = v0 * std::cos(std::numbers::pi / 6);
    const double vp = e * v_imp, R = std::hypot(s, vp / w), phi = std::asin(s / R);
    const double t2 = t1 + (std::numbers::pi + 2 * phi) / w;
    const auto tr = run(model, Vector2d(0, -v0), t2 + 0.1 / w);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << "omega " << w << ": " << tr.message;
    ASSERT_GE(tr.events.size(), 2u) << "omega " << w;
    EXPECT_NEAR(tr.events[0].t * w, t1 * w, 1e-9) << "omega " << w;
    EXPECT_NEAR(tr.events[0].state_before(1), -v_imp, 1e-9 * v0) << "omega " << w;
    EXPECT_NEAR(tr.events[0].state_after(1), vp, 1e-9 * v0) << "omega " << w;
    EXPECT_NEAR(tr.events[1].t * w, t2 * w, 1e-9) << "omega " << w;
    EXPECT_NEAR(tr.events[1].state_before(0) / s, -1.0, 1e-9) << "omega " << w;
  }
}

// ---------------------------------------------------------------------------
// The default impact law with several closed contacts (the KUKA case of
// issue 12): contact 1 rests (zero gap, zero rate, e = 1/4) while contact 0
// is hit (e = 1/2); M = I and E = [[1, 0], [-0.8, 0.6]], so W = [[1, -0.8],
// [-0.8, 1]]: contact 0's impulse pushes contact 1 into its stop.
// - Default, Moreau–Jean's law 0 <= E v+ + e∘a ⟂ lambda >= 0 with
//   a = E v- = (-1, 0): both active, W lambda = (1.5, 0), lambda =
//   (1.5, 1.2)/0.36 >= 0, so E v+ = (0.5, 0): contact 1 stays at rest.
// - "moreau": Newton's (1+e) on Moreau's inelastic impulse (25, 20)/9 gives
//   E v+ = (17, -10)/18: contact 1 driven into its stop (a warning); the
//   second round, on contact 1 alone (lambda = 10/18, times 1.25), leaves
//   E v+ = (7, 2.5)/18: contact 1, which never approached, rebounds at 0.139.
// Rational arithmetic up to rounding: 1e-14.
TEST(CoupledContacts, DefaultLawKeepsARestingContactAtRest) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  m.E = (MatrixXd(2, 2) << 1, 0, -0.8, 0.6).finished().sparseView();
  m.restitution = Vector2d(0.5, 0.25);
  const mech::Model model = mech::model_of(m, "resting_and_hit");
  const MatrixXd E = m.E.toDense();
  const Vector2d v = E.inverse() * Vector2d(-1, 0);  // E v = (-1, 0) at q = 0
  const auto tr = run(model, Vector4d(0, 0, v(0), v(1)), 1e-3);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  EXPECT_EQ(tr.impact_law, "moreau-restitution");
  EXPECT_EQ(tr.warning_count(), 0) << "an admissible jump needs no warning";
  ASSERT_GE(tr.events.size(), 1u);
  const Vector2d rate = E * tr.events[0].state_after.tail(2);
  EXPECT_NEAR(rate(0), 0.5, 1e-14);
  EXPECT_NEAR(rate(1), 0.0, 1e-14);
  EXPECT_LE(tr.energy_final, tr.energy_initial);

  sim::Options opt;
  opt.t_end = 1e-3;
  opt.impact = "moreau";
  const auto old = sim::simulate_event_driven(model, Vector4d(0, 0, v(0), v(1)), opt);
  ASSERT_EQ(old.status, sim::RunStatus::kCompleted) << old.message;
  EXPECT_EQ(old.impact_law, "newton");  // "moreau" is an alias of "newton"
  EXPECT_GE(old.warning_count("impact-not-admissible"), 1) << "the first v+ is not admissible";
  const Vector2d old_rate = E * old.events[0].state_after.tail(2);
  EXPECT_NEAR(old_rate(0), 7.0 / 18, 1e-14);
  EXPECT_NEAR(old_rate(1), 2.5 / 18, 1e-14) << "the resting contact rebounds under Newton's (1+e)";
}

// ---------------------------------------------------------------------------
// The NAO legs of issue 12 (robots/nao_legs_scene.yaml): to t = 2 with fewer
// than 100 events, never infeasible beyond rounding, and energy never rising
// across an event (the scene has no damping, so phases conserve it).
TEST(CoupledContacts, NaoLegsRunWithoutChatter) {
  const std::string path = std::string(LCSIM_SOURCE_DIR) + "/robots/nao_legs_scene.yaml";
  const mech::Model model = scene::load_model(path);
  sim::Options opt;
  opt.t_end = 2.0;
  opt.dt_out = 0.01;
  const auto tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  EXPECT_LT(tr.events.size(), 100u);
  EXPECT_EQ(tr.events_not_recorded, 0);
  // 1e-9 of the joint-angle scale (~1 rad): rounding of the gaps is ~1e-16.
  EXPECT_GE(tr.max_violation, -1e-9);
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  for (const auto& e : tr.events) {
    const double Eb = mech::total_energy(m, e.state_before.head(N), e.state_before.tail(N));
    const double Ea = mech::total_energy(m, e.state_after.head(N), e.state_after.tail(N));
    EXPECT_LE(Ea, Eb + 1e-9 * (1 + std::abs(Eb))) << "energy rose at t = " << e.t;
  }
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// The livelock guard: with accumulations not taken (accumulation_tail and
// accumulation_dt at 0), the NAO legs' knee and ankle impacts alternate until
// the rounding of the gaps drives them (every ~2e-9 s, jumps of ~1e-7 that no
// longer shrink). The run must fail with one line naming both contacts, long
// before the 1e6-event guard, and never report "completed".
TEST(CoupledContacts, LivelockFailsNamingTheContacts) {
  const std::string path = std::string(LCSIM_SOURCE_DIR) + "/robots/nao_legs_scene.yaml";
  const mech::Model model = scene::load_model(path);
  sim::Options opt;
  opt.t_end = 2.0;
  opt.accumulation_dt = 0.0;
  opt.accumulation_tail = 0.0;
  const auto tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kEventLimit);
  EXPECT_NE(tr.message.find("no progress"), std::string::npos) << tr.message;
  EXPECT_NE(tr.message.find("'LHipPitch_upper'"), std::string::npos) << tr.message;
  EXPECT_NE(tr.message.find("'LAnklePitch_upper'"), std::string::npos) << tr.message;
  EXPECT_LT(tr.events.size(), 1000u);
}

// Past Options::max_recorded_events, events are counted, not kept, with one
// warning; the run itself is unchanged (bitwise the same final state as an
// uncapped run of the ball with e = 1/2, whose impacts accumulate).
TEST(CoupledContacts, EventsPastTheCapAreCountedNotRecorded) {
  const mech::Model model = mech::ball_model(0.5);
  sim::Options opt;
  opt.t_end = 2.0;
  const auto full = sim::simulate_event_driven(model, Vector2d(1, 0), opt);
  ASSERT_EQ(full.status, sim::RunStatus::kCompleted) << full.message;
  ASSERT_GT(full.events.size(), 5u);
  opt.max_recorded_events = 3;
  const auto capped = sim::simulate_event_driven(model, Vector2d(1, 0), opt);
  ASSERT_EQ(capped.status, sim::RunStatus::kCompleted) << capped.message;
  EXPECT_EQ(capped.events.size(), 3u);
  EXPECT_EQ(capped.events_not_recorded, static_cast<long>(full.events.size()) - 3);
  EXPECT_EQ(capped.warning_count(), full.warning_count() + 1);
  EXPECT_EQ(capped.warning_count("events-not-recorded"), 1);
  EXPECT_EQ(capped.final_state, full.final_state);
}

}  // namespace
}  // namespace lcsim

namespace lcsim {
namespace {

// A light gripper on a heavy arm (the linearised model of a public robot
// arm's scene, rounded): joint 3 (M33 = 3.2e-4) against its upper stop c6
// since t = 0.31, when joint 1 hits its upper stop c2 at t = 0.9575. The
// coupling M13, M23 sends the gripper into its stop at ~36 rad/s unless c6
// takes part in that impact. Its gap, held at zero by the phase, drifts to
// -2.8e-13 through the rounding of the whole state (q ~ 1): the impact law
// must still count c6 as closed. Before, c6 was left out and the run ended
// "constraint 'c6' is violated" (exit 3).
// Reference: Moreau–Jean, an independent code path, converges to the exact
// final state at first order: max error 6.7e-3, 7.0e-4, 5.3e-5 at h = 1e-3,
// 1e-4, 1e-5 (measured); bounds 2x those at 1e-4 and 1e-5, and a ratio of
// at least 5 per decade (first order gives ~10).
TEST(CoupledContacts, HeldContactTakesPartInAnImpactThroughTheCoupling) {
  mech::MechanicalModel m;
  MatrixXd M(3, 3), K(3, 3), D = Eigen::Vector3d(2, 1, 1).asDiagonal();
  M << 0.47, 0.19, 0.0016, 0.19, 0.30, 0.002, 0.0016, 0.002, 0.00032;
  K << -10.86, -1.438, -0.0103, -1.438, -1.438, -0.0103, -0.0103, -0.0103, -0.0103;
  MatrixXd E(6, 3);
  E << 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 1, 0, 0, -1;
  m.M = M.sparseView();
  m.K = K.sparseView();
  m.D = D.sparseView();
  m.E = E.sparseView();
  m.g = (VectorXd(6) << 0, 2.967, 2.88, 0, 1.5707, 0).finished();
  m.f = Eigen::Vector3d(-7.42, 8.03, 0.0358);
  const mech::Model model = mech::model_of(m, "light_gripper");
  VectorXd x0 = VectorXd::Zero(6);
  x0(0) = 1;
  x0(1) = -1;
  const sim::Trajectory tr = run(model, x0, 2.0, 0.01);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  bool seen = false;
  for (const sim::Event& e : tr.events) {
    if (std::find(e.mode_after.begin(), e.mode_after.end(), 1) == e.mode_after.end()) continue;
    seen = true;
    EXPECT_NEAR(e.t, 0.9575, 1e-3);
    EXPECT_NE(std::find(e.mode_after.begin(), e.mode_after.end(), 5), e.mode_after.end())
        << "the gripper's stop c6 left the mode at t = " << e.t;
    EXPECT_LE(std::abs(e.state_after(5)), 1e-9) << "the gripper was sent into its stop";
    break;
  }
  EXPECT_TRUE(seen) << "joint 1 never reached its upper stop";
  // Rounding of the held gaps only (measured 2.8e-13; 1e-9 of q ~ 3).
  EXPECT_GE(tr.max_violation, -1e-9);
  double previous = 0.0;
  for (double h : {1e-4, 1e-5}) {
    sim::Options o;
    o.t_end = 2.0;
    o.h = h;
    const sim::Trajectory mj = sim::integrators().make("moreau-jean")->run(model, x0, o);
    ASSERT_EQ(mj.status, sim::RunStatus::kCompleted) << mj.message;
    const double err = (mj.final_state - tr.final_state).cwiseAbs().maxCoeff();
    EXPECT_LE(err, h == 1e-4 ? 1.4e-3 : 1.1e-4) << "h = " << h;
    if (previous > 0.0) {
      EXPECT_GE(previous / err, 5.0);
    }
    previous = err;
  }
}

}  // namespace
}  // namespace lcsim
