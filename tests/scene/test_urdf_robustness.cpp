// URDF features met in public robot descriptions (bullet3's data/,
// example-robot-data), reproduced by small URDFs written here: continuous
// joints, Bullet's "lower > upper means no limit", links without <inertial>
// (src/scene/scene.cpp, src/scene/urdf_model.cpp, docs/model-format.md).
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>

#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;

// Scenes below are written with "urdf: r.urdf" in front.
class UrdfRobustness : public test_support::SceneFiles {
 protected:
  scene::Scene load(const std::string& urdf, const std::string& scene) {
    write("r.urdf", urdf);
    return *scene::load_scene_details(write("s.yaml", "urdf: r.urdf\n" + scene));
  }
  std::string error(const std::string& urdf, const std::string& scene) {
    return SceneFiles::error(urdf, "urdf: r.urdf\n" + scene);
  }
};

// A link of mass m with its centre l below its joint and rotational inertia
// `i` about every axis through its centre.
std::string link(const std::string& name, double m, double l, double i) {
  const auto s = [](double x) { return std::to_string(x); };
  return "<link name='" + name + "'><inertial><origin xyz='0 0 " + s(-l) + "'/><mass value='" +
         s(m) + "'/><inertia ixx='" + s(i) + "' ixy='0' ixz='0' iyy='" + s(i) + "' iyz='0' izz='" +
         s(i) + "'/></inertial></link>";
}

// Joint `name` of type `type` from `parent` to `child`, about x, at height z.
std::string joint(const std::string& name, const std::string& type, const std::string& parent,
                  const std::string& child, const std::string& limit = "", double z = 0.0) {
  return "<joint name='" + name + "' type='" + type + "'><parent link='" + parent +
         "'/><child link='" + child + "'/><origin xyz='0 0 " + std::to_string(z) +
         "'/><axis xyz='1 0 0'/>" + limit + "</joint>";
}

std::string limit(double lower, double upper) {
  return "<limit lower='" + std::to_string(lower) + "' upper='" + std::to_string(upper) +
         "' effort='1' velocity='1'/>";
}

// A pendulum (mass 2, centre 0.5 below the pivot, inertia 0.1 about its
// centre) hanging from a continuous joint, as the pendulums and wheels of
// bullet3's pendulum5.urdf, cartpole.urdf and mini_cheetah.urdf.
std::string pendulum(const std::string& type, const std::string& lim = "") {
  return "<robot name='p'><link name='base'/>" + link("bob", 2.0, 0.5, 0.1) +
         joint("j", type, "base", "bob", lim) + "</robot>";
}

TEST_F(UrdfRobustness, ContinuousJointIsSimulatedWithoutStops) {
  const scene::Scene s = load(pendulum("continuous"), "joints: [j]\n");
  const mech::MechanicalModel& m = *s.model.mechanical;
  // M = I + m l^2 = 0.1 + 2 * 0.25 = 0.6; sums and products of exactly
  // representable numbers up to one rounding of the rotation (cos 0 = 1).
  EXPECT_NEAR(MatrixXd(m.M)(0, 0), 0.6, 1e-15);
  // Hanging at q0 = 0: K_g = m g l = 2 * 9.81 * 0.5 = 9.81; the central
  // difference's error is below 1e-10 (docs/model-format.md), 1e-8 asked.
  EXPECT_NEAR(MatrixXd(m.K)(0, 0), 9.81, 1e-8);
  EXPECT_EQ(m.E.rows(), 0);  // a continuous joint has no stops
  EXPECT_TRUE(m.constraints.empty());
}

TEST_F(UrdfRobustness, ContinuousJointIgnoresItsLimit) {
  // example-robot-data's double_pendulum_continuous.urdf has
  // <limit lower="0" upper="0"> on continuous joints; URDF ignores lower and
  // upper there, so they are neither stops nor bounds of the linear range.
  const scene::Scene s = load(pendulum("continuous", limit(0, 0)), "joints: [j]\n");
  EXPECT_EQ(s.model.mechanical->E.rows(), 0);
  const auto r = scene::linear_ranges(s, 0.01);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_NE(r[0].lower_end, "limit");
  EXPECT_NE(r[0].upper_end, "limit");
  EXPECT_LT(r[0].lower, 0.0);
  EXPECT_GT(r[0].upper, 0.0);
  // The same pendulum on a revolute joint without stops is the same model.
  const scene::Scene rev =
      load(pendulum("revolute", limit(-1, 1)), "joints: [{name: j, stops: []}]\n");
  EXPECT_EQ(MatrixXd(rev.model.mechanical->M), MatrixXd(s.model.mechanical->M));
  EXPECT_EQ(MatrixXd(rev.model.mechanical->K), MatrixXd(s.model.mechanical->K));
}

TEST_F(UrdfRobustness, ContinuousJointRefusesStops) {
  const std::string e = error(pendulum("continuous"), "joints: [{name: j, stops: [lower]}]\n");
  EXPECT_NE(e.find("s.yaml: joints[0].stops: joint 'j' is continuous"), std::string::npos) << e;
  EXPECT_NE(e.find("write stops: []"), std::string::npos) << e;
}

// Bullet's Pendulum_Tendon_1_Cart_Rail.urdf writes lower='1' upper='0' (its
// convention for "no limit") on joints a scene may freeze.
std::string cart_with_unlimited_pendulum() {
  return "<robot name='c'><link name='base'/>" + link("cart", 3.0, 0.0, 0.2) +
         link("bob", 2.0, 0.5, 0.1) + joint("x", "prismatic", "base", "cart", limit(-1, 1)) +
         joint("p", "revolute", "cart", "bob", limit(1, 0)) + "</robot>";
}

TEST_F(UrdfRobustness, LowerAboveUpperOnAFrozenJointIsUnused) {
  const scene::Scene s = load(cart_with_unlimited_pendulum(), "joints: [x]\n");
  // The frozen pendulum rides on the cart: M = 3 + 2 (axis x is prismatic:
  // only the masses count), exact.
  EXPECT_EQ(MatrixXd(s.model.mechanical->M)(0, 0), 5.0);
  EXPECT_EQ(s.model.mechanical->constraints, (std::vector<std::string>{"x_lower", "x_upper"}));
}

TEST_F(UrdfRobustness, LowerAboveUpperIsSimulatedWithoutStops) {
  const scene::Scene s =
      load(cart_with_unlimited_pendulum(), "joints: [x, {name: p, stops: []}]\n");
  EXPECT_EQ(s.model.mechanical->constraints, (std::vector<std::string>{"x_lower", "x_upper"}));
  // Nor does the unusable limit bound p's linear range (it used to end at
  // "limit" upper = 0, the reference position itself).
  const auto r = scene::linear_ranges(s, 0.01);
  ASSERT_EQ(r.size(), 2u);
  EXPECT_NE(r[1].lower_end, "limit");
  EXPECT_NE(r[1].upper_end, "limit");
  EXPECT_GT(r[1].upper, 0.0);
}

TEST_F(UrdfRobustness, LowerAboveUpperCannotBeAStop) {
  const std::string e = error(cart_with_unlimited_pendulum(), "joints: [x, p]\n");
  EXPECT_NE(e.find("r.urdf: joint 'p': <limit>: lower > upper (got lower=1, upper=0)"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("s.yaml: joints[1]: write stops: []"), std::string::npos) << e;
}

TEST_F(UrdfRobustness, LowerAboveUpperOnAMimicCannotBeAStop) {
  const std::string u = "<robot name='g'><link name='base'/>" + link("a", 1.0, 0.0, 0.1) +
                        link("b", 1.0, 0.0, 0.1) +
                        joint("f1", "prismatic", "base", "a", limit(0, 0.04)) +
                        "<joint name='f2' type='prismatic'><parent link='base'/><child "
                        "link='b'/><axis xyz='1 0 0'/>" +
                        limit(1, 0) + "<mimic joint='f1' multiplier='-1'/></joint></robot>";
  const std::string e = error(u, "joints: [f1]\n");
  EXPECT_NE(e.find("joint 'f2': <limit>: lower > upper"), std::string::npos) << e;
  EXPECT_NE(e.find("joints[0]: write mimic_stops: []"), std::string::npos) << e;
  const scene::Scene s = load(u, "joints: [{name: f1, mimic_stops: []}]\n");
  // Both fingers move along x: M = 1 + (-1)^2 * 1 = 2, exact.
  EXPECT_EQ(MatrixXd(s.model.mechanical->M)(0, 0), 2.0);
}

TEST_F(UrdfRobustness, LinkWithoutInertialIsMassless) {
  // URDF allows a link without <inertial> (sensor frames, bullet3's
  // widowx gripper_aux_link, example-robot-data's 'world' links): lcsim
  // gives it no mass. Here the simulated joint moves such a link with a
  // massive link fixed below it: M is that link's alone.
  const std::string u = "<robot name='w'><link name='base'/><link name='frame'/>" +
                        link("bob", 2.0, 0.5, 0.1) +
                        joint("j", "revolute", "base", "frame", limit(-1, 1)) +
                        joint("f", "fixed", "frame", "bob") + "</robot>";
  const scene::Scene s = load(u, "joints: [j]\n");
  EXPECT_NEAR(MatrixXd(s.model.mechanical->M)(0, 0), 0.6, 1e-15);  // as the pendulum above
}

TEST_F(UrdfRobustness, JointCarryingNoMassIsRefused) {
  // The leaf link 'tip' has no <inertial> and nothing below it: joint t
  // moves nothing.
  const std::string u = "<robot name='w'><link name='base'/><link name='tip'/>" +
                        link("bob", 2.0, 0.5, 0.1) +
                        joint("j", "revolute", "base", "bob", limit(-1, 1)) +
                        joint("t", "revolute", "bob", "tip", limit(-1, 1)) + "</robot>";
  const std::string e = error(u, "joints: [j, t]\n");
  EXPECT_NE(e.find("r.urdf: link 'tip': moved by joint 't' but it (with every link fixed, frozen "
                   "or jointed below it) has no <inertial> mass (got total mass 0)"),
            std::string::npos)
      << e;
}

TEST_F(UrdfRobustness, MasslessLinkBetweenSimulatedJoints) {
  // A two-axis hip as bullet3's humanoid.urdf writes it: joint z turns a
  // massless link, joint x below it turns the leg (mass 2, centre 0.5 below
  // the hip, inertia 0.1 about every axis through its centre). At q = 0,
  // about z the leg's centre is on the axis: M_zz = 0.1; about x as the
  // pendulum above, M_xx = 0.6; the axes are orthogonal and the centre is
  // on z, so M_zx = 0. Up to one rounding each (1e-15).
  const std::string u =
      "<robot name='h'><link name='base'/><link name='mid'/>" + link("leg", 2.0, 0.5, 0.1) +
      "<joint name='z' type='revolute'><parent link='base'/><child link='mid'/><axis xyz='0 0 "
      "1'/>" +
      limit(-1, 1) + "</joint>" + joint("x", "revolute", "mid", "leg", limit(-1, 1)) + "</robot>";
  const scene::Scene s = load(u, "joints: [z, x]\n");
  const MatrixXd M = MatrixXd(s.model.mechanical->M);
  EXPECT_NEAR(M(0, 0), 0.1, 1e-15);
  EXPECT_NEAR(M(1, 1), 0.6, 1e-15);
  EXPECT_NEAR(M(0, 1), 0.0, 1e-15);
}

TEST_F(UrdfRobustness, GeometryIsNotRead) {
  // What urdfdom refuses in public robots' geometry, which lcsim never
  // uses: Bullet's capsule (humanoid.urdf), a mesh scale of four numbers
  // (racecar_differential.urdf), two materials of one name; a comment
  // holding an unclosed <visual> tag and a quoted '>' in an attribute must
  // not confuse the scan.
  const std::string u =
      "<?xml version='1.0'?><robot name='g'><material name='white'/><material name='white'/>"
      "<!-- <visual> --><link name='base'><visual name='a>b'><geometry><mesh filename='x.obj' "
      "scale='1 1 1 1'/></geometry><material name='white'/></visual></link>"
      "<link name='bob'><collision><geometry><capsule radius='0.1' length='1'/></geometry>"
      "</collision><visual/>"
      "<inertial><origin xyz='0 0 -0.500000'/><mass value='2'/><inertia ixx='0.1' ixy='0' "
      "ixz='0' iyy='0.1' iyz='0' izz='0.1'/></inertial></link>" +
      joint("j", "revolute", "base", "bob", limit(-1, 1)) + "</robot>";
  const scene::Scene s = load(u, "joints: [j]\n");
  EXPECT_NEAR(MatrixXd(s.model.mechanical->M)(0, 0), 0.6, 1e-15);  // the pendulum above
}

TEST_F(UrdfRobustness, UnclosedVisualIsStillAnError) {
  const std::string e =
      error("<robot name='g'><link name='base'><visual></link></robot>", "joints: [j]\n");
  EXPECT_NE(e.find("r.urdf: not a valid URDF: "), std::string::npos) << e;
}

TEST_F(UrdfRobustness, SingularMassMatrixNamesTheJoint) {
  // j2 turns a point mass (zero inertia tensor) about a vertical axis
  // through it, as bullet3's sphere_small_zeroinertia.urdf would: its column
  // of M is zero, so M is singular along e_j2 and the message names j2 only.
  const std::string u =
      "<robot name='pm'><link name='base'/>" + link("a", 1.0, 0.0, 0.1) +
      "<link name='b'><inertial><mass value='1'/><inertia ixx='0' ixy='0' ixz='0' iyy='0' "
      "iyz='0' izz='0'/></inertial></link>" +
      joint("j1", "revolute", "base", "a", limit(-1, 1)) +
      "<joint name='j2' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>" +
      limit(-1, 1) + "</joint></robot>";
  const std::string e = error(u, "joints: [j1, j2]\n");
  EXPECT_NE(e.find("s.yaml: joints: the mass matrix at q0 is not positive definite"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("along joint 'j2')"), std::string::npos) << e;
}

TEST_F(UrdfRobustness, PointMassOnAFloatingBaseNamesTheBase) {
  // bullet3's sphere_small_zeroinertia.urdf on a floating base: mass 0.1,
  // inertia tensor zero. M is singular along the three rotations; the
  // message says it is the floating base (key `base`), not a joint, and how
  // to fix it. Before, it read "joints: ... along joint 'p.rx' ...: the joint
  // moves no inertia about its axis".
  const std::string u =
      "<robot name='p'><link name='b'><inertial><mass value='0.1'/><inertia ixx='0' ixy='0' "
      "ixz='0' iyy='0' iyz='0' izz='0'/></inertial><collision><geometry><sphere "
      "radius='0.03'/></geometry></collision></link></robot>";
  const std::string e = error(u, "base: {type: floating, pose: {xyz: [0, 0, 0.03]}}\n");
  EXPECT_NE(e.find("s.yaml: base: the mass matrix at q0 is not positive definite"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("along the floating base's 'p.r"), std::string::npos) << e;
  EXPECT_NE(e.find("no rotational inertia"), std::string::npos) << e;
  EXPECT_EQ(e.find("joint"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << e;  // one line
}

}  // namespace
}  // namespace lcsim
