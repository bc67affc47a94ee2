// Regressions found by running public robots (bullet3's pybullet_data: r2d2,
// the DeepMimic humanoid) through scenes as a new user writes them. The
// fixtures are small URDFs written here with the same features, not the
// robots' files.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <lcsim/io/text.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
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

// bullet3's husky rolls its wheels through 1.2-1.4 rad in half a second:
// the rim points the scene keeps (max_distance) turn away from the floor,
// where the linear model holds them at the bottom, and neither the mass nor
// the forces (a wheel is symmetric about its axle) showed it. The run's
// linearisation check measures each contact's gap too: the toe's sphere
// L = 0.4 m below its hip, turned by th, has the exact gap L (1 - cos th),
// the linear one 0 (its row has no hip entry at the bottom), and moved
// 2 L sin(th/2): e_C = sin(th/2) (to 1e-12: rounding of L (1 - cos th)
// ~1e-16 m against ~1e-2 m). Lifted 1 m off the floor, the same turn changes
// the gap by less than its distance in both models: not counted, e_C = 0.
TEST_F(RobotSurvey, TheRunsLinearisationCheckMeasuresTheContactsGaps) {
  const scene::Scene s = load(kLegScene, leg_and_gripper(-3.0, 0.0));
  for (const double th : {0.05, 0.5, 1.2}) {
    const scene::LinearisationCheck c =
        scene::check_linearisation(s, {Eigen::Vector3d(0.0, th, 0.0)});
    EXPECT_NEAR(c.contact_error, std::sin(th / 2), 1e-12) << th;
    EXPECT_EQ(c.contact, "toe.sphere0") << th;
    EXPECT_GE(c.error, c.contact_error) << th;
  }
  const scene::LinearisationCheck lifted =
      scene::check_linearisation(s, {Eigen::Vector3d(1.0, 0.5, 0.0)});
  EXPECT_EQ(lifted.contact_error, 0.0);
  EXPECT_EQ(lifted.contact, "");
  const std::string w = scene::linearisation_warning(
      scene::check_linearisation(s, {Eigen::Vector3d(0.0, 1.2, 0.0)}), 0.01);
  EXPECT_NE(w.find("contact 'toe.sphere0' " + io::format_number(100 * std::sin(0.6), 3) + " %"),
            std::string::npos)
      << w;
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

// bullet3's cube_small.urdf: a 5 cm cube of 0.1 kg whose <inertia> is 1 kg
// m^2 about each axis (Bullet's inertia_scaling hack), so its four bottom
// corners act almost as one point (the Delassus matrix's rotational part
// is r^2 / I = 1.25e-3 of its translational 1/m). Dropped flat from 1 cm
// while sliding at (1, 0.3) m/s onto a floor with mu = 0.5 (d = 4),
// Moreau–Jean "completed" at h = 1e-4, 5e-4 and 2e-3 with the slide
// reversed (v_x = -1.49 m/s after landing at h = 1e-4) and the energy risen
// from 0.0888 J to 0.159 J in the landing step: the dense cone LCP's last
// fallback had accepted lambda_N = 0 beside edge impulses 0.28 N s. With
// e = 0 and no input nothing may raise the energy, and Coulomb friction
// can slow the slide along x or stop it but never reverse it. Whatever the
// outcome, every recorded sample must keep both; a run that stops is a
// numerical failure, never an input error. Tolerances: free flight under
// gravity is exact in the theta = 1/2 step (constant force), so the energy
// moves by rounding only, 1e-12 J against 0.09 J; a stuck corner's
// velocity is 0 to rounding of 1 m/s, 1e-12.
TEST_F(RobotSurvey, AFlatCubeWithAHugeInertiaNeverGainsEnergyInMoreauJean) {
  write("r.urdf", R"(<robot name="cube"><link name="baseLink"><inertial><mass value="0.1"/>
      <inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
      <collision><geometry><box size="0.05 0.05 0.05"/></geometry></collision></link></robot>)");
  const auto loaded = scene::load_model_and_scene(write("s.yaml", R"(urdf: r.urdf
base: {type: floating, pose: {xyz: [0, 0, 0.025]}}
planes: [{name: floor, normal: [0, 0, 1]}]
contacts: [{link: baseLink, plane: floor, friction: 0.5, d: 4}]
contact_options: {max_distance: 0.01}
initial: {q: {cube.z: 0.035}, v: {cube.x: 1, cube.y: 0.3}}
)"));
  const mech::MechanicalModel& m = *loaded.model.mechanical;
  const Eigen::Index n = m.dofs();
  const double e0 =
      mech::total_energy(m, loaded.model.initial.head(n), loaded.model.initial.tail(n));
  for (const double h : {1e-4, 5e-4, 2e-3}) {
    sim::Options o;
    o.t_end = 0.1;  // it lands at t = 0.045 s
    o.h = h;
    const sim::Trajectory tr =
        sim::make_integrator("moreau-jean")->run(loaded.model, loaded.model.initial, o);
    const std::string at = "h = " + std::to_string(h) + ": " + tr.message;
    EXPECT_NE(tr.status, Status::kInvalidInput) << at;
    ASSERT_FALSE(tr.samples.empty()) << at;
    for (const sim::Sample& s : tr.samples) {
      EXPECT_LE(mech::total_energy(m, s.x.head(n), s.x.tail(n)), e0 + 1e-12) << at << " t " << s.t;
      EXPECT_GE(s.x(n), -1e-12) << at << " t " << s.t;  // v_x
    }
  }
}

// bullet3's robots give <inertial> frames turned from their link's (the
// A1's hips: rpy = (pi, 0, 0); Laikago's and Aliengo's links): the tensor
// is written in the inertial frame, which lcsim must turn into the link's.
// One link on a revolute joint about y at the origin, its centre of mass at
// c = (0.3, 0.1, 0.2) m in a frame turned by rpy = (0.4, -0.3, 0.7), its
// principal moments (0.01, 0.02, 0.025) kg m^2 along that frame's axes,
// m = 2 kg. Independently: M = (R I R')_yy + m (cx^2 + cz^2) (parallel
// axes), R = Rz(0.7) Ry(-0.3) Rx(0.4) (URDF's rpy); gravity (0, 0, -9.81)
// gives the torque (c x m g)_y = m 9.81 cx at q0 = 0. Tolerance: rounding
// of sums of a few products of numbers below 1, 1e-14.
TEST_F(RobotSurvey, AnInertialFrameTurnedByRpyEntersTheMassMatrix) {
  write("r.urdf", R"(<robot name="pendulum"><link name="base"/>
    <link name="arm"><inertial><origin xyz="0.3 0.1 0.2" rpy="0.4 -0.3 0.7"/><mass value="2"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.025"/></inertial></link>
    <joint name="j" type="continuous"><parent link="base"/><child link="arm"/>
      <axis xyz="0 1 0"/></joint></robot>)");
  const auto loaded = scene::load_model_and_scene(write("s.yaml", "urdf: r.urdf\njoints: [j]\n"));
  const mech::MechanicalModel& m = *loaded.model.mechanical;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  const Eigen::Matrix3d I = R * Eigen::Vector3d(0.01, 0.02, 0.025).asDiagonal() * R.transpose();
  const double mass = 2.0, cx = 0.3, cz = 0.2;
  ASSERT_EQ(m.dofs(), 1);
  EXPECT_NEAR(Eigen::MatrixXd(m.M)(0, 0), I(1, 1) + mass * (cx * cx + cz * cz), 1e-14);
  EXPECT_NEAR(m.f(0), mass * 9.81 * cx, 1e-14);
  // The turn matters: the unturned tensor's I_yy (0.02) differs by far more.
  EXPECT_GT(std::abs(I(1, 1) - 0.02), 1e-3);
}

}  // namespace
}  // namespace lcsim
