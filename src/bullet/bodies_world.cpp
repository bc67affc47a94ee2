// A scene of several bodies (`bodies:`) in Bullet: one Featherstone
// btMultiBody per body with coordinates (urdf_multibody.hpp: a floating base
// at its pose, or a fixed base at its pose), an obstacle (a fixed body
// without joints) as static collision objects at its pose, all in one
// btMultiBodyDynamicsWorld stepped as the one-URDF scene is
// (multibody_world.cpp: the same solver settings, the scene's springs and
// dampers as joint torques and base forces before every step).
//
// Contacts, exactly the scene's rows (docs/contacts.md, "Peers on contact
// scenes"):
// - each contact point is a collider of its own: a btSphereShape of its
//   radius (0 for a corner: a point) at its place in its link's frame, on a
//   btMultiBodyLinkCollider of the link's Bullet link (a compound of a
//   link's points would not do: Bullet tests a compound's child against
//   another body's shape only once their bounding boxes overlap, so the
//   contact would not be speculative);
// - a target shape is a btSphereShape, btBoxShape, btCapsuleShapeZ or
//   btCylinderShapeZ at its place in its link's frame, on its link's
//   collider (a static object for an obstacle); a plane a
//   btStaticPlaneShape;
// - an overlap filter lets exactly these (point, target) pairs collide;
//   nothing else does (links of the same body, other pairs, the planes and
//   the shapes among themselves);
// - the colliders are placed before every step at the links' poses at
//   Bullet's state (scene::Bodies::link_pose, the scene's exact kinematics),
//   where Bullet's contact solver takes each point's Jacobian from the same
//   multibody state.
// Friction and restitution per point (Bullet multiplies the two colliders'
// coefficients: the row's mu and e, 1 on the targets). The contact rows are
// speculative within WorldSettings::contact_threshold (and the broadphase's
// 0.02 m margin on each bounding box), as on the one-URDF scene.
#include <BulletCollision/CollisionShapes/btBoxShape.h>
#include <BulletCollision/CollisionShapes/btCapsuleShape.h>
#include <BulletCollision/CollisionShapes/btCylinderShape.h>
#include <BulletCollision/CollisionShapes/btSphereShape.h>
#include <BulletCollision/CollisionShapes/btStaticPlaneShape.h>
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <btBulletDynamicsCommon.h>
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/scene/bodies.hpp>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <stdexcept>
#include <utility>

#include "bullet/multibody_scene.hpp"
#include "bullet/pipeline.hpp"
#include "bullet/run_recorder.hpp"
#include "bullet/step_loop.hpp"
#include "bullet/urdf_multibody.hpp"

namespace lcsim::bullet {

namespace {

using Eigen::MatrixXd;
using Eigen::Vector3d;
using Eigen::VectorXd;
using Vector6d = Eigen::Matrix<double, 6, 1>;

btVector3 bt(const Vector3d& v) { return btVector3(v.x(), v.y(), v.z()); }
Vector3d eig(const btVector3& v) { return Vector3d(v.x(), v.y(), v.z()); }
btTransform bt(const Eigen::Isometry3d& X) {
  const Eigen::Matrix3d& R = X.linear();
  return btTransform(
      btMatrix3x3(R(0, 0), R(0, 1), R(0, 2), R(1, 0), R(1, 1), R(1, 2), R(2, 0), R(2, 1), R(2, 2)),
      bt(Vector3d(X.translation())));
}

// Lets only the listed pairs of collision objects collide.
struct PairFilter : btOverlapFilterCallback {
  std::set<std::pair<const void*, const void*>> allowed;
  void allow(const btCollisionObject* a, const btCollisionObject* b) {
    allowed.insert({a, b});
    allowed.insert({b, a});
  }
  bool needBroadphaseCollision(btBroadphaseProxy* p0, btBroadphaseProxy* p1) const override {
    return allowed.count({p0->m_clientObject, p1->m_clientObject}) > 0;
  }
};

// One body of the scene in Bullet: its multibody (none for an obstacle)
// and where its coordinates sit in the scene's.
struct Part {
  UrdfMultiBody mb;
  int offset = 0, nb = 0, size = 0;
  scene::BasePose base;
  bool moving() const { return mb.body != nullptr; }
};

// A collider that moves with a link: its object, its link, its place in
// the link's frame.
struct Placed {
  btCollisionObject* object = nullptr;
  std::size_t body = 0;
  std::string link;
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();
};

// Members in construction order: destruction runs limits -> colliders ->
// multibodies, then the Pipeline's world -> solver -> ... (the destructor
// removes them from the world first).
struct BodiesWorld : Pipeline<btMultiBodyConstraintSolver, btMultiBodyDynamicsWorld> {
  PairFilter filter;
  std::vector<Part> parts;
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::vector<std::unique_ptr<btCollisionObject>> objects;  // every collider, planes too
  std::vector<Placed> placed;
  std::map<const btCollisionObject*, int> row_of;  // a contact point's collider -> its row
  std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>> limits;
  std::vector<JointLimit> limit_rows;
  std::vector<Vector3d> row_t1, row_t2;     // each row's world tangents (scene::ContactFrame)
  SceneForces torques;                      // tau = f_s - K_s q - D v
  std::optional<scene::Bodies> kinematics;  // the scene's, where the colliders are placed
  ~BodiesWorld() {
    for (auto& c : limits) world->removeMultiBodyConstraint(c.get());
    for (auto& o : objects) world->removeCollisionObject(o.get());
    for (auto& p : parts)
      if (p.moving()) world->removeMultiBody(p.mb.body.get());
  }
};

// The part and Bullet link of a joint coordinate c; -1 link for a base's.
std::pair<std::size_t, int> link_of(const BodiesWorld& w, int c) {
  for (std::size_t i = 0; i < w.parts.size(); ++i) {
    const Part& p = w.parts[i];
    if (c < p.offset || c >= p.offset + p.size) continue;
    if (c < p.offset + p.nb) return {i, -1};
    return {i, p.mb.link[static_cast<std::size_t>(c - p.offset - p.nb)]};
  }
  return {0, -1};
}

void set_state(BodiesWorld& w, const VectorXd& q, const VectorXd& v) {
  for (Part& p : w.parts) {
    if (!p.moving()) continue;
    btMultiBody& b = *p.mb.body;
    if (p.nb > 0)
      set_floating_base(b, p.mb, p.base, q.segment<6>(p.offset), v.segment<6>(p.offset));
    for (int c = p.nb; c < p.size; ++c) {
      const int link = p.mb.link[static_cast<std::size_t>(c - p.nb)];
      b.setJointPos(link, q(p.offset + c));
      b.setJointVel(link, v(p.offset + c));
    }
    place_link_colliders(b);
  }
}

// Every collider that moves, at its link's pose at q.
void place_colliders(BodiesWorld& w, const scene::Bodies& bodies, const VectorXd& q) {
  for (const Placed& p : w.placed)
    p.object->setWorldTransform(bt(bodies.link_pose(p.body, p.link, q) * p.local));
}

// A collider of `shape` on link `link` of body b (a static object for an
// obstacle), placed before every step.
btCollisionObject* add_collider(BodiesWorld& w, std::size_t b, const std::string& link,
                                const Eigen::Isometry3d& local, btCollisionShape* shape) {
  Part& p = w.parts[b];
  std::unique_ptr<btCollisionObject> obj;
  if (p.moving()) {
    const auto own = p.mb.owner.find(link);
    if (own == p.mb.owner.end())
      throw std::invalid_argument("bullet: link '" + link + "' is not in Bullet's multibody");
    obj = std::make_unique<btMultiBodyLinkCollider>(p.mb.body.get(), own->second);
  } else {
    obj = std::make_unique<btCollisionObject>();
  }
  obj->setCollisionShape(shape);
  obj->setActivationState(DISABLE_DEACTIVATION);
  obj->setRestitution(1.0);
  obj->setFriction(1.0);
  obj->setRollingFriction(0.0);
  obj->setSpinningFriction(0.0);
  w.placed.push_back({obj.get(), b, link, local});
  w.world->addCollisionObject(obj.get());
  w.objects.push_back(std::move(obj));
  return w.objects.back().get();
}

// Bullet's shape of another body's primitive (scene::BodyShape).
std::unique_ptr<btCollisionShape> target_shape(const scene::BodyShape& s) {
  std::unique_ptr<btCollisionShape> out;
  if (s.kind == "sphere")
    out = std::make_unique<btSphereShape>(s.radius);
  else if (s.kind == "box")
    out = std::make_unique<btBoxShape>(bt(s.half));
  else if (s.kind == "capsule")
    out = std::make_unique<btCapsuleShapeZ>(s.radius, 2.0 * s.half.z());
  else if (s.kind == "cylinder")
    out = std::make_unique<btCylinderShapeZ>(btVector3(s.radius, s.radius, s.half.z()));
  else
    throw std::invalid_argument("bullet: body '" + std::to_string(s.body) + "' shape '" + s.name +
                                "' is a " + s.kind +
                                ": Bullet holds spheres, boxes, capsules and cylinders");
  out->setMargin(0.0);
  return out;
}

// Each row's mu (-1: none).
std::vector<double> row_mu(const mech::MechanicalModel& m) {
  std::vector<double> mu(static_cast<std::size_t>(m.num_constraints()), -1.0);
  for (const mech::FrictionalContact& f : m.friction)
    mu[static_cast<std::size_t>(f.contact)] = f.mu;
  return mu;
}

// The contacts' colliders: one sphere per contact point (on its own: a
// compound's child is tested against the other shape only once their
// bounding boxes overlap, which would make a body's contacts
// non-speculative), the targets' shapes and the planes, and the filter's
// pairs.
void add_contacts(BodiesWorld& w, const scene::Scene& setup, const mech::MechanicalModel& m) {
  const std::vector<double> mu = row_mu(m);
  w.row_t1.assign(static_cast<std::size_t>(m.num_constraints()), Vector3d::Zero());
  w.row_t2 = w.row_t1;
  std::map<std::string, btCollisionObject*> target;  // plane or shape name -> its object
  for (const scene::Plane& pl : setup.planes) {
    auto shape = std::make_unique<btStaticPlaneShape>(bt(pl.normal), pl.normal.dot(pl.point));
    auto obj = std::make_unique<btCollisionObject>();
    obj->setCollisionShape(shape.get());
    obj->setRestitution(1.0);
    obj->setFriction(1.0);
    obj->setRollingFriction(0.0);
    obj->setSpinningFriction(0.0);
    w.world->addCollisionObject(obj.get());
    target["plane:" + pl.name] = obj.get();
    w.shapes.push_back(std::move(shape));
    w.objects.push_back(std::move(obj));
  }
  for (const scene::ContactFrame& cf : setup.contacts) {
    const scene::ContactPoint& p = cf.point;
    const auto row = static_cast<std::size_t>(cf.row);
    w.row_t1[row] = cf.tangent1;
    w.row_t2[row] = cf.tangent2;
    std::string to = "plane:" + cf.plane;
    if (cf.against) {
      to = "shape:" + cf.against->name;
      if (!target.count(to)) {
        w.shapes.push_back(target_shape(*cf.against));
        target[to] = add_collider(w, cf.against->body, cf.against->link, cf.against->local,
                                  w.shapes.back().get());
      }
    }
    auto sphere = std::make_unique<btSphereShape>(p.radius);
    Eigen::Isometry3d at = Eigen::Isometry3d::Identity();
    at.translation() = p.local;
    btCollisionObject* obj = add_collider(w, p.body, p.link, at, sphere.get());
    w.shapes.push_back(std::move(sphere));
    obj->setRestitution(m.restitution(static_cast<int>(cf.row)));
    obj->setFriction(std::max(0.0, mu[row]));
    w.filter.allow(obj, target.at(to));
    w.row_of[obj] = static_cast<int>(cf.row);
  }
}

// The multibodies of the scene's bodies with coordinates (fixed or floating
// base at its pose), each link with a collider that collides with nothing
// (a joint limit on a link without one is ignored), and the joint limits.
void add_bodies(BodiesWorld& w, const scene::Scene& setup, const std::vector<JointLimit>& limits,
                const WorldSettings& s) {
  const scene::Bodies bodies = scene::scene_bodies(setup);
  for (std::size_t i = 0; i < setup.bodies.size(); ++i) {
    const scene::SceneBody& sb = setup.bodies[i];
    Part p;
    p.offset = static_cast<int>(sb.offset);
    p.size = static_cast<int>(bodies.body_size(i));
    p.nb = sb.base.floating ? 6 : 0;
    p.base = sb.base;
    if (p.size > 0) {
      p.mb = build_urdf_multibody(*sb.urdf, sb.joints, sb.q0, sb.base);
      add_pinned_multibody(*w.world, *p.mb.body);
    }
    w.parts.push_back(std::move(p));
  }
  w.shapes.push_back(std::make_unique<btSphereShape>(0.01));
  for (Part& p : w.parts) {
    if (!p.moving()) continue;
    btMultiBody& b = *p.mb.body;
    for (int link = -1; link < b.getNumLinks(); ++link) {
      auto col = std::make_unique<btMultiBodyLinkCollider>(&b, link);
      col->setCollisionShape(w.shapes.back().get());
      col->setActivationState(DISABLE_DEACTIVATION);
      w.world->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter, 0);
      if (link < 0)
        b.setBaseCollider(col.get());
      else
        b.getLink(link).m_collider = col.get();
      w.objects.push_back(std::move(col));
    }
  }
  for (const JointLimit& L : limits) {
    const auto [part, link] = link_of(w, L.coordinate);
    w.limits.push_back(add_joint_limit(*w.world, w.parts[part].mb.body.get(), link, L, s));
    w.limit_rows.push_back(L);
  }
}

std::unique_ptr<BodiesWorld> build(const scene::Scene& setup, const mech::MechanicalModel& m,
                                   const std::vector<JointLimit>& limits, const WorldSettings& s) {
  auto w = std::make_unique<BodiesWorld>();
  w->config = std::make_unique<btDefaultCollisionConfiguration>();
  w->dispatcher = make_dispatcher(w->config.get(), s.contact_threshold);
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  w->solver = std::make_unique<btMultiBodyConstraintSolver>();
  w->world = std::make_unique<btMultiBodyDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                        w->solver.get(), w->config.get());
  w->world->setGravity(bt(setup.gravity));
  pin_solver_info(w->world->getSolverInfo(), s, m.has_friction());
  w->world->getPairCache()->setOverlapFilterCallback(&w->filter);
  add_bodies(*w, setup, limits, s);
  add_contacts(*w, setup, m);
  return w;
}

// One step of length h under the generalised forces tau from q: the state
// it reached.
void take_step(BodiesWorld& w, const VectorXd& q, const VectorXd& tau, double h, VectorXd& q_next,
               VectorXd& v_next) {
  for (Part& p : w.parts) {
    if (!p.moving()) continue;
    btMultiBody& b = *p.mb.body;
    if (p.nb > 0)
      add_floating_base_force(b, p.mb, p.base, q.segment<6>(p.offset), tau.segment<6>(p.offset));
    for (int c = p.nb; c < p.size; ++c)
      b.addJointTorque(p.mb.link[static_cast<std::size_t>(c - p.nb)], tau(p.offset + c));
  }
  reset_limit_impulses(w.limits);
  place_colliders(w, *w.kinematics, q);
  w.world->stepSimulation(h, 0, h);  // exactly one step of length h
  q_next = q;
  v_next.setZero();
  for (Part& p : w.parts) {
    if (!p.moving()) continue;
    const btMultiBody& b = *p.mb.body;
    if (p.nb > 0)
      get_floating_base(b, p.mb, p.base, q_next.segment<6>(p.offset), v_next.segment<6>(p.offset));
    for (int c = p.nb; c < p.size; ++c) {
      const int link = p.mb.link[static_cast<std::size_t>(c - p.nb)];
      q_next(p.offset + c) = b.getJointPos(link);
      v_next(p.offset + c) = b.getJointVel(link);
    }
  }
}

// The step's impulses by row (N s): normal, and the friction impulse on the
// contact point along the row's tangents t1, t2 (scene::ContactFrame).
// Bullet's friction impulses act on body A along its friction directions
// and on body B against them; m_normalWorldOnB points from B to A.
bool step_impulses(BodiesWorld& w, const StepTaken& /*taken*/, VectorXd& normal, VectorXd& t1,
                   VectorXd& t2) {
  normal.setZero();
  t1.setZero();
  t2.setZero();
  for (int i = 0; i < w.dispatcher->getNumManifolds(); ++i) {
    const btPersistentManifold* pm = w.dispatcher->getManifoldByIndexInternal(i);
    for (int j = 0; j < pm->getNumContacts(); ++j) {
      const btManifoldPoint& pt = pm->getContactPoint(j);
      double sign = 1.0;
      auto it = w.row_of.find(pm->getBody0());
      if (it == w.row_of.end()) {
        it = w.row_of.find(pm->getBody1());
        sign = -1.0;
      }
      if (it == w.row_of.end()) continue;
      const int row = it->second;
      normal(row) += pt.m_appliedImpulse;
      const Vector3d f = sign * (pt.m_appliedImpulseLateral1 * eig(pt.m_lateralFrictionDir1) +
                                 pt.m_appliedImpulseLateral2 * eig(pt.m_lateralFrictionDir2));
      t1(row) += w.row_t1[static_cast<std::size_t>(row)].dot(f);
      t2(row) += w.row_t2[static_cast<std::size_t>(row)].dot(f);
    }
  }
  for (std::size_t i = 0; i < w.limits.size(); ++i) {
    const JointLimit& L = w.limit_rows[i];
    normal(L.row) = w.limits[i]->getAppliedImpulse(L.lower ? 0 : 1) / std::abs(L.c);
  }
  return true;  // friction along t1, t2 (zero where no contact has friction)
}

// The scene's own torques (SceneForces).
void step_forces(BodiesWorld& w, const VectorXd& q, const VectorXd& v, VectorXd& tau) {
  tau = w.torques.f_s - w.torques.K_s * q - w.torques.D * v;
}

}  // namespace

std::string bodies_refusal(const scene::Scene& setup) {
  for (const scene::SceneBody& b : setup.bodies)
    for (const auto& [name, j] : b.urdf->joints_)
      if (j->mimic)
        return "body '" + b.name + "': joint '" + name +
               "' is a mimic: Bullet's model of a scene of bodies has none";
  return "";
}

std::vector<JointLimit> bodies_joint_limits(const mech::MechanicalModel& m,
                                            const scene::Scene& setup) {
  std::vector<JointLimit> out = joint_limits_of(m, setup.model.source, &setup);
  for (const JointLimit& L : out)
    for (const scene::SceneBody& b : setup.bodies)
      if (b.base.floating && L.coordinate >= b.offset && L.coordinate < b.offset + 6)
        throw std::invalid_argument("bullet: " + setup.model.source + ": constraint '" +
                                    m.constraints[static_cast<std::size_t>(L.row)] +
                                    "' is a stop on the floating base's "
                                    "coordinate '" +
                                    m.coordinates[static_cast<std::size_t>(L.coordinate)] +
                                    "': Bullet's multibody has limits on joints only");
  return out;
}

std::string bodies_description(const WorldSettings& s, bool friction) {
  std::string d = multibody_description(s, true, friction);
  const std::string from = "btMultiBody from the URDF, ";
  return "one btMultiBody per body (its URDF, its base fixed or floating at its pose; an "
         "obstacle a static object), " +
         d.substr(from.size()) +
         "; another body's shapes as btSphereShape / btBoxShape / btCapsuleShapeZ / "
         "btCylinderShapeZ, each contact point a collider of its own (its mu and e), an overlap "
         "filter letting only the scene's pairs collide";
}

sim::Trajectory simulate_bodies(const mech::Model& model, const scene::Scene& setup,
                                const std::vector<JointLimit>& limits, const VectorXd& x0,
                                const sim::Options& opt, const WorldSettings& s) {
  const mech::MechanicalModel& m = *model.mechanical;
  sim::Trajectory tr = started_run("bullet " + bodies_description(s, m.has_friction()), x0, opt);
  tr.dynamics = "the URDFs' nonlinear multibodies (Bullet)";
  const int N = m.dofs();
  warn_explicit_damping(tr, m, opt.h, "joint torques");
  SceneForces forces = scene_forces(setup, m);
  scene::Bodies bodies = scene::scene_bodies(setup);
  std::unique_ptr<BodiesWorld> w;
  try {
    w = build(setup, m, limits, s);
    set_state(*w, x0.head(N), x0.tail(N));
  } catch (const std::exception& e) {
    return failed_run(std::move(tr), std::string("bullet: ") + e.what());
  }
  w->torques = std::move(forces);
  w->kinematics.emplace(std::move(bodies));
  return run_steps(*w, model, x0, opt, std::move(tr), m.has_friction());
}

}  // namespace lcsim::bullet
