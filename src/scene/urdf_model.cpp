// URDF models (urdfdom) and their linearisation about a reference
// configuration: the joint-space mass matrix by the composite-rigid-body
// algorithm, the gravity generalised force and the gravity stiffness.
//
// Spatial algebra, all in the URDF root frame (the "world", a fixed base):
// a twist is (omega, v0) with v0 the velocity of the material point at the
// world origin; a wrench is (n0, F) with n0 the moment about the origin, so
// power = twist . wrench. The spatial inertia of a body of mass m, centre of
// mass c and rotational inertia I_c about c (world axes) is
//   I = [ I_c + m [c]x [c]x^T   m [c]x ]
//       [ m [c]x^T              m 1    ]
// and, with S_i the motion subspace (6-vector) of joint i and Ic_i the sum of
// the inertias of every body moved by joint i (the composite body), the mass
// matrix is M_ij = S_j^T Ic_i S_i for j an ancestor of (or equal to) i and 0
// for joints on different branches (Featherstone, Rigid Body Dynamics
// Algorithms, §6.2; expressed in world coordinates no transforms between
// body frames are needed).
#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <lcsim/core/format.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/scene/so3.hpp>
#include <lcsim/scene/urdf.hpp>
#include <set>
#include <sstream>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::one_line;

namespace {

using Eigen::Isometry3d;
using Eigen::Matrix3d;
using Eigen::Vector3d;
using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

[[noreturn]] void fail(const std::string& source, const std::string& element,
                       const std::string& what) {
  throw InputError(source + ": " + element + ": " + what);
}

Vector3d vec(const urdf::Vector3& v) { return {v.x, v.y, v.z}; }

Isometry3d pose(const urdf::Pose& p) {
  Isometry3d X = Isometry3d::Identity();
  X.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  X.translation() = vec(p.position);
  return X;
}

bool moves(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
         j.type == urdf::Joint::PRISMATIC;
}

// The joint's own motion at position q (child frame relative to the joint
// frame). Frozen floating and planar joints sit at their origin.
Isometry3d motion(const urdf::Joint& j, double q) {
  Isometry3d X = Isometry3d::Identity();
  const Vector3d a = vec(j.axis).normalized();
  if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
    X.linear() = Eigen::AngleAxisd(q, a).toRotationMatrix();
  else if (j.type == urdf::Joint::PRISMATIC)
    X.translation() = q * a;
  return X;
}

bool finite_pose(const urdf::Pose& p) {
  return std::isfinite(p.position.x) && std::isfinite(p.position.y) &&
         std::isfinite(p.position.z) && std::isfinite(p.rotation.x) &&
         std::isfinite(p.rotation.y) && std::isfinite(p.rotation.z) && std::isfinite(p.rotation.w);
}

// Relative tolerance of the inertia checks, against the largest principal
// moment. URDF files write inertias with 6 or so significant digits
// (CAD exports, xacro arithmetic): each entry then carries a rounding error
// up to 5e-6 of the largest, and the principal moments move by at most the
// 2-norm of that 3 x 3 error, <= 3 * 5e-6 = 1.5e-5 of the largest; a sum of
// two of them (the triangle inequality) up to 3e-5. 1e-4 leaves a margin of
// 3 over that while anything physical is refused: a negative moment or a
// violated triangle of a real body is off by a sizeable fraction.
constexpr double kInertiaTolerance = 1e-4;

// The principal moments (ascending) after balance_inertia's repair: each
// negative moment set to 0, then, if I1 + I2 < I3, I1 and I2 each raised by
// half the deficit d = I3 - I1 - I2. Why that change: a body's principal
// moments are I1 = s2 + s3, I2 = s1 + s3, I3 = s1 + s2 with s_k = sum m x_k^2
// its second moments of mass along the principal axes, all >= 0 for a real
// body. The triangle inequality is s3 = (I1 + I2 - I3) / 2 >= 0; the repair
// sets the negative s3 to 0 (a body flat across the third axis) and keeps
// s1 and s2, so I3 = s1 + s2 is kept and I1, I2 rise by -s3 = d / 2 each.
// MuJoCo's balanceinertia sets all three to their mean instead (a sphere), a
// change of order I3 however small the violation. Moments that are equal
// stay equal, so the result does not depend on the axes chosen in a
// degenerate eigenspace.
Vector3d balanced_moments(Vector3d p) {
  p = p.cwiseMax(0.0);
  const double d = p(2) - p(0) - p(1);
  if (d > 0.0) {
    p(0) += 0.5 * d;
    p(1) += 0.5 * d;
  }
  return p;
}

// An <inertia> (about the centre of mass) of a rigid body: its principal
// moments I1 <= I2 <= I3 are >= 0 (positive semi-definite) and satisfy the
// triangle inequality I1 + I2 >= I3 (I1 + I2 - I3 = 2 sum m z^2 over the
// body along the third axis), both to kInertiaTolerance * I3. Every link
// is checked, simulated or not, as masses are: a frozen or fixed link's
// inertia enters the composite body of the joint that carries it.
// A tensor that fails is refused, or with `balance` repaired in place
// (balanced_moments; principal axes and mass kept): the note on the repair
// is returned ("" when the tensor was valid). This is the one place
// inertias are checked and repaired.
std::string check_inertia(urdf::Inertial& in, bool balance, const std::string& source,
                          const std::string& el) {
  Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  const Eigen::SelfAdjointEigenSolver<Matrix3d> es(I);
  const Vector3d p = es.eigenvalues();
  const double tol = kInertiaTolerance * std::max(std::abs(p(0)), std::abs(p(2)));
  // The moments are computed, not read: 6 significant digits (the file's
  // own values are in `got`, exactly).
  const auto three = [&](const Vector3d& v) { return number_list(v, 6); };
  std::string problem, why;
  if (p(0) < -tol) {
    problem =
        "not positive semi-definite: principal moments " + three(p) + " (kg m^2), a negative one";
    why = "a negative moment";
  } else if (p(0) + p(1) < p(2) - tol) {
    problem = "principal moments " + three(p) + " break the triangle inequality (" +
              short_number(p(0)) + " + " + short_number(p(1)) + " < " + short_number(p(2)) +
              "): no rigid body has them";
    why = "the triangle inequality broken";
  }
  if (problem.empty()) return "";
  const std::string got = "(got ixx=" + format_number(in.ixx) + ", ixy=" + format_number(in.ixy) +
                          ", ixz=" + format_number(in.ixz) + ", iyy=" + format_number(in.iyy) +
                          ", iyz=" + format_number(in.iyz) + ", izz=" + format_number(in.izz) + ")";
  if (!balance)
    fail(source, el,
         problem + " " + got +
             "; write balance_inertia: true in the scene to repair it (like MuJoCo's "
             "balanceinertia, by a smaller change: docs/model-format.md)");
  const Vector3d q = balanced_moments(p);
  const Matrix3d& R = es.eigenvectors();
  const Matrix3d J = R * q.asDiagonal() * R.transpose();
  in.ixx = J(0, 0);
  in.iyy = J(1, 1);
  in.izz = J(2, 2);
  in.ixy = 0.5 * (J(0, 1) + J(1, 0));
  in.ixz = 0.5 * (J(0, 2) + J(2, 0));
  in.iyz = 0.5 * (J(1, 2) + J(2, 1));
  return source + ": " + el + ": repaired (balance_inertia: " + why + "): principal moments " +
         three(p) + " -> " + three(q) + " kg m^2 (principal axes and mass kept)";
}

// The joints form a tree.
void check_tree(const urdf::ModelInterface& m, const std::string& source) {
  // urdfdom accepts a joint whose parent is its own child (it only looks for
  // a root): the link then lists itself among its children and every walk
  // down the tree recurses for ever. Refuse it, and any link reached twice.
  for (const auto& [name, joint] : m.joints_)
    if (joint->parent_link_name == joint->child_link_name)
      fail(source, "joint '" + name + "'",
           "parent and child are the same link '" + joint->parent_link_name +
               "' (the joints must form a tree)");
  if (const auto root = m.getRoot()) {
    std::set<const urdf::Link*> seen;
    std::vector<const urdf::Link*> todo{root.get()};
    while (!todo.empty()) {
      const urdf::Link* l = todo.back();
      todo.pop_back();
      if (!seen.insert(l).second)
        fail(source, "link '" + l->name + "'",
             "reached twice from the root (the joints must form a tree)");
      for (const auto& c : l->child_links) todo.push_back(c.get());
    }
  }
}

// Every <inertial>: finite, mass >= 0, a tensor some rigid body has (or
// repaired when repairs.balance_inertia, noted in repairs.notes).
void check_links(urdf::ModelInterface& m, const std::string& source, UrdfRepairs& repairs) {
  for (const auto& [name, link] : m.links_) {
    if (!link->inertial) continue;
    urdf::Inertial& in = *link->inertial;
    const std::string el = "link '" + name + "': <inertial>";
    if (!finite_pose(in.origin)) fail(source, el + " <origin>", "not finite");
    if (!std::isfinite(in.mass) || in.mass < 0.0)
      fail(source, el + " <mass value>",
           "must be finite and >= 0 (got " + format_number(in.mass) + ")");
    for (double x : {in.ixx, in.ixy, in.ixz, in.iyy, in.iyz, in.izz})
      if (!std::isfinite(x))
        fail(source, el + " <inertia>", "not finite (got " + format_number(x) + ")");
    if (std::string note = check_inertia(in, repairs.balance_inertia, source, el + " <inertia>");
        !note.empty())
      repairs.notes.push_back(one_line(note));
  }
}

// Joint `name`: finite <origin>, a non-zero <axis> if it moves, finite
// <limit>, <mimic> and <dynamics damping> >= 0.
void check_joint(const std::string& name, const urdf::Joint& j, const std::string& source) {
  const std::string el = "joint '" + name + "'";
  if (!finite_pose(j.parent_to_joint_origin_transform))
    fail(source, el + ": <origin>", "not finite");
  const Vector3d a = vec(j.axis);
  if (moves(j) && (!a.allFinite() || a.norm() == 0.0))
    fail(source, el + ": <axis xyz>",
         "must be finite and non-zero (got " + format_number(a.x()) + " " + format_number(a.y()) +
             " " + format_number(a.z()) + ")");
  if (j.limits) {
    const urdf::JointLimits& l = *j.limits;
    if (!std::isfinite(l.lower) || !std::isfinite(l.upper))
      fail(source, el + ": <limit>",
           "lower and upper must be finite (got lower=" + format_number(l.lower) +
               ", upper=" + format_number(l.upper) + ")");
    // lower > upper (Bullet's data files use it for "no limit") is refused
    // only where the limit becomes a stop (scene_stops.cpp): a frozen joint's
    // limits are never used.
  }
  if (j.mimic && (!std::isfinite(j.mimic->multiplier) || !std::isfinite(j.mimic->offset)))
    fail(source, el + ": <mimic>",
         "multiplier and offset must be finite (got multiplier=" +
             format_number(j.mimic->multiplier) + ", offset=" + format_number(j.mimic->offset) +
             ")");
  if (j.dynamics) {
    const double d = j.dynamics->damping;
    if (!std::isfinite(d) || d < 0.0)
      fail(source, el + ": <dynamics damping>",
           "must be finite and >= 0 (got " + format_number(d) + ")");
  }
}

// Checks what lcsim relies on (parse_urdf); inertias are repaired in `m`
// instead of refused when repairs.balance_inertia, noted in repairs.notes.
void check_urdf(urdf::ModelInterface& m, const std::string& source, UrdfRepairs& repairs) {
  check_tree(m, source);
  check_links(m, source, repairs);
  for (const auto& [name, joint] : m.joints_) check_joint(name, *joint, source);
  (void)mimic_joints(m, source);  // every leader exists, has a position, no cycles
}

// The scene's tree. Its moving joints are the simulated joints (coordinate
// order) and then the mimic joints that follow them; joint velocities are
// T times the coordinate velocities (T = [1; rows with the mimics'
// multipliers]), so M = T' M_moving T and tau = T' tau_moving: the mimics'
// motion enters every body's Jacobian. Each link is owned by the moving
// joint that moves it as a rigid part of its body (-1: the world).
struct Tree {
  const urdf::ModelInterface& model;
  std::vector<std::string> joints;      // moving joints: simulated, then their mimics
  std::size_t n = 0;                    // coordinates (simulated joints)
  std::vector<int> coord;               // coordinate of each moving joint
  MatrixXd T;                           // moving joint velocities = T * coordinate velocities
  std::map<std::string, int> index;     // moving joint -> its position in `joints`
  std::vector<int> parent;              // parent moving joint of each (-1: world)
  std::map<std::string, int> owner;     // link -> moving joint moving it rigidly
  std::vector<std::string> link_order;  // root first (depth first)
  std::map<std::string, Mimic> mimics;  // every mimic joint of the URDF, resolved
  BasePose base;                        // where the root sits
  std::size_t nb = 0;                   // a floating base's coordinates (0 or 6), first in joints
};

Tree make_tree(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
               const std::string& source, const BasePose& base) {
  Tree t{model, base_coordinates(base),
         0,     {},
         {},    {},
         {},    {},
         {},    mimic_joints(model, source, joints),
         base,  0};
  if (!model.getRoot()) fail(source, "<robot>", "no root link");
  t.nb = t.joints.size();
  for (std::size_t i = 0; i < t.nb; ++i) {
    t.index[t.joints[i]] = static_cast<int>(i);
    t.coord.push_back(static_cast<int>(i));
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const auto j = model.getJoint(joints[i]);
    if (!j) fail(source, "joint '" + joints[i] + "'", "no such joint in the URDF");
    if (!moves(*j))
      fail(source, "joint '" + joints[i] + "'",
           "unsupported type for a simulated joint (only revolute, continuous and prismatic "
           "joints can be simulated; freeze it by leaving it out of the scene)");
    t.index[joints[i]] = static_cast<int>(t.joints.size());
    t.coord.push_back(static_cast<int>(t.joints.size()));
    t.joints.push_back(joints[i]);
  }
  t.n = t.joints.size();
  std::vector<std::pair<int, double>> follow;  // (coordinate, multiplier) of each mimic
  for (const auto& [name, mm] : t.mimics) {
    const auto it = t.index.find(mm.leader);
    if (it == t.index.end() || it->second >= static_cast<int>(t.n)) continue;
    t.index[name] = static_cast<int>(t.joints.size());
    t.joints.push_back(name);
    t.coord.push_back(it->second);
    follow.emplace_back(it->second, mm.multiplier);
  }
  const auto n = static_cast<Eigen::Index>(t.n);
  t.T = MatrixXd::Zero(static_cast<Eigen::Index>(t.joints.size()), n);
  t.T.topRows(n).setIdentity();
  for (std::size_t k = 0; k < follow.size(); ++k)
    t.T(n + static_cast<Eigen::Index>(k), follow[k].first) = follow[k].second;
  t.parent.assign(t.joints.size(), -1);
  for (std::size_t k = 1; k < t.nb; ++k) t.parent[k] = static_cast<int>(k - 1);  // x, y, ... rz
  std::function<void(const urdf::Link&, int)> walk = [&](const urdf::Link& link, int owner) {
    t.owner[link.name] = owner;
    t.link_order.push_back(link.name);
    for (const auto& cj : link.child_joints) {
      int child_owner = owner;
      const auto it = t.index.find(cj->name);
      if (it != t.index.end()) {
        t.parent[static_cast<std::size_t>(it->second)] = owner;
        child_owner = it->second;
      }
      walk(*model.getLink(cj->child_link_name), child_owner);
    }
  };
  walk(*model.getRoot(), static_cast<int>(t.nb) - 1);  // the root: the base's last (or the world)
  return t;
}

// The configuration at coordinates q: every joint position (the simulated
// joints from q, the frozen ones from q0 (0 if absent), each mimic from its
// leader) and the root's world pose.
struct Config {
  std::map<std::string, double> q;  // joint positions by name
  Isometry3d root;                  // world pose of the root link
  Vector3d rot = Vector3d::Zero();  // a floating base's rotation vector (rad)
};

Config positions(const Tree& t, const std::map<std::string, double>& q0, const VectorXd& q) {
  Config c{q0, t.base.pose};
  for (std::size_t i = t.nb; i < t.n; ++i) c.q[t.joints[i]] = q(static_cast<Eigen::Index>(i));
  for (const auto& [name, mm] : t.mimics) {
    const auto it = c.q.find(mm.leader);
    c.q[name] = mm.multiplier * (it == c.q.end() ? 0.0 : it->second) + mm.offset;
  }
  if (t.nb > 0) {
    c.rot = q.segment<3>(3);
    c.root.linear() = exp_so3(c.rot) * t.base.pose.linear();
    c.root.translation() = q.head<3>();
  }
  return c;
}

// World pose of every link with simulated and frozen joints at q (by name).
std::map<std::string, Isometry3d> link_poses(const Tree& t, const Config& c) {
  const std::map<std::string, double>& q = c.q;
  std::map<std::string, Isometry3d> X;
  X[t.model.getRoot()->name] = c.root;
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    for (const auto& cj : link->child_joints) {
      const auto qi = q.find(cj->name);
      X[cj->child_link_name] = X[name] * pose(cj->parent_to_joint_origin_transform) *
                               motion(*cj, qi == q.end() ? 0.0 : qi->second);
    }
  }
  return X;
}

// Each link's step from its parent for link_pose, precomputed so that one
// link's pose is the products along its path alone: link_poses' products
// in the same order (so the same numbers) without the poses of every other
// link, and without a name looked up (link_pose is called per contact and
// per probe by the contact ranges, on trees of up to a hundred links).
struct LinkStep {
  int parent = -1;                             // its parent link's step (-1: the root)
  const urdf::Joint* joint = nullptr;          // the joint from the parent (none at the root)
  Isometry3d origin = Isometry3d::Identity();  // pose(parent_to_joint_origin_transform)
  // Its position as positions() sets it: a simulated joint's coordinate or a
  // frozen joint's q0 (0 if absent); a mimic's multiplier * that of its
  // leader (simulated or frozen, never a mimic: mimic_joints resolves
  // chains) + offset.
  int coordinate = -1;  // the coordinate read (its own or its leader's), -1: frozen
  double frozen = 0.0;  // the q0 read when frozen
  bool mimic = false;
  double multiplier = 1.0, offset = 0.0;
  double position(const VectorXd& q) const {
    const double own = coordinate >= 0 ? q(coordinate) : frozen;
    return mimic ? multiplier * own + offset : own;
  }
};
struct LinkSteps {
  std::vector<LinkStep> steps;
  std::map<std::string, int> index;  // link name -> its step
};

LinkSteps link_steps(const Tree& t, const std::map<std::string, double>& q0) {
  const auto read = [&](LinkStep& s, const std::string& name) {
    const auto i = t.index.find(name);
    if (i != t.index.end() && i->second >= static_cast<int>(t.nb) &&
        i->second < static_cast<int>(t.n)) {
      s.coordinate = i->second;
      return;
    }
    const auto it = q0.find(name);
    s.frozen = it == q0.end() ? 0.0 : it->second;
  };
  LinkSteps out;
  for (const auto& name : t.link_order) {  // root first: a parent before its children
    LinkStep s;
    const auto link = t.model.getLink(name);
    if (const auto& j = link->parent_joint) {
      s.parent = out.index.at(j->parent_link_name);
      s.joint = j.get();
      s.origin = pose(j->parent_to_joint_origin_transform);
      const auto m = t.mimics.find(j->name);
      s.mimic = m != t.mimics.end();
      if (s.mimic) s.multiplier = m->second.multiplier, s.offset = m->second.offset;
      read(s, s.mimic ? m->second.leader : j->name);
    }
    out.index[name] = static_cast<int>(out.steps.size());
    out.steps.push_back(s);
  }
  return out;
}

// World pose of one link at q (root: as positions() places it).
Isometry3d path_pose(const Tree& t, const LinkSteps& k, const VectorXd& q, int link) {
  std::vector<int> path;  // from the link up to the root's child
  for (int l = link; k.steps[static_cast<std::size_t>(l)].parent >= 0;
       l = k.steps[static_cast<std::size_t>(l)].parent)
    path.push_back(l);
  Isometry3d X = t.base.pose;
  if (t.nb > 0) {
    X.linear() = exp_so3(q.segment<3>(3)) * t.base.pose.linear();
    X.translation() = q.head<3>();
  }
  for (auto l = path.rbegin(); l != path.rend(); ++l) {
    const LinkStep& s = k.steps[static_cast<std::size_t>(*l)];
    X = X * s.origin * motion(*s.joint, s.position(q));
  }
  return X;
}

// Motion subspace of moving joint i in world coordinates. A floating
// base's translations move the root along the world axes; its rotation
// coordinate k turns the tree about the root's origin p with angular
// velocity J_l(r) e_k (so v0 = p x omega, as for a revolute joint at p).
Vector6d subspace(const Tree& t, std::size_t i, const std::map<std::string, Isometry3d>& X,
                  const Config& c) {
  Vector6d S;
  if (i < t.nb) {
    if (i < 3) {
      S << Vector3d::Zero(), Vector3d::Unit(static_cast<Eigen::Index>(i));
    } else {
      const Vector3d w = left_jacobian(c.rot).col(static_cast<Eigen::Index>(i - 3));
      S << w, c.root.translation().cross(w);
    }
    return S;
  }
  const auto j = t.model.getJoint(t.joints[i]);
  const Isometry3d& Xc = X.at(j->child_link_name);  // joint frame after its motion
  const Vector3d a = Xc.linear() * vec(j->axis).normalized();
  if (j->type == urdf::Joint::PRISMATIC)
    S << Vector3d::Zero(), a;
  else
    S << a, Xc.translation().cross(a);
  return S;
}

struct LinkInertia {
  double m;
  Vector3d c;   // world centre of mass
  Matrix3d Ic;  // about c, world axes
};

LinkInertia link_inertia(const urdf::Link& link, const Isometry3d& X) {
  const urdf::Inertial& in = *link.inertial;
  const Isometry3d Xi = X * pose(in.origin);
  Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  return {in.mass, Xi.translation(), Xi.linear() * I * Xi.linear().transpose()};
}

Matrix6d spatial(const LinkInertia& b) {
  const Matrix3d C = skew(b.c);
  Matrix6d I;
  I << b.Ic + b.m * C * C.transpose(), b.m * C, b.m * C.transpose(), b.m * Matrix3d::Identity();
  return I;
}

// Calls f(i) for coordinate `o` and each of its ancestors.
template <class F>
void up(const Tree& t, int o, F f) {
  for (int b = o; b >= 0; b = t.parent[static_cast<std::size_t>(b)]) f(b);
}

MatrixXd crba(const Tree& t, const Config& q) {
  const auto X = link_poses(t, q);
  const auto n = static_cast<Eigen::Index>(t.joints.size());
  std::vector<Matrix6d> Ic(t.joints.size(), Matrix6d::Zero());
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    const int o = t.owner.at(name);
    if (o < 0 || !link->inertial) continue;
    const Matrix6d I = spatial(link_inertia(*link, X.at(name)));
    up(t, o, [&](int b) { Ic[static_cast<std::size_t>(b)] += I; });
  }
  std::vector<Vector6d> S;
  for (std::size_t i = 0; i < t.joints.size(); ++i) S.push_back(subspace(t, i, X, q));
  MatrixXd M = MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    const Vector6d F = Ic[ui] * S[ui];
    up(t, static_cast<int>(i),
       [&](int j) { M(i, j) = M(j, i) = S[static_cast<std::size_t>(j)].dot(F); });
  }
  return t.T.transpose() * M * t.T;
}

// tau_g,i = S_i . (sum of the gravity wrenches (c x m g, m g) of the bodies
// joint i moves).
VectorXd gravity_force(const Tree& t, const Config& q, const Vector3d& gravity) {
  const auto X = link_poses(t, q);
  std::vector<Vector6d> F(t.joints.size(), Vector6d::Zero());
  for (const auto& name : t.link_order) {
    const auto link = t.model.getLink(name);
    const int o = t.owner.at(name);
    if (o < 0 || !link->inertial) continue;
    const LinkInertia b = link_inertia(*link, X.at(name));
    Vector6d w;
    w << b.c.cross(b.m * gravity), b.m * gravity;
    up(t, o, [&](int k) { F[static_cast<std::size_t>(k)] += w; });
  }
  VectorXd tau(static_cast<Eigen::Index>(t.joints.size()));
  for (std::size_t i = 0; i < t.joints.size(); ++i)
    tau(static_cast<Eigen::Index>(i)) = subspace(t, i, X, q).dot(F[i]);
  return t.T.transpose() * tau;
}

// Collects urdfdom's messages (sent through console_bridge) while it
// parses, so that the InputError can quote its errors: they name the element.
// Installed for the duration of one parse; console_bridge's handler is
// process-global, so parsing is not thread-safe (neither is urdfdom's log).
class CapturedLog : public console_bridge::OutputHandler {
 public:
  CapturedLog() { console_bridge::useOutputHandler(this); }
  ~CapturedLog() override { console_bridge::restorePreviousOutputHandler(); }
  CapturedLog(const CapturedLog&) = delete;
  CapturedLog& operator=(const CapturedLog&) = delete;
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level < console_bridge::CONSOLE_BRIDGE_LOG_ERROR) return;
    std::string t = text;
    while (!t.empty() && (t.back() == '\n' || t.back() == ' ' || t.back() == '.')) t.pop_back();
    if (!t.empty()) text_ += (text_.empty() ? "" : "; ") + t;
  }
  const std::string& text() const { return text_; }

 private:
  std::string text_;
};

}  // namespace

namespace {
// Every error of the URDF path is one line: names and values in a URDF may
// hold newlines (found by fuzz_scene), so the public entry points fold them.
template <class F>
auto one_line_errors(F&& f) {
  try {
    return f();
  } catch (const InputError& e) {
    throw InputError(one_line(e.what()));
  }
}
}  // namespace

static std::shared_ptr<urdf::ModelInterface> parse_urdf_unfolded(const std::string& xml,
                                                                 const std::string& source,
                                                                 UrdfRepairs& repairs) {
  urdf::ModelInterfaceSharedPtr m;
  std::string log;
  try {
    const CapturedLog capture;
    try {
      m = urdf::parseURDF(without_geometry(xml));
    } catch (const std::exception& e) {
      throw InputError(source + ": not a valid URDF: " + one_line(e.what()));
    }
    log = capture.text();
  } catch (const InputError&) {
    throw;
  }
  // urdfdom reports some bad elements (e.g. a non-numeric <mass value>) as
  // errors but goes on without them: refuse those as well.
  if (!m || !log.empty())
    throw InputError(source + ": not a valid URDF: " +
                     one_line(log.empty() ? std::string("urdfdom refused it") : log));
  check_urdf(*m, source, repairs);
  return m;
}

std::shared_ptr<urdf::ModelInterface> load_urdf(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw InputError(path.string() + ": cannot open URDF: no such file");
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path.string() + ": cannot open URDF: unreadable");
  std::ostringstream ss;
  ss << in.rdbuf();
  return parse_urdf(ss.str(), path.string());
}

std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml,
                                                 const std::string& source) {
  UrdfRepairs none;
  return parse_urdf(xml, source, none);
}

std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source,
                                                 UrdfRepairs& repairs) {
  return one_line_errors([&] { return parse_urdf_unfolded(xml, source, repairs); });
}

std::map<std::string, Mimic> mimic_joints(const urdf::ModelInterface& model,
                                          const std::string& source,
                                          const std::vector<std::string>& simulated) {
  const auto is_simulated = [&](const std::string& n) {
    return std::find(simulated.begin(), simulated.end(), n) != simulated.end();
  };
  std::map<std::string, Mimic> out;
  for (const auto& [name, joint] : model.joints_) {
    if (!joint->mimic || !moves(*joint) || is_simulated(name)) continue;
    Mimic mm{name, 1.0, 0.0};
    std::vector<std::string> chain{name};
    for (std::shared_ptr<const urdf::Joint> j = joint;
         j->mimic && (j == joint || !is_simulated(j->name));) {
      const std::string el =
          "joint '" + j->name + "': <mimic joint='" + j->mimic->joint_name + "'>";
      const auto leader = model.getJoint(j->mimic->joint_name);
      if (!leader) fail(source, el, "no joint '" + j->mimic->joint_name + "' in the URDF");
      if (!moves(*leader))
        fail(source, el,
             "joint '" + leader->name +
                 "' has no position to follow (only revolute, continuous and prismatic joints)");
      // q_m = a q_j + b and q_j = a' q_leader + b'  =>  q_m = a a' q_leader + (a b' + b)
      mm.offset += mm.multiplier * j->mimic->offset;
      mm.multiplier *= j->mimic->multiplier;
      mm.leader = leader->name;
      if (std::count(chain.begin(), chain.end(), leader->name)) {
        std::string c;
        for (const auto& x : chain) c += x + " -> ";
        fail(source, "joint '" + name + "': <mimic>", "a cycle of mimics: " + c + leader->name);
      }
      chain.push_back(leader->name);
      j = leader;
    }
    out[name] = mm;
  }
  return out;
}

struct UrdfDynamics::Impl {
  Tree tree;
  std::map<std::string, double> q0;
  Eigen::Vector3d gravity;
  LinkSteps steps;
};

static std::shared_ptr<const UrdfDynamics::Impl> make_dynamics(
    const urdf::ModelInterface& model, const std::vector<std::string>& joints,
    const std::map<std::string, double>& q0, const Eigen::Vector3d& gravity,
    const std::string& source, const BasePose& base) {
  Tree t = make_tree(model, joints, source, base);
  // A simulated joint must move some mass: the links it carries (its child
  // link, the links fixed or frozen to it, those its mimics move, and
  // everything below them, simulated or not) need an <inertial> with mass
  // > 0. A massless link between two simulated joints (a hip or shoulder
  // written as chained revolute joints) is fine: the joint above still
  // moves the limb below it.
  std::vector<double> moved(t.n, 0.0);
  for (const auto& [name, o] : t.owner) {
    const auto link = model.getLink(name);
    if (o < 0 || !link->inertial) continue;
    std::set<int> coords;  // each coordinate once, even if it and a mimic both carry the link
    up(t, o, [&](int b) { coords.insert(t.coord[static_cast<std::size_t>(b)]); });
    for (int c : coords) moved[static_cast<std::size_t>(c)] += link->inertial->mass;
  }
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const double mass = moved[t.nb + i];
    if (!(mass > 0.0))
      fail(
          source, "link '" + model.getJoint(joints[i])->child_link_name + "'",
          "moved by joint '" + joints[i] +
              "' but it (with every link fixed, frozen or jointed below it) has no <inertial> mass "
              "(got total mass " +
              format_number(mass) + ")");
  }
  LinkSteps steps = link_steps(t, q0);
  return std::make_shared<const UrdfDynamics::Impl>(
      UrdfDynamics::Impl{std::move(t), q0, gravity, std::move(steps)});
}

UrdfDynamics::UrdfDynamics(const urdf::ModelInterface& model,
                           const std::vector<std::string>& joints,
                           const std::map<std::string, double>& q0, const Eigen::Vector3d& gravity,
                           const std::string& source, const BasePose& base)
    : impl_(one_line_errors(
          [&] { return make_dynamics(model, joints, q0, gravity, source, base); })) {
  joints_.assign(impl_->tree.joints.begin(),
                 impl_->tree.joints.begin() + static_cast<std::ptrdiff_t>(impl_->tree.n));
}

std::vector<std::string> base_coordinates(const BasePose& base) {
  if (!base.floating) return {};
  std::vector<std::string> out;
  for (const char* c : {"x", "y", "z", "rx", "ry", "rz"}) out.push_back(base.name + "." + c);
  return out;
}

VectorXd UrdfDynamics::reference() const {
  VectorXd q(static_cast<Eigen::Index>(joints_.size()));
  const std::size_t nb = impl_->tree.nb;
  for (std::size_t i = 0; i < nb; ++i)  // the base at its reference pose: (p0, 0)
    q(static_cast<Eigen::Index>(i)) =
        i < 3 ? impl_->tree.base.pose.translation()(static_cast<Eigen::Index>(i)) : 0.0;
  for (std::size_t i = nb; i < joints_.size(); ++i) {
    const auto it = impl_->q0.find(joints_[i]);
    q(static_cast<Eigen::Index>(i)) = it == impl_->q0.end() ? 0.0 : it->second;
  }
  return q;
}

MatrixXd UrdfDynamics::mass_matrix(const VectorXd& q) const {
  return crba(impl_->tree, positions(impl_->tree, impl_->q0, q));
}

VectorXd UrdfDynamics::gravity_force(const VectorXd& q) const {
  return scene::gravity_force(impl_->tree, positions(impl_->tree, impl_->q0, q), impl_->gravity);
}

VectorXd UrdfDynamics::damping() const {
  // A mimic's damper acts through its leader: d_J + sum a_m^2 d_m (T' D T).
  const Tree& t = impl_->tree;
  VectorXd d = VectorXd::Zero(static_cast<Eigen::Index>(t.joints.size()));
  for (std::size_t i = t.nb; i < t.joints.size(); ++i) {  // the base has no damper
    const auto j = t.model.getJoint(t.joints[i]);
    if (j->dynamics) d(static_cast<Eigen::Index>(i)) = j->dynamics->damping;
  }
  return (t.T.transpose() * d.asDiagonal() * t.T).diagonal();
}

Eigen::Isometry3d UrdfDynamics::link_pose(const std::string& link, const VectorXd& q) const {
  const Tree& t = impl_->tree;
  if (!t.owner.count(link)) throw InputError("no link '" + link + "' in the URDF");
  return path_pose(t, impl_->steps, q, impl_->steps.index.at(link));
}

Eigen::Matrix3Xd UrdfDynamics::point_jacobian(const std::string& link, const Eigen::Vector3d& local,
                                              const VectorXd& q) const {
  const Tree& t = impl_->tree;
  if (!t.owner.count(link)) throw InputError("no link '" + link + "' in the URDF");
  const Config c = positions(t, impl_->q0, q);
  const auto X = link_poses(t, c);
  const Vector3d w = X.at(link) * local;
  // Moving joint b turns with omega and moves the world origin's point
  // with v0: the point w moves with v0 + omega x w.
  Eigen::Matrix3Xd J = Eigen::Matrix3Xd::Zero(3, static_cast<Eigen::Index>(t.joints.size()));
  up(t, t.owner.at(link), [&](int b) {
    const Vector6d S = subspace(t, static_cast<std::size_t>(b), X, c);
    J.col(b) = S.tail<3>() + S.head<3>().cross(w);
  });
  return J * t.T;
}

UrdfLinearisation linearise_urdf(const urdf::ModelInterface& model,
                                 const std::vector<std::string>& joints,
                                 const std::map<std::string, double>& q0,
                                 const Eigen::Vector3d& gravity, const std::string& source,
                                 const BasePose& base) {
  const UrdfDynamics dyn(model, joints, q0, gravity, source, base);
  const VectorXd q = dyn.reference();
  UrdfLinearisation lin;
  lin.joints = dyn.joints();
  lin.M = dyn.mass_matrix(q);
  lin.tau_g = dyn.gravity_force(q);
  // Gravity stiffness by central differences: tau_g is a sum of products of
  // sines and cosines (revolute) and polynomials of degree <= 1 (prismatic)
  // of q, so the error is h^2/6 |tau'''| (truncation) + eps |tau| / h
  // (rounding). h = 6e-6 ~ eps^(1/3) balances them: both are about 1e-11
  // relative to the scale of tau_g (|tau'''| ~ |tau| for lever arms ~1 m;
  // h is absolute, in rad or m). The result is symmetrised (it is minus the
  // Hessian of the potential energy), which does not increase that error.
  const double h = 6e-6;
  const auto n = q.size();
  lin.K_g = MatrixXd::Zero(n, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    VectorXd qp = q, qm = q;
    qp(j) += h;
    qm(j) -= h;
    lin.K_g.col(j) = -(dyn.gravity_force(qp) - dyn.gravity_force(qm)) / (2 * h);
  }
  lin.K_g = (0.5 * (lin.K_g + lin.K_g.transpose())).eval();
  lin.damping = dyn.damping();
  return lin;
}

}  // namespace lcsim::scene
