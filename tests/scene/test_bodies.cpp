// Several URDFs in one scene and contacts between bodies (issue 26 part A;
// src/scene/scene_bodies.cpp, bodies.cpp, contact_pairs.cpp,
// scene_body_contacts.cpp; docs/contacts.md, "Several bodies").
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/bodies.hpp>
#include <lcsim/scene/contacts.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <map>
#include <random>
#include <sstream>

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
// configurations about q0 (up to `spread` rad or m away). Step h = 1e-5:
// truncation h^2/6 |phi'''| <= 2e-11 (lever arms and distances below 2 m,
// and no point within 0.5 m of a box's edge or corner, where phi''' grows
// as L^3 / d^2 with the distance d) plus rounding eps |phi| / h <= 5e-10
// (|phi| < 2 m), so 1e-8 leaves a margin of 20; a smaller `h` where points
// come closer to an edge. The tangent rows are checked as the derivatives of the
// relative position of the two material points along t1, t2. Every pair
// contact of `s`, at `draws` random configurations; the number of rows
// checked per shape kind.
std::map<std::string, int> expect_exact_pair_rows(const scene::Scene& s, int draws, unsigned seed,
                                                  double spread = 0.3, double h = 1e-5) {
  const scene::Bodies dyn = scene::scene_bodies(s);
  const VectorXd q0 = dyn.reference();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-spread, spread);
  std::map<std::string, int> rows;
  for (int d = 0; d < draws; ++d) {
    VectorXd q = q0;
    for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += u(rng);
    for (const scene::ContactFrame& c0 : s.contacts) {
      if (!c0.against) continue;
      rows[c0.against->kind] += 1;
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
      // An orthonormal frame to rounding: the normal is a unit vector rotated
      // by the shape's pose, the tangents its cross products; each entry of
      // F'F - I and of det F - 1 carries a few eps (2.2e-16): 4e-15.
      EXPECT_LE((F.transpose() * F - Eigen::Matrix3d::Identity()).norm(), 4e-15);
      EXPECT_NEAR(F.determinant(), 1.0, 4e-15);
    }
  }
  return rows;
}

TEST_F(BodyScenes, PairJacobiansAreTheExactGradientWithRespectToBothBodies) {
  const scene::Scene s = load(kTwoBodies);
  // tool: sphere + box (9 points) on blk's box and sphere: 18; rev: blk's
  // 8 corners and sphere on tool's sphere and box: 18; pt: 2; floor: 9.
  ASSERT_EQ(s.contacts.size(), 18u + 18u + 2u + 9u);
  EXPECT_EQ(s.contacts[0].point.name, "arm.tool.sphere0_box0");
  EXPECT_EQ(s.contacts[0].plane, "blk/block.box0");
  EXPECT_EQ(s.contacts[36].point.name, "pt.point0_box0");
  const std::map<std::string, int> rows = expect_exact_pair_rows(s, 4, 26);
  EXPECT_GT(rows.at("box"), 0);
  EXPECT_GT(rows.at("sphere"), 0);
}

// A third body: a capsule and a cylinder on rotated, shifted origins.
const std::string kPill = R"(<robot name="pill">
  <link name="pill">
    <inertial><mass value="2"/>
      <inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.01"/></inertial>
    <collision><origin xyz="0.05 -0.02 0.1" rpy="0.4 -0.3 0.2"/>
      <geometry><capsule radius="0.08" length="0.5"/></geometry></collision>
    <collision><origin xyz="-0.1 0.05 -0.05" rpy="-0.2 0.5 0.1"/>
      <geometry><cylinder radius="0.15" length="0.3"/></geometry></collision>
  </link>
</robot>)";

// The arm's tool (its sphere and box corners) and explicit points on its
// base against the pill's capsule and cylinder, at q0 facing the capsule's
// side and cap and the cylinder's side, end and rim (the points below are
// placed in the pill's frame through the base's pose at q0).
const std::string kRound = R"(bodies:
  - name: arm
    urdf: arm.urdf
    base: {type: floating, pose: {xyz: [0.1, -0.2, 0.5], rpy: [0.3, -0.1, 0.7]}}
    joints: [j1]
    q0: {j1: 0.4}
  - name: pill
    urdf: pill.urdf
    base: {type: floating, pose: {xyz: [1.2, 0.3, 0.6], rpy: [-0.2, 0.4, 0.1]}}
contacts:
  - {link: arm/tool, against: pill/pill}
  - {link: arm/base, against: pill/pill, points: [[1.0, 0.6, 0.3], [1.4, 0.2, 0.1], [0.9, 0.1, -0.2], [1.5, 0.9, 0.8]], radius: 0.01, name: pt}
)";

// Points ys given in the frame of the first pair contact's shape of `kind`
// on body `body`, at q0, as points of the arm's base in the scene's text
// ("[x, y, z], ..." to 17 digits): places them, through the poses, in a
// chosen region of that shape.
std::string base_points(const scene::Scene& s, const std::string& kind, std::size_t body,
                        const std::vector<Vector3d>& ys) {
  const scene::Bodies dyn = scene::scene_bodies(s);
  const VectorXd q0 = dyn.reference();
  const auto c = std::find_if(s.contacts.begin(), s.contacts.end(), [&](const auto& f) {
    return f.against && f.against->kind == kind && f.against->body == body;
  });
  EXPECT_NE(c, s.contacts.end()) << kind;
  if (c == s.contacts.end()) return "";
  const Eigen::Isometry3d X =
      dyn.link_pose(c->against->body, c->against->link, q0) * c->against->local;
  const Eigen::Isometry3d base = dyn.link_pose(0, "base", q0);
  std::ostringstream o;
  o << std::setprecision(17);
  for (std::size_t i = 0; i < ys.size(); ++i) {
    const Vector3d b = base.inverse() * (X * ys[i]);
    o << (i ? ", " : "") << "[" << b.x() << ", " << b.y() << ", " << b.z() << "]";
  }
  return o.str();
}

// kRound with one more contact: two points on the arm's base, computed from
// the poses at q0, 0.2 m beyond the cylinder's +z end on its axis and beyond
// its rim (0.1 m out radially, 0.1 m past the -z end), so that q0 itself
// visits the end cap and the rim.
class RoundScenes : public BodyScenes {
 protected:
  scene::Scene load_round() {
    write("pill.urdf", kPill);
    const scene::Scene first = load(kRound);
    return load(kRound + "  - {link: arm/base, against: pill/pill, points: [" +
                base_points(first, "cylinder", 1, {{0, 0, 0.35}, {0.25, 0, -0.25}}) +
                "], name: far}\n");
  }
};

// Capsules and cylinders as the other body's shapes: the same central
// differences as above (same step and tolerance: lever arms and distances
// below 2 m), at configurations up to 0.05 rad or m from q0 that put points
// on the cylinder's side, its end caps and beyond its rim (counted: each
// region must be visited).
TEST_F(RoundScenes, CapsuleAndCylinderRowsAreTheExactGradient) {
  const scene::Scene s = load_round();
  const std::map<std::string, int> rows = expect_exact_pair_rows(s, 6, 27, 0.05);
  EXPECT_GT(rows.at("capsule"), 0);
  EXPECT_GT(rows.at("cylinder"), 0);
  // The regions of the cylinder visited at q0 and the draws.
  const scene::Bodies dyn = scene::scene_bodies(s);
  std::mt19937 rng(27);
  std::uniform_real_distribution<double> u(-0.05, 0.05);
  int side = 0, end = 0, rim = 0;
  for (int d = 0; d < 6; ++d) {
    VectorXd q = dyn.reference();
    for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += u(rng);
    for (const scene::ContactFrame& c0 : s.contacts) {
      if (!c0.against || c0.against->kind != "cylinder") continue;
      const Eigen::Isometry3d X =
          dyn.link_pose(c0.against->body, c0.against->link, q) * c0.against->local;
      const Vector3d y =
          X.inverse() * (dyn.link_pose(c0.point.body, c0.point.link, q) * c0.point.local);
      const double dr = y.head<2>().norm() - 0.15, dz = std::abs(y.z()) - 0.15;
      (dr > 0 && dz > 0 ? rim : dr > dz ? side : end) += 1;
    }
  }
  EXPECT_GT(side, 0);
  EXPECT_GT(end, 0);
  EXPECT_GT(rim, 0);
}

// The capsule's and cylinder's gaps at q0 against closed forms computed here
// from the poses (the distance to the capsule's axis segment; the cylinder's
// by its regions), for every pair: sums of O(1) m terms, rounding 1e-14.
TEST_F(RoundScenes, CapsuleAndCylinderGapsAtQ0AreTheClosedFormDistances) {
  const scene::Scene s = load_round();
  const mech::MechanicalModel& m = *s.model.mechanical;
  const scene::Bodies dyn = scene::scene_bodies(s);
  const VectorXd q0 = dyn.reference();
  const Eigen::Isometry3d pill = dyn.link_pose(1, "pill", q0);
  const auto pose = [](double x, double y, double z, double r, double p, double w) {
    return Eigen::Isometry3d(
        Eigen::Translation3d(x, y, z) * Eigen::AngleAxisd(w, Vector3d::UnitZ()) *
        Eigen::AngleAxisd(p, Vector3d::UnitY()) * Eigen::AngleAxisd(r, Vector3d::UnitX()));
  };
  const Eigen::Isometry3d cap = pill * pose(0.05, -0.02, 0.1, 0.4, -0.3, 0.2);
  const Eigen::Isometry3d cyl = pill * pose(-0.1, 0.05, -0.05, -0.2, 0.5, 0.1);
  int checked = 0;
  for (Eigen::Index r = 0; r < static_cast<Eigen::Index>(s.contacts.size()); ++r) {
    const scene::ContactFrame& c = s.contacts[static_cast<size_t>(r)];
    const Vector3d w = dyn.link_pose(c.point.body, c.point.link, q0) * c.point.local;
    double phi = 0.0;
    if (c.against->kind == "capsule") {
      const Vector3d y = cap.inverse() * w;
      const double z = std::min(0.25, std::max(-0.25, y.z()));
      phi = std::sqrt(y.x() * y.x() + y.y() * y.y() + (y.z() - z) * (y.z() - z)) - 0.08;
    } else {
      const Vector3d y = cyl.inverse() * w;
      const double dr = std::sqrt(y.x() * y.x() + y.y() * y.y()) - 0.15;
      const double dz = std::abs(y.z()) - 0.15;
      phi = dr > 0 && dz > 0 ? std::sqrt(dr * dr + dz * dz) : std::max(dr, dz);
    }
    const auto it = std::find(m.constraints.begin(), m.constraints.end(), c.point.name);
    ASSERT_NE(it, m.constraints.end()) << c.point.name;
    const Eigen::Index row = it - m.constraints.begin();
    EXPECT_NEAR(m.E.row(row).dot(q0) + m.g(row), phi - c.point.radius, 1e-14) << c.point.name;
    ++checked;
  }
  EXPECT_EQ(checked, static_cast<int>(s.contacts.size()));
}

// A mesh of the other link is refused naming the link and the element.
TEST_F(BodyScenes, AMeshCannotBeTouched) {
  write("pill.urdf", R"(<robot name="pill"><link name="pill">
    <inertial><mass value="2"/><inertia ixx="0.02" ixy="0" ixz="0" iyy="0.03" iyz="0" izz="0.01"/></inertial>
    <collision><geometry><mesh filename="pill.stl"/></geometry></collision>
  </link></robot>)");
  try {
    load(kRound);
    ADD_FAILURE() << "a mesh was touched";
  } catch (const io::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("pill"), std::string::npos) << what;
    EXPECT_NE(what.find("<mesh>"), std::string::npos) << what;
  }
}

// The signed distance of y (in a box's frame) from the box of half sizes
// `half`, written independently of the library's: outside, the distance to
// the nearest point sqrt(sum max(|y_a| - h_a, 0)^2); inside (or on), minus
// the depth under the nearest face, max_a (|y_a| - h_a).
double box_distance(const Vector3d& y, const Vector3d& half) {
  const Vector3d out = (y.cwiseAbs() - half).cwiseMax(0.0);
  return out.norm() > 0.0 ? out.norm() : (y.cwiseAbs() - half).maxCoeff();
}

// The region of y about a box of half sizes `half`: the number of
// coordinates beyond the box (0 inside, 1 a face's, 2 an edge's, 3 a
// corner's).
int box_region(const Vector3d& y, const Vector3d& half) {
  return static_cast<int>(((y.cwiseAbs() - half).array() > 0.0).count());
}

// kTwoBodies with points on the arm's base placed, through the poses at q0,
// in the block's box's frame beyond a face (0.25 m), an edge and a corner
// (0.2 m out along each axis beyond), so that q0 itself visits each region.
class BoxScenes : public BodyScenes {
 protected:
  scene::Scene load_box_regions() {
    const scene::Scene first = load(kTwoBodies);
    return load(
        kTwoBodies + "  - {link: arm/base, against: blk/block, points: [" +
        base_points(first, "box", 1, {{0.45, 0.02, -0.03}, {0.4, -0.35, 0.01}, {-0.4, 0.35, 0.3}}) +
        "], name: far}\n");
  }
};

// The box's rows beyond its faces, edges and corners: the central
// differences of expect_exact_pair_rows at configurations up to 0.02 rad or
// m from q0 (the points then move by at most 0.14 m relative to the box:
// 0.035 m per base translation, 0.035 rad on lever arms up to 1.6 m), so
// they stay 0.14 m from an edge or a corner and phi''' <= L^3 / d^2 = 400;
// step 1e-6: truncation h^2/6 400 = 7e-11, rounding eps 2 m / h = 4.4e-10,
// within 1e-8. Each region visited (counted); the gaps at q0 against
// box_distance.
TEST_F(BoxScenes, BoxRowsAreTheExactGradientBeyondFacesEdgesAndCorners) {
  const scene::Scene s = load_box_regions();
  const std::map<std::string, int> rows = expect_exact_pair_rows(s, 6, 28, 0.02, 1e-6);
  EXPECT_GT(rows.at("box"), 0);
  const scene::Bodies dyn = scene::scene_bodies(s);
  const mech::MechanicalModel& m = *s.model.mechanical;
  const VectorXd q0 = dyn.reference();
  std::mt19937 rng(28);
  std::uniform_real_distribution<double> u(-0.02, 0.02);
  std::map<int, int> regions;
  for (int d = 0; d <= 6; ++d) {  // d = 6: q0 itself
    VectorXd q = q0;
    if (d < 6)
      for (Eigen::Index i = 0; i < q.size(); ++i) q(i) += u(rng);
    for (const scene::ContactFrame& c : s.contacts) {
      if (!c.against || c.against->kind != "box") continue;
      const Eigen::Isometry3d X =
          dyn.link_pose(c.against->body, c.against->link, q) * c.against->local;
      const Vector3d y =
          X.inverse() * (dyn.link_pose(c.point.body, c.point.link, q) * c.point.local);
      regions[box_region(y, c.against->half)] += 1;
      if (d < 6) continue;
      // Sums of O(1) m terms: rounding 1e-14.
      const auto it = std::find(m.constraints.begin(), m.constraints.end(), c.point.name);
      ASSERT_NE(it, m.constraints.end()) << c.point.name;
      const Eigen::Index row = it - m.constraints.begin();
      EXPECT_NEAR(m.E.row(row).dot(q0) + m.g(row),
                  box_distance(y, c.against->half) - c.point.radius, 1e-14)
          << c.point.name;
    }
  }
  EXPECT_GT(regions[1], 0);
  EXPECT_GT(regions[2], 0);
  EXPECT_GT(regions[3], 0);
}

// Closed forms of the two geometries at q0, independent of the code's:
// sphere against sphere |c1 - c2| - r1 - r2; a point against a box its
// distance from the box (box_distance).
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
  const double face = box_distance(y, half);
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

// An obstacle: a body with a fixed base and no joints has no coordinates
// (a table top, 1 m x 1 m x 0.1 m, its top face at z = 0.55 m); a floating
// ball (m = 1 kg, radius 0.1 m) dropped from z = 0.9 m meets it when its
// centre reaches 0.65 m: at t* = sqrt(2 h / g), h = 0.25 m, with speed g t*;
// the inelastic impact stops it there, and the energy falls by exactly the
// kinetic energy at impact, m g h. Event times are roots found to rounding
// (1e-12 s); positions are sums of O(1) m terms (1e-12 m).
const std::string kTable = R"(<robot name="table"><link name="top">
  <inertial><mass value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  <collision><geometry><box size="1 1 0.1"/></geometry></collision>
</link></robot>)";
const std::string kBall = R"(<robot name="ball"><link name="ball">
  <inertial><mass value="1"/><inertia ixx="0.004" ixy="0" ixz="0" iyy="0.004" iyz="0" izz="0.004"/></inertial>
  <collision><geometry><sphere radius="0.1"/></geometry></collision>
</link></robot>)";

TEST_F(BodyScenes, ABodyWithoutCoordinatesIsAnObstacle) {
  write("table.urdf", kTable);
  write("ball.urdf", kBall);
  const mech::Model model = scene::load_model(write("s.yaml", R"(bodies:
  - {name: table, urdf: table.urdf, base: {type: fixed, pose: {xyz: [0, 0, 0.5]}}}
  - {name: ball, urdf: ball.urdf, base: {type: floating, pose: {xyz: [0, 0, 0.7]}}}
contacts:
  - {link: ball/ball, against: table/top}
initial:
  q: {ball.z: 0.9}
t_end: 0.5
)"));
  const mech::MechanicalModel& m = *model.mechanical;
  ASSERT_EQ(m.coordinates.size(), 6u);  // the ball's alone
  EXPECT_EQ(m.coordinates[2], "ball.z");
  sim::Options opt;
  opt.t_end = model.t_end;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  ASSERT_FALSE(tr.events.empty());
  const double h = 0.25, t_star = std::sqrt(2 * h / kG);
  EXPECT_NEAR(tr.events.front().t, t_star, 1e-12);
  EXPECT_NEAR(tr.events.front().state_before(8), -kG * t_star, 1e-12);
  EXPECT_NEAR(tr.final_state(2), 0.65, 1e-12);
  EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_NEAR(tr.energy_initial - tr.energy_final, 1.0 * kG * h, 1e-12);
}

TEST_F(BodyScenes, AllBodiesFixedIsRefused) {
  write("table.urdf", kTable);
  const std::string e = error("", R"(bodies:
  - {name: a, urdf: table.urdf, base: {type: fixed}}
  - {name: b, urdf: table.urdf, base: {type: fixed, pose: {xyz: [0, 0, 1]}}}
t_end: 1
)");
  EXPECT_NE(e.find("s.yaml: bodies: no body has a coordinate"), std::string::npos) << e;
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
// under the springs; the box rests on the floor (it sank 0.0143 h before
// Moreau-Jean's activation test allowed for rounding: the test below) and
// 0.02 h bounds what the squeeze moves it by; the box's x and y stay 0 by
// symmetry (1e-12), and it tilts by a first-order amount (measured at most
// 0.024 h rad: 0.05 h).
// Moreau-Jean holds a box resting flat on its four corners (robots/box.urdf
// at z = 0.05 m, its corners' gaps exactly 0): the predicted gaps are zero
// to rounding every step, and each corner stays in the active set, so the
// box neither sinks nor tilts. Compared with exactly zero, rounding left two
// corners at +1e-21 m at the fourth step; they dropped out for one step and
// the box pivoted on the other two and sank 0.0143 h for good. Positions
// are O(0.05) m: 1e-15 m is a few ulp.
TEST_F(BodyScenes, MoreauJeanHoldsABoxRestingOnFourCorners) {
  std::filesystem::copy_file(kRobots + "box.urdf", dir_ / "box.urdf");
  const mech::Model model = scene::load_model(write("s.yaml", R"(urdf: box.urdf
base: {type: floating, pose: {xyz: [0, 0, 0.05]}}
planes: [{name: floor, normal: [0, 0, 1]}]
contacts: [{link: box, plane: floor}]
t_end: 0.5
)"));
  for (const double h : {2e-3, 1e-3}) {
    sim::Options opt;
    opt.t_end = model.t_end;
    opt.h = h;
    const sim::Trajectory tr = sim::make_integrator("moreau-jean")->run(model, model.initial, opt);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    EXPECT_GE(tr.max_violation, -1e-15) << h;
    EXPECT_NEAR(tr.final_state(2), 0.05, 1e-15) << h;
    for (int i : {3, 4, 5}) EXPECT_NEAR(tr.final_state(i), 0.0, 1e-15) << h << " " << i;
  }
}

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
