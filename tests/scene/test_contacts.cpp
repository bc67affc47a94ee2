// Floating bases and contacts against world planes (issue 26;
// src/scene/scene_base.cpp, scene_contacts.cpp, contact_geometry.cpp,
// contacts.cpp, the floating base in urdf_model.cpp; docs/contacts.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/contacts.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>

#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
constexpr double kG = 9.81;

// A floating base carrying a revolute joint (skew axis, rotated origin) and a
// prismatic one below it; every URDF primitive lcsim reads, each on a
// rotated and shifted <collision> origin, plus a mesh (used only with points).
const std::string kArm = R"(<robot name="arm">
  <link name="base">
    <inertial><origin xyz="0.02 -0.01 0.03"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial>
    <collision><origin xyz="0.01 0.02 -0.03" rpy="0.1 -0.2 0.3"/>
      <geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <link name="upper">
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
    <collision><origin xyz="0.05 0 0.3"/><geometry><sphere radius="0.07"/></geometry></collision>
    <collision><origin xyz="0 0.04 0.1" rpy="0.4 0.2 -0.1"/>
      <geometry><capsule radius="0.03" length="0.2"/></geometry></collision>
  </link>
  <link name="tool">
    <inertial><mass value="0.5"/>
      <inertia ixx="0.001" ixy="0" ixz="0" iyy="0.001" iyz="0" izz="0.001"/></inertial>
    <collision><origin xyz="0.1 0 0" rpy="0 1.2 0.3"/>
      <geometry><cylinder radius="0.04" length="0.12"/></geometry></collision>
  </link>
  <link name="sensor">
    <visual><geometry><mesh filename="package://none/tool.stl"/></geometry></visual>
    <collision><geometry><mesh filename="package://none/tool.stl"/></geometry></collision>
  </link>
  <joint name="mount" type="fixed">
    <parent link="tool"/><child link="sensor"/><origin xyz="0 0 0.05"/>
  </joint>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="upper"/>
    <origin xyz="0.1 0.05 0.08" rpy="0.2 0.1 -0.3"/><axis xyz="0.3 0.5 0.8"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
  <joint name="j2" type="prismatic">
    <parent link="upper"/><child link="tool"/>
    <origin xyz="0 0 0.4" rpy="0 0.3 0"/><axis xyz="1 0.2 0"/>
    <limit lower="-0.5" upper="0.5" effort="1" velocity="1"/>
  </joint>
</robot>)";

const std::string kArmContacts = R"(
planes:
  - {name: floor, point: [0, 0, 0.1], normal: [0.1, -0.2, 1]}
  - {name: wall, point: [3, 0, 0], normal: [-1, 0.3, 0]}
contacts:
  - {link: base, plane: floor}
  - {link: upper, plane: floor}
  - {link: upper, plane: wall, name: upper_wall}
  - {link: tool, plane: floor, points: [[0.1, 0, 0], [0, 0.05, 0.02]], radius: 0.01, name: tool_pts}
  - {link: tool, plane: wall, points: [[0.2, 0.1, 0]], name: tool_wall}
)";

class Contacts : public test_support::SceneFiles {
 protected:
  scene::Scene load(const std::string& scene_text, const std::string& urdf = kArm) {
    write("r.urdf", urdf);
    return *scene::load_scene_details(write("s.yaml", scene_text));
  }
};

// The exact dynamics a scene was linearised from (its base included).
scene::UrdfDynamics dynamics_of(const scene::Scene& s) {
  const std::size_t nb = scene::base_coordinates(s.base).size();
  const std::vector<std::string> joints(s.lin.joints.begin() + static_cast<std::ptrdiff_t>(nb),
                                        s.lin.joints.end());
  return scene::UrdfDynamics(*s.urdf, joints, s.q0, s.gravity, s.urdf_source, s.base);
}

const scene::Plane& plane_of(const scene::Scene& s, const std::string& name) {
  return *std::find_if(s.planes.begin(), s.planes.end(),
                       [&](const scene::Plane& p) { return p.name == name; });
}

// Central differences of the exact signed distance against the contact
// frame's normal row at random configurations about q0 (up to 0.6 rad or m
// from it). Step h = 1e-5: truncation h^2/6 |phi'''| <= 2e-11 (lever arms
// and |phi'''| below 1 m here) plus rounding eps |phi| / h <= 1e-10 (|phi| <
// 5 m), so 1e-8 leaves a factor of about 100. The tangent rows are checked
// as the derivatives of the material contact point's position along t1, t2.
void expect_exact_gradients(const scene::Scene& s, int draws) {
  const scene::UrdfDynamics dyn = dynamics_of(s);
  const VectorXd q0 = dyn.reference();
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u(-0.6, 0.6);
  const double h = 1e-5;
  for (int d = 0; d < draws; ++d) {
    VectorXd q = q0;
    for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += u(rng);
    for (const scene::ContactFrame& c0 : s.contacts) {
      const scene::Plane& plane = plane_of(s, c0.plane);
      const scene::ContactFrame c = scene::contact_frame(dyn, c0.point, plane, q);
      EXPECT_NEAR(c.gap, scene::signed_distance(dyn, c0.point, plane, q), 1e-15);
      const Eigen::Isometry3d X = dyn.link_pose(c0.point.link, q);
      const Vector3d material = X.inverse() * c.position;  // link frame
      for (Eigen::Index j = 0; j < q.size(); ++j) {
        VectorXd qp = q, qm = q;
        qp(j) += h;
        qm(j) -= h;
        const double fd = (scene::signed_distance(dyn, c0.point, plane, qp) -
                           scene::signed_distance(dyn, c0.point, plane, qm)) /
                          (2 * h);
        EXPECT_NEAR(c.normal_row(j), fd, 1e-8) << c0.point.name << " coordinate " << j;
        const Vector3d dp = (dyn.link_pose(c0.point.link, qp) * material -
                             dyn.link_pose(c0.point.link, qm) * material) /
                            (2 * h);
        EXPECT_NEAR(c.tangent1_row(j), c.tangent1.dot(dp), 1e-8) << c0.point.name;
        EXPECT_NEAR(c.tangent2_row(j), c.tangent2.dot(dp), 1e-8) << c0.point.name;
      }
      // (n, t1, t2) right-handed and orthonormal (to rounding).
      Eigen::Matrix3d F;
      F << c.normal, c.tangent1, c.tangent2;
      EXPECT_LE((F.transpose() * F - Eigen::Matrix3d::Identity()).norm(), 1e-15);
      EXPECT_NEAR(F.determinant(), 1.0, 1e-15);
    }
  }
}

TEST_F(Contacts, JacobianOfEveryPrimitiveWithAFloatingBaseIsTheExactGradient) {
  const scene::Scene s = load(R"(urdf: r.urdf
base: {type: floating, pose: {xyz: [0.1, -0.2, 2], rpy: [0.3, -0.1, 0.7]}}
joints: [j1, j2]
q0: {j1: 0.4, j2: 0.1}
)" + kArmContacts);
  const mech::MechanicalModel& m = *s.model.mechanical;
  // 8 corners, a sphere and two capsule caps on the floor, the same three
  // against the wall, 2 + 1 given points, the mesh never read.
  ASSERT_EQ(s.contacts.size(), 8u + 3u + 3u + 2u + 1u);
  EXPECT_EQ(m.coordinates[0], "arm.x");
  EXPECT_EQ(m.coordinates[5], "arm.rz");
  std::vector<std::string> names;
  for (const auto& c : s.contacts) names.push_back(c.point.name);
  EXPECT_EQ(names[0], "base.corner0");
  EXPECT_EQ(names[8], "upper.sphere0");
  EXPECT_EQ(names[9], "upper.cap0");
  EXPECT_EQ(names[11], "upper_wall.sphere0");
  EXPECT_EQ(names[14], "tool_pts.point0");
  EXPECT_EQ(names[16], "tool_wall.point0");
  // Each contact's row of E and g: gap ~ phi(q0) + J_n (q - q0).
  const VectorXd q0 = dynamics_of(s).reference();
  for (const auto& c : s.contacts) {
    EXPECT_EQ(m.constraints[static_cast<std::size_t>(c.row)], c.point.name);
    EXPECT_EQ(VectorXd(m.E.row(c.row).transpose()), c.normal_row);
    EXPECT_NEAR(m.E.row(c.row).dot(q0) + m.g(c.row), c.gap, 1e-15);
  }
  expect_exact_gradients(s, 5);
}

TEST_F(Contacts, JacobianWithAFixedBaseAtAPoseAndTheCylinderRim) {
  const scene::Scene s = load(R"(urdf: r.urdf
base: {type: fixed, pose: {xyz: [0.3, 0.2, 1.5], rpy: [0.2, 0.1, -0.4]}}
joints: [j1, j2]
planes: [{name: floor, normal: [0, 0, 1]}]
contacts: [{link: tool, plane: floor, points: [[0, 0, 0]]}, {link: upper, plane: floor}]
)");
  EXPECT_EQ(s.model.mechanical->coordinates, (std::vector<std::string>{"j1", "j2"}));
  expect_exact_gradients(s, 5);
  // The cylinder (radius 0.04, length 0.12): 16 points on its rims, each
  // at 0.04 m from its axis and 0.06 m from its mid-plane (link frame).
  const scene::Scene c = load(R"(urdf: r.urdf
joints: [j1, j2]
planes: [{name: floor, point: [0, 0, -5], normal: [0, 0, 1]}]
contacts: [{link: tool, plane: floor}]
)");
  ASSERT_EQ(c.contacts.size(), 16u);
  const Eigen::Isometry3d O = Eigen::Translation3d(0.1, 0, 0) *
                              Eigen::AngleAxisd(0.3, Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(1.2, Vector3d::UnitY());
  for (const auto& f : c.contacts) {
    const Vector3d p = O.inverse() * f.point.local;
    EXPECT_NEAR(p.head<2>().norm(), 0.04, 1e-15) << f.point.name;
    EXPECT_NEAR(std::abs(p.z()), 0.06, 1e-15) << f.point.name;
  }
  expect_exact_gradients(c, 2);
}

// A box on the floor, its floating base at its reference pose: the gap of
// each corner is its height (4 at 0, 4 at 0.1 m), the sphere of radius r at
// centre height h has gap h - r; K has no entry on x, y, z (gravity does not
// change with position) and f = m g on z.
TEST_F(Contacts, BoxAtRestHasTheGapsAndForcesOfItsGeometry) {
  const scene::Scene s = *scene::load_scene_details(kRobots + "box_drop_scene.yaml");
  const mech::MechanicalModel& m = *s.model.mechanical;
  ASSERT_EQ(m.coordinates.size(), 6u);
  ASSERT_EQ(s.contacts.size(), 8u);
  for (const auto& c : s.contacts) {
    const double height = c.point.local.z() > 0 ? 0.1 : 0.0;
    EXPECT_NEAR(c.gap, height, 1e-17) << c.point.name;
    EXPECT_EQ(c.normal_row(2), 1.0);  // d gap / d z
  }
  EXPECT_EQ(m.constraints[7], "box.corner7");
  EXPECT_EQ(MatrixXd(m.K).leftCols(3), MatrixXd::Zero(6, 3));
  EXPECT_EQ(m.f(2), -1.2 * kG);
  EXPECT_EQ(m.M.coeff(0, 0), 1.2);
  EXPECT_EQ(m.M.coeff(3, 3), 0.005);
  EXPECT_EQ(m.M.coeff(5, 5), 0.013);
  // analyze's linear ranges: the position is exact everywhere (the search
  // ends at 1 m), each rotation holds to some angle.
  const auto ranges = scene::linear_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 6u);
  EXPECT_EQ(ranges[2].joint, "box.z");
  EXPECT_EQ(ranges[2].unit, "m");
  EXPECT_EQ(ranges[2].upper_end, "search");
  EXPECT_EQ(ranges[3].unit, "rad");
}

// analyze's contact section (scene::contact_ranges) on the box at rest:
// the bottom corners are closed, the top ones 0.1 m open; for corner0 at
// p = (-0.15, -0.1, -0.05) the tightest coordinate is the roll rx, where
// the exact gap changes by py sin(th) + pz (cos(th) - 1), the linear one by
// py th, and the corner moves by 2 rho |sin(th/2)|, rho = |(py, pz)|. The
// 1 % crossing of the gap's error relative to that displacement, found
// here by bisection on the closed form on each side (the nearer one
// counts), agrees with the scan's 50 bisections to 1e-12 rad (the scan's
// bisection interval ends near 1e-17 rad; rounding in the error, ~1e-16 m
// against a displacement ~4e-3 m, moves the crossing by ~1e-13 rad).
// (Before the displacement was the scale, the error was taken relative to
// the larger of the two gap changes: 0.0389915 rad then, 0.0434653 now.)
TEST(ContactRanges, BoxCornersAtRest) {
  const scene::Scene s = *scene::load_scene_details(kRobots + "box_drop_scene.yaml");
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 8u);
  for (const auto& r : ranges) {
    const bool top = r.contact >= "box.corner4";
    EXPECT_EQ(r.closed, !top) << r.contact;
    EXPECT_NEAR(r.gap, top ? 0.1 : 0.0, 1e-15) << r.contact;
  }
  const double py = -0.1, pz = -0.05, rho = std::hypot(py, pz);
  const auto off = [&](double th) {
    const double exact = py * std::sin(th) + pz * (std::cos(th) - 1), linear = py * th;
    return std::abs(exact - linear) - 0.01 * 2 * rho * std::abs(std::sin(th / 2));
  };
  double nearest = 10.0;
  for (const double dir : {-1.0, 1.0}) {
    double lo = 1e-6, hi = 1.0;  // off(lo) < 0 < off(hi) on both sides
    ASSERT_LT(off(dir * lo), 0.0);
    ASSERT_GT(off(dir * hi), 0.0);
    for (int k = 0; k < 200; ++k) {
      const double mid = 0.5 * (lo + hi);
      (off(dir * mid) > 0 ? hi : lo) = mid;
    }
    nearest = std::min(nearest, lo);
  }
  EXPECT_EQ(ranges[0].contact, "box.corner0");
  EXPECT_EQ(ranges[0].coordinate, "box.rx");
  EXPECT_EQ(ranges[0].unit, "rad");
  EXPECT_EQ(ranges[0].end, "threshold");
  EXPECT_NEAR(ranges[0].range, nearest, 1e-12);
}

// A leg: a revolute hip (about y) over a floor, a sphere of radius 0.05
// at L = 0.4 m straight below it, touching the floor. Along the hip the
// linear gap does not change (the row of E is 0 there) while the exact one
// rises by L (1 - cos th) and the sphere's centre moves by 2 L |sin(th/2)|:
// the error relative to that displacement is |sin(th/2)|, 1 % at
// th = 2 asin(0.01) on both sides, whatever L. (A second leg's joint
// does not move the sphere: it is no candidate.) Tolerance 1e-12 rad: the bisection's interval ends
// near 1e-17 rad and rounding in L (1 - cos th) (~1e-16 m against ~8e-5 m) moves the crossing by
// ~1e-13 rad.
TEST_F(Contacts, ToeBelowAHipHoldsForTwiceTheArcsineOfTheThreshold) {
  const std::string link = R"(<inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>)";
  const auto leg = [&](const std::string& n, const std::string& parent, double x) {
    return "<link name=\"" + n + "\">" + link +
           "<collision><origin xyz=\"0 0 -0.4\"/><geometry><sphere radius=\"0.05\"/></geometry>"
           "</collision></link><joint name=\"" +
           n + "_hip\" type=\"revolute\"><parent link=\"" + parent + "\"/><child link=\"" + n +
           "\"/><origin xyz=\"" + std::to_string(x) +
           " 0 0\"/><axis xyz=\"0 1 0\"/><limit lower=\"-3\" upper=\"3\" effort=\"1\" "
           "velocity=\"1\"/></joint>";
  };
  // The leg rides on a vertical slider `lift` (so that the toe's row of E
  // is not zero: a contact no coordinate moves is refused); in metres, it
  // is no candidate beside the rotations.
  const std::string urdf =
      "<robot name=\"legs\"><link name=\"base\">" + link + "</link><link name=\"carriage\">" +
      link +
      "</link><joint name=\"lift\" type=\"prismatic\"><parent link=\"base\"/><child "
      "link=\"carriage\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
      "velocity=\"1\"/></joint>" +
      leg("a", "carriage", 0.0) + leg("b", "base", 0.3) + "</robot>";
  const scene::Scene s = load(R"(urdf: r.urdf
joints: [{name: lift, stops: []}, {name: a_hip, stops: []}, {name: b_hip, stops: []}]
planes: [{name: floor, point: [0, 0, -0.45], normal: [0, 0, 1]}]
contacts: [{link: a, plane: floor, name: toe_a}]
)",
                              urdf);
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_EQ(ranges[0].coordinate, "a_hip");
  EXPECT_EQ(ranges[0].unit, "rad");
  EXPECT_EQ(ranges[0].end, "threshold");
  EXPECT_TRUE(ranges[0].closed);
  EXPECT_NEAR(ranges[0].range, 2 * std::asin(0.01), 1e-12);
}

// The same toe on a leg whose hip is no coordinate: it mimics the other
// leg's hip with multiplier 2 (so the toe's only rotation is a_hip's,
// through the mimic; the contact ranges evaluate a coordinate only where
// it moves the point, and must find this one). Along a_hip by th the leg
// turns by 2 th: the error is |sin(th)|, 1 % at th = asin(0.01) on both
// sides (same tolerance, same reasons as above).
TEST_F(Contacts, ToeOfAMimicLegHoldsForTheArcsineOverTheMultiplier) {
  const std::string link = R"(<inertial><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>)";
  const auto leg = [&](const std::string& n, double x, const std::string& mimic) {
    return "<link name=\"" + n + "\">" + link +
           "<collision><origin xyz=\"0 0 -0.4\"/><geometry><sphere radius=\"0.05\"/></geometry>"
           "</collision></link><joint name=\"" +
           n + "_hip\" type=\"revolute\"><parent link=\"carriage\"/><child link=\"" + n +
           "\"/><origin xyz=\"" + std::to_string(x) + " 0 0\"/><axis xyz=\"0 1 0\"/>" + mimic +
           "<limit lower=\"-3\" upper=\"3\" effort=\"1\" velocity=\"1\"/></joint>";
  };
  const std::string urdf =
      "<robot name=\"legs\"><link name=\"base\">" + link + "</link><link name=\"carriage\">" +
      link +
      "</link><joint name=\"lift\" type=\"prismatic\"><parent link=\"base\"/><child "
      "link=\"carriage\"/><axis xyz=\"0 0 1\"/><limit lower=\"-1\" upper=\"1\" effort=\"1\" "
      "velocity=\"1\"/></joint>" +
      leg("a", 0.0, "") + leg("b", 0.3, "<mimic joint=\"a_hip\" multiplier=\"2\"/>") + "</robot>";
  const scene::Scene s = load(R"(urdf: r.urdf
joints: [{name: lift, stops: []}, {name: a_hip, stops: [], mimic_stops: []}]
planes: [{name: floor, point: [0, 0, -0.45], normal: [0, 0, 1]}]
contacts: [{link: b, plane: floor, name: toe_b}]
)",
                              urdf);
  const auto ranges = scene::contact_ranges(s, 0.01);
  ASSERT_EQ(ranges.size(), 1u);
  EXPECT_EQ(ranges[0].coordinate, "a_hip");
  EXPECT_EQ(ranges[0].unit, "rad");
  EXPECT_EQ(ranges[0].end, "threshold");
  EXPECT_TRUE(ranges[0].closed);
  EXPECT_NEAR(ranges[0].range, std::asin(0.01), 1e-12);
}

// Body against body (robots/gripper_box_scene.yaml): each fingertip's
// sphere centre lies on the normal of the box's side face through the
// box's centre, at d from it. Rolling the box by th about its centre (x)
// tilts the face: the exact gap changes by d (cos th - 1), the linear one
// not at all (its row is 0 along box.rx), and the tip, seen from the box,
// moves by 2 d |sin(th/2)|: 1 % at th = 2 asin(0.01), as for the toe
// (same tolerance, same reasons).
TEST(ContactRanges, FingertipAgainstATurningBoxHoldsForTwiceTheArcsine) {
  const scene::Scene s = *scene::load_scene_details(kRobots + "gripper_box_scene.yaml");
  const auto ranges = scene::contact_ranges(s, 0.01);
  int tips = 0;
  for (const auto& r : ranges) {
    if (r.plane != "box/box") continue;
    ++tips;
    EXPECT_EQ(r.coordinate, "box.rx") << r.contact;
    EXPECT_EQ(r.end, "threshold") << r.contact;
    EXPECT_NEAR(r.range, 2 * std::asin(0.01), 1e-12) << r.contact;
  }
  EXPECT_EQ(tips, 2);
}

// A floating body without contacts or torque: z(t) = z0 + vz t - g t^2/2
// and x(t) = x0 + vx t exactly (the linear model of a free body is exact),
// the rotation unchanged. The exact method's matrix exponentials reproduce
// the polynomial to rounding: 1e-12 m over a run of 1 s at ~1 m.
TEST_F(Contacts, FloatingBodyInFreeFallIsParabolicAndDoesNotTurn) {
  write("box.urdf", io::read_file(kRobots + "box.urdf"));
  const std::string path = write("fall.yaml", R"(urdf: box.urdf
base: {type: floating, pose: {xyz: [0.5, -0.25, 1], rpy: [0.1, 0.2, 0.3]}}
initial: {v: {box.x: 0.3, box.z: 2}}
t_end: 1
)");
  const mech::Model model = scene::load_model(path);
  sim::Options opt;
  opt.t_end = 1.0;
  opt.dt_out = 0.125;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.samples.size(), 9u);
  for (const sim::Sample& s : tr.samples) {
    const double t = s.t;
    EXPECT_NEAR(s.x(0), 0.5 + 0.3 * t, 1e-12) << t;
    EXPECT_NEAR(s.x(1), -0.25, 1e-12) << t;
    EXPECT_NEAR(s.x(2), 1.0 + 2.0 * t - 0.5 * kG * t * t, 1e-12) << t;
    EXPECT_LE(s.x.segment<3>(3).cwiseAbs().maxCoeff(), 1e-12) << t;
    EXPECT_LE(s.x.tail<3>().cwiseAbs().maxCoeff(), 1e-12) << t;
  }
}

// Springs hold a floating base like a joint: a spring k on box.z with rest
// r and no gravity makes z(t) = r + (z0 - r) cos(w t), w = sqrt(k / m), and
// an initial spin about x turns it at a constant rate (no torque; the
// linear model's rotation is the angular velocity at q0). Closed forms to
// the exact method's rounding: 1e-12.
TEST_F(Contacts, SpringHoldsAFloatingBase) {
  write("box.urdf", io::read_file(kRobots + "box.urdf"));
  const std::string path = write("spring.yaml", R"(urdf: box.urdf
base: floating
gravity: [0, 0, 0]
springs: [{name: hold, joint: box.z, stiffness: 30, rest: 0.5}]
initial: {q: {box.z: 0.7}, v: {box.rx: 0.25}}
t_end: 1
)");
  const mech::Model model = scene::load_model(path);
  sim::Options opt;
  opt.t_end = 1.0;
  opt.dt_out = 0.1;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double w = std::sqrt(30.0 / 1.2);
  for (const sim::Sample& x : tr.samples) {
    EXPECT_NEAR(x.x(2), 0.5 + 0.2 * std::cos(w * x.t), 1e-12) << x.t;
    EXPECT_NEAR(x.x(3), 0.25 * x.t, 1e-12) << x.t;
  }
}

// Gravity's stiffness on a floating base whose centre of mass sits d = 0.1 m
// below the root's origin: the potential m g z_c with z_c = z - d cos(rx)
// (and the same in ry) gives K(rx, rx) = K(ry, ry) = m g d, no stiffness in
// rz nor in the position, and no force at q0 on the rotations. K_g is a
// central difference (h = 6e-6, urdf_model.cpp): 1e-8 as for the joints.
TEST_F(Contacts, GravityStiffensAFloatingBaseAboutItsCentreOfMass) {
  write("low.urdf", R"(<robot name="low"><link name="b">
    <inertial><origin xyz="0 0 -0.1"/><mass value="1.2"/>
      <inertia ixx="0.005" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.013"/></inertial>
  </link></robot>)");
  const mech::Model model = scene::load_model(write("low.yaml", R"(urdf: low.urdf
base: {type: floating, pose: {xyz: [0, 0, 1]}}
)"));
  const MatrixXd K(model.mechanical->K);
  MatrixXd expected = MatrixXd::Zero(6, 6);
  expected(3, 3) = expected(4, 4) = 1.2 * kG * 0.1;
  EXPECT_LE((K - expected).cwiseAbs().maxCoeff(), 1e-8) << K;
  EXPECT_NEAR(model.mechanical->f(2), -1.2 * kG, 1e-12);
  EXPECT_LE(model.mechanical->f.tail<3>().cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_EQ(model.mechanical->coordinates[3], "low.rx");
}

std::vector<int> bottom_corners(const mech::MechanicalModel& m) {
  std::vector<int> out;
  for (const char* n : {"box.corner0", "box.corner1", "box.corner2", "box.corner3"})
    out.push_back(static_cast<int>(std::find(m.constraints.begin(), m.constraints.end(), n) -
                                   m.constraints.begin()));
  return out;
}

// The box dropped flat from h = 0.2 m above its rest: the four bottom
// corners close together at t = sqrt(2 h / g) in one inelastic impact,
// which takes exactly the kinetic energy m v^2 / 2 (v = g t); then it rests
// on them. The event time is a root of a polynomial found to rounding
// (1e-12 s); energies are O(1) J computed from O(1) numbers (1e-12 J).
TEST(ContactRuns, BoxDroppedFlatLandsOnFourCornersAtOnceAndRests) {
  const mech::Model model = scene::load_model(kRobots + "box_drop_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  const sim::Event& e = tr.events[0];
  const double t_hit = std::sqrt(2 * 0.2 / kG);
  EXPECT_NEAR(e.t, t_hit, 1e-12);
  const VectorXd gap_before = m.E * e.state_before.head(6) + m.g;
  // All four close at that instant and stay closed: zero gap before, zero
  // normal velocity after (the impulses among them are not unique, E M^-1 E'
  // being singular on four corners of one face, §4.6.1; the velocities are).
  const VectorXd rate_after = m.E * e.state_after.tail(6);
  for (int c : bottom_corners(m)) {
    EXPECT_NEAR(gap_before(c), 0.0, 1e-12) << m.constraints[static_cast<std::size_t>(c)];
    EXPECT_NEAR(rate_after(c), 0.0, 1e-12) << m.constraints[static_cast<std::size_t>(c)];
  }
  const double v = kG * t_hit;
  EXPECT_NEAR(e.state_before(8), -v, 1e-12);
  EXPECT_LE(e.state_after.tail(6).cwiseAbs().maxCoeff(), 1e-12);  // at rest after it
  EXPECT_NEAR(tr.energy_initial - tr.energy_final, 0.5 * 1.2 * v * v, 1e-12);
  EXPECT_NEAR(tr.final_state(2), 0.05, 1e-12);
  EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GE(tr.max_violation, -1e-12);
}

// analyze's sets that can be active together on the shipped box: the four
// bottom corners close together (flat on the floor: rank 3, a plane through
// four points, so dependent, §4.6.1), and no top corner can ever close (its
// gap is the one below it plus the height, 0.1 m, on every q: equal rows of
// E). Before the fix in mech/coactive.cpp every corner read "never active".
TEST(ContactRuns, BoxsBottomCornersCanCloseTogetherAndItsTopOnesNever) {
  const mech::Model model = scene::load_model(kRobots + "box_drop_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  std::vector<int> bottom = bottom_corners(m);
  std::sort(bottom.begin(), bottom.end());
  std::vector<int> top;
  for (int i = 0; i < m.num_constraints(); ++i)
    if (!std::binary_search(bottom.begin(), bottom.end(), i)) top.push_back(i);
  ASSERT_EQ(top.size(), 4u);
  const mech::CoactiveSets s = mech::coactive_sets(m);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.maximal, (std::vector<std::vector<int>>{bottom}));
  EXPECT_EQ(s.never_active, top);
  const mech::CoactiveWellPosedness w = mech::coactive_well_posedness(m, s);
  ASSERT_EQ(w.sets.size(), 1u);
  EXPECT_EQ(w.sets[0].rank, 3);
  EXPECT_TRUE(w.dependent);
}

// The box tipped by th0 = 0.2 rad about x, on its bottom edge y = -b
// (b = 0.1 m, half its width) with that edge's linear gap (z - z0) - b rx
// at 0, released at rest. While it pivots that gap stays 0, z'' = b rx'',
// with m z'' = -m g + lam and I rx'' = -b lam (I = Ixx = 0.005 kg m^2; M is
// diagonal at q0, the centre of mass at the base's origin), so
//   lam = g / (1/m + b^2/I),   z'' = -g + lam/m.
// The far edge's gap (z - z0) + b rx starts at 2 b th0 with second
// derivative 2 z'' and closes at t* = sqrt(2 b th0 / -z''). A closed form
// of the linear model, independent of the simulator; the event is a root
// found to rounding: 1e-12 s.
TEST(ContactRuns, BoxTippedOnAnEdgeFallsOntoItsFaceAtTheClosedFormTime) {
  const mech::Model model = scene::load_model(kRobots + "box_tip_scene.yaml");
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const double m = 1.2, I = 0.005, b = 0.1, th0 = 0.2;
  const double lam = kG / (1.0 / m + b * b / I);
  const double zdd = -kG + lam / m;      // = b rx''
  const double far_gap_acc = 2.0 * zdd;  // d^2/dt^2 of (z - z0) + b rx
  const double t_star = std::sqrt(-2.0 * (2.0 * b * th0) / far_gap_acc);
  ASSERT_GE(tr.events.size(), 1u);
  // The first impact (events before it, if any, are the contact mode at t = 0).
  const auto hit = std::find_if(tr.events.begin(), tr.events.end(), [](const sim::Event& e) {
    return e.impulse.size() > 0 && e.impulse.cwiseAbs().maxCoeff() > 0.0;
  });
  ASSERT_NE(hit, tr.events.end());
  EXPECT_NEAR(hit->t, t_star, 1e-12);
  EXPECT_NEAR(tr.final_state(2), 0.05, 1e-12);  // flat on its face
  EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-12);
}

// Restitution per contact, as for stops: 0.5 on the four bottom corners
// sends the dropped box back up at half its impact speed, and it lands
// again 2 (v/2) / g later (closed forms; the event times are roots found to
// rounding, 1e-12 s).
TEST_F(Contacts, RestitutionPerContactBouncesTheBox) {
  write("box.urdf", io::read_file(kRobots + "box.urdf"));
  const std::string path =
      write("bounce.yaml", io::read_file(kRobots + "box_drop_scene.yaml") +
                               "restitution: {box.corner0: 0.5, box.corner1: 0.5, box.corner2: "
                               "0.5, box.corner3: 0.5}\n");
  const mech::Model model = scene::load_model(path);
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 2u);
  const double t1 = std::sqrt(2 * 0.2 / kG), v = kG * t1;
  EXPECT_NEAR(tr.events[0].t, t1, 1e-12);
  EXPECT_NEAR(tr.events[0].state_after(8), 0.5 * v, 1e-12);
  EXPECT_NEAR(tr.events[1].t, t1 + v / kG, 1e-12);
}

// The quadruped (robots/quadruped_drop_scene.yaml: floating base, 8 joints
// held by PD springs, 4 sphere feet) dropped h = 3 cm onto its straight
// legs: gravity exerts no torque on a vertical leg, so it falls rigidly and
// lands on its four feet at once at sqrt(2 h / g); the impact takes its
// kinetic energy M_total g h (6 kg) and it then stays at rest on its feet.
// Closed forms to rounding (1e-12 s, 1e-12 J; 1e-10 m/s for the final
// velocities, which carry K_g's central-difference noise of ~1e-19 N/m on
// the positions through the whole run).
TEST(ContactRuns, QuadrupedLandsOnItsFourFeetAndStands) {
  const mech::Model model = scene::load_model(kRobots + "quadruped_drop_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  ASSERT_EQ(m.coordinates.size(), 14u);
  ASSERT_EQ(m.constraints.size(), 4u);
  EXPECT_EQ(m.constraints[0], "fl_foot.sphere0");
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  const double h = 0.03, t_hit = std::sqrt(2 * h / kG);
  EXPECT_NEAR(tr.events[0].t, t_hit, 1e-12);
  const VectorXd gaps = m.E * tr.events[0].state_before.head(14) + m.g;
  EXPECT_LE(gaps.cwiseAbs().maxCoeff(), 1e-12);  // all four feet at once
  // The energies are ~22 J, sums over 14 coordinates of terms up to ~20 J
  // carried through 31 LCP solves and matrix exponentials of the 29-state
  // LCS: rounding of order 1e-15 relative per step leaves ~1e-12 J in their
  // difference (measured 1.2e-12); 1e-11 J is 6e-12 of the 1.77 J lost.
  EXPECT_NEAR(tr.energy_initial - tr.energy_final, 6.0 * kG * h, 1e-11);
  EXPECT_NEAR(tr.final_state(2), 0.35, 1e-12);
  EXPECT_LE(tr.final_state.tail(14).cwiseAbs().maxCoeff(), 1e-10);
}

// Backward Euler and Moreau-Jean on the dropped box, both first order.
// Free fall before the impact: backward Euler's z_n = z0 - g h^2 n(n+1)/2
// is off by exactly -g t h / 2 (a closed form of the scheme), while
// Moreau-Jean's theta = 1/2 is exact for a constant force (1e-12 m). After
// the impact both rest on the floor: backward Euler's position-level
// constraint within a step's fall g h^2, Moreau-Jean's velocity-level one
// sunk by at most the step's travel h |v| at impact (v = -1.98 m/s), an
// offset it keeps: first order in h, measured at three steps.
sim::Trajectory run_with(const std::string& method, const mech::Model& model, double h, double t) {
  sim::Options opt;
  opt.t_end = t;
  opt.h = h;
  return sim::make_integrator(method)->run(model, model.initial, opt);
}

TEST(ContactRuns, TimeSteppingRunsTheDroppedBoxToFirstOrder) {
  const mech::Model model = scene::load_model(kRobots + "box_drop_scene.yaml");
  const double t = 0.15, z_exact = 0.25 - 0.5 * kG * t * t, v = kG * std::sqrt(2 * 0.2 / kG);
  for (const double h : {2e-3, 1e-3, 5e-4}) {
    const sim::Trajectory be = run_with("euler", model, h, t);
    const sim::Trajectory mj = run_with("moreau-jean", model, h, t);
    ASSERT_EQ(be.status, sim::RunStatus::kCompleted) << be.message;
    ASSERT_EQ(mj.status, sim::RunStatus::kCompleted) << mj.message;
    EXPECT_NEAR(be.final_state(2) - z_exact, -0.5 * kG * t * h, 1e-12) << h;
    EXPECT_NEAR(mj.final_state(2), z_exact, 1e-12) << h;
    const sim::Trajectory be_rest = run_with("euler", model, h, model.t_end);
    const sim::Trajectory mj_rest = run_with("moreau-jean", model, h, model.t_end);
    ASSERT_EQ(be_rest.status, sim::RunStatus::kCompleted) << be_rest.message;
    ASSERT_EQ(mj_rest.status, sim::RunStatus::kCompleted) << mj_rest.message;
    EXPECT_NEAR(be_rest.final_state(2), 0.05, kG * h * h) << h;
    EXPECT_LE(mj_rest.final_state(2), 0.05 + 1e-12) << h;
    EXPECT_GE(mj_rest.final_state(2), 0.05 - h * v) << h;
    EXPECT_LE(be_rest.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-9) << h;
    EXPECT_LE(mj_rest.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-9) << h;
  }
}

// Bad input: one line naming the scene's key (or the URDF's element) and
// the value.
TEST_F(Contacts, BadInputIsOneClearLine) {
  const std::string head = "urdf: r.urdf\nbase: floating\n";
  const std::string floor = "planes: [{name: floor, normal: [0, 0, 1]}]\n";
  write("r.urdf", kArm);
  std::string e = error("", head + floor + "contacts: [{link: sensor, plane: floor}]\n");
  EXPECT_NE(e.find("r.urdf: link 'sensor': <collision> 0: <mesh>: lcsim has no contact points"),
            std::string::npos)
      << e;
  e = error("", head + floor + "contacts: [{link: nope, plane: floor}]\n");
  EXPECT_NE(e.find("s.yaml: contacts[0].link: no link 'nope' in"), std::string::npos) << e;
  e = error("", head + "planes: [{name: floor, normal: [0, 0, 0]}]\n");
  EXPECT_NE(e.find("s.yaml: planes[0].normal: must be non-zero (got 0, 0, 0)"), std::string::npos)
      << e;
  e = error("", head + "planes: [{name: floor, point: [0, 0, 0.5], normal: [0, 0, 1]}]\n" +
                    "contacts: [{link: base, plane: floor, points: [[0, 0, 0.2]]}]\n");
  EXPECT_NE(
      e.find("s.yaml: contacts[0]: contact 'base.point0' penetrates plane 'floor' by 0.3 m at q0"),
      std::string::npos)
      << e;
  e = error("", "urdf: r.urdf\nbase: {type: fixed, pose: {xyz: [0, 0, 1, 2]}}\njoints: [j1]\n");
  EXPECT_NE(e.find("s.yaml: base.pose.xyz: expected 3 entries (x, y, z in m) (got 4)"),
            std::string::npos)
      << e;
  e = error("", "urdf: r.urdf\nbase: {type: floating, pose: {rpy: [0, 1]}}\n");
  EXPECT_NE(e.find("s.yaml: base.pose.rpy: expected 3 entries"), std::string::npos) << e;
  e = error("",
            "urdf: r.urdf\njoints: [j1]\n"
            "planes: [{name: floor, point: [0, 0, -1], normal: [0, 0, 1]}]\n"
            "contacts: [{link: base, plane: floor}]\n");
  EXPECT_NE(e.find("s.yaml: contacts[0].link: contact 'base.corner0' does not move toward or "
                   "away from plane 'floor' at q0"),
            std::string::npos)
      << e;
  e = error("", "urdf: r.urdf\nbase: flying\n");
  EXPECT_NE(e.find("s.yaml: base: expected fixed or floating (got 'flying')"), std::string::npos)
      << e;
  for (const std::string& line : {e}) EXPECT_EQ(line.find('\n'), std::string::npos);
}

// The <collision> scan: an element in a comment is not one, a second
// element of a link counts on, and a bad size names the link, the element
// and the text.
TEST_F(Contacts, CollisionScanReadsOnlyRealElements) {
  const std::string urdf = R"(<robot name="b"><link name="b">
    <inertial><mass value="1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
    <!-- <collision><geometry><box size="1 1 1"/></geometry></collision> -->
    <collision name="ball"><origin xyz="0 0 0.5"/><geometry><sphere radius="0.25"/></geometry></collision>
    <collision><geometry><sphere radius="0.5"/></geometry></collision>
  </link></robot>)";
  const scene::Scene s = load(R"(urdf: r.urdf
base: floating
planes: [{name: floor, point: [0, 0, -1], normal: [0, 0, 1]}]
contacts: [{link: b, plane: floor}]
)",
                              urdf);
  ASSERT_EQ(s.contacts.size(), 2u);
  EXPECT_EQ(s.contacts[0].point.name, "b.sphere0");
  EXPECT_EQ(s.contacts[0].gap, 1.25);  // centre 0.5 above the origin, 1 m above the floor
  EXPECT_EQ(s.contacts[1].point.name, "b.sphere1");
  EXPECT_EQ(s.contacts[1].gap, 0.5);
  std::string bad = urdf;
  bad.replace(bad.find("radius=\"0.5\""), 12, "radius=\"-1\"");
  write("r.urdf", bad);
  const std::string e = error("", R"(urdf: r.urdf
base: floating
planes: [{name: floor, point: [0, 0, -1], normal: [0, 0, 1]}]
contacts: [{link: b, plane: floor}]
)");
  EXPECT_NE(e.find("r.urdf: link 'b': <collision> 1: <sphere radius>: must be > 0 (got -1)"),
            std::string::npos)
      << e;
}

// contact_options.max_distance drops the points farther than it at q0, and
// the scene's notes say how many.
TEST_F(Contacts, FarPointsAreDroppedAndCounted) {
  write("box.urdf", io::read_file(kRobots + "box.urdf"));
  const std::string path = write("d.yaml", io::read_file(kRobots + "box_drop_scene.yaml") +
                                               "contact_options: {max_distance: 0.05}\n");
  const scene::Scene s = *scene::load_scene_details(path);
  ASSERT_EQ(s.contacts.size(), 4u);  // the top corners are 0.1 m up
  EXPECT_EQ(s.model.mechanical->E.rows(), 4);
  ASSERT_EQ(s.notes.size(), 1u);
  EXPECT_NE(s.notes[0].find("dropped 4 of 8 contact points farther than "
                            "contact_options.max_distance = 0.05 m"),
            std::string::npos)
      << s.notes[0];
}

}  // namespace
}  // namespace lcsim
