// Issue 27 with planar friction (d = 1, one tangent row per contact): the
// box of robots/box.urdf landing flat on its four coplanar corners at
// mu = 100 (Painlevé-type alone, so the impact is decided by enumerating
// the corners' modes; the normal block of the four corners has rank 3, so
// several mode systems are singular). Before, the planar enumeration
// refused the first singular system ("is singular (it may hold a continuum
// of motions)"); it now judges it by velocity uniqueness as the cone's does
// (detail::solve_mode_system), and the landing is one motion: every corner
// sticks along its tangent.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim {
namespace {

using Eigen::Vector3d;
using Eigen::VectorXd;

constexpr double kG = 9.81, kDrop = 0.2;    // m/s^2; m (the base at 0.25, its half height 0.05)
constexpr double kVx = 1.0, kVy = 0.4;      // m/s, robots/box_slide_scene.yaml's sideways velocity
constexpr double kTEnd = 0.5, kMu = 100.0;  // s, -

// The box dropped flat with planar friction (d = 1) on its corners
// (tests/sim/data/box_drop_planar_high_mu.yaml: mu = kMu, the velocity
// (kVx, kVy), t_end = kTEnd).
mech::Model load() {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) +
                           "/tests/sim/data/box_drop_planar_high_mu.yaml");
}

// The corners' tangent in the world: with d = 1 every corner's friction
// acts along one horizontal unit vector t_w (the translational part of its
// tangent row; the base's first three coordinates are its position).
Vector3d world_tangent(const mech::MechanicalModel& m) {
  const Vector3d t = VectorXd(m.friction.front().tangent).head(3);
  for (const mech::FrictionalContact& fc : m.friction)
    EXPECT_LE((VectorXd(fc.tangent).head(3) - t).cwiseAbs().maxCoeff(), 1e-15);
  EXPECT_NEAR(t.norm(), 1.0, 1e-15);
  EXPECT_NEAR(t(2), 0.0, 1e-15);
  return t;
}

// Closed form (one point mass, as the d = 2 / 4 test): the landing at t_i
// = sqrt(2 h / g) with V = g t_i. Sticking along t_w needs the impulse m
// |s . t_w| <= mu m V (0.4 <= 198 N s per kg), so the impact removes the
// velocity along t_w and leaves s_perp = s - (s . t_w) t_w, with no
// rotation (every corner's normal and tangential rate is zero after it,
// which fixes roll, pitch and yaw rates). Then the box slides at s_perp
// without friction (d = 1: none across t_w) and sticks along t_w.
struct Landing {
  double ti;
  Vector3d s_perp;
};
Landing closed_form(const Vector3d& t) {
  const Vector3d s(kVx, kVy, 0.0);
  const double ti = std::sqrt(2 * kDrop / kG);
  EXPECT_LE(std::abs(s.dot(t)), kMu * kG * ti);  // it sticks
  return {ti, s - s.dot(t) * t};
}

// The impact law at the landing state, through the library API: the
// bottom corners closed (gap zero), Newton's law with friction ("moreau";
// the scene's restitution is 0). The corners slide across t_w after it
// (their outcome is a slip, without friction that way), so the check is on
// the velocity and the impulses' sums. The
// post-impact velocity to 1e-12 m/s: the impact LCP is solved to rounding
// on terms of V ~ 2 m/s (1e-16 relative), 1e-12 leaves room for the
// conditioning of the rank-3 normal block.
TEST(PlanarBoxLanding, ImpactLawSticksEveryCornerAlongItsTangent) {
  const mech::Model model = load();
  const mech::MechanicalModel& m = *model.mechanical;
  const Landing c = closed_form(world_tangent(m));
  impact::ImpactInput in;
  in.model = &m;
  in.q = VectorXd::Zero(m.dofs());
  in.q << kVx * c.ti, kVy * c.ti, 0.05, 0, 0, 0;
  in.v = VectorXd::Zero(m.dofs());
  in.v << kVx, kVy, -kG * c.ti, 0, 0, 0;
  const VectorXd gap = m.E * in.q + m.g;
  // The bottom corners touch to the rounding of E q + g (terms ~0.2 m).
  for (int i = 0; i < gap.size(); ++i)
    if (std::abs(gap(i)) <= 1e-12) in.closed.push_back(i);
  ASSERT_EQ(in.closed.size(), 4u);
  const impact::ImpactResult r =
      impact::make_impact_law("moreau")->apply(in, *lcp::make_solver("lemke"));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.painleve);
  VectorXd expected = VectorXd::Zero(m.dofs());
  expected.head(3) = c.s_perp;
  EXPECT_LE((r.v_after - expected).cwiseAbs().maxCoeff(), 1e-12) << r.v_after.transpose();
  // The split among the corners is not unique (rank 3); the sums are: the
  // normal impulse m V, the friction along t_w -m (s . t_w) (m = 1.2 kg,
  // robots/box.urdf), each corner's inside |P_T| <= mu P_N. To 1e-11 N s:
  // m times the velocity's 1e-12, with room for the sum of four.
  const double mass = 1.2, V = kG * c.ti;
  double normal = 0.0, friction = 0.0;
  for (const int row : in.closed) {
    normal += r.impulse(row);
    friction += r.friction_impulse(row);
    EXPECT_LE(std::abs(r.friction_impulse(row)), kMu * r.impulse(row) + 1e-11) << row;
  }
  EXPECT_NEAR(normal, mass * V, 1e-11);
  EXPECT_NEAR(friction, -mass * Vector3d(kVx, kVy, 0).dot(world_tangent(m)), 1e-11);
}

// The exact method (Algorithm 3.7.1) on the whole drop: the landing is an
// impact at t_i, the box then slides at s_perp, level, to t_end. Tolerance
// 1e-12 as the d = 2 / 4 test (BoxLandingFlatAtHighMuSticksWhereItLands):
// the phases' exponentials and the event's root are exact to rounding
// (1e-16 relative) on positions of 0.5 m and speeds of 2 m/s.
TEST(PlanarBoxLanding, ExactMethodLandsAndSticksWhereItLands) {
  const mech::Model model = load();
  const Landing c = closed_form(world_tangent(*model.mechanical));
  sim::Options o;
  o.t_end = kTEnd;
  const sim::Trajectory tr = sim::make_integrator("event")->run(model, model.initial, o);
  ASSERT_EQ(tr.status, Status::kOk) << tr.message;
  ASSERT_FALSE(tr.events.empty());
  const sim::Event& impact = tr.events.front();
  EXPECT_EQ(impact.type, sim::EventType::kImpact);
  EXPECT_NEAR(impact.t, c.ti, 1e-12);
  const VectorXd& xa = impact.state_after;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(xa(6 + k), c.s_perp(k), 1e-12) << k;
  EXPECT_LE(xa.segment(9, 3).cwiseAbs().maxCoeff(), 1e-12);  // no rotation
  const VectorXd& xf = tr.final_state;
  const Vector3d at_end = Vector3d(kVx, kVy, 0) * c.ti + c.s_perp * (kTEnd - c.ti);
  EXPECT_NEAR(xf(0), at_end(0), 1e-12);
  EXPECT_NEAR(xf(1), at_end(1), 1e-12);
  EXPECT_NEAR(xf(2), 0.05, 1e-12);
  EXPECT_LE(xf.segment(3, 3).cwiseAbs().maxCoeff(), 1e-12);  // level, no yaw
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(xf(6 + k), c.s_perp(k), 1e-12) << k;
  EXPECT_LE(xf.segment(9, 3).cwiseAbs().maxCoeff(), 1e-12);
}

}  // namespace
}  // namespace lcsim
