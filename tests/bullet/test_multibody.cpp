// Cross-check of the composite-rigid-body mass matrix of src/io against
// Bullet's Featherstone btMultiBody (src/bullet/multibody.cpp).
//
// Tolerance: both are double-precision evaluations of the same exact M. The
// CRBA is accurate to a few ulp of max|M|; Bullet's side computes M^{-1} by
// the articulated-body algorithm (relative error ~ n * eps per column) and we
// invert it, which multiplies that by cond(M) (< 1e3 for the models below),
// and its Jacobi diagonalisation of merged inertias stops at 1e-15 relative.
// So ~1e-13 relative is expected; we assert 1e-10 relative to max|M|, which
// any modelling difference (a wrong frame, a missing frozen mass, a sign)
// would exceed by many orders.
#include <gtest/gtest.h>
#include <urdf_model/model.h>

#include <cstdio>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>

namespace lcsim {
namespace {

using Eigen::MatrixXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

double cross_check(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
                   const std::map<std::string, double>& q0, const std::string& what) {
  const scene::UrdfLinearisation lin =
      scene::linearise_urdf(model, joints, q0, Eigen::Vector3d(0, 0, -9.81), what);
  const MatrixXd Mb = bullet::multibody_mass_matrix(model, joints, q0);
  const double rel = (lin.M - Mb).cwiseAbs().maxCoeff() / lin.M.cwiseAbs().maxCoeff();
  std::printf("[ M check  ] %-28s N = %d  max|M| = %.6g  max|M_crba - M_bullet| / max|M| = %.3g\n",
              what.c_str(), static_cast<int>(joints.size()), lin.M.cwiseAbs().maxCoeff(), rel);
  EXPECT_LE(rel, 1e-10) << what << "\nCRBA:\n" << lin.M << "\nBullet:\n" << Mb;
  return rel;
}

TEST(Multibody, DoublePendulumMassMatrixMatchesBullet) {
  const auto model = scene::load_urdf(kRobots + "double_pendulum.urdf");
  cross_check(*model, {"shoulder", "elbow"}, {}, "double pendulum q0 = 0");
  cross_check(*model, {"shoulder", "elbow"}, {{"shoulder", 0.3}, {"elbow", -0.2}},
              "double pendulum q0 = (.3,-.2)");
  cross_check(*model, {"elbow"}, {{"shoulder", 0.7}, {"elbow", 1.1}}, "pendulum, shoulder frozen");
}

TEST(Multibody, ArmWithFrozenGripperMatchesBullet) {
  const auto model = scene::load_urdf(kRobots + "arm_gripper.urdf");
  const std::map<std::string, double> q0 = {{"shoulder", 0.2},
                                            {"elbow", 0.5},
                                            {"wrist", 0.4},
                                            {"finger_left", 0.02},
                                            {"finger_right", 0.02}};
  cross_check(*model, {"shoulder", "elbow"}, q0, "arm, gripper frozen");
  cross_check(*model, {"shoulder", "elbow", "wrist", "finger_left", "finger_right"}, q0,
              "arm, all 5 moving joints");
  // Coordinate order other than the tree's: the permutation must be undone.
  cross_check(*model, {"finger_right", "elbow", "shoulder"}, q0, "arm, permuted order");
}

TEST(Multibody, TwoCartsMatchBullet) {
  const auto model = scene::load_urdf(kRobots + "two_carts.urdf");
  cross_check(*model, {"x1", "x2"}, {{"x1", 0.3}}, "two carts");
}

// A spatial tree: non-parallel axes, rotated joint frames (rpy), tilted
// inertials with products of inertia, a prismatic joint between revolute
// ones, a branch, a fixed joint and a frozen revolute joint.
const char* kSpatial = R"(<robot name="spatial">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.1 0.05 0.2" rpy="0.3 -0.2 0.5"/><mass value="1.5"/>
    <inertia ixx="0.05" ixy="0.004" ixz="-0.003" iyy="0.04" iyz="0.002" izz="0.03"/></inertial></link>
  <link name="b"><inertial><origin xyz="0 0.1 0.15" rpy="-0.4 0.1 0"/><mass value="0.8"/>
    <inertia ixx="0.02" ixy="0" ixz="0.001" iyy="0.025" iyz="-0.002" izz="0.01"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.05 0 0.1"/><mass value="0.6"/>
    <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.012" iyz="0" izz="0.008"/></inertial></link>
  <link name="d"><inertial><origin xyz="0 0 0.05" rpy="0 0 0.7"/><mass value="0.3"/>
    <inertia ixx="0.003" ixy="0" ixz="0" iyy="0.002" iyz="0" izz="0.001"/></inertial></link>
  <link name="e"><inertial><origin xyz="0.02 0.03 0"/><mass value="0.2"/>
    <inertia ixx="0.001" ixy="0.0002" ixz="0" iyy="0.0018" iyz="0" izz="0.001"/></inertial></link>
  <link name="f"><inertial><origin xyz="0 0.04 0.02"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0.0005" izz="0.002"/></inertial></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1" rpy="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="slide" type="prismatic"><parent link="a"/><child link="b"/>
    <origin xyz="0.2 0 0.3" rpy="0.5 0 0"/><axis xyz="0.6 0 0.8"/>
    <limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
  <joint name="tilt" type="revolute"><parent link="b"/><child link="c"/>
    <origin xyz="0 0.2 0.1" rpy="0.1 0.2 0.3"/><axis xyz="1 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="frozen" type="revolute"><parent link="c"/><child link="d"/>
    <origin xyz="0.1 0 0.2"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="weld" type="fixed"><parent link="d"/><child link="e"/>
    <origin xyz="0 0.1 0.1" rpy="0.2 0 0"/></joint>
  <joint name="branch" type="revolute"><parent link="a"/><child link="f"/>
    <origin xyz="-0.1 0.1 0.2" rpy="0 0.4 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
</robot>)";

TEST(Multibody, SpatialTreeMatchesBullet) {
  const auto model = scene::parse_urdf(kSpatial, "spatial.urdf");
  const std::map<std::string, double> q0 = {
      {"yaw", 0.4}, {"slide", 0.15}, {"tilt", -0.6}, {"frozen", 0.9}, {"branch", 0.3}};
  cross_check(*model, {"yaw", "slide", "tilt", "branch"}, q0, "spatial tree");
  cross_check(*model, {"yaw", "slide", "tilt", "branch"}, {}, "spatial tree at q = 0");
  cross_check(*model, {"tilt", "branch"}, q0, "spatial tree, yaw+slide frozen");
  // The check can fail: the same tree at another configuration of a frozen
  // joint, or of a simulated one, gives a clearly different M.
  auto q1 = q0;
  q1["frozen"] = -0.5;
  q1["tilt"] = 0.8;
  const scene::UrdfLinearisation lin = scene::linearise_urdf(
      *model, {"yaw", "slide", "tilt", "branch"}, q0, Eigen::Vector3d::Zero(), "spatial");
  const MatrixXd other =
      bullet::multibody_mass_matrix(*model, {"yaw", "slide", "tilt", "branch"}, q1);
  EXPECT_GT((lin.M - other).cwiseAbs().maxCoeff(), 1e-3);
}

}  // namespace
}  // namespace lcsim
