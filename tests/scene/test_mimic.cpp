// <mimic> joints in URDF scenes (src/scene/urdf_model.cpp, src/scene/scene.cpp):
// a mimic follows its leader (q_m = a q_J + b), its mass, gravity and limits
// act through the leader, and it is frozen with its leader.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <random>

#include "scene/scene_files.hpp"
#include "support/same_model.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

// A scene directory in /tmp holding r.urdf and s.yaml (SceneFiles' error()
// loads the same way).
class Mimic : public test_support::SceneFiles {
 protected:
  mech::Model load(const std::string& urdf, const std::string& scene) {
    write("r.urdf", urdf);
    return scene::load_model(write("s.yaml", scene));
  }
};

const char* kInertia = "<inertia ixx='0.003' ixy='0' ixz='0' iyy='0.002' iyz='0' izz='0.004'/>";

// A wrist (revolute about z through the origin) carrying a hand (mass on the
// axis, izz = 0.05) and two prismatic fingers along the hand's y axis at
// height 0.1, centres 0.02 above their joints, mass mf = 0.2, izz = 0.004
// each. The right finger mimics the left with `multiplier` and `offset`;
// `right_limit` is its <limit> ("": [-1, 1]; urdfdom needs one on a
// prismatic joint).
std::string gripper(double multiplier, double offset, const std::string& right_limit) {
  return std::string(
             "<robot name='g'><link name='base'/>"
             "<link name='hand'><inertial><origin xyz='0 0 0.05'/><mass value='1'/>"
             "<inertia ixx='0.03' ixy='0' ixz='0' iyy='0.03' iyz='0' izz='0.05'/></inertial></link>"
             "<link name='left'><inertial><origin xyz='0 0 0.02'/><mass value='0.2'/>") +
         kInertia +
         "</inertial></link><link name='right'><inertial><origin xyz='0 0 0.02'/><mass "
         "value='0.2'/>" +
         kInertia +
         "</inertial></link>"
         "<joint name='wrist' type='revolute'><parent link='base'/><child link='hand'/>"
         "<axis xyz='0 0 1'/><limit lower='-3' upper='3' effort='1' velocity='1'/></joint>"
         "<joint name='finger_l' type='prismatic'><parent link='hand'/><child link='left'/>"
         "<origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>"
         "<limit lower='0' upper='0.04' effort='1' velocity='1'/></joint>"
         "<joint name='finger_r' type='prismatic'><parent link='hand'/><child link='right'/>"
         "<origin xyz='0 0 0.1'/><axis xyz='0 1 0'/>" +
         (right_limit.empty() ? "<limit lower='-1' upper='1' effort='1' velocity='1'/>"
                              : right_limit) +
         "<mimic joint='finger_l' multiplier='" + std::to_string(multiplier) + "' offset='" +
         std::to_string(offset) + "'/></joint></robot>";
}

// Hand derivation, coordinates (wrist angle th, left finger q), right finger
// at y = a q + b in the hand frame (a = multiplier, b = offset). A finger
// centre at hand coordinates (0, y, 0.12) has velocity th' z x r + y' e_y
// (rotated), i.e. speed^2 = th'^2 y^2 + y'^2, no cross term because
// z x (0, y, 0) is along -x and the finger moves along y. So
//   T = 1/2 (I_hand + 2 izz_f + mf (q^2 + (a q + b)^2)) th'^2
//     + 1/2 mf (1 + a^2) q'^2,
//   M = diag(0.05 + 0.008 + 0.2 (q^2 + (a q + b)^2), 0.2 (1 + a^2)).
MatrixXd gripper_M(double q, double a, double b) {
  MatrixXd M = MatrixXd::Zero(2, 2);
  M(0, 0) = 0.05 + 2 * 0.004 + 0.2 * (q * q + (a * q + b) * (a * q + b));
  M(1, 1) = 0.2 * (1 + a * a);
  return M;
}

// Tolerance: the CRBA does a few dozen operations on numbers of order 0.1:
// 1e-15 absolute is ~100 ulp of them; a mimic ignored or applied with the
// wrong multiplier changes M by >= 1e-4 (0.2 * 0.03^2) or 0.2.
constexpr double kTolM = 1e-15;

TEST_F(Mimic, OppositeFingersMoveAsOneCoordinate) {
  const mech::Model m =
      load(gripper(-1, 0, "<limit lower='-0.04' upper='0' effort='1' velocity='1'/>"),
           "urdf: r.urdf\njoints: [wrist, finger_l]\n"
           "q0: {finger_l: 0.03}\n");
  ASSERT_EQ(m.mechanical->dofs(), 2);
  EXPECT_LE((m.mechanical->M.toDense() - gripper_M(0.03, -1, 0)).cwiseAbs().maxCoeff(), kTolM)
      << m.mechanical->M;
  // Gravity along -z, the fingers move horizontally: no force on q, and the
  // wrist turns about the vertical: none on th either.
  EXPECT_LE(m.mechanical->f.cwiseAbs().maxCoeff(), 1e-12);
}

TEST_F(Mimic, MultiplierAndOffsetEnterTheMassMatrix) {
  const mech::Model m = load(gripper(0.5, 0.01, ""),
                             "urdf: r.urdf\njoints: [wrist, finger_l]\nq0: {finger_l: 0.03}\n");
  EXPECT_LE((m.mechanical->M.toDense() - gripper_M(0.03, 0.5, 0.01)).cwiseAbs().maxCoeff(), kTolM)
      << m.mechanical->M;
}

// The leader frozen: the mimic is frozen at a q0_J + b. With the left finger
// at 0.03 the right one sits at -0.03 (a = -1), not at 0 (its own q0), which
// the wrist's inertia shows: 0.2 * 0.03^2 = 1.8e-4 >> kTolM.
TEST_F(Mimic, FrozenWithItsLeader) {
  const mech::Model m = load(gripper(-1, 0, ""),
                             "urdf: r.urdf\njoints: [wrist]\n"
                             "q0: {finger_l: 0.03}\n");
  ASSERT_EQ(m.mechanical->dofs(), 1);
  EXPECT_NEAR(m.mechanical->M.coeff(0, 0), gripper_M(0.03, -1, 0)(0, 0), kTolM);
}

// Limits of the mimic become stops on the leader: lower <= a q + b <= upper.
// Right finger a = -1, b = 0, limits [-0.04, 0.005]:
//   -q + 0.04 >= 0  (finger_r_lower: row -1, gap 0 - (-0.04))
//    q + 0.005 >= 0 (finger_r_upper: row +1, gap 0.005 - 0)
TEST_F(Mimic, LimitsBecomeStopsOnTheLeader) {
  const mech::Model m =
      load(gripper(-1, 0, "<limit lower='-0.04' upper='0.005' effort='1' velocity='1'/>"),
           "urdf: r.urdf\njoints: [{name: finger_l, stops: [lower]}]\n");
  const mech::MechanicalModel& mm = *m.mechanical;
  EXPECT_EQ(mm.constraints,
            (std::vector<std::string>{"finger_l_lower", "finger_r_lower", "finger_r_upper"}));
  ASSERT_EQ(mm.E.rows(), 3);
  EXPECT_EQ(mm.E.coeff(0, 0), 1.0);
  EXPECT_EQ(mm.E.coeff(1, 0), -1.0);
  EXPECT_EQ(mm.E.coeff(2, 0), 1.0);
  EXPECT_EQ(mm.g(1), 0.04);
  EXPECT_EQ(mm.g(2), 0.005);
  // mimic_stops chooses them as stops chooses the leader's own.
  const mech::Model only = load(gripper(-1, 0,
                                        "<limit lower='-0.04' upper='0.005' effort='1' "
                                        "velocity='1'/>"),
                                "urdf: r.urdf\njoints: [{name: finger_l, stops: [], "
                                "mimic_stops: [upper]}]\n");
  EXPECT_EQ(only.mechanical->constraints, (std::vector<std::string>{"finger_r_upper"}));
}

// The Panda (robots/panda.urdf): finger 2 mimics finger 1 with multiplier 1
// and the same limits, so its stops are the leader's rows and are not
// repeated; the coordinate carries both fingers' mass, 0.1 kg each (a
// prismatic coordinate's M entry is the translated mass: sum m a^2).
TEST(MimicPanda, FingersAreOneCoordinateWithBothMasses) {
  const mech::Model m = scene::load_model(kRobots + "panda_gripper_scene.yaml");
  const mech::MechanicalModel& mm = *m.mechanical;
  EXPECT_EQ(mm.coordinates, (std::vector<std::string>{"panda_joint7", "panda_finger_joint1"}));
  EXPECT_EQ(mm.constraints, (std::vector<std::string>{"panda_joint7_lower", "panda_joint7_upper",
                                                      "panda_finger_joint1_lower",
                                                      "panda_finger_joint1_upper", "object"}));
  // 0.1 + 0.1 from a sum of a few products of unit vectors: 1e-15.
  EXPECT_NEAR(mm.M.coeff(1, 1), 0.2, 1e-15);
}

// A revolute mimic with multiplier 0.5 and offset 0.1: the elbow of the
// double pendulum (robots/double_pendulum.urdf) follows the shoulder,
// th2 = 0.5 th1 + 0.1. Substituting into the Lagrangian of the double
// pendulum (M2, V2 as in test_scene.cpp: l1 = 1, c1 = 0.5, c2 = 0.4,
// m1 = 1, m2 = 0.5, I1 = 0.02, I2 = 0.01) gives for the one coordinate th1:
//   M = M11 + 2 a M12 + a^2 M22 at th2 = a th1 + b,
//   tau = tau1 + a tau2,  K = K11 + 2 a K12 + a^2 K22.
struct Pendulum2 {
  double m1 = 1, m2 = 0.5, l1 = 1, c1 = 0.5, c2 = 0.4, I1 = 0.02, I2 = 0.01, G = 9.81;
  double a = 0.5, b = 0.1;
  double M(double t1) const {
    const double t2 = a * t1 + b;
    const double M11 =
        I1 + m1 * c1 * c1 + I2 + m2 * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * std::cos(t2));
    const double M12 = I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(t2)), M22 = I2 + m2 * c2 * c2;
    return M11 + 2 * a * M12 + a * a * M22;
  }
  double tau(double t1) const {
    const double t2 = a * t1 + b;
    const double tau1 = -G * ((m1 * c1 + m2 * l1) * std::sin(t1) + m2 * c2 * std::sin(t1 + t2));
    const double tau2 = -G * m2 * c2 * std::sin(t1 + t2);
    return tau1 + a * tau2;
  }
  double K(double t1) const {
    const double t2 = a * t1 + b, k = G * m2 * c2 * std::cos(t1 + t2);
    return G * (m1 * c1 + m2 * l1) * std::cos(t1) + k + 2 * a * k + a * a * k;
  }
};

std::string pendulum_with_mimic(const std::string& mimic) {
  std::ifstream in(kRobots + "double_pendulum.urdf");
  std::string u((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string tail = "<limit lower=\"-2\" upper=\"2\" effort=\"100\" velocity=\"10\"/>";
  u.replace(u.find(tail), tail.size(), tail + mimic);
  return u;
}

// Tolerances: M as kTolM scaled to entries of order 1 (1e-13, as in
// test_scene.cpp); tau_g is a few products (1e-13); K_g by central
// differences, 1e-8 as in test_scene.cpp.
TEST_F(Mimic, RevoluteHalfMultiplierMatchesTheSubstitutedLagrangian) {
  const std::string u =
      pendulum_with_mimic("<mimic joint='shoulder' multiplier='0.5' offset='0.1'/>");
  const Pendulum2 p;
  for (const double t1 : {0.0, 0.4}) {
    const mech::Model m =
        load(u, "urdf: r.urdf\njoints: [{name: shoulder, stops: []}]\nq0: {shoulder: " +
                    std::to_string(t1) + "}\n");
    const mech::MechanicalModel& mm = *m.mechanical;
    EXPECT_NEAR(mm.M.coeff(0, 0), p.M(t1), 1e-13) << t1;
    EXPECT_NEAR(mm.K.coeff(0, 0), p.K(t1), 1e-8) << t1;
    // f = tau(q0) + K q0
    EXPECT_NEAR(mm.f(0), p.tau(t1) + p.K(t1) * t1, 1e-8) << t1;
    // the elbow's limits [-2, 2] through th2 = 0.5 th1 + 0.1:
    // 0.5 th1 + 2.1 >= 0 and -0.5 th1 + 1.9 >= 0
    EXPECT_EQ(mm.constraints, (std::vector<std::string>{"elbow_lower", "elbow_upper"}));
    EXPECT_EQ(mm.E.coeff(0, 0), 0.5);
    EXPECT_EQ(mm.E.coeff(1, 0), -0.5);
    EXPECT_NEAR(mm.g(0), 2.1, 1e-15);
    EXPECT_NEAR(mm.g(1), 1.9, 1e-15);
  }
}

// A chain: C mimics B (a = 2, b = 0.1), B mimics A (a = -0.5, b = 0.3):
// q_C = 2 (-0.5 q_A + 0.3) + 0.1 = -q_A + 0.7.
TEST(MimicChain, MapsCompose) {
  const std::string x =
      "<robot name='c'><link name='w'/><link name='a'/><link name='b'/><link name='c'/>"
      "<joint name='A' type='revolute'><parent link='w'/><child link='a'/><axis xyz='0 0 1'/>"
      "<limit lower='-1' upper='1' effort='1' velocity='1'/></joint>"
      "<joint name='B' type='revolute'><parent link='a'/><child link='b'/><axis xyz='0 0 1'/>"
      "<limit lower='-1' upper='1' effort='1' velocity='1'/>"
      "<mimic joint='A' multiplier='-0.5' offset='0.3'/></joint>"
      "<joint name='C' type='prismatic'><parent link='b'/><child link='c'/><axis xyz='1 0 0'/>"
      "<limit lower='-1' upper='1' effort='1' velocity='1'/>"
      "<mimic joint='B' multiplier='2' offset='0.1'/></joint></robot>";
  const auto model = scene::parse_urdf(x, "c.urdf");
  const auto m = scene::mimic_joints(*model, "c.urdf");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m.at("B").leader, "A");
  EXPECT_EQ(m.at("C").leader, "A");
  EXPECT_EQ(m.at("C").multiplier, -1.0);
  EXPECT_NEAR(m.at("C").offset, 0.7, 1e-15);
}

// urdfdom's defaults when only the leader is named: multiplier 1, offset 0.
TEST(MimicChain, DefaultsAreOneAndZero) {
  const auto model = scene::load_urdf(kRobots + "panda.urdf");
  const auto m = scene::mimic_joints(*model, "panda.urdf");
  ASSERT_EQ(m.count("panda_finger_joint2"), 1u);
  EXPECT_EQ(m.at("panda_finger_joint2").leader, "panda_finger_joint1");
  EXPECT_EQ(m.at("panda_finger_joint2").multiplier, 1.0);
  EXPECT_EQ(m.at("panda_finger_joint2").offset, 0.0);
}

// ---- refusals ----

// A mimic joint the scene names in `joints:` is its own coordinate: the
// scene's explicit choice wins over the URDF's <mimic> (the NAO legs of
// issue 12 simulate RHipYawPitch, which the URDF ties to LHipYawPitch). Both
// fingers simulated, wrist frozen at 0: each finger moves its own mass only,
// M = diag(mf, mf) = diag(0.2, 0.2) (no cross term, see gripper_M).
TEST_F(Mimic, ASimulatedMimicIsItsOwnCoordinate) {
  const mech::Model m = load(gripper(-1, 0, ""), "urdf: r.urdf\njoints: [finger_l, finger_r]\n");
  ASSERT_EQ(m.mechanical->dofs(), 2);
  const MatrixXd want = (MatrixXd(2, 2) << 0.2, 0, 0, 0.2).finished();
  EXPECT_LE((m.mechanical->M.toDense() - want).cwiseAbs().maxCoeff(), kTolM) << m.mechanical->M;
  // Its own limits are its stops ([-1, 1]), not mapped onto finger_l.
  EXPECT_EQ(m.mechanical->constraints,
            (std::vector<std::string>{"finger_l_lower", "finger_l_upper", "finger_r_lower",
                                      "finger_r_upper"}));
}

// The same with its leader frozen (at 0): the wrist and finger_r, with M as
// in gripper_M with the left finger at 0 and the right at q = 0:
// diag(0.05 + 0.008, 0.2).
TEST_F(Mimic, ASimulatedMimicOfAFrozenJointIsItsOwnCoordinate) {
  const mech::Model m = load(gripper(-1, 0, ""), "urdf: r.urdf\njoints: [wrist, finger_r]\n");
  ASSERT_EQ(m.mechanical->dofs(), 2);
  const MatrixXd want = (MatrixXd(2, 2) << 0.058, 0, 0, 0.2).finished();
  EXPECT_LE((m.mechanical->M.toDense() - want).cwiseAbs().maxCoeff(), kTolM) << m.mechanical->M;
}

TEST_F(Mimic, Q0OfAMimicIsRefused) {
  const std::string e =
      error(gripper(-1, 0, ""), "urdf: r.urdf\njoints: [wrist]\nq0: {finger_r: 0.01}\n");
  EXPECT_NE(e.find("q0.finger_r: joint 'finger_r' mimics 'finger_l'"), std::string::npos) << e;
}

TEST_F(Mimic, MissingLeaderIsRefused) {
  std::string u = gripper(-1, 0, "");
  u.replace(u.find("<mimic joint='finger_l'"), 23, "<mimic joint='thumb'");
  const std::string e = error(u, "urdf: r.urdf\njoints: [wrist]\n");
  EXPECT_NE(e.find("r.urdf: joint 'finger_r': <mimic joint='thumb'>: no joint 'thumb'"),
            std::string::npos)
      << e;
}

TEST_F(Mimic, CycleIsRefused) {
  std::string u = gripper(-1, 0, "");
  // finger_l mimics finger_r, which mimics finger_l.
  const std::string axis = "<axis xyz='0 1 0'/><limit lower='0' upper='0.04'";
  u.replace(u.find(axis), axis.size(), "<mimic joint='finger_r'/>" + axis);
  const std::string e = error(u, "urdf: r.urdf\njoints: [wrist]\n");
  EXPECT_NE(e.find("a cycle of mimics: "), std::string::npos) << e;
  EXPECT_NE(e.find("finger_l"), std::string::npos) << e;
  EXPECT_NE(e.find("finger_r"), std::string::npos) << e;
}

TEST_F(Mimic, LeaderWithoutPositionIsRefused) {
  std::string u = gripper(-1, 0, "");
  u.replace(u.find("<mimic joint='finger_l'"), 23, "<mimic joint='fixed_j'");
  u.replace(u.find("</robot>"), 8,
            "<link name='z'/><joint name='fixed_j' type='fixed'><parent link='hand'/>"
            "<child link='z'/></joint></robot>");
  const std::string e = error(u, "urdf: r.urdf\njoints: [wrist]\n");
  EXPECT_NE(e.find("joint 'fixed_j' has no position to follow"), std::string::npos) << e;
}

}  // namespace
}  // namespace lcsim
