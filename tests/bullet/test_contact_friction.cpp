// Bullet's friction on a contact scene (WorldSettings::friction): the box
// sliding on the floor at a heading, against the closed forms.
//
// Why the tolerances are what they are. The box rests on its four bottom
// corners (Bullet's speculative rows at ERP 0 hold it at the floor; the
// normal impulses sum to m g h every step) and slides under the friction
// impulse mu m g h per step, so its speed falls by exactly mu g h per step:
// semi-implicit Euler, v_{k+1} = v_k - mu g h, x_{k+1} = x_k + h v_{k+1}.
// - the speed reaches 0 in the step that ends within h after the closed
//   form's stop v0/(mu g); the measured stop (the first sample from which
//   the speed stays <= v_stop = 1e-3 m/s) may come v_stop/(mu g) = 3.4e-4 s
//   before it: |t - t*| <= 2 h;
// - the distance is h times the sum of the step-end speeds,
//   v0^2/(2 mu g) - v0 h/2 + O(h^2): |d - d*| <= v0 h;
// - the heading: along t1 (psi = 0) the corners' friction acts through the
//   box's centre plane symmetrically, so the direction stays psi up to the
//   solver's residual (100 sweeps; measured 2e-17), asserted at 1e-9 rad.
// The box friction bounds each tangent's impulse alone, so each axis slows
// at mu g alone: the components v0 |cos psi|, v0 |sin psi| stop at their own
// times, the last at v0 max(|cos psi|, |sin psi|)/(mu g) (the same 2 h),
// after c1^2/(2 mu g) and c2^2/(2 mu g) along the axes (the same v0 h), the
// last phase along the faster component's axis (psi = pi/4: both stop
// together, straight along psi).
// Bullet's circular cone away from the axes (psi = pi/8, pi/4) is not
// asserted: its Gauss-Seidel pass solves each point's two rows in turn and
// scales the result back onto the circle, which is not the impulse opposite
// the sliding when the rows are coupled (a corner's Delassus block couples
// t1 and t2 through the box's rotation), so the box turns (measured: the
// final heading 0.065 rad for psi = pi/8, 0.18 for pi/4; docs/contacts.md).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

#include "support/slide_scene.hpp"

namespace lcsim::bullet {
namespace {

constexpr double kMu = 0.3, kG = 9.81, kV0 = 1.0, kH = 1e-3;

test_support::SlideMeasure slide(double psi, WorldSettings::Friction f,
                                 std::string* method = nullptr) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("lcsim_bullet_slide_" + std::to_string(::getpid()));
  const mech::Model m = scene::load_model(test_support::write_slide_scene(dir, psi, kMu, kV0, 0.6));
  sim::Options o;
  o.t_end = 0.6;
  o.h = kH;
  o.dt_out = kH;
  WorldSettings ws;
  ws.friction = f;
  const sim::Trajectory tr = simulate_bullet(m, m.initial, o, ws);
  EXPECT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  if (method) *method = tr.method;
  std::filesystem::remove_all(dir);
  const auto s = test_support::measure_slide(tr, 1e-3, 0.05);
  std::printf("[ bullet   ] psi %.4f %s: stop %.6f distance %.6f heading %.6f dz %.2e\n", psi,
              friction_name(f).c_str(), s.t_stop, s.distance, s.heading, s.max_height_change);
  return s;
}

TEST(BulletFriction, TheConeSlidesTheBoxAlongATangentAsTheCircularConeSays) {
  const auto s = slide(0.0, WorldSettings::Friction::kCone);
  EXPECT_NEAR(s.t_stop, kV0 / (kMu * kG), 2 * kH);
  EXPECT_NEAR(s.distance, kV0 * kV0 / (2 * kMu * kG), kV0 * kH);
  EXPECT_NEAR(s.heading, 0.0, 1e-9);
}

TEST(BulletFriction, TheBoxFrictionSlowsEachAxisAlone) {
  for (const double psi : {0.0, M_PI / 8, M_PI / 4}) {
    const auto s = slide(psi, WorldSettings::Friction::kBox);
    const double c1 = kV0 * std::cos(psi), c2 = kV0 * std::sin(psi);
    EXPECT_NEAR(s.t_stop, std::max(c1, c2) / (kMu * kG), 2 * kH) << psi;
    EXPECT_NEAR(s.distance, std::hypot(c1 * c1, c2 * c2) / (2 * kMu * kG), kV0 * kH) << psi;
    EXPECT_NEAR(s.heading, psi == M_PI / 4 ? psi : 0.0, 1e-9) << psi;
  }
}

TEST(BulletFriction, TheSettingsAreReportedAndBadNamesRefused) {
  std::string method;
  slide(0.0, WorldSettings::Friction::kCone, &method);
  EXPECT_NE(method.find("SOLVER_USE_2_FRICTION_DIRECTIONS with implicit cone friction"),
            std::string::npos)
      << method;
  EXPECT_NE(method.find("friction mu (link) x 1 (plane)"), std::string::npos) << method;
  EXPECT_EQ(parse_friction("box"), WorldSettings::Friction::kBox);
  try {
    parse_friction("pyramid");
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "bullet: unknown friction model 'pyramid' (cone, box, one-direction)");
  }
}

TEST(BulletFriction, ALinkWithTwoCoefficientsIsRefusedInOneLine) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lcsim_bullet_two_mu_" + std::to_string(::getpid()));
  const std::string path = test_support::write_two_mu_scene(dir);
  const mech::Model m = scene::load_model(path);
  try {
    check_expressible(m);
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), ("bullet: " + path +
                            ": contact 'box_wall.corner1' has friction mu = 0.5 but contact "
                            "'box.corner0' of the same link 'box' has mu = 0.3: Bullet's "
                            "friction is per collider (one mu per link)")
                               .c_str());
  }
  std::filesystem::remove_all(dir);
}

// The samples' friction multipliers (issue 27's outputs) on the box sliding
// along the floor's first tangent (psi = 0: +t1 = +y): each step's friction
// on the four corners sums to -mu times their normal multipliers while it
// slides (on the cone's boundary, against the velocity: to rounding of O(1)
// N), nothing acts along t2, and the multipliers are the whole horizontal
// force on the box, so their impulse is its momentum change,
// sum h u_t = m (v_y(T) - v0), to rounding (600 steps: 1e-12 N s).
TEST(PeerFrictionOutputs, TheSamplesCarryTheFrictionAlongTheTangents) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lcsim_bullet_slide_ut_" + std::to_string(::getpid()));
  const mech::Model m = scene::load_model(test_support::write_slide_scene(dir, 0.0, kMu, kV0, 0.6));
  sim::Options o;
  o.t_end = 0.6;
  o.h = kH;
  o.dt_out = kH;
  const sim::Trajectory tr = simulate_bullet(m, m.initial, o);
  std::filesystem::remove_all(dir);  // the peer has read the scene again
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_EQ(tr.samples.back().u_t.size(), 4);  // the bottom corners (max_distance drops the top)
  ASSERT_EQ(tr.samples.back().u_t2.size(), 4);
  double coulomb = 0.0, across = 0.0, impulse = 0.0;
  int sliding = 0;
  for (std::size_t j = 1; j < tr.samples.size(); ++j) {
    const sim::Sample& s = tr.samples[j];
    impulse += kH * s.u_t.sum();
    across = std::max(across, std::abs(s.u_t2.sum()));
    if (s.x(7) < 0.05) continue;  // sliding: v_y well above 0
    coulomb = std::max(coulomb, std::abs(s.u_t.sum() + kMu * s.u.sum()));
    ++sliding;
  }
  const double mass = 1.2, v_end = tr.final_state(7);
  std::printf(
      "[ bullet   ] |u_t + mu u_n| <= %.3e N over %d sliding steps, |u_t2| <= %.3e N, "
      "impulse %.12g N s (m (v_end - v0) = %.12g)\n",
      coulomb, sliding, across, impulse, mass * (v_end - kV0));
  EXPECT_GT(sliding, 250);
  EXPECT_LE(coulomb, 1e-9);
  EXPECT_LE(across, 1e-9);
  EXPECT_NEAR(impulse, mass * (v_end - kV0), 1e-12);
}

// `--method bullet` (the registered integrator) runs a contact scene's
// friction as simulate_bullet with its default settings does: the same run,
// bit for bit (one code path), and the closed form's stop as above. A model
// of matrices with friction has no contact for Bullet's friction: refused in
// one line naming the model and the methods that simulate it.
TEST(BulletFriction, MethodBulletRunsASceneWithFrictionAndRefusesMatrices) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("lcsim_bullet_method_" + std::to_string(::getpid()));
  const mech::Model m = scene::load_model(test_support::write_slide_scene(dir, 0.0, kMu, kV0, 0.6));
  sim::Options o;
  o.t_end = 0.6;
  o.h = kH;
  o.dt_out = kH;
  const sim::Trajectory tr = sim::make_integrator("bullet")->run(m, m.initial, o);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const sim::Trajectory direct = simulate_bullet(m, m.initial, o, WorldSettings{});
  std::filesystem::remove_all(dir);  // Bullet reads the scene's file (model.source)
  ASSERT_EQ(tr.final_state.size(), direct.final_state.size());
  EXPECT_EQ(tr.final_state, direct.final_state);  // the same code path: no rounding apart
  const auto s = test_support::measure_slide(tr, 1e-3, 0.05);
  EXPECT_NEAR(s.t_stop, kV0 / (kMu * kG), 2 * kH);  // the tolerances of the first test
  EXPECT_NEAR(s.distance, kV0 * kV0 / (2 * kMu * kG), kV0 * kH);

  mech::MechanicalModel b;  // a unit mass on the floor y >= 0, friction along x
  b.M = Eigen::MatrixXd::Identity(2, 2).sparseView();
  b.E = Eigen::RowVector2d(0, 1).sparseView();
  b.f = Eigen::Vector2d(0, -kG);
  b.friction.push_back(mech::FrictionalContact(0, Eigen::Vector2d(1, 0), kMu));
  const mech::Model block = mech::model_of(b, "block");
  const sim::Trajectory refused =
      sim::make_integrator("bullet")->run(block, (Eigen::VectorXd(4) << 0, 0, 1, 0).finished(), o);
  EXPECT_EQ(refused.status, sim::RunStatus::kInvalidInput);
  EXPECT_EQ(refused.message,
            "bullet: model 'block': mechanical.friction on a model that is not a URDF contact "
            "scene: Bullet runs friction at a scene's contacts only (methods 'event', "
            "'moreau-jean' and 'euler' simulate it)");
}

}  // namespace
}  // namespace lcsim::bullet
