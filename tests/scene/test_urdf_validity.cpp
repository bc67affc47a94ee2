// URDF validity (issue 24, item 6): inertia tensors that no rigid body has,
// a <limit> without lower or upper used as a stop, and q0 given to a mimic
// joint (robots' reference poses list every joint).
#include <gtest/gtest.h>
#include <urdf_model/model.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cstdio>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

#include "scene/detail.hpp"
#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::Matrix3d;
using Eigen::MatrixXd;
using Eigen::Vector3d;
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
  const mech::Model m = scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\n"));
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
    EXPECT_NO_THROW(scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\n"))) << in;
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
      scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [{name: j, stops: []}]\n"));
  // No stop of j's own; the mimic f's limits (-1 <= -2 q + 0.1 <= 1) stay.
  EXPECT_EQ(m.mechanical->constraints, (std::vector<std::string>{"f_lower", "f_upper"}));
}

TEST(UrdfLimitScan, FindsMissingBoundsOnly) {
  const auto m = scene::limits_without_bounds(
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
      scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2}\n"));
  const mech::Model b =
      scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2, f: -0.3}\n"));
  EXPECT_EQ(MatrixXd(a.mechanical->M), MatrixXd(b.mechanical->M));
  EXPECT_EQ(a.mechanical->f, b.mechanical->f);
  // The leader frozen (not simulated) and not named: q_j = 0, so f = 0.1.
  EXPECT_NO_THROW(scene::load_model(write("s.yaml", "urdf: r.urdf\njoints: [f]\nq0: {f: 0.1}\n")))
      << "f simulated: its own coordinate";
  const std::string e =
      error(robot(kGoodInertia, kLimit), "urdf: r.urdf\njoints: [j]\nq0: {j: 0.2, f: 0.3}\n");
  // -2 * 0.2 + 0.1 is -0.30000000000000004 in doubles, printed as read back.
  EXPECT_NE(e.find("s.yaml: q0.f: joint 'f' mimics 'j' (q = -2 q_j + 0.1 = -0.3"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("at q0.j = 0.2), got 0.3; give q0 for 'j' only"), std::string::npos) << e;
}

// ---- balance_inertia: repairing what the checks above refuse ----

// <inertia> with the entries of the symmetric I, written to 17 digits (they
// read back exactly).
std::string inertia_element(const Matrix3d& I) {
  char buf[256];
  std::snprintf(
      buf, sizeof buf,
      "<inertia ixx='%.17g' ixy='%.17g' ixz='%.17g' iyy='%.17g' iyz='%.17g' izz='%.17g'/>", I(0, 0),
      I(0, 1), I(0, 2), I(1, 1), I(1, 2), I(2, 2));
  return buf;
}

// A rotation with no axis along x, y or z, so that the principal axes are
// not the URDF's and their being kept is a real check.
Matrix3d tilt() {
  return Eigen::AngleAxisd(0.7, Vector3d(1, 2, 3).normalized()).toRotationMatrix();
}

// What loading robot(inertia) as a scene with `balance_inertia: true` gives.
struct Loaded {
  Matrix3d I;                      // the arm's tensor after loading
  double mass;                     // the arm's mass after loading
  MatrixXd M;                      // the scene's mass matrix
  std::vector<std::string> notes;  // the scene's notes as analyze gets them
};
class BalanceInertia : public UrdfValidity {
 protected:
  Loaded load(const std::string& inertia, const std::string& key = "balance_inertia: true\n") {
    write("r.urdf", robot(inertia, kLimit));
    const scene::LoadedModel l =
        scene::load_model_and_scene(write("s.yaml", "urdf: r.urdf\njoints: [j]\n" + key));
    const urdf::Inertial& in = *l.scene->urdf->getLink("arm")->inertial;
    Matrix3d I;
    I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
    return {I, in.mass, MatrixXd(l.model.mechanical->M), scene::model_notes(l)};
  }
  // The repaired tensor has the principal moments `want` (ascending) on the
  // axes R of the file's tensor R diag(p) R', is positive semi-definite and
  // meets the triangle inequality, the mass is kept, and the dynamics use it:
  // M is that of the same scene with R diag(want) R' written in the file.
  // Tolerances: the file's entries are exact to 17 digits and the repair is
  // an eigen-decomposition and a product of 3 x 3 matrices, each with
  // rounding errors of a few eps * |I| ~ 1e-17 kg m^2 here; 1e-14 * I3
  // leaves a margin of 100 and is far below the changes tested (>= 3.5e-8).
  void expect_repaired(const Loaded& r, const Matrix3d& R, const Vector3d& want) {
    const double tol = 1e-14 * want(2);
    const Vector3d got = Eigen::SelfAdjointEigenSolver<Matrix3d>(r.I).eigenvalues();
    EXPECT_LT((got - want).cwiseAbs().maxCoeff(), tol) << got.transpose();
    EXPECT_GE(got(0), -tol);
    EXPECT_GE(got(0) + got(1), got(2) - tol);
    // Principal axes kept: R' I R is diagonal, with the moments in R's order.
    const Matrix3d D = R.transpose() * r.I * R;
    EXPECT_LT((D - Matrix3d(want.asDiagonal())).cwiseAbs().maxCoeff(), tol) << D;
    EXPECT_EQ(r.mass, 1.0);
    const Loaded same = load(inertia_element(R * want.asDiagonal() * R.transpose()), "");
    for (const auto& n : same.notes)
      EXPECT_EQ(n.find("repaired"), std::string::npos)
          << "the written tensor needs no repair: " << n;
    EXPECT_LT((r.M - same.M).cwiseAbs().maxCoeff(), 1e-12 * same.M.cwiseAbs().maxCoeff());
  }
};

// Principal moments 0.01, 0.02, 0.05 on tilted axes: 0.01 + 0.02 < 0.05 by
// d = 0.02. The repair raises the two smaller by d/2 = 0.01 each (the
// second moment of mass along the third axis, (0.01 + 0.02 - 0.05)/2 < 0,
// set to 0): 0.02, 0.03, 0.05 (0.02 + 0.03 = 0.05 exactly).
TEST_F(BalanceInertia, TriangleBreakingTensorIsRepaired) {
  const Matrix3d R = tilt();
  const Loaded r =
      load(inertia_element(R * Vector3d(0.01, 0.02, 0.05).asDiagonal() * R.transpose()));
  expect_repaired(r, R, Vector3d(0.02, 0.03, 0.05));
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("r.urdf: link 'arm': <inertial> <inertia>: repaired (balance_inertia: "
                            "the triangle inequality broken): principal moments 0.01, 0.02, 0.05 "
                            "-> 0.02, 0.03, 0.05 kg m^2 (principal axes and mass kept)"),
            std::string::npos)
      << r.notes[0];
}

// Tiago's base_antenna links: a moment of -3.5e-8 kg m^2 (beyond the
// tolerance 1e-4 * 1.2e-4 = 1.2e-8). Moments -3.5e-8, 1e-4, 1.2e-4: the
// negative one set to 0, then 0 + 1e-4 < 1.2e-4 by 2e-5, so 1e-5 added to
// the two smaller: 1e-5, 1.1e-4, 1.2e-4. Diagonal, the clip alone suffices:
// -3.5e-8, 1e-4, 1e-4 -> 0, 1e-4, 1e-4.
TEST_F(BalanceInertia, SlightlyNegativeMomentIsRepaired) {
  const Matrix3d R = tilt();
  const Loaded r =
      load(inertia_element(R * Vector3d(-3.5e-8, 1e-4, 1.2e-4).asDiagonal() * R.transpose()));
  expect_repaired(r, R, Vector3d(1e-5, 1.1e-4, 1.2e-4));
  ASSERT_FALSE(r.notes.empty());
  EXPECT_NE(r.notes[0].find("link 'arm': <inertial> <inertia>: repaired (balance_inertia: a "
                            "negative moment): principal moments -3.5e-08, 0.0001, 0.00012 -> "
                            "1e-05, 0.00011, 0.00012 kg m^2"),
            std::string::npos)
      << r.notes[0];
  const Loaded d = load("<inertia ixx='1e-4' ixy='0' ixz='0' iyy='-3.5e-8' iyz='0' izz='1e-4'/>");
  // About y = the second principal axis of the diagonal tensor: iyy 0 exactly.
  EXPECT_EQ(d.I, Matrix3d(Vector3d(1e-4, 0.0, 1e-4).asDiagonal()));
}

// Valid tensors are never changed, even within the tolerance (the thin disc
// rounded to 6 digits), and give no note.
TEST_F(BalanceInertia, ValidTensorsAreKeptAsWritten) {
  for (const char* in :
       {"<inertia ixx='0.02' ixy='0' ixz='0' iyy='0.02' iyz='0' izz='0.01'/>",
        "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.0200001'/>"}) {
    const Loaded r = load(in);
    const Loaded plain = load(in, "");
    EXPECT_EQ(r.I, plain.I) << in;
    EXPECT_EQ(r.notes, plain.notes) << in;
    EXPECT_EQ(r.M, plain.M) << in;
  }
  EXPECT_EQ(load(kGoodInertia, "balance_inertia: false\n").I(2, 2), 0.01);
}

// Without the key (or with false) the refusals suggest it.
TEST_F(UrdfValidity, RefusalsSuggestBalanceInertia) {
  const std::string hint =
      "; write balance_inertia: true in the scene to repair it (like MuJoCo's balanceinertia, by "
      "a smaller change: docs/model-format.md)";
  for (const char* in : {"<inertia ixx='0.02' ixy='0' ixz='0' iyy='-0.01' iyz='0' izz='0.02'/>",
                         "<inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.05'/>"})
    for (const char* key : {"", "balance_inertia: false\n"}) {
      const std::string e =
          error(robot(in, kLimit), std::string("urdf: r.urdf\njoints: [j]\n") + key);
      EXPECT_EQ(e.size() >= hint.size() ? e.substr(e.size() - hint.size()) : e, hint) << e;
    }
}

// The key takes true or false only (yaml-cpp would read yes and on as true).
TEST_F(UrdfValidity, BalanceInertiaTakesTrueOrFalse) {
  for (const char* v : {"3", "yes", "[true]", "''"}) {
    const std::string e =
        error(robot(kGoodInertia, kLimit),
              std::string("urdf: r.urdf\njoints: [j]\nbalance_inertia: ") + v + "\n");
    EXPECT_NE(e.find("s.yaml: balance_inertia: expected true or false (got "), std::string::npos)
        << e;
  }
}

}  // namespace
}  // namespace lcsim
