// Several URDFs in one scene and contacts between bodies (issue 26 part A;
// src/scene/scene_bodies.cpp, bodies.cpp, contact_pairs.cpp,
// scene_body_contacts.cpp; docs/contacts.md, "Several bodies").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/bodies.hpp>
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

// A floating arm: a base and a revolute joint (skew axis, rotated origin)
// carrying a tool with a sphere and a box on shifted, rotated origins.
const std::string kArm = R"(<robot name="arm">
  <link name="base">
    <inertial><origin xyz="0.02 -0.01 0.03"/><mass value="2"/>
      <inertia ixx="0.02" ixy="0.001" ixz="0" iyy="0.03" iyz="0" izz="0.04"/></inertial>
    <collision><origin xyz="0.01 0.02 -0.03" rpy="0.1 -0.2 0.3"/>
      <geometry><box size="0.3 0.2 0.1"/></geometry></collision>
  </link>
  <link name="tool">
    <inertial><origin xyz="0 0 0.2"/><mass value="1"/>
      <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.002"/></inertial>
    <collision><origin xyz="0.05 0 0.3"/><geometry><sphere radius="0.07"/></geometry></collision>
    <collision><origin xyz="0 0.04 0.1" rpy="0.4 0.2 -0.1"/>
      <geometry><box size="0.1 0.06 0.04"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute">
    <parent link="base"/><child link="tool"/>
    <origin xyz="0.1 0.05 0.08" rpy="0.2 0.1 -0.3"/><axis xyz="0.3 0.5 0.8"/>
    <limit lower="-2" upper="2" effort="1" velocity="1"/>
  </joint>
</robot>)";

// A second body: one link with a sphere and a rotated box.
const std::string kBlock = R"(<robot name="block">
  <link name="block">
    <inertial><mass value="3"/>
      <inertia ixx="0.03" ixy="0" ixz="0" iyy="0.04" iyz="0" izz="0.05"/></inertial>
    <collision><origin xyz="0.1 0 0" rpy="0.3 -0.2 0.5"/>
      <geometry><box size="0.4 0.3 0.2"/></geometry></collision>
    <collision><origin xyz="-0.2 0.1 0.05"/><geometry><sphere radius="0.12"/></geometry></collision>
  </link>
</robot>)";

class BodyScenes : public test_support::SceneFiles {
 protected:
  scene::Scene load(const std::string& scene_text) {
    write("arm.urdf", kArm);
    write("block.urdf", kBlock);
    return *scene::load_scene_details(write("s.yaml", scene_text));
  }
};

const std::string kTwoBodies = R"(bodies:
  - name: arm
    urdf: arm.urdf
    base: {type: floating, pose: {xyz: [0.1, -0.2, 0.5], rpy: [0.3, -0.1, 0.7]}}
    joints: [j1]
    q0: {j1: 0.4}
  - name: blk
    urdf: block.urdf
    base: {type: floating, pose: {xyz: [1.6, 0.3, 0.6], rpy: [-0.2, 0.4, 0.1]}}
planes: [{name: floor, normal: [0, 0, 1]}]
contacts:
  - {link: arm/tool, against: blk/block}
  - {link: blk/block, against: arm/tool, name: rev}
  - {link: arm/base, against: blk/block, points: [[0.3, 0.1, 0]], radius: 0.02, name: pt}
  - {link: blk/block, plane: floor}
)";

// The coordinates are the bodies' in order, named <body>.<joint> and
// <body>.x ... .rz; M, K and the damping are block diagonal, each block the
// one the body has alone (its own one-URDF scene gives the same numbers).
TEST_F(BodyScenes, CoordinatesAreConcatenatedAndTheModelBlockDiagonal) {
  const scene::Scene s = load(kTwoBodies);
  const mech::MechanicalModel& m = *s.model.mechanical;
  const std::vector<std::string> names{"arm.x",  "arm.y",  "arm.z", "arm.rx", "arm.ry",
                                       "arm.rz", "arm.j1", "blk.x", "blk.y",  "blk.z",
                                       "blk.rx", "blk.ry", "blk.rz"};
  EXPECT_EQ(m.coordinates, names);
  const MatrixXd M = m.M.toDense(), K = m.K.toDense();
  EXPECT_TRUE(M.block(0, 7, 7, 6).isZero(0.0));
  EXPECT_TRUE(K.block(0, 7, 7, 6).isZero(0.0));
  // The arm alone, as a one-URDF scene: the same block, bit for bit.
  const scene::Scene alone = load(R"(urdf: arm.urdf
base: {type: floating, name: arm, pose: {xyz: [0.1, -0.2, 0.5], rpy: [0.3, -0.1, 0.7]}}
joints: [j1]
q0: {j1: 0.4}
)");
  EXPECT_EQ(MatrixXd(M.topLeftCorner(7, 7)), alone.model.mechanical->M.toDense());
  EXPECT_EQ(MatrixXd(K.topLeftCorner(7, 7)), alone.model.mechanical->K.toDense());
  EXPECT_EQ(VectorXd(m.f.head(7)), alone.model.mechanical->f);
  // The block: mass 3 kg on its translations, gravity m g on z.
  EXPECT_EQ(M(7, 7), 3.0);
  EXPECT_NEAR(m.f(9), -3.0 * kG, 1e-12);
}

// Central differences of the exact signed distance (scene::signed_distance
// on the bodies) against each pair contact's normal row, at random
// configurations about q0 (up to 0.3 rad or m away). Step h = 1e-5:
// truncation h^2/6 |phi'''| <= 2e-11 (lever arms and distances below 2 m)
// plus rounding eps |phi| / h <= 5e-10 (|phi| < 2 m), so 1e-8 leaves a
// margin of 20. The tangent rows are checked as the derivatives of the
// relative position of the two material points along t1, t2.
TEST_F(BodyScenes, PairJacobiansAreTheExactGradientWithRespectToBothBodies) {
  const scene::Scene s = load(kTwoBodies);
  const scene::Bodies dyn = scene::scene_bodies(s);
  // tool: sphere + box (9 points) on blk's box and sphere: 18; rev: blk's
  // 8 corners and sphere on tool's sphere and box: 18; pt: 2; floor: 9.
  ASSERT_EQ(s.contacts.size(), 18u + 18u + 2u + 9u);
  EXPECT_EQ(s.contacts[0].point.name, "arm.tool.sphere0_box0");
  EXPECT_EQ(s.contacts[0].plane, "blk/block.box0");
  EXPECT_EQ(s.contacts[36].point.name, "pt.point0_box0");
  const VectorXd q0 = dyn.reference();
  std::mt19937 rng(26);
  std::uniform_real_distribution<double> u(-0.3, 0.3);
  const double h = 1e-5;
  int box_rows = 0, sphere_rows = 0;
  for (int d = 0; d < 4; ++d) {
    VectorXd q = q0;
    for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += u(rng);
    for (const scene::ContactFrame& c0 : s.contacts) {
      if (!c0.against) continue;
      (c0.against->kind == "box" ? box_rows : sphere_rows) += 1;
      const scene::ContactFrame c = scene::contact_frame(dyn, c0.point, *c0.against, q);
      EXPECT_NEAR(c.gap, scene::signed_distance(dyn, c0, s.planes, q), 1e-15);
      const scene::BodyShape& o = *c0.against;
      const Eigen::Isometry3d Xp = dyn.link_pose(c0.point.body, c0.point.link, q);
      const Eigen::Isometry3d Xo = dyn.link_pose(o.body, o.link, q);
      const Vector3d mp = Xp.inverse() * c.position;
      // The shape's material point touching first: the point's nearest
      // surface point (c.position moved by the gap along the normal).
      const Vector3d mo = Xo.inverse() * (c.position - c.gap * c.normal);
      for (Eigen::Index j = 0; j < q.size(); ++j) {
        VectorXd qp = q, qm = q;
        qp(j) += h;
        qm(j) -= h;
        const double fd = (scene::signed_distance(dyn, c0, s.planes, qp) -
                           scene::signed_distance(dyn, c0, s.planes, qm)) /
                          (2 * h);
        EXPECT_NEAR(c.normal_row(j), fd, 1e-8) << c0.point.name << " coordinate " << j;
        const Vector3d dr = ((dyn.link_pose(c0.point.body, c0.point.link, qp) * mp -
                              dyn.link_pose(o.body, o.link, qp) * mo) -
                             (dyn.link_pose(c0.point.body, c0.point.link, qm) * mp -
                              dyn.link_pose(o.body, o.link, qm) * mo)) /
                            (2 * h);
        EXPECT_NEAR(c.tangent1_row(j), c.tangent1.dot(dr), 1e-8) << c0.point.name;
        EXPECT_NEAR(c.tangent2_row(j), c.tangent2.dot(dr), 1e-8) << c0.point.name;
      }
      Eigen::Matrix3d F;
      F << c.normal, c.tangent1, c.tangent2;
      EXPECT_LE((F.transpose() * F - Eigen::Matrix3d::Identity()).norm(), 1e-15);
      EXPECT_NEAR(F.determinant(), 1.0, 1e-15);
    }
  }
  EXPECT_GT(box_rows, 0);
  EXPECT_GT(sphere_rows, 0);
}

// Closed forms of the two geometries at q0, independent of the code's:
// sphere against sphere |c1 - c2| - r1 - r2; a point against a box face
// n . (w - o) - h_f, with n the face the point is farthest outside of.
TEST_F(BodyScenes, PairGapsAtQ0AreTheClosedFormDistances) {
  const scene::Scene s = load(kTwoBodies);
  const mech::MechanicalModel& m = *s.model.mechanical;
  const scene::Bodies dyn = scene::scene_bodies(s);
  const VectorXd q0 = dyn.reference();
  const Eigen::Isometry3d tool = dyn.link_pose(0, "tool", q0), blk = dyn.link_pose(1, "block", q0);
  const Vector3d c_tool = tool * Vector3d(0.05, 0, 0.3), c_blk = blk * Vector3d(-0.2, 0.1, 0.05);
  const Eigen::Isometry3d box =
      blk * Eigen::Translation3d(0.1, 0, 0) * Eigen::AngleAxisd(0.5, Vector3d::UnitZ()) *
      Eigen::AngleAxisd(-0.2, Vector3d::UnitY()) * Eigen::AngleAxisd(0.3, Vector3d::UnitX());
  const Vector3d y = box.inverse() * c_tool, half(0.2, 0.15, 0.1);
  double face = -1e9;
  for (int a = 0; a < 3; ++a) face = std::max({face, y(a) - half(a), -y(a) - half(a)});
  const auto gap = [&](const std::string& name) {
    const auto it = std::find(m.constraints.begin(), m.constraints.end(), name);
    EXPECT_NE(it, m.constraints.end()) << name;
    const Eigen::Index r = it - m.constraints.begin();
    return m.E.row(r).dot(q0) + m.g(r);
  };
  // Sums of O(1) m terms: rounding 1e-15.
  EXPECT_NEAR(gap("arm.tool.sphere0_sphere0"), (c_tool - c_blk).norm() - 0.07 - 0.12, 1e-14);
  EXPECT_NEAR(gap("arm.tool.sphere0_box0"), face - 0.07, 1e-14);
}

// The gripper (robots/gripper_box_scene.yaml): each finger (m = 0.1 kg,
// spring k = 40 N/m to rest 0.05 m, from 0.15 m) follows q(t) = 0.05 + 0.1
// cos(w t), w = 20 rad/s, and meets the box's face (q = 0.11 m: the face at
// 0.1 m plus the tip's radius 0.01 m) at t* = acos(0.6) / w. Both fingers at
// once: the box feels equal and opposite impulses, so it stays where it
// was, on the floor; the fingers stop there (no restitution) and squeeze.
// Event times are roots found to rounding (1e-12 s); positions and rates
// are sums of O(0.1) numbers (1e-12).
TEST(BodiesRuns, GripperClosesOnTheBoxAtTheClosedFormTimeAndTheBoxStaysOnTheFloor) {
  const mech::Model model = scene::load_model(kRobots + "gripper_box_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  ASSERT_EQ(m.coordinates.size(), 8u);
  EXPECT_EQ(m.coordinates[0], "gripper.left");
  EXPECT_EQ(m.coordinates[2], "box.x");
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const auto hit = std::find_if(tr.events.begin(), tr.events.end(), [](const sim::Event& e) {
    return e.impulse.size() > 0 && e.impulse.cwiseAbs().maxCoeff() > 0.0;
  });
  ASSERT_NE(hit, tr.events.end());
  const double w = 20.0, t_star = std::acos(0.6) / w;
  EXPECT_NEAR(hit->t, t_star, 1e-12);
  const auto row = [&](const std::string& name) {
    return std::find(m.constraints.begin(), m.constraints.end(), name) - m.constraints.begin();
  };
  const VectorXd gaps = m.E * hit->state_before.head(8) + m.g;
  EXPECT_NEAR(gaps(row("left_tip.sphere0")), 0.0, 1e-12);
  EXPECT_NEAR(gaps(row("right_tip.sphere0")), 0.0, 1e-12);
  EXPECT_NEAR(hit->state_before(8), -0.1 * w * std::sin(w * t_star), 1e-12);  // -1.6 m/s
  const VectorXd& x = tr.final_state;
  EXPECT_NEAR(x(0), 0.11, 1e-12);
  EXPECT_NEAR(x(1), 0.11, 1e-12);
  for (int i = 2; i < 8; ++i) EXPECT_NEAR(x(i), i == 4 ? 0.05 : 0.0, 1e-12) << m.coordinates[i];
  EXPECT_LE(x.tail(8).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_GE(tr.max_violation, -1e-12);
}

// Moreau-Jean on the gripper scene, first order in h against the exact run
// (the test above): a contact closing at speed v sinks by at most the
// step's travel h v (the fingers close at 1.6 m/s) and never opens again
// under the springs; the resting box sinks by 0.0143 h under Moreau-Jean
// before any impact, alone as well (measured on robots/box.urdf at rest
// on the floor, h = 2e-3 and 1e-3: 2.86e-5 and 1.43e-5 m), so 0.02 h bounds
// it; the box's x and y stay 0 by symmetry (1e-12), and it tilts, as it
// sinks, by a first-order amount (measured at most 0.024 h rad: 0.05 h).
TEST(BodiesRuns, MoreauJeanOnTheGripperIsFirstOrder) {
  const mech::Model model = scene::load_model(kRobots + "gripper_box_scene.yaml");
  for (const double h : {1e-3, 5e-4, 2.5e-4}) {
    sim::Options opt;
    opt.t_end = 0.1;
    opt.h = h;
    const sim::Trajectory tr = sim::make_integrator("moreau-jean")->run(model, model.initial, opt);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    const VectorXd& x = tr.final_state;
    for (int i = 0; i < 2; ++i) {
      EXPECT_LE(x(i), 0.11 + 1e-12) << h;
      EXPECT_GE(x(i), 0.11 - 1.6 * h) << h;
    }
    EXPECT_NEAR(x(4), 0.05, 0.02 * h) << h;
    for (int i : {2, 3}) EXPECT_NEAR(x(i), 0.0, 1e-12) << h << " " << i;
    for (int i : {5, 6, 7}) EXPECT_NEAR(x(i), 0.0, 0.05 * h) << h << " " << i;
    EXPECT_LE(x.tail(8).cwiseAbs().maxCoeff(), 1e-9) << h;
  }
}

// Ghost Robotics' Vision 60 (robots/vision60_drop_scene.yaml: a public
// URDF, floating base, 12 joints held by damped PD springs) dropped h =
// 3 cm. A free body falls rigidly under uniform gravity (M (-g e_z) is
// the gravity force, springs at rest), so its four toes, all at gap 0 at
// q0, land together at sqrt(2 h / g) (a root found to rounding, 1e-12 s).
// It then settles on them: after 1 s the velocities are below 1e-8 (the
// slowest mode, damped by 20 N m s/rad springs, has decayed by e^-40 and
// more; the measured maximum is 3e-11) and no toe is below the floor by
// more than the event tolerance's scale, 1e-9 m.
TEST(BodiesRuns, Vision60LandsOnItsFourToesAndSettles) {
  const mech::Model model = scene::load_model(kRobots + "vision60_drop_scene.yaml");
  const mech::MechanicalModel& m = *model.mechanical;
  ASSERT_EQ(m.coordinates.size(), 18u);
  EXPECT_EQ(m.coordinates[0], "vision60.x");
  EXPECT_EQ(m.coordinates[6], "vision60.8");
  ASSERT_EQ(m.constraints.size(), 4u);
  EXPECT_EQ(m.constraints[0], "toe0.sphere0");
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_GE(tr.events.size(), 1u);
  const double h = 0.03;
  EXPECT_NEAR(tr.events[0].t, std::sqrt(2 * h / kG), 1e-12);
  const VectorXd at_impact = m.E * tr.events[0].state_before.head(18) + m.g;
  EXPECT_LE(at_impact.cwiseAbs().maxCoeff(), 1e-12);  // all four at once
  EXPECT_NEAR(tr.events[0].state_before(20), -kG * std::sqrt(2 * h / kG), 1e-12);
  EXPECT_LE(tr.final_state.tail(18).cwiseAbs().maxCoeff(), 1e-8);
  const VectorXd gaps = m.E * tr.final_state.head(18) + m.g;
  EXPECT_GE(gaps.minCoeff(), -1e-9);
  EXPECT_GE(tr.max_violation, -1e-9);
}

}  // namespace
}  // namespace lcsim
