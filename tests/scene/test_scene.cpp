// Scenes: URDF + scene file -> linear mechanical model (src/scene/scene.cpp,
// src/scene/urdf_model.cpp).
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>

#include "scene/scene_files.hpp"
#include "support/same_model.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

// Exact equality (expect_same_matrices): the scene's numbers are sums and
// products of exactly representable inputs (unit masses, unit springs, axis
// (1,0,0), zero gravity component along x), so nothing may differ, not even
// in the last bit.
using test_support::expect_same_matrices;

void expect_same_run(const mech::Model& a, const mech::Model& b) {
  sim::Options opt;
  opt.t_end = a.t_end;
  const sim::Trajectory ta = sim::simulate_event_driven(a, a.initial, opt);
  const sim::Trajectory tb = sim::simulate_event_driven(b, b.initial, opt);
  ASSERT_EQ(ta.status, sim::RunStatus::kCompleted) << ta.message;
  ASSERT_EQ(tb.status, sim::RunStatus::kCompleted) << tb.message;
  ASSERT_EQ(ta.events.size(), tb.events.size());
  ASSERT_GT(ta.events.size(), 0u);
  // Same matrices and initial state: the runs must agree to rounding; 1e-12
  // as asked, although they are in fact identical.
  for (std::size_t i = 0; i < ta.events.size(); ++i)
    EXPECT_NEAR(ta.events[i].t, tb.events[i].t, 1e-12) << "event " << i;
  EXPECT_LE((ta.final_state - tb.final_state).cwiseAbs().maxCoeff(), 1e-12);
}

TEST(Scene, TwoCartsGivesTheMatricesAndRunOfTheYamlModel) {
  const mech::Model yaml = scene::load_model(kRobots + "two_carts.yaml");
  const mech::Model scene = scene::load_model(kRobots + "two_carts_scene.yaml");
  ASSERT_TRUE(scene.is_mechanical());
  expect_same_matrices(*yaml.mechanical, *scene.mechanical);
  EXPECT_EQ(scene.mechanical->coordinates, (std::vector<std::string>{"x1", "x2"}));
  EXPECT_EQ(scene.mechanical->constraints, (std::vector<std::string>{"x1_lower"}));
  EXPECT_EQ(yaml.initial, scene.initial);
  EXPECT_EQ(yaml.t_end, scene.t_end);
  expect_same_run(yaml, scene);
}

TEST(Scene, TwoCartsHookGivesTheMatricesAndRunOfTheYamlModel) {
  const mech::Model yaml = scene::load_model(kRobots + "two_carts_hook.yaml");
  const mech::Model scene = scene::load_model(kRobots + "two_carts_hook_scene.yaml");
  expect_same_matrices(*yaml.mechanical, *scene.mechanical);
  EXPECT_EQ(scene.mechanical->constraints, (std::vector<std::string>{"x1_lower", "hook"}));
  EXPECT_EQ(yaml.initial, scene.initial);
  expect_same_run(yaml, scene);
}

// Double pendulum (robots/double_pendulum.urdf), both joints about y, angles
// theta1 (shoulder, absolute) and theta2 (elbow, relative). Lengths l1 = 1
// (shoulder to elbow), c1 = 0.5, c2 = 0.4 (joint to centre of mass, hanging
// along -z), masses m1 = 1, m2 = 0.5, inertias about the centres I1 = 0.02,
// I2 = 0.01 (about y). A rotation by theta about +y takes (0, 0, -l) to
// (-l sin theta, 0, -l cos theta), so the centres are at heights
//   z1 = -c1 cos th1,   z2 = -l1 cos th1 - c2 cos(th1 + th2)
// and the usual Lagrangian derivation gives
//   M11 = I1 + m1 c1^2 + I2 + m2 (l1^2 + c2^2 + 2 l1 c2 cos th2)
//   M12 = I2 + m2 (c2^2 + l1 c2 cos th2),   M22 = I2 + m2 c2^2
//   V = m1 G z1 + m2 G z2 (G = 9.81), tau_g = -dV/dq:
//   tau1 = -G [(m1 c1 + m2 l1) sin th1 + m2 c2 sin(th1 + th2)]
//   tau2 = -G m2 c2 sin(th1 + th2)
//   K_g = d^2V/dq^2:  K11 = G [(m1 c1 + m2 l1) cos th1 + m2 c2 cos(th1 + th2)],
//                     K12 = K21 = K22 = G m2 c2 cos(th1 + th2)
// and with coordinates = joint angles, f = tau_g(q0) + K_g q0.
struct Pendulum {
  double m1 = 1, m2 = 0.5, l1 = 1, c1 = 0.5, c2 = 0.4, I1 = 0.02, I2 = 0.01, G = 9.81;
  MatrixXd M(double t2) const {
    MatrixXd m(2, 2);
    m << I1 + m1 * c1 * c1 + I2 + m2 * (l1 * l1 + c2 * c2 + 2 * l1 * c2 * std::cos(t2)),
        I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(t2)), I2 + m2 * (c2 * c2 + l1 * c2 * std::cos(t2)),
        I2 + m2 * c2 * c2;
    return m;
  }
  VectorXd tau(double t1, double t2) const {
    VectorXd t(2);
    t << -G * ((m1 * c1 + m2 * l1) * std::sin(t1) + m2 * c2 * std::sin(t1 + t2)),
        -G * m2 * c2 * std::sin(t1 + t2);
    return t;
  }
  MatrixXd K(double t1, double t2) const {
    const double k = G * m2 * c2 * std::cos(t1 + t2);
    MatrixXd m(2, 2);
    m << G * (m1 * c1 + m2 * l1) * std::cos(t1) + k, k, k, k;
    return m;
  }
};

// Tolerances: M is computed by the CRBA in a few dozen floating-point
// operations on numbers of order 1: 1e-13 is ~500 ulp. K_g comes from central
// differences with h = 6e-6: rounding eps |tau| / h ~ 2.2e-16 * 12 / 6e-6
// ~ 4e-10 plus truncation h^2/6 |tau'''| ~ 7e-11 (|tau| and |tau'''| <= 12 N m
// here), so 1e-8 leaves a factor 20; f inherits it through K_g q0 (|q0| <= 0.3).
TEST(Scene, DoublePendulumAtTheHangingEquilibrium) {
  const mech::Model model = scene::load_model(kRobots + "double_pendulum_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  const Pendulum p;
  EXPECT_LE((m.M.toDense() - p.M(0.0)).cwiseAbs().maxCoeff(), 1e-13) << m.M;
  EXPECT_NEAR(m.M.coeff(0, 0), 1.26, 1e-13);  // 0.02 + 0.25 + 0.01 + 0.5 * 1.96
  EXPECT_NEAR(m.M.coeff(0, 1), 0.29, 1e-13);
  EXPECT_NEAR(m.M.coeff(1, 1), 0.09, 1e-13);
  EXPECT_LE((m.K.toDense() - p.K(0.0, 0.0)).cwiseAbs().maxCoeff(), 1e-8) << m.K;
  EXPECT_NEAR(m.K.coeff(0, 0), 9.81 * 1.2, 1e-8);
  EXPECT_NEAR(m.K.coeff(1, 1), 9.81 * 0.2, 1e-8);
  EXPECT_LE(m.f.cwiseAbs().maxCoeff(), 1e-8);  // an equilibrium: no net force at q0 = 0
  // the stop: shoulder - (-0.2) >= 0
  ASSERT_EQ(m.E.rows(), 1);
  EXPECT_EQ(m.E.coeff(0, 0), 1.0);
  EXPECT_EQ(m.E.coeff(0, 1), 0.0);
  EXPECT_EQ(m.g(0), 0.2);
  EXPECT_EQ(m.restitution(0), 0.5);
  ASSERT_EQ(model.initial.size(), 4);
  EXPECT_EQ(model.initial(0), 0.3);
  // It swings into the stop: the run has at least one impact and stays feasible.
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  EXPECT_GE(tr.events.size(), 1u);
  EXPECT_GE(tr.max_violation, -1e-9);
}

TEST(Scene, DoublePendulumAwayFromEquilibrium) {
  const std::string text =
      "urdf: double_pendulum.urdf\n"
      "joints: [shoulder, elbow]\n"
      "q0: {shoulder: 0.3, elbow: -0.2}\n";
  const mech::Model model = scene::parse_model(text, kRobots + "inline_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  const Pendulum p;
  const double t1 = 0.3, t2 = -0.2;
  EXPECT_LE((m.M.toDense() - p.M(t2)).cwiseAbs().maxCoeff(), 1e-13) << m.M;
  EXPECT_LE((m.K.toDense() - p.K(t1, t2)).cwiseAbs().maxCoeff(), 1e-8) << m.K;
  std::printf("[ K_g check] double pendulum q0 = (0.3, -0.2): max|K - K_hand| = %.3g N m/rad\n",
              (m.K.toDense() - p.K(t1, t2)).cwiseAbs().maxCoeff());
  const VectorXd q0 = (VectorXd(2) << t1, t2).finished();
  const VectorXd f = p.tau(t1, t2) + p.K(t1, t2) * q0;
  EXPECT_LE((m.f - f).cwiseAbs().maxCoeff(), 1e-8) << m.f.transpose();
  // both limits of both joints, lower then upper
  ASSERT_EQ(m.E.rows(), 4);
  EXPECT_EQ(m.constraints, (std::vector<std::string>{"shoulder_lower", "shoulder_upper",
                                                     "elbow_lower", "elbow_upper"}));
  EXPECT_EQ(m.E.coeff(1, 0), -1.0);
  EXPECT_EQ(m.g(1), 1.5);
  EXPECT_EQ(m.g(2), 2.0);
  // No `initial` in the file: q0 at rest, (0.3, -0.2, 0, 0) exactly (the
  // absolute joint positions of q0, docs/model-format.md).
  EXPECT_EQ(model.initial, (VectorXd(4) << t1, t2, 0.0, 0.0).finished());
}

// The arm with a gripper: 6 joints, 2 simulated. Expected M by a method
// independent of the CRBA: the sum over links k of the Jacobian terms
//   m_k (a x (c_k - o_i)) . (a x (c_k - o_j)) + a' I_k a
// over the joints i, j that move link k, all axes a = y, with the link
// positions from hand-written forward kinematics (the wrist frozen at 0.4 rad,
// the fingers at +-0.02 m, the tool fixed). Rotations are all about y, so
// a' R I R' a = I_yy of each inertial.
TEST(Scene, FrozenJointsAddMassButNoCoordinates) {
  const mech::Model model = scene::load_model(kRobots + "arm_gripper_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  ASSERT_EQ(m.dofs(), 2);
  EXPECT_EQ(m.coordinates, (std::vector<std::string>{"shoulder", "elbow"}));
  EXPECT_EQ(m.num_constraints(), 4);
  EXPECT_EQ(model.state_size(), 4);

  using Eigen::AngleAxisd;
  using Eigen::Isometry3d;
  using Eigen::Translation3d;
  using Eigen::Vector3d;
  const Vector3d y = Vector3d::UnitY();
  const auto Ry = [&](double a) { return Isometry3d(AngleAxisd(a, y)); };
  const auto Tr = [](double x, double z) { return Isometry3d(Translation3d(x, 0, z)); };
  const double qs = 0.2, qe = 0.5, qw = 0.4, qf = 0.02;
  const Isometry3d upper = Tr(0, 0.3) * Ry(qs);
  const Isometry3d fore = upper * Tr(0, 0.4) * Ry(qe);
  const Isometry3d hand = fore * Tr(0, 0.3) * Ry(qw);
  const Isometry3d fl = hand * Tr(0, 0.1) * Tr(qf, 0);
  const Isometry3d fr = hand * Tr(0, 0.1) * Tr(-qf, 0);
  const Isometry3d tool = hand * Tr(0, 0.15);
  struct L {
    Isometry3d X;
    Vector3d com;
    double mass, iyy;
    bool elbow;
  };
  const std::vector<L> links = {
      {upper, {0.01, 0, 0.2}, 2, 0.04, false},    {fore, {0, 0, 0.15}, 1, 0.012, true},
      {hand, {0.02, 0, 0.05}, 0.4, 0.0012, true}, {fl, {0, 0, 0.03}, 0.05, 0.00002, true},
      {fr, {0, 0, 0.03}, 0.05, 0.00002, true},    {tool, {0, 0, 0}, 0.1, 0.0001, true}};
  const Vector3d o_s = upper.translation(), o_e = fore.translation();
  MatrixXd M = MatrixXd::Zero(2, 2);
  for (const L& l : links) {
    const Vector3d c = l.X * l.com;
    const Vector3d js = y.cross(c - o_s), je = y.cross(c - o_e);
    M(0, 0) += l.mass * js.dot(js) + l.iyy;
    if (l.elbow) {
      M(0, 1) += l.mass * js.dot(je) + l.iyy;
      M(1, 1) += l.mass * je.dot(je) + l.iyy;
    }
  }
  M(1, 0) = M(0, 1);
  // Same quantities by a different summation order: 1e-13 (~500 ulp of O(1)).
  EXPECT_LE((m.M.toDense() - M).cwiseAbs().maxCoeff(), 1e-13) << m.M << "\n" << M;
  // The frozen gripper matters: without it (hand, fingers, tool) M22 would be
  // smaller by far more than the tolerance.
  EXPECT_GT(m.M.coeff(1, 1) - (1 * 0.15 * 0.15 + 0.012), 0.05);
  // D: <dynamics damping> plus the scene's dampers; E: both limits per joint.
  EXPECT_NEAR(m.D.coeff(0, 0), 2.1, 1e-15);
  EXPECT_NEAR(m.D.coeff(1, 1), 1.05, 1e-15);
  EXPECT_EQ(m.D.coeff(0, 1), 0.0);
}

// ---- bad input ----

using SceneErrors = test_support::SceneFiles;

std::string urdf_with(const std::string& extra_joint_attrs, const std::string& limit,
                      bool inertial = true) {
  return std::string("<robot name='r'><link name='base'/><link name='b'>") +
         (inertial ? "<inertial><mass value='1'/><inertia ixx='1' ixy='0' ixz='0' iyy='1' "
                     "iyz='0' izz='1'/></inertial>"
                   : "") +
         "</link><link name='c'><inertial><mass value='1'/><inertia ixx='1' ixy='0' ixz='0' "
         "iyy='1' iyz='0' izz='1'/></inertial></link>"
         "<joint name='j' " +
         extra_joint_attrs + "><parent link='base'/><child link='b'/><axis xyz='1 0 0'/>" + limit +
         "</joint><joint name='k' type='prismatic'><parent link='b'/><child link='c'/><axis "
         "xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint></robot>";
}
const std::string kLimit = "<limit lower='-1' upper='1' effort='1' velocity='1'/>";

TEST_F(SceneErrors, MalformedXml) {
  const std::string e = error("<robot name='r'><link name='a'>", "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("r.urdf"), std::string::npos) << e;
  EXPECT_NE(e.find("not a valid URDF: "), std::string::npos) << e;
}

// urdfdom refuses non-finite numbers itself; its message, quoted in the
// error, names the element.
TEST_F(SceneErrors, NonFiniteValueInUrdf) {
  std::string u = urdf_with("type='prismatic'", kLimit);
  u.replace(u.find("<mass value='1'/>"), 17, "<mass value='nan'/>");
  const std::string e = error(u, "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("r.urdf: not a valid URDF: "), std::string::npos) << e;
  EXPECT_NE(e.find("mass [nan]"), std::string::npos) << e;
  EXPECT_NE(e.find("Link [b]"), std::string::npos) << e;
}

// Link b, moved by j, has no <inertial>, but j also carries link c (mass 1)
// through k: j moves c along x, k along y, so M = diag(1, 1) exactly. (This
// was refused until the robots session: bullet3's humanoid.urdf has such
// massless links between the joints of its hips and shoulders.) A joint
// that carries no mass at all is refused (test_urdf_robustness.cpp).
TEST_F(SceneErrors, MovingLinkWithoutInertiaCarriesTheLinksBelow) {
  write("r.urdf", urdf_with("type='prismatic'", kLimit, false));
  const mech::Model m = scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j, k]\n"));
  EXPECT_EQ(MatrixXd(m.mechanical->M), MatrixXd::Identity(2, 2));
}

// urdfdom itself refuses a cycle of joints (no root), but accepts a joint
// whose parent is its child; lcsim refuses both instead of recursing for ever
// down the tree (that crashed with a stack overflow). urdfdom leaks the
// cyclic links (scripts/lsan.supp).
TEST_F(SceneErrors, CyclicJointGraph) {
  const std::string links =
      "<robot name='r'><link name='a'/><link name='b'><inertial><mass value='1'/><inertia "
      "ixx='1' ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial></link>"
      "<joint name='j' type='prismatic'><parent link='a'/><child link='b'/><axis xyz='1 0 0'/>" +
      kLimit + "</joint>";
  const std::string self = error(links +
                                     "<joint name='k' type='prismatic'><parent link='b'/><child "
                                     "link='b'/><axis xyz='1 0 0'/>" +
                                     kLimit + "</joint></robot>",
                                 "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(self.find("r.urdf: joint 'k': parent and child are the same link 'b'"),
            std::string::npos)
      << self;
  const std::string cycle = error(links +
                                      "<joint name='k' type='fixed'><parent link='b'/><child "
                                      "link='a'/></joint></robot>",
                                  "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(cycle.find("r.urdf: not a valid URDF: "), std::string::npos) << cycle;
  EXPECT_NE(cycle.find("not a valid tree"), std::string::npos) << cycle;
}

TEST_F(SceneErrors, UnknownJoint) {
  const std::string e =
      error(urdf_with("type='prismatic'", kLimit), "urdf: r.urdf\njoints: [j, nope]\n");
  EXPECT_NE(e.find("s.yaml: joints[1]: no joint 'nope'"), std::string::npos) << e;
}

TEST_F(SceneErrors, UnsupportedJointType) {
  // Continuous joints are simulated (test_urdf_robustness.cpp); floating
  // and planar ones are not.
  const std::string e = error(urdf_with("type='floating'", ""), "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("s.yaml: joints[0]: joint 'j' is not revolute, continuous or prismatic"),
            std::string::npos)
      << e;
}

TEST_F(SceneErrors, LowerAboveUpper) {
  const std::string e =
      error(urdf_with("type='prismatic'", "<limit lower='1' upper='0' effort='1' velocity='1'/>"),
            "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("joint 'j': <limit>: lower > upper (got lower=1, upper=0)"), std::string::npos)
      << e;
}

TEST_F(SceneErrors, NonFiniteValue) {
  const std::string e = error(urdf_with("type='prismatic'", kLimit),
                              "urdf: r.urdf\njoints: [j]\n"
                              "springs: [{joint: j, stiffness: .inf}]\n");
  EXPECT_NE(e.find("s.yaml: springs[0].stiffness: not finite (got '.inf')"), std::string::npos)
      << e;
}

TEST_F(SceneErrors, SpringOnFrozenJoint) {
  const std::string e = error(urdf_with("type='prismatic'", kLimit),
                              "urdf: r.urdf\njoints: [j]\n"
                              "springs: [{joint: j, other: k, stiffness: 1}]\n");
  EXPECT_NE(e.find("s.yaml: springs[0].other: joint 'k' is frozen"), std::string::npos) << e;
}

TEST_F(SceneErrors, MissingUrdfFile) {
  const std::string e = error("", "urdf: missing.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("s.yaml: urdf: no such file (got 'missing.urdf'"), std::string::npos) << e;
}

TEST_F(SceneErrors, UnknownKeyAndUnknownRestitution) {
  const std::string u = urdf_with("type='prismatic'", kLimit);
  std::string e = error(u, "urdf: r.urdf\njoints: [j]\nsprngs: []\n");
  EXPECT_NE(e.find("s.yaml: sprngs: unknown key"), std::string::npos) << e;
  e = error(u, "urdf: r.urdf\njoints: [j]\nrestitution: {j_middle: 0.5}\n");
  EXPECT_NE(e.find("s.yaml: restitution.j_middle: no constraint 'j_middle'"), std::string::npos)
      << e;
}

}  // namespace
}  // namespace lcsim
