// URDF validity (issue 24, item 6): inertia tensors that no rigid body has,
// a <limit> without lower or upper used as a stop, and q0 given to a mimic
// joint (robots' reference poses list every joint).
#include <gtest/gtest.h>

#include <lcsim/io/io.hpp>
#include <string>

#include "io/detail.hpp"
#include "io/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using UrdfValidity = test_support::SceneFiles;

// A base, a link 'arm' on revolute joint 'j' (about y; `limit` its <limit>
// element) with mass 1 at 0.5 below the joint and the inertia `inertia`,
// and a prismatic joint 'f' (mimicking j with multiplier -2, offset 0.1) to
// a 'finger' of mass 0.1.
std::string robot(const std::string& inertia, const std::string& limit) {
  return "<robot name='r'><link name='base'/>"
         "<link name='arm'><inertial><origin xyz='0 0 -0.5'/><mass value='1'/>" +
         inertia +
         "</inertial></link>"
         "<link name='finger'><inertial><mass value='0.1'/>"
         "<inertia ixx='1e-4' ixy='0' ixz='0' iyy='1e-4' iyz='0' izz='1e-4'/></inertial></link>"
         "<joint name='j' type='revolute'><parent link='base'/><child link='arm'/>"
         "<axis xyz='0 1 0'/>" +
         limit +
         "</joint>"
         "<joint name='f' type='prismatic'><parent link='arm'/><child link='finger'/>"
         "<axis xyz='1 0 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/>"
         "<mimic joint='j' multiplier='-2' offset='0.1'/></joint></robot>";
}
const std::string kGoodInertia =
    "<inertia ixx='0.02' ixy='0' ixz='0' iyy='0.02' iyz='0' izz='0.01'/>";
const std::string kLimit = "<limit lower='-1' upper='1' effort='1' velocity='1'/>";

TEST_F(UrdfValidity, AValidRobotLoads) {
  write("r.urdf", robot(kGoodInertia, kLimit));
  const mech::Model m = io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\n"));
  EXPECT_EQ(m.mechanical->dofs(), 1);
}

// A negative iyy: principal moments -0.01, 0.02, 0.02. Before the check it
// was accepted (the joint is about y: M = 1 * 0.25 - 0.01 + the finger > 0).
TEST_F(UrdfValidity, NegativeMomentIsRefusedAsNotPositiveSemiDefinite) {
  const std::string e =
      error(robot("<inertia ixx='0.02' ixy='0' ixz='0' iyy='-0.01' iyz='0' izz='0.02'/>", kLimit),
            "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("r.urdf: link 'arm': <inertial> <inertia>: not positive semi-definite: "
                   "principal moments -0.01, 0.02, 0.02"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("iyy=-0.01"), std::string::npos) << e;
}

// A frozen link's inertia is checked too (it enters the composite body of
// the joint that carries it): the same arm with j frozen and only f
// simulated (a simulated mimic is its own coordinate).
TEST_F(UrdfValidity, FrozenLinksInertiaIsCheckedToo) {
  const std::string e =
      error(robot("<inertia ixx='0.02' ixy='0' ixz='0' iyy='-0.01' iyz='0' izz='0.02'/>", kLimit),
            "urdf: r.urdf\njoints: [f]\n");
  EXPECT_NE(e.find("link 'arm'"), std::string::npos) << e;
}

// Principal moments 0.01, 0.01, 0.05: 0.01 + 0.01 < 0.05 (a thin disc has
// I1 + I2 = I3 at most). Positive definite, so only the triangle refuses it.
TEST_F(UrdfValidity, TriangleInequalityIsChecked) {
  const std::string e =
      error(robot("<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.05'/>", kLimit),
            "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("r.urdf: link 'arm': <inertial> <inertia>: principal moments 0.01, 0.01, "
                   "0.05 break the triangle inequality (0.01 + 0.01 < 0.05)"),
            std::string::npos)
      << e;
}

// The limit case passes: a thin disc (0.01, 0.01, 0.02: equality), and one
// rounded to 6 digits off by 1e-6 relative (inside the 1e-4 tolerance), and
// a rotated tensor whose eigenvalues are the disc's.
TEST_F(UrdfValidity, ThinDiscAndRoundingPass) {
  for (const char* in :
       {"<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.02'/>",
        "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.0200001'/>",
        "<inertia ixx='0.015' ixy='0.005' ixz='0' iyy='0.015' iyz='0' izz='0.01'/>"}) {
    write("r.urdf", robot(in, kLimit));
    EXPECT_NO_THROW(io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\n"))) << in;
  }
}

// bullet3's Minitaur knees: <limit effort velocity/> only. urdfdom reads
// lower = upper = 0: as stops they would lock the joint at 0. Before the
// check the scene loaded with two stops at 0.
TEST_F(UrdfValidity, LimitWithoutBoundsIsRefusedAsAStop) {
  const std::string u = robot(kGoodInertia, "<limit effort='1' velocity='1'/>");
  const std::string e = error(u, "urdf: r.urdf\njoints: [j]\n");
  EXPECT_NE(e.find("r.urdf: joint 'j': <limit>: no lower and upper (URDF reads a missing bound "
                   "as 0"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("s.yaml: joints[0]: write stops: [] to simulate it without stops"),
            std::string::npos)
      << e;
  // With stops: [] it is simulated, unlocked.
  write("r.urdf", u);
  const mech::Model m =
      io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [{name: j, stops: []}]\n"));
  // No stop of j's own; the mimic f's limits (-1 <= -2 q + 0.1 <= 1) stay.
  EXPECT_EQ(m.mechanical->constraints, (std::vector<std::string>{"f_lower", "f_upper"}));
}

TEST(UrdfLimitScan, FindsMissingBoundsOnly) {
  const auto m = io::limits_without_bounds(
      "<robot><!-- <joint name='c'><limit effort='1'/></joint> -->"
      "<joint name='a' type='revolute'><limit lower='0' effort='1' velocity='1'/></joint>"
      "<joint name=\"b\" type='revolute'><limit upper=\"1\" lower=\"-1\"/></joint>"
      "<joint name='k' type='revolute'><limit effort='1' velocity='1'/></joint>"
      "<transmission><joint name='a'><hardwareInterface>x</hardwareInterface></joint>"
      "</transmission></robot>");
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m.at("a"), "upper");
  EXPECT_EQ(m.at("k"), "lower and upper");
}

// q0 of a mimic consistent with its leader (f = -2 j + 0.1) is accepted
// and says nothing new; an inconsistent one names both joints.
TEST_F(UrdfValidity, MimicQ0ConsistentWithItsLeaderIsAccepted) {
  write("r.urdf", robot(kGoodInertia, kLimit));
  const mech::Model a =
      io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2}\n"));
  const mech::Model b =
      io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2, f: -0.3}\n"));
  EXPECT_EQ(MatrixXd(a.mechanical->M), MatrixXd(b.mechanical->M));
  EXPECT_EQ(a.mechanical->f, b.mechanical->f);
  // The leader frozen (not simulated) and not named: q_j = 0, so f = 0.1.
  EXPECT_NO_THROW(io::load_model(write("s.yaml", "urdf: r.urdf\njoints: [f]\nq0: {f: 0.1}\n")))
      << "f simulated: its own coordinate";
  const std::string e =
      error(robot(kGoodInertia, kLimit), "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2, f: 0.3}\n");
  // -2 * 0.2 + 0.1 is -0.30000000000000004 in doubles, printed as read back.
  EXPECT_NE(e.find("s.yaml: q0.f: joint 'f' mimics 'j' (q = -2 q_j + 0.1 = -0.3"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("at q0.j = 0.2), got 0.3; give q0 for 'j' only"), std::string::npos) << e;
}

}  // namespace
}  // namespace lcsim
