// Friction at a scene's contacts (issue 27; src/scene/scene_contact_friction.cpp,
// docs/contacts.md): `friction:` and `d:` per contacts entry or in
// contact_options make each contact row a 3-D frictional contact with its
// ContactFrame's tangents; bad values are one line naming the key.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>

#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
constexpr double kG = 9.81, kMu = 0.3;

class ContactFriction : public test_support::SceneFiles {
 protected:
  // robots/box.urdf resting flat on the floor (the box_drop scene at its
  // rest), its four bottom corners kept (the top ones are 0.1 m up), with
  // `entry` added to its contacts entry and `options` to contact_options.
  std::string scene(const std::string& entry, const std::string& options = "",
                    const std::string& v = "") {
    write("box.urdf", io::read_file(kRobots + "box.urdf"));
    return write("slide.yaml",
                 "name: box_slide\nurdf: box.urdf\n"
                 "base: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n"
                 "planes:\n  - {name: floor, point: [0, 0, 0], normal: [0, 0, 1]}\n"
                 "contacts:\n  - {link: box, plane: floor" +
                     entry + "}\ncontact_options: {max_distance: 0.05" + options +
                     "}\ninitial:\n  v: {" + v + "}\nt_end: 1\n");
  }
};

TEST_F(ContactFriction, EachContactRowBecomesA3dFrictionalContact) {
  const auto loaded = scene::load_model_and_scene(scene(", friction: 0.3, d: 6"));
  const mech::MechanicalModel& m = *loaded.model.mechanical;
  ASSERT_EQ(m.friction.size(), 4u);
  for (std::size_t i = 0; i < 4; ++i) {
    const mech::FrictionalContact& c = m.friction[i];
    const scene::ContactFrame& f = loaded.scene->contacts[i];
    EXPECT_EQ(c.contact, f.row);
    EXPECT_EQ(c.mu, 0.3);
    EXPECT_EQ(c.edges, 6);
    EXPECT_TRUE(c.is_3d());
    EXPECT_TRUE(c.world_frame);
    EXPECT_EQ((VectorXd(c.tangent) - f.tangent1_row).norm(), 0.0);
    EXPECT_EQ((VectorXd(c.tangent2) - f.tangent2_row).norm(), 0.0);
  }
  // The default from contact_options, d the model's (4) when not given.
  const mech::Model d = scene::load_model(scene("", ", friction: 0.5"));
  ASSERT_EQ(d.mechanical->friction.size(), 4u);
  EXPECT_EQ(d.mechanical->friction[0].mu, 0.5);
  EXPECT_EQ(d.mechanical->edges_of(d.mechanical->friction[0]), 4);
  // Without the key: frictionless, as before.
  EXPECT_TRUE(scene::load_model(scene("")).mechanical->friction.empty());
}

TEST_F(ContactFriction, BadValuesAreOneLineNamingTheKey) {
  auto error = [](const std::string& path) -> std::string {
    try {
      scene::load_model(path);
    } catch (const io::InputError& e) {
      return e.what();
    }
    return "no error";
  };
  const std::string p1 = scene(", friction: -0.1");
  EXPECT_EQ(error(p1), p1 + ": contacts[0].friction: must be a coefficient mu >= 0 (got -0.1)");
  const std::string p2 = scene(", friction: 0.3, d: 0");
  EXPECT_EQ(error(p2), p2 + ": contacts[0].d: must be a whole number >= 1 and <= 1024 (got '0')");
  const std::string p3 = scene(", d: 4");
  EXPECT_EQ(error(p3), p3 + ": contacts[0].d: applies to a contact with friction: (give its mu)");
  const std::string p4 = scene("", ", friction: 0.3, d: 2.5");
  EXPECT_EQ(error(p4),
            p4 + ": contact_options.d: must be a whole number >= 1 and <= 1024 (got '2.5')");
}

// The box given a sideways velocity slides and stops as mech::cone_slide
// says: its four corners share the load m g (a redistribution among them,
// front to back, balances the friction's pitching moment; the centre of
// pressure moves along the friction force, so the yaw moment is zero) and
// each slides on the same facet, so the box translates as one point mass
// on the cone of 2d edges of its contact frame (t1, t2 of the floor). The
// bound is test_mj_friction3d.cpp's: the stop within [0, h] after the
// closed form's (plus 1e-9 for the rounding of the step count), the heading
// at rest to 1e-9 rad, the displacement (theta = 0.5, trapezoids exact on
// the linear phases) within 2 mu g h^2 per component. The box stays level
// but for the steps where the frictionless step's active-set rule leaves a
// corner out (a gap ending at +1e-21, test_mj_friction3d.cpp): in such a
// step the friction's pitching moment mu m g (0.05 m) = 0.18 N m acts on
// I_y = 0.01 kg m^2 unbalanced, turning the box by 0.18 h^2 / 0.01 = 1.8e-5
// rad; a few such steps: the rotation within 2e-4 rad, the centre's height
// within the corner's lever 0.15 m times that (3e-5 m). Measured: at most
// 3.1e-5 rad and 1.5e-5 m.
TEST_F(ContactFriction, BoxSlidesAndStopsAtTheClosedFormsDistance) {
  const double pi = std::acos(-1.0), s0 = 1.0, h = 1e-3;
  for (double psi : {0.0, pi / 8, 0.3}) {  // on an edge, on a bisector, between (d = 4)
    // The floor's frame: t1 = +y, t2 = n x t1 = -x (scene::contact_frame),
    // so a heading psi from t1 is the world velocity s0 (-sin psi, cos psi).
    const double vx = -s0 * std::sin(psi), vy = s0 * std::cos(psi);
    const auto loaded = scene::load_model_and_scene(
        scene(", friction: 0.3, d: 4", "",
              "box.x: " + format_number(vx) + ", box.y: " + format_number(vy)));
    const scene::ContactFrame& f = loaded.scene->contacts[0];
    ASSERT_NEAR(f.tangent1.dot(Eigen::Vector3d(vx, vy, 0)), s0 * std::cos(psi), 1e-15);
    ASSERT_NEAR(f.tangent2.dot(Eigen::Vector3d(vx, vy, 0)), s0 * std::sin(psi), 1e-15);
    const mech::ConeSlide cs = mech::cone_slide(s0, psi, kMu, kG, 4);
    sim::Options o;
    o.t_end = cs.t_stop + 0.05;
    o.h = h;
    const sim::Trajectory tr =
        sim::make_integrator("moreau-jean")->run(loaded.model, loaded.model.initial, o);
    ASSERT_EQ(tr.status, Status::kOk) << tr.message;
    double t_stop = -1.0;
    Eigen::Vector3d at_stop = Eigen::Vector3d::Zero();
    for (const sim::Sample& s : tr.samples)
      if (s.t > 0.0 && std::hypot(s.x(6), s.x(7)) <= 1e-12 * s0) {
        t_stop = s.t;
        at_stop = s.x.head(3);
        break;
      }
    const std::string at = "psi = " + std::to_string(psi);
    ASSERT_GT(t_stop, 0.0) << at;
    EXPECT_GE(t_stop - cs.t_stop, -1e-9) << at;
    EXPECT_LE(t_stop - cs.t_stop, h + 1e-9) << at;
    // Displacement along t1, t2: (y, -x) in the world.
    const double rem = 2 * kMu * kG * h * h;
    EXPECT_NEAR(at_stop(1), cs.x, rem) << at;
    EXPECT_NEAR(-at_stop(0), cs.y, rem) << at;
    EXPECT_NEAR(at_stop(2), 0.05, 3e-5) << at;
    EXPECT_LE(tr.final_state.segment(3, 3).cwiseAbs().maxCoeff(), 2e-4) << at;
  }
}

}  // namespace
}  // namespace lcsim
