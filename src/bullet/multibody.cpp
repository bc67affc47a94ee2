// A Bullet Featherstone btMultiBody built from a URDF, used to cross-check the
// composite-rigid-body mass matrix of src/scene. Deliberately independent of
// src/scene's kinematics: link poses, the merging of frozen links and the
// principal axes are computed here with Bullet's own types.
#include <BulletDynamics/Featherstone/btMultiBody.h>
#include <BulletDynamics/Featherstone/btMultiBodyLink.h>
#include <urdf_model/model.h>

#include <algorithm>
#include <functional>
#include <lcsim/bullet/bullet.hpp>
#include <memory>
#include <stdexcept>

#include "bullet/urdf_multibody.hpp"

namespace lcsim::bullet {

namespace {

btTransform to_bt(const urdf::Pose& p) {
  return btTransform(btQuaternion(p.rotation.x, p.rotation.y, p.rotation.z, p.rotation.w),
                     btVector3(p.position.x, p.position.y, p.position.z));
}

btVector3 to_bt(const urdf::Vector3& v) { return btVector3(v.x, v.y, v.z); }

// The joint's own motion at q; frozen joints only (simulated ones are built
// at q = 0 and then set by btMultiBody::setJointPos).
btTransform frozen_motion(const urdf::Joint& j, double q) {
  const btVector3 a = to_bt(j.axis).normalized();
  if (j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS)
    return btTransform(btQuaternion(a, q), btVector3(0, 0, 0));
  if (j.type == urdf::Joint::PRISMATIC) return btTransform(btQuaternion::getIdentity(), q * a);
  return btTransform::getIdentity();
}

struct Body {
  std::string joint;  // simulated joint whose child this body is
  int parent = -1;    // Bullet link index of the parent body (-1: the base)
  double mass = 0.0;
  btVector3 com{0, 0, 0};  // world, at the build configuration
  btMatrix3x3 inertia;     // about com, world axes
  btTransform com_frame;   // world pose of the principal-axes frame at com
  btVector3 principal{0, 0, 0};
  double speck = 0.0;  // > 0: a massless body's stand-in inertia (give_massless_bodies_a_speck)
};

// Turns the summed mass moments of each body into its centre of mass. A
// body whose links carry no mass (a link without <inertial> between two
// simulated joints, e.g. the yoke of a universal joint) is massless in
// lcsim's model, where it contributes nothing to M (io counts the mass
// below a joint). btMultiBody cannot take a zero mass (its centre of mass
// divides by it, its articulated inertia must be positive), so such a body
// gets a speck: a mass 1e-9 times the total at its pivot, with an isotropic
// inertia 1e-9 times the largest link inertia. At the pivot the speck adds no
// torque about its own joint, and it changes M and the gravity torques by
// ~1e-9 relative, far below Bullet's O(h) step error: the dynamics stay
// lcsim's. std::invalid_argument naming the link when no body has mass.
void give_massless_bodies_a_speck(const urdf::ModelInterface& model,
                                  std::map<std::string, btTransform>& X,
                                  std::vector<Body>& bodies) {
  double total = 0.0, inertia = 0.0;
  for (const auto& b : bodies) total += b.mass;
  for (const auto& [name, link] : model.links_)
    if (link->inertial)
      inertia = std::max({inertia, link->inertial->ixx, link->inertial->iyy, link->inertial->izz});
  for (auto& b : bodies) {
    if (b.mass > 0.0) {
      b.com /= b.mass;
      continue;
    }
    const auto j = model.getJoint(b.joint);
    if (!(total > 0.0))
      throw std::invalid_argument("link '" + j->child_link_name + "' (child of joint '" + b.joint +
                                  "') and every other simulated link have no mass");
    b.mass = 1e-9 * total;
    b.com = X[j->child_link_name].getOrigin();
    b.speck = 1e-9 * (inertia > 0.0 ? inertia : total);
  }
}

// A joint's position: q0, or for a mimic not in q0 a q_leader + b (the
// mimic of a simulated joint is frozen there: see warn_frozen_mimics).
double position_of(const urdf::ModelInterface& model, const std::map<std::string, double>& q0,
                   const std::string& name) {
  const auto it = q0.find(name);
  if (it != q0.end()) return it->second;
  const auto j = model.getJoint(name);
  if (j && j->mimic && j->type != urdf::Joint::FIXED)
    return j->mimic->multiplier * position_of(model, q0, j->mimic->joint_name) + j->mimic->offset;
  return 0.0;
}

// The index of joint `name` in `joints` (-1: frozen).
int simulated_index(const std::vector<std::string>& joints, const std::string& name) {
  for (std::size_t i = 0; i < joints.size(); ++i)
    if (joints[i] == name) return static_cast<int>(i);
  return -1;
}

// The URDF tree cut into bodies, one per simulated joint: world poses with
// simulated joints at 0 and frozen joints at q0, the body owning each link,
// and the bodies in depth-first order (Bullet wants parents before
// children).
struct Tree {
  std::map<std::string, btTransform> X;
  std::map<std::string, int> owner;  // link -> Bullet link index (-1: base)
  std::vector<Body> bodies;
  // The root link and every link frozen to it: Bullet's base. Its mass and
  // frame matter only for a floating base (merge_base); a fixed base's frame
  // is the root link's (com_frame stays the identity).
  Body base;
};

Tree cut_into_bodies(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
                     const std::map<std::string, double>& q0) {
  Tree t;
  std::function<void(const urdf::Link&, int)> walk = [&](const urdf::Link& link, int own) {
    t.owner[link.name] = own;
    for (const auto& cj : link.child_joints) {
      btTransform Xc = t.X[link.name] * to_bt(cj->parent_to_joint_origin_transform);
      int child_owner = own;
      if (simulated_index(joints, cj->name) >= 0) {
        Body b;
        b.joint = cj->name;
        b.parent = own;
        t.bodies.push_back(b);
        child_owner = static_cast<int>(t.bodies.size()) - 1;
      } else {
        Xc = Xc * frozen_motion(*cj, position_of(model, q0, cj->name));
      }
      t.X[cj->child_link_name] = Xc;
      walk(*model.getLink(cj->child_link_name), child_owner);
    }
  };
  t.X[model.getRoot()->name] = btTransform::getIdentity();
  walk(*model.getRoot(), -1);
  t.base.com_frame = btTransform::getIdentity();
  if (t.bodies.size() != joints.size())
    throw std::invalid_argument("bullet: a simulated joint is not in the URDF tree");
  return t;
}

// Each body's total mass and centre of mass (a massless one's speck).
void merge_masses(const urdf::ModelInterface& model, Tree& t) {
  for (const auto& [name, own] : t.owner) {
    const auto link = model.getLink(name);
    if (own < 0 || !link->inertial) continue;
    Body& b = t.bodies[static_cast<std::size_t>(own)];
    const btTransform Xi = t.X[name] * to_bt(link->inertial->origin);
    b.com += link->inertial->mass * Xi.getOrigin();
    b.mass += link->inertial->mass;
  }
  give_massless_bodies_a_speck(model, t.X, t.bodies);
}

// Adds a link's inertia (its <inertial> at world pose Xi) to body b, about
// b's centre of mass (parallel-axis theorem).
void add_inertia(Body& b, const btTransform& Xi, const urdf::Inertial& in) {
  const btMatrix3x3 I(in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz);
  const btMatrix3x3& R = Xi.getBasis();
  const btVector3 d = Xi.getOrigin() - b.com;
  const btMatrix3x3 parallel(d.dot(d) - d.x() * d.x(), -d.x() * d.y(), -d.x() * d.z(),
                             -d.y() * d.x(), d.dot(d) - d.y() * d.y(), -d.y() * d.z(),
                             -d.z() * d.x(), -d.z() * d.y(), d.dot(d) - d.z() * d.z());
  b.inertia = b.inertia + R * I * R.transpose() + parallel * in.mass;
}

// b's principal moments and its frame at the centre of mass in principal axes.
void principal_frame(Body& b) {
  btMatrix3x3 rot;
  btMatrix3x3 diag = b.inertia;
  diag.diagonalize(rot, 1e-15, 200);  // inertia = rot * diag * rot^T
  b.principal = btVector3(diag[0][0], diag[1][1], diag[2][2]);
  b.com_frame = btTransform(rot, b.com);
}

// Each body's inertia about its centre of mass (parallel-axis theorem), then
// its principal axes.
void merge_inertias(const urdf::ModelInterface& model, Tree& t) {
  for (auto& b : t.bodies) b.inertia.setValue(0, 0, 0, 0, 0, 0, 0, 0, 0);
  for (const auto& [name, own] : t.owner) {
    const auto link = model.getLink(name);
    if (own < 0 || !link->inertial) continue;
    Body& b = t.bodies[static_cast<std::size_t>(own)];
    add_inertia(b, t.X[name] * to_bt(link->inertial->origin), *link->inertial);
  }
  for (auto& b : t.bodies)
    if (b.speck > 0.0) b.inertia = b.inertia + btMatrix3x3::getIdentity() * b.speck;
  for (auto& b : t.bodies) principal_frame(b);
}

// A floating base: the root link and every link frozen to it, one rigid
// body at its centre of mass in principal axes (Bullet's base frame).
// std::invalid_argument when it has no mass.
void merge_base(const urdf::ModelInterface& model, Tree& t) {
  Body& b = t.base;
  b.inertia.setValue(0, 0, 0, 0, 0, 0, 0, 0, 0);
  for (const auto& [name, own] : t.owner) {
    const auto link = model.getLink(name);
    if (own >= 0 || !link->inertial) continue;
    b.com += link->inertial->mass * (t.X[name] * to_bt(link->inertial->origin)).getOrigin();
    b.mass += link->inertial->mass;
  }
  if (!(b.mass > 0.0))
    throw std::invalid_argument("bullet: the floating base's root link '" + model.getRoot()->name +
                                "' (with every link fixed or frozen to it) has no mass");
  b.com /= b.mass;
  for (const auto& [name, own] : t.owner) {
    const auto link = model.getLink(name);
    if (own >= 0 || !link->inertial) continue;
    add_inertia(b, t.X[name] * to_bt(link->inertial->origin), *link->inertial);
  }
  principal_frame(b);
}

// Bullet link i: body i on its joint (prismatic, else revolute), in its
// parent's principal frame.
void set_up_link(const urdf::ModelInterface& model, Tree& t, int i, btMultiBody& mb) {
  const Body& b = t.bodies[static_cast<std::size_t>(i)];
  const auto j = model.getJoint(b.joint);
  const btTransform parent_frame =
      b.parent < 0 ? t.base.com_frame : t.bodies[static_cast<std::size_t>(b.parent)].com_frame;
  const btMatrix3x3& Rp = parent_frame.getBasis();
  const btMatrix3x3& Rc = b.com_frame.getBasis();
  const btTransform& Xj = t.X[j->child_link_name];  // joint frame at q = 0
  const btVector3 pivot = Xj.getOrigin();
  const btVector3 axis = Rc.transpose() * (Xj.getBasis() * to_bt(j->axis).normalized());
  btQuaternion rot_parent_to_this;
  (Rc.transpose() * Rp).getRotation(rot_parent_to_this);
  const btVector3 parent_com_to_pivot = Rp.transpose() * (pivot - parent_frame.getOrigin());
  const btVector3 pivot_to_com = Rc.transpose() * (b.com - pivot);
  if (j->type == urdf::Joint::PRISMATIC)
    mb.setupPrismatic(i, b.mass, b.principal, b.parent, rot_parent_to_this, axis,
                      parent_com_to_pivot, pivot_to_com, true);
  else
    mb.setupRevolute(i, b.mass, b.principal, b.parent, rot_parent_to_this, axis,
                     parent_com_to_pivot, pivot_to_com, true);
}

}  // namespace

namespace {

btTransform to_bt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d R = X.linear();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      btVector3(X.translation().x(), X.translation().y(), X.translation().z()));
}

// Where each URDF link sits in its Bullet body's frame.
void record_links(const Tree& t, UrdfMultiBody& out) {
  for (const auto& [name, own] : t.owner) {
    const btTransform& body =
        own < 0 ? t.base.com_frame : t.bodies[static_cast<std::size_t>(own)].com_frame;
    out.owner[name] = own;
    out.link_in_body[name] = body.inverse() * t.X.at(name);
  }
}

}  // namespace

UrdfMultiBody build_urdf_multibody(const urdf::ModelInterface& model,
                                   const std::vector<std::string>& joints,
                                   const std::map<std::string, double>& q0,
                                   const scene::BasePose& base) {
  Tree t = cut_into_bodies(model, joints, q0);
  merge_masses(model, t);
  merge_inertias(model, t);
  if (base.floating) merge_base(model, t);

  const int n = static_cast<int>(t.bodies.size());
  UrdfMultiBody out;
  if (base.floating)
    out.body = std::make_unique<btMultiBody>(n, t.base.mass, t.base.principal, /*fixedBase=*/false,
                                             /*canSleep=*/false);
  else
    out.body = std::make_unique<btMultiBody>(n, 1.0, btVector3(1, 1, 1), /*fixedBase=*/true,
                                             /*canSleep=*/false);
  btMultiBody& mb = *out.body;
  out.root_to_base = t.base.com_frame;
  mb.setBaseWorldTransform(to_bt(base.pose) * out.root_to_base);
  record_links(t, out);
  for (int i = 0; i < n; ++i) set_up_link(model, t, i, mb);
  mb.finalizeMultiDof();
  // Pitfall (shared/notes/bullet.md): default damping 0.04.
  mb.setLinearDamping(0);
  mb.setAngularDamping(0);
  out.coordinate.resize(static_cast<std::size_t>(n));
  out.link.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    const std::string& joint = t.bodies[static_cast<std::size_t>(i)].joint;
    const int c = simulated_index(joints, joint);
    out.coordinate[static_cast<std::size_t>(i)] = c;
    out.link[static_cast<std::size_t>(c)] = i;
    mb.setJointPos(i, position_of(model, q0, joint));
  }
  mb.clearForcesAndTorques();
  mb.clearVelocities();
  return out;
}

Eigen::MatrixXd multibody_mass_matrix(const urdf::ModelInterface& model,
                                      const std::vector<std::string>& joints,
                                      const std::map<std::string, double>& q0) {
  UrdfMultiBody built = build_urdf_multibody(model, joints, q0);
  btMultiBody& mb = *built.body;
  const int n = mb.getNumLinks();
  // No gyroscopic terms at zero velocity anyway. No gravity: a btMultiBody
  // outside a world feels only the forces added to it.
  mb.setUseGyroTerm(false);

  btAlignedObjectArray<btScalar> scratch_r;
  btAlignedObjectArray<btVector3> scratch_v;
  btAlignedObjectArray<btMatrix3x3> scratch_m;
  mb.computeAccelerationsArticulatedBodyAlgorithmMultiDof(1e-3, scratch_r, scratch_v, scratch_m,
                                                          false, false, false);
  // Bullet link order -> the caller's joint order.
  const std::vector<int>& coord = built.coordinate;
  Eigen::MatrixXd Minv(n, n);
  std::vector<btScalar> force(static_cast<std::size_t>(6 + n)),
      out(static_cast<std::size_t>(6 + n));
  for (int c = 0; c < n; ++c) {
    std::fill(force.begin(), force.end(), 0.0);
    force[static_cast<std::size_t>(6 + c)] = 1.0;
    mb.calcAccelerationDeltasMultiDof(force.data(), out.data(), scratch_r, scratch_v);
    for (int r = 0; r < n; ++r)
      Minv(coord[static_cast<std::size_t>(r)], coord[static_cast<std::size_t>(c)]) =
          out[static_cast<std::size_t>(6 + r)];
  }
  return Minv.inverse();
}

}  // namespace lcsim::bullet
