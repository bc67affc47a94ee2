// The exact event-driven method on a box landing flat on its four corners
// with friction (issue 27, issue 26's scenes): the impact on four coplanar
// corners (W_NN of rank 3: redundant, not Painlevé) and the slide on them
// to rest, against the closed form of one point mass; the tipped box with
// friction against the laws it must keep (gaps, Coulomb, energy).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <lcsim/core/format.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <tuple>

#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::Vector2d;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
const double kPi = std::acos(-1.0);
constexpr double kG = 9.81, kMu = 0.3, kDrop = 0.2;  // m/s^2, -, m (box_drop_scene.yaml)

// The closest point to p of the polygon R conv{D_i}, D_i at the angles
// pi i/d (i = 0 .. 2d-1); d = 1 is the segment [-R, R] along the first axis.
// Written here from its definition (inside: p itself; else the nearest point
// of the boundary's segments), independent of lcsim's cone code.
Vector2d project_on_polygon(const Vector2d& p, double R, int d) {
  const auto vertex = [&](int i) {
    return Vector2d(R * std::cos(kPi * i / d), R * std::sin(kPi * i / d));
  };
  bool inside = d >= 2;
  for (int j = 0; j < 2 * d && inside; ++j) {
    const double th = kPi * (j + 0.5) / d;
    inside = p.dot(Vector2d(std::cos(th), std::sin(th))) <= R * std::cos(kPi / (2 * d));
  }
  if (inside) return p;
  Vector2d best = vertex(0);
  for (int i = 0; i < 2 * d; ++i) {
    const Vector2d a = vertex(i), b = vertex(i + 1), ab = b - a;
    const double s = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
    const Vector2d c = a + s * ab;
    if ((c - p).norm() < (best - p).norm()) best = c;
  }
  return best;
}

class ExactBoxFriction : public test_support::SceneFiles {
 protected:
  // robots/quadruped_drop_scene.yaml landing with a sideways velocity
  // (vx, vy) m/s and friction mu, d on its four feet.
  std::string quadruped(double mu, int d, double vx = 0.05, double vy = 0.03) {
    write("quadruped.urdf", io::read_file(kRobots + "quadruped.urdf"));
    std::string t = io::read_file(kRobots + "quadruped_drop_scene.yaml");
    const std::string init = "  q: {quad.z: 0.38}";
    const size_t at_init = t.find(init);
    EXPECT_NE(at_init, std::string::npos);
    t.replace(
        at_init, init.size(),
        init + "\n  v: {quad.x: " + format_number(vx) + ", quad.y: " + format_number(vy) + "}");
    for (const std::string foot : {"fl_foot", "fr_foot", "hl_foot", "hr_foot"}) {
      const std::string entry = "name: " + foot + "}";
      const size_t at = t.find(entry);
      EXPECT_NE(at, std::string::npos) << foot;
      t.replace(
          at, entry.size(),
          "name: " + foot + ", friction: " + format_number(mu) + ", d: " + std::to_string(d) + "}");
    }
    return write("quad.yaml", t);
  }
  // robots/box_drop_scene.yaml with friction and a horizontal velocity
  // (vx, vy) in the world (m/s).
  std::string drop(int d, double vx, double vy, double mu = kMu) {
    write("box.urdf", io::read_file(kRobots + "box.urdf"));
    return write("drop.yaml",
                 "name: box_drop\nurdf: box.urdf\n"
                 "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n"
                 "planes:\n  - {name: floor, point: [0, 0, 0], normal: [0, 0, 1]}\n"
                 "contacts:\n  - {link: box, plane: floor, friction: " +
                     format_number(mu) + ", d: " + std::to_string(d) +
                     "}\ninitial:\n  q: {box.z: 0.25}\n  v: {box.x: " + format_number(vx) +
                     ", box.y: " + format_number(vy) + "}\nt_end: 2\n");
  }
};

// Every sample of a run on the box: gaps >= 0, normal forces >= 0 and each
// corner's friction force inside its polygon mu u_N conv{D_i} (for d = 1
// the segment |u_t| <= mu u_N, no force along t2), to 1e-9 of m g (the
// forces are m g / 4 ~ 3 N formed from terms of that size; 1e-9 is far above
// their rounding, far below any real violation); the energy never rises
// from one sample to the next (1e-9 J of 0.6 J: rounding).
void expect_laws(const mech::MechanicalModel& m, const sim::Trajectory& tr, const std::string& at) {
  const double mg = m.M.coeff(0, 0) * kG, tol = 1e-9 * mg;
  const Eigen::Index N = m.dofs();
  double last_energy = std::numeric_limits<double>::infinity();
  for (const sim::Sample& s : tr.samples) {
    ASSERT_EQ(s.u_t.size(), static_cast<Eigen::Index>(m.friction.size())) << at;
    EXPECT_GE(s.y.minCoeff(), -1e-12) << at << " t = " << s.t;
    for (size_t f = 0; f < m.friction.size(); ++f) {
      const mech::FrictionalContact& fc = m.friction[f];
      const int d = m.edges_of(fc);
      const double uN = s.u(fc.contact), ut = s.u_t(static_cast<Eigen::Index>(f));
      const double ut2 = s.u_t2.size() ? s.u_t2(static_cast<Eigen::Index>(f)) : 0.0;
      EXPECT_GE(uN, -tol) << at << " t = " << s.t;
      if (d == 1) {
        EXPECT_LE(std::abs(ut), fc.mu * uN + tol) << at << " t = " << s.t;
        EXPECT_LE(std::abs(ut2), tol) << at << " t = " << s.t;
        continue;
      }
      for (int j = 0; j < 2 * d; ++j) {
        const double th = kPi * (j + 0.5) / d;
        EXPECT_LE(std::cos(th) * ut + std::sin(th) * ut2,
                  fc.mu * std::cos(kPi / (2 * d)) * uN + tol)
            << at << " t = " << s.t << ", face " << j;
      }
    }
    const double e = mech::total_energy(m, s.x.head(N), s.x.segment(N, N));
    EXPECT_LE(e, last_energy + 1e-9) << at << " t = " << s.t;
    last_energy = e;
  }
}

// The box dropped flat from 0.2 m with a horizontal velocity lands at
// sqrt(2h/g) on its four corners in one impact and slides to rest as one
// point mass: all four corners move alike (no rotation), so each corner's
// friction impulse lies on the same facet of its polygon, and their sum is
// the point mass's. The impact's friction impulse P (per unit mass) is the
// one of maximal dissipation in the polygon mu V conv{D_i} (V = g t_i the
// speed at impact, the normal impulse per unit mass at e = 0), i.e. the
// projection of -s onto it (s the sliding velocity before); from s + P the
// box slides as mech::cone_slide says (d = 1: the planar law, here with s
// along t1). In the floor's frame t1 = +y, t2 = -x (scene::contact_frame),
// so a velocity s along (t1, t2) is (-s2, s1) in the world.
// Tolerance: the exact method's phases are matrix exponentials and its
// events roots found to rounding (docs/friction.md: errors of 1e-16 on the
// point mass); 1e-12 (s, m, rad) leaves three orders for the few events.
TEST_F(ExactBoxFriction, BoxLandingFlatSlidesToRestAsOnePointMass) {
  const double ti = std::sqrt(2 * kDrop / kG), V = kG * ti;
  struct Case {
    int d;
    double psi, s0;
  };
  std::vector<Case> cases;
  for (const double psi : {0.0, kPi}) cases.push_back({1, psi, 1.0});  // along t1
  for (const int d : {2, 4})
    for (const double psi : {0.0, kPi / (2 * d), 0.3, 2.0, -2.5}) cases.push_back({d, psi, 1.0});
  cases.push_back({4, 1.1, 0.5});  // sticks at the impact: |s| < mu V = 0.59
  for (const Case& c : cases) {
    const std::string at = "d = " + std::to_string(c.d) + ", psi = " + std::to_string(c.psi) +
                           ", s0 = " + std::to_string(c.s0);
    // d = 1: exactly along t1 (sin(pi) is 1.2e-16, and d = 1 never stops
    // a velocity with a component along t2).
    const Vector2d s(c.s0 * std::cos(c.psi), c.d == 1 ? 0.0 : c.s0 * std::sin(c.psi));
    const double vx = -s(1), vy = s(0);
    const mech::Model model = scene::load_model(drop(c.d, vx, vy));
    sim::Options o;
    o.t_end = 2.0;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    ASSERT_FALSE(tr.events.empty()) << at;
    const sim::Event& impact = tr.events.front();
    EXPECT_EQ(impact.type, sim::EventType::kImpact) << at;
    EXPECT_NEAR(impact.t, ti, 1e-12) << at;
    // Just after the impact: the point mass's velocity, no rotation (d = 1:
    // the planar law along t1, s along t1 here).
    const Vector2d u =
        c.d == 1 ? Vector2d(s(0) - std::copysign(std::min(std::abs(s(0)), kMu * V), s(0)), 0.0)
                 : Vector2d(s + project_on_polygon(-s, kMu * V, c.d));
    // Sliding, the four corners are held together (sticking, the LDCP's
    // two diagonal ones suffice: the others' gaps stay zero, checked below).
    if (u.norm() > 0.0) {
      EXPECT_EQ(impact.mode_after.size(), 4u) << at << ": the four corners close together";
    }
    const VectorXd& xa = impact.state_after;
    EXPECT_NEAR(xa(6), -u(1), 1e-12) << at;
    EXPECT_NEAR(xa(7), u(0), 1e-12) << at;
    EXPECT_NEAR(xa(8), 0.0, 1e-12) << at;
    EXPECT_LE(xa.segment(9, 3).cwiseAbs().maxCoeff(), 1e-12) << at;
    // The stop: the event after which every corner sticks, and the rest.
    double t_stop = ti, x = vx * ti, y = vy * ti;
    if (u.norm() > 0.0) {
      const mech::ConeSlide cs = mech::cone_slide(u.norm(), std::atan2(u(1), u(0)), kMu, kG, c.d);
      t_stop += cs.t_stop;
      x -= cs.y;
      y += cs.x;
    }
    // (The top corners are contacts too, open throughout.)
    const auto stop = std::find_if(tr.events.begin(), tr.events.end(), [](const sim::Event& e) {
      const auto& fm = e.friction_mode_after;
      return e.type == sim::EventType::kStick &&
             std::count(fm.begin(), fm.end(), sim::FrictionMode::kStick) == 4 &&
             std::count(fm.begin(), fm.end(), sim::FrictionMode::kOpen) + 4 ==
                 static_cast<long>(fm.size());
    });
    if (u.norm() > 0.0) {
      ASSERT_NE(stop, tr.events.end()) << at;
      EXPECT_NEAR(stop->t, t_stop, 1e-12) << at;
    }
    const VectorXd& xf = tr.final_state;
    EXPECT_NEAR(xf(0), x, 1e-12) << at;
    EXPECT_NEAR(xf(1), y, 1e-12) << at;
    EXPECT_NEAR(xf(2), 0.05, 1e-12) << at;
    EXPECT_LE(xf.segment(3, 3).cwiseAbs().maxCoeff(), 1e-12) << at;  // level, no yaw
    EXPECT_LE(xf.segment(6, 6).cwiseAbs().maxCoeff(), 1e-12) << at;  // at rest
    expect_laws(*model.mechanical, tr, at);
  }
}

// Issue 27 at d >= 2: the box landing flat at mu = 100 with the sideways
// velocity of robots/box_slide_scene.yaml (1, 0.4) m/s. Each corner alone
// is Painlevé-type (W_NN - mu max_i |W_N D_i| = 5.08 - 100 * 1.24 < 0 at
// d = 4), so the cone law enumerates the four corners' modes (18^4 = 104976
// at d = 4, 10^4 at d = 2; the normal block of the coplanar corners is
// singular, judged by velocity uniqueness) and finds one motion: every
// corner sticks. Closed form (one point mass): |s| = 1.08 m/s < mu V =
// 198 m/s, so the impact stops it; it rests where it lands, (vx, vy) t_i.
// Tolerance 1e-12 as BoxLandingFlatSlidesToRestAsOnePointMass.
TEST_F(ExactBoxFriction, BoxLandingFlatAtHighMuSticksWhereItLands) {
  const double ti = std::sqrt(2 * kDrop / kG), vx = 1.0, vy = 0.4;
  for (const int d : {2, 4}) {
    const std::string at = "d = " + std::to_string(d);
    const mech::Model model = scene::load_model(drop(d, vx, vy, 100.0));
    sim::Options o;
    o.t_end = 0.5;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    ASSERT_FALSE(tr.events.empty()) << at;
    const sim::Event& impact = tr.events.front();
    EXPECT_EQ(impact.type, sim::EventType::kImpact) << at;
    EXPECT_NEAR(impact.t, ti, 1e-12) << at;
    EXPECT_LE(impact.state_after.segment(6, 6).cwiseAbs().maxCoeff(), 1e-12) << at;
    const VectorXd& xf = tr.final_state;
    EXPECT_NEAR(xf(0), vx * ti, 1e-12) << at;
    EXPECT_NEAR(xf(1), vy * ti, 1e-12) << at;
    EXPECT_NEAR(xf(2), 0.05, 1e-12) << at;
    EXPECT_LE(xf.segment(3, 3).cwiseAbs().maxCoeff(), 1e-12) << at;  // level, no yaw
    EXPECT_LE(xf.segment(6, 6).cwiseAbs().maxCoeff(), 1e-12) << at;  // at rest
    expect_laws(*model.mechanical, tr, at);
  }
}

// The box tipped onto an edge falling onto its face (robots/box_tip_scene.yaml)
// with friction 0.5 (d = 1, 2, 4; the face impact closes four coplanar
// corners, which the impact law refused as Painlevé-type before): the run
// completes, on every sample the laws hold (expect_laws), and it ends at
// rest, level.
TEST_F(ExactBoxFriction, TippedBoxWithFrictionKeepsTheLaws) {
  write("box.urdf", io::read_file(kRobots + "box.urdf"));
  std::string text = io::read_file(kRobots + "box_tip_scene.yaml");
  const std::string entry = "- {link: box, plane: floor}";
  const size_t at_entry = text.find(entry);
  ASSERT_NE(at_entry, std::string::npos);
  for (const int d : {1, 2, 4}) {
    std::string t = text;
    t.replace(at_entry, entry.size(),
              "- {link: box, plane: floor, friction: 0.5, d: " + std::to_string(d) + "}");
    const mech::Model model = scene::load_model(write("tip.yaml", t));
    sim::Options o;
    o.t_end = 0.5;
    o.dt_out = 1e-3;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    const std::string at = "d = " + std::to_string(d);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    expect_laws(*model.mechanical, tr, at);
    EXPECT_LE(tr.final_state.segment(3, 3).cwiseAbs().maxCoeff(), 1e-12) << at;  // level
    EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-12) << at;        // at rest
  }
}

// The quadruped of robots/quadruped_drop_scene.yaml landing with friction
// (d = 4) and a sideways velocity (0.05, 0.03) m/s. Its four feet's normal
// rows have rank 3 (straight legs: the pitch joints move the feet
// horizontally only), so the LDCP holds three and leaves one undetermined.
// Before, 1.3 ms after the landing the slipping foot's normal force reached
// zero while the foot diagonally opposite (undetermined) was pressed shut;
// the selection kept the same three feet and the run ended "no progress" (64
// events in 0 s). Now the slipping foot is released and the diagonal one
// takes the load. Checked: the run reaches t_end; on every sample the laws
// (expect_laws: gaps, normal forces, friction in the polygon, energy never
// rising); after the landing, each closed sticking foot's sliding velocity
// (both tangents) is zero. Tolerance 1e-12 m/s against speeds of 5e-2: the
// stick rows are held at acceleration level from a state projected to
// exactly zero sliding, so only the rounding of the phases' exponentials
// (1e-16 relative) and event roots accumulates over the few events.
TEST_F(ExactBoxFriction, QuadrupedLandingSidewaysWithFrictionRunsToTheEnd) {
  for (const double mu : {0.8, 0.3}) {
    const mech::Model model = scene::load_model(quadruped(mu, 4));
    const mech::MechanicalModel& m = *model.mechanical;
    sim::Options o;
    o.t_end = 1.0;
    o.dt_out = 1e-3;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    const std::string at = "mu = " + format_number(mu);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    ASSERT_FALSE(tr.samples.empty());
    EXPECT_EQ(tr.samples.back().t, 1.0) << at;
    expect_laws(m, tr, at);
    const Eigen::Index N = m.dofs();
    const double t_land = std::sqrt(2 * 0.03 / kG);  // the scene's header
    int stuck = 0;
    for (const sim::Sample& s : tr.samples) {
      if (s.t <= t_land + 1e-9) continue;
      const VectorXd v = s.x.segment(N, N);
      for (size_t f = 0; f < m.friction.size(); ++f) {
        const mech::FrictionalContact& fc = m.friction[f];
        const bool closed = std::find(s.mode.begin(), s.mode.end(), fc.contact) != s.mode.end();
        if (!closed || s.friction_mode[f] != sim::FrictionMode::kStick) continue;
        ++stuck;
        EXPECT_LE(std::abs(fc.sliding(v)), 1e-12) << at << " t = " << s.t << " foot " << f;
        EXPECT_LE(std::abs(fc.tangent2.dot(v)), 1e-12) << at << " t = " << s.t << " foot " << f;
      }
    }
    EXPECT_GT(stuck, 0) << at;  // the check above ran
  }
}

// The same landing six times faster, (0.3, 0.1) and (0.3, 0) m/s, at d = 2
// and 4. The landing's impulse goes to two diagonal feet (fr, hl: the rows
// have rank 3, so the impulse is not unique and the LCP takes a vertex), hr
// closes without force and slips, fl is undetermined. 1.4 ms later the
// slip's friction unloads hr while the LDCP (frictionless) keeps {fr, hl, hr}
// with fl undetermined: before, the selection kept hr and the run ended "no
// progress at t = 0.0795: 64 events in 0 s" at hr_foot. Now the unloaded
// foot is released (release_normal): {fl, fr, hl} hold with hr undetermined,
// its row being in their span. Checked as above: the run reaches t_end, the
// laws on every 1 ms sample, and a closed sticking foot does not slide.
TEST_F(ExactBoxFriction, QuadrupedLandingFasterReleasesTheFootItsSlipUnloads) {
  for (const double vy : {0.1, 0.0})
    for (const int d : {2, 4})
      for (const double mu : {0.8, 0.3}) {
        const mech::Model model = scene::load_model(quadruped(mu, d, 0.3, vy));
        const mech::MechanicalModel& m = *model.mechanical;
        sim::Options o;
        o.t_end = 0.3;
        o.dt_out = 1e-3;
        const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
        const std::string at = "vy = " + format_number(vy) + ", d = " + std::to_string(d) +
                               ", mu = " + format_number(mu);
        ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
        ASSERT_FALSE(tr.samples.empty());
        EXPECT_EQ(tr.samples.back().t, 0.3) << at;
        expect_laws(m, tr, at);
        const Eigen::Index N = m.dofs();
        int stuck = 0;
        for (const sim::Sample& s : tr.samples) {
          if (s.t <= std::sqrt(2 * 0.03 / kG) + 1e-9) continue;  // after the landing
          const VectorXd v = s.x.segment(N, N);
          for (size_t f = 0; f < m.friction.size(); ++f) {
            const mech::FrictionalContact& fc = m.friction[f];
            if (std::find(s.mode.begin(), s.mode.end(), fc.contact) == s.mode.end() ||
                s.friction_mode[f] != sim::FrictionMode::kStick)
              continue;
            ++stuck;  // the tolerance of the test above
            EXPECT_LE(std::abs(fc.sliding(v)), 1e-12) << at << " t = " << s.t << " foot " << f;
            EXPECT_LE(std::abs(fc.tangent2.dot(v)), 1e-12) << at << " t = " << s.t;
          }
        }
        EXPECT_GT(stuck, 0) << at;
      }
}

// The same landing with d = 1 (friction along each foot's t = +y only),
// which the impact law refused as Painlevé-type before (issue 27): its test
// enumerated every slip sign pattern in advance, and fl slipping +t with fr
// slipping -t (a yaw) gives on {fl, fr} a minor -0.2499 for mu = 0.8
// (non-P for mu > 0.2712), although the landing does not take that pattern.
// The law now solves the impact LCP and judges the modes of its solution
// (every foot sticks after this landing, so nothing slips and the normal
// matrix is Delassus's). Checked: the run reaches t_end and on every 1 ms
// sample the Coulomb law holds: expect_laws (gaps >= -1e-12 m, normal forces
// >= 0, |u_T| <= mu u_N, no force along t2, the energy never rising), and a
// closed foot in slip has its force on the edge opposite its sliding, u_T =
// -sign(t'v) mu u_N, to 1e-9 m g (the tolerance of expect_laws: forces
// solved to rounding from a 12-dof system of O(m g) terms); one sticking has
// t'v = 0 to 1e-12 m/s (as the d = 4 test above).
// Vision 60 landing on its four toes with a 3-D cone and a sideways
// velocity. Its toes stick at the landing; 10-15 ms later their stick
// forces reach the polygons together and each toe may stick or start to
// slide on any of its edges and faces: (1 + 4d)^4 combinations (6561 at
// d = 2, 83 521 at d = 4), of which the selection tries 4096. These two runs
// were refused there ("none of the first 4096 of ... combinations ... is
// consistent"); the cone LCP's guess (cone_guess.cpp) is now tried first.
// Checked: the run reaches t_end, and the laws on every 1 ms sample
// (expect_laws, as above). The seven variants the guess did not settle run
// since cone_boundary.cpp: tests/scene/test_vision60_friction.cpp.
TEST_F(ExactBoxFriction, Vision60LandingSidewaysTakesTheConeLcpGuess) {
  for (const auto& [d, vx, vy] : {std::tuple{2, 0.3, 0.1}, std::tuple{4, 1.0, 0.0}}) {
    const mech::Model model = scene::load_model(vision60_friction(0.3, d, vx, vy));
    sim::Options o;
    o.t_end = 0.3;
    o.dt_out = 1e-3;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    const std::string at = "d = " + std::to_string(d) + ", v = " + format_number(vx);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    ASSERT_FALSE(tr.samples.empty());
    EXPECT_EQ(tr.samples.back().t, 0.3) << at;
    expect_laws(*model.mechanical, tr, at);
  }
}

TEST_F(ExactBoxFriction, QuadrupedLandingSidewaysWithPlanarFrictionIsNotPainleve) {
  for (const double mu : {0.8, 0.3}) {
    const mech::Model model = scene::load_model(quadruped(mu, 1));
    const mech::MechanicalModel& m = *model.mechanical;
    sim::Options o;
    o.t_end = 1.0;
    o.dt_out = 1e-3;
    const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
    const std::string at = "d = 1, mu = " + format_number(mu);
    ASSERT_EQ(tr.status, Status::kOk) << at << ": " << tr.message;
    ASSERT_FALSE(tr.samples.empty());
    EXPECT_EQ(tr.samples.back().t, 1.0) << at;
    ASSERT_FALSE(tr.events.empty());
    const double t_land = std::sqrt(2 * 0.03 / kG);  // the scene's header
    EXPECT_NEAR(tr.events.front().t, t_land, 1e-9) << at;
    expect_laws(m, tr, at);
    const Eigen::Index N = m.dofs();
    const double tol = 1e-9 * m.M.coeff(0, 0) * kG;
    int slipping = 0, sticking = 0;
    for (const sim::Sample& s : tr.samples) {
      const VectorXd v = s.x.segment(N, N);
      for (size_t f = 0; f < m.friction.size(); ++f) {
        const mech::FrictionalContact& fc = m.friction[f];
        if (std::find(s.mode.begin(), s.mode.end(), fc.contact) == s.mode.end()) continue;
        const double uN = s.u(fc.contact), ut = s.u_t(static_cast<Eigen::Index>(f));
        const sim::FrictionMode fm = s.friction_mode[f];
        if (fm == sim::FrictionMode::kSlipPositive || fm == sim::FrictionMode::kSlipNegative) {
          ++slipping;
          const double sigma = fm == sim::FrictionMode::kSlipPositive ? 1.0 : -1.0;
          EXPECT_GE(sigma * fc.sliding(v), 0.0) << at << " t = " << s.t << " foot " << f;
          EXPECT_NEAR(ut, -sigma * fc.mu * uN, tol) << at << " t = " << s.t << " foot " << f;
        } else if (fm == sim::FrictionMode::kStick && s.t > t_land + 1e-9) {
          ++sticking;
          EXPECT_LE(std::abs(fc.sliding(v)), 1e-12) << at << " t = " << s.t << " foot " << f;
        }
      }
    }
    std::printf("[ quadruped ] %s: %zu events, closed-foot samples slipping %d, sticking %d\n",
                at.c_str(), tr.events.size(), slipping, sticking);
    EXPECT_GT(sticking, 0) << at;  // the checks above ran
  }
}

}  // namespace
}  // namespace lcsim
