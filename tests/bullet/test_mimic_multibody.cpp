// Cross-check of the mass matrix of a scene with <mimic> joints (src/io)
// against Bullet's Featherstone btMultiBody (src/bullet/multibody.cpp), which
// knows nothing of mimics: Bullet's M_b is computed with the mimic as an
// independent joint placed at a q_J + b, and the mimic's equality maps it to
// the leader's coordinates, M = T' M_b T with T = [I; a e_J'] (rows of the
// moving joints, columns of the coordinates). Tolerance as in
// test_multibody.cpp: 1e-10 relative to max|M|.
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

// `joints` simulated; `mimic` follows coordinate `leader` with multiplier a.
void cross_check_mimic(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
                       std::map<std::string, double> q0, const std::string& mimic, int leader,
                       double a, double b, const std::string& what) {
  const scene::UrdfLinearisation lin =
      scene::linearise_urdf(model, joints, q0, Eigen::Vector3d(0, 0, -9.81), what);
  std::vector<std::string> moving = joints;
  moving.push_back(mimic);
  q0[mimic] = a * (q0.count(joints[static_cast<std::size_t>(leader)])
                       ? q0.at(joints[static_cast<std::size_t>(leader)])
                       : 0.0) +
              b;
  const MatrixXd Mb = bullet::multibody_mass_matrix(model, moving, q0);
  const auto n = static_cast<Eigen::Index>(joints.size());
  MatrixXd T = MatrixXd::Zero(n + 1, n);
  T.topRows(n).setIdentity();
  T(n, leader) = a;
  const MatrixXd M = T.transpose() * Mb * T;
  const double rel = (lin.M - M).cwiseAbs().maxCoeff() / lin.M.cwiseAbs().maxCoeff();
  std::printf("[ M check  ] %-28s N = %d  max|M_crba - T'M_bullet T| / max|M| = %.3g\n",
              what.c_str(), static_cast<int>(n), rel);
  EXPECT_LE(rel, 1e-10) << what << "\nCRBA:\n" << lin.M << "\nBullet T'MT:\n" << M;
}

TEST(MultibodyMimic, PandaFingersMatchBullet) {
  const auto model = scene::load_urdf(kRobots + "panda.urdf");
  const std::map<std::string, double> q0 = {{"panda_joint2", -0.785},
                                            {"panda_joint4", -2.356},
                                            {"panda_joint6", 1.571},
                                            {"panda_joint7", 0.785},
                                            {"panda_finger_joint1", 0.03}};
  cross_check_mimic(*model, {"panda_joint7", "panda_finger_joint1"}, q0, "panda_finger_joint2", 1,
                    1.0, 0.0, "panda wrist + fingers");
  cross_check_mimic(*model, {"panda_joint2", "panda_joint4", "panda_finger_joint1"}, q0,
                    "panda_finger_joint2", 2, 1.0, 0.0, "panda arm + fingers");
}

// The spatial tree of test_multibody.cpp with the branch joint mimicking the
// tilt joint on another branch (multiplier -0.7, offset 0.2).
TEST(MultibodyMimic, RevoluteMimicOnAnotherBranchMatchesBullet) {
  const std::string urdf = R"(<robot name="m">
  <link name="base"/>
  <link name="a"><inertial><origin xyz="0.1 0.05 0.2" rpy="0.3 -0.2 0.5"/><mass value="1.5"/>
    <inertia ixx="0.05" ixy="0.004" ixz="-0.003" iyy="0.04" iyz="0.002" izz="0.03"/></inertial></link>
  <link name="c"><inertial><origin xyz="0.05 0 0.1"/><mass value="0.6"/>
    <inertia ixx="0.01" ixy="0.001" ixz="0" iyy="0.012" iyz="0" izz="0.008"/></inertial></link>
  <link name="f"><inertial><origin xyz="0 0.04 0.02"/><mass value="0.4"/>
    <inertia ixx="0.002" ixy="0" ixz="0" iyy="0.003" iyz="0.0005" izz="0.002"/></inertial></link>
  <joint name="yaw" type="revolute"><parent link="base"/><child link="a"/>
    <origin xyz="0 0 0.1" rpy="0 0 0.3"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="tilt" type="revolute"><parent link="a"/><child link="c"/>
    <origin xyz="0 0.2 0.1" rpy="0.1 0.2 0.3"/><axis xyz="1 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/></joint>
  <joint name="branch" type="revolute"><parent link="a"/><child link="f"/>
    <origin xyz="-0.1 0.1 0.2" rpy="0 0.4 0"/><axis xyz="0 1 0"/>
    <limit lower="-3" upper="3" effort="1" velocity="1"/>
    <mimic joint="tilt" multiplier="-0.7" offset="0.2"/></joint>
</robot>)";
  const auto model = scene::parse_urdf(urdf, "mimic.urdf");
  cross_check_mimic(*model, {"yaw", "tilt"}, {{"yaw", 0.4}, {"tilt", -0.6}}, "branch", 1, -0.7, 0.2,
                    "tree, branch mimics tilt");
}

}  // namespace
}  // namespace lcsim
