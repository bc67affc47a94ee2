// Regressions found by running public robots (bullet3's pybullet_data: r2d2,
// the DeepMimic humanoid) through scenes as a new user writes them. The
// fixtures are small URDFs written here with the same features, not the
// robots' files.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

#include "scene_files.hpp"

namespace lcsim {
namespace {

class RobotSurvey : public test_support::SceneFiles {
 protected:
  scene::Scene load(const std::string& scene_text, const std::string& urdf) {
    write("r.urdf", urdf);
    return *scene::load_scene_details(write("s.yaml", scene_text));
  }
};

const char* const kInertial = R"(<inertial><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>)";

// A vertical slider `lift` carrying leg `a` (revolute hip about y, limits
// [a_lower, 3]) with a sphere of radius 0.05 at L = 0.4 m straight below the
// hip, touching the floor, and a second joint `b` on the base (limits
// [b_lower, 0.5]) that does not move the sphere (the r2d2's gripper beside
// its wheels).
std::string leg_and_gripper(double a_lower, double b_lower) {
  const std::string link = kInertial;
  return "<robot name=\"legs\"><link name=\"base\">" + link + "</link><link name=\"carriage\">" +
         link +
         "</link><joint name=\"lift\" type=\"prismatic\"><parent link=\"base\"/><child "
         "link=\"carriage\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
         "velocity=\"1\"/></joint><link name=\"a\">" +
         link +
         "<collision><origin xyz=\"0 0 -0.4\"/><geometry><sphere radius=\"0.05\"/></geometry>"
         "</collision></link><joint name=\"a_hip\" type=\"revolute\"><parent link=\"carriage\"/>"
         "<child link=\"a\"/><axis xyz=\"0 1 0\"/><limit lower=\"" +
         std::to_string(a_lower) +
         "\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint><link name=\"b\">" + link +
         "</link><joint name=\"b_grip\" type=\"revolute\"><parent link=\"base\"/><child "
         "link=\"b\"/><origin xyz=\"0.3 0 0\"/><axis xyz=\"0 1 0\"/><limit lower=\"" +
         std::to_string(b_lower) + "\" upper=\"0.5\" effort=\"1\" velocity=\"1\"/></joint></robot>";
}

const char* const kLegScene = R"(urdf: r.urdf
joints: [{name: lift, stops: []}, {name: a_hip, stops: []}, {name: b_grip, stops: []}]
planes: [{name: floor, point: [0, 0, -0.45], normal: [0, 0, 1]}]
contacts: [{link: a, plane: floor, name: toe}]
)";

// bullet3's r2d2 with its gripper joints simulated: every wheel contact was
// reported as "|left_gripper_joint - q0| <= 0 rad (limit)", the gripper's q0
// = 0 being its lower limit. A coordinate that does not move the point
// never ends its range (docs/contacts.md): here b_grip, at its lower limit.
// The toe's range is then its own hip's, |sin(th/2)| = 1 % at
// th = 2 asin(0.01) (as ToeBelowAHipHoldsForTwiceTheArcsineOfTheThreshold in
// test_contacts.cpp: the scan's 50 bisections end near 1e-17 rad, rounding
// in L (1 - cos th) moves the crossing by ~1e-13 rad, so 1e-12).
TEST_F(RobotSurvey, AJointThatDoesNotMoveTheContactNeverEndsItsRange) {
  const scene::Scene s = load(kLegScene, leg_and_gripper(-3.0, 0.0));
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_EQ(ranges[0].coordinate, "a_hip");
  EXPECT_EQ(ranges[0].unit, "rad");
  EXPECT_EQ(ranges[0].end, "threshold");
  EXPECT_NEAR(ranges[0].range, 2 * std::asin(0.01), 1e-12);
}

// The DeepMimic humanoid's knees have q0 = 0 at their upper limit: each
// foot corner was reported as "|right_knee - q0| <= 0 rad (limit)". A way
// the coordinate cannot move at all is not scanned, so the other way
// counts: a_hip at its lower limit 0 is scanned towards + only, where the
// error crosses 1 % at 2 asin(0.01) (same tolerance, same reasons).
TEST_F(RobotSurvey, AWayBlockedAtQ0ByALimitIsNotARangeOfZero) {
  const scene::Scene s = load(kLegScene, leg_and_gripper(0.0, 0.0));
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_EQ(ranges[0].coordinate, "a_hip");
  EXPECT_EQ(ranges[0].end, "threshold");
  EXPECT_NEAR(ranges[0].range, 2 * std::asin(0.01), 1e-12);
}

// The toe moved by the slider alone (a_hip frozen), beside a rotation that
// does not move it (b_grip, at its lower limit): the rotation is no
// candidate, so the slider is reported (in metres: the gap is affine along
// it, so the scan reaches its limit, 1 m, without a crossing). Before, the
// rotation was reported with a range of 0.
TEST_F(RobotSurvey, APointMovedByTranslationsAloneReportsTheTranslation) {
  const std::string urdf = leg_and_gripper(-3.0, 0.0);
  const scene::Scene s = load(R"(urdf: r.urdf
joints: [{name: lift, stops: []}, {name: b_grip, stops: []}]
planes: [{name: floor, point: [0, 0, -0.45], normal: [0, 0, 1]}]
contacts: [{link: a, plane: floor, name: toe}]
)",
                              urdf);
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_EQ(ranges[0].coordinate, "lift");
  EXPECT_EQ(ranges[0].unit, "m");
  EXPECT_EQ(ranges[0].end, "limit");
  EXPECT_EQ(ranges[0].range, 1.0);  // the limit's distance, exact
}

// bullet3's a1.urdf is <robot name="a1_description">: a user writing the
// floating base's height as `a1.z` read "no joint 'a1.z' in a1.urdf", which
// does not say what the base's coordinates are called. The message now
// names them.
TEST_F(RobotSurvey, AWrongBaseCoordinateNameSaysWhatTheBaseIsCalled) {
  const std::string urdf = std::string("<robot name=\"a1_description\"><link name=\"trunk\">") +
                           kInertial + "</link></robot>";
  write("r.urdf", urdf);
  const std::string message = error("", R"(urdf: r.urdf
base: floating
initial: {q: {a1.z: 0.3}}
)");
  EXPECT_NE(message.find("s.yaml: initial.q.a1.z: no joint 'a1.z' in "), std::string::npos)
      << message;
  EXPECT_NE(message.find("r.urdf (the floating base's coordinates are a1_description.x ... "
                         "a1_description.rz: base.name, by default the URDF's <robot name>)"),
            std::string::npos)
      << message;
  EXPECT_EQ(message.find('\n'), std::string::npos) << message;  // one line
  // A joint's name (no base coordinate's suffix) keeps the plain message.
  const std::string plain = error("", R"(urdf: r.urdf
base: floating
initial: {q: {knee: 0.3}}
)");
  EXPECT_EQ(plain.find("floating base"), std::string::npos) << plain;
}

}  // namespace
}  // namespace lcsim
