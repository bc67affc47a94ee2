// A model from a URDF scene built in Bullet as the URDF itself: a
// Featherstone btMultiBody (urdf_multibody.hpp) in a btMultiBodyDynamicsWorld,
// run with Bullet's fixed step.
//
// What Bullet integrates. The scene's simulated joints are the links of the
// multibody, every other joint is frozen at the scene's q0 (merged into its
// parent link), the URDF root is the fixed base. A mimic of a simulated
// joint is a link of its own geared to its leader (FollowingMimic), as
// lcsim's model moves it with the leader. Bullet integrates the
// nonlinear rigid-body dynamics (gravity is the world's, set to the scene's);
// lcsim's model is their linearisation about q0. The rest of the scene is
// added as joint torques before every step:
//   tau = f_s - K_s q - D v,   K_s = K - K_g,   f_s = f - tau_g(q0) - K_g q0,
// i.e. the scene's springs and dampers (and the URDF's joint damping, all in
// D), without the linearised gravity that K and f also hold (scene::Scene).
//
// Constraints. Each row of E must be a joint limit c q_j + g >= 0 (one
// non-zero coefficient): it becomes a btMultiBodyJointLimitConstraint on q_j
// with the bound -g / c on its side and the other side limit_range away.
// Bullet creates a limit row only once the joint is at or past the bound at
// the start of a step (no speculative rows), and its target velocity is
// limit_erp * penetration / h (Baumgarte): with ERP 0 an impact leaves a
// penetration of at most |v| h, which stays while in contact. Bullet's limits
// have no restitution (the constraint solver pushes the joint velocity to the
// Baumgarte target, never to -e v).
//
// Step. btMultiBodyDynamicsWorld: v* = v + h M(q)^{-1}(tau + gravity - bias),
// limit impulses from v*, then q+ = q + h v+ (semi-implicit Euler, first
// order in h).
//
// Settings pinned here and in WorldSettings: solver btMultiBodyConstraintSolver
// (sequential impulse; btMultiBodyMLCPConstraintSolver only on request, see
// WorldSettings::multibody_mlcp), iterations, global ERP = limit ERP, CFM 0,
// split impulse off (not implemented for multibodies anyway), no articulated
// warm starting (each step's limit impulses start at 0), SOR 1, least-squares
// early exit off; the multibody: linear and angular damping 0 (default 0.04),
// gyroscopic term on, max coordinate velocity 1e30 (default 100), no sleeping,
// no self-collision; every link has a btMultiBodyLinkCollider (a limit on a
// link without one is silently ignored) that collides with nothing (mask 0);
// the limits' max impulse (default 100).
#include <BulletDynamics/Featherstone/btMultiBodyConstraintSolver.h>
#include <BulletDynamics/Featherstone/btMultiBodyDynamicsWorld.h>
#include <BulletDynamics/Featherstone/btMultiBodyGearConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyJointLimitConstraint.h>
#include <BulletDynamics/Featherstone/btMultiBodyLinkCollider.h>
#include <BulletDynamics/Featherstone/btMultiBodyMLCPConstraintSolver.h>
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
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
using Eigen::VectorXd;

// A mimic joint m of a simulated joint J (coordinate `leader`), q_m = a q_J + b:
// a link of its own in Bullet, tied to J's by a gear constraint.
struct FollowingMimic {
  std::string joint;
  int leader = 0;
  double a = 1.0, b = 0.0;
  int link = 0;  // Bullet link
};

// The mimics of `coordinates` in the URDF (scene::mimic_joints, chains resolved).
std::vector<FollowingMimic> following_mimics(const scene::Scene& setup,
                                             const std::vector<std::string>& coordinates) {
  std::vector<FollowingMimic> out;
  for (const auto& [name, mm] : scene::mimic_joints(*setup.urdf, setup.urdf_source, coordinates)) {
    const auto it = std::find(coordinates.begin(), coordinates.end(), mm.leader);
    if (it == coordinates.end()) continue;  // frozen with its frozen leader
    out.push_back({name, static_cast<int>(it - coordinates.begin()), mm.multiplier, mm.offset, 0});
  }
  return out;
}

// The multibody's world (the step loop's calls, step_loop.hpp, are
// take_step and the two beside it); members in construction order, so that
// destruction runs limits -> colliders -> multibody -> world -> solvers.
// The dispatcher is make_dispatcher's with contacts.
struct MbWorld : Pipeline<btMultiBodyConstraintSolver, btMultiBodyDynamicsWorld> {
  std::unique_ptr<btSphereShape> shape;
  UrdfMultiBody mb;
  int nb = 0;                 // the floating base's coordinates (6), first in q; else 0
  scene::BasePose base;       // the scene's
  ContactColliders contacts;  // shapes outlive the colliders below
  std::unique_ptr<btMultiBodyLinkCollider> base_collider;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>> limits;
  std::vector<FollowingMimic> mimics;
  std::vector<std::unique_ptr<btMultiBodyGearConstraint>> gears;  // one per mimic
  std::vector<JointLimit> limit_rows;                             // limits[i]'s row of E
  SceneForces torques;                                            // tau = f_s - K_s q - D v
  ~MbWorld() {
    for (auto& c : gears) world->removeMultiBodyConstraint(c.get());
    for (auto& c : limits) world->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders) world->removeCollisionObject(c.get());
    if (base_collider) world->removeCollisionObject(base_collider.get());
    for (auto& p : contacts.planes) world->removeCollisionObject(p.get());
    if (mb.body) world->removeMultiBody(mb.body.get());
  }
};

// The Bullet link of coordinate c (a joint: c >= w.nb).
int link_of(const MbWorld& w, int c) { return w.mb.link[static_cast<std::size_t>(c - w.nb)]; }

void set_state(MbWorld& w, const VectorXd& q, const VectorXd& v) {
  btMultiBody& b = *w.mb.body;
  if (w.nb > 0) set_floating_base(b, w.mb, w.base, q.head<6>(), v.head<6>());
  for (int c = w.nb; c < q.size(); ++c) {
    b.setJointPos(link_of(w, c), q(c));
    b.setJointVel(link_of(w, c), v(c));
  }
  for (const FollowingMimic& f : w.mimics) {
    b.setJointPos(f.link, f.a * q(w.nb + f.leader) + f.b);
    b.setJointVel(f.link, f.a * v(w.nb + f.leader));
  }
  place_link_colliders(b);
}

// An empty world with the scene's gravity and the pinned settings (the
// file's header comment).
std::unique_ptr<MbWorld> make_world(const scene::Scene& setup, const WorldSettings& s,
                                    bool friction) {
  auto w = std::make_unique<MbWorld>();
  w->config = std::make_unique<btDefaultCollisionConfiguration>();
  if (setup.contacts.empty())
    w->dispatcher = std::make_unique<btCollisionDispatcher>(w->config.get());
  else
    w->dispatcher = make_dispatcher(w->config.get(), s.contact_threshold);
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  if (s.multibody_mlcp) {
    w->mlcp = std::make_unique<btDantzigSolver>();
    w->solver = std::make_unique<btMultiBodyMLCPConstraintSolver>(w->mlcp.get());
  } else {
    w->solver = std::make_unique<btMultiBodyConstraintSolver>();
  }
  w->world = std::make_unique<btMultiBodyDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                        w->solver.get(), w->config.get());
  w->world->setGravity(btVector3(setup.gravity.x(), setup.gravity.y(), setup.gravity.z()));
  pin_solver_info(w->world->getSolverInfo(), s, friction);
  return w;
}

// The collider of Bullet link `link` (-1: the base): its contact points'
// compound colliding with the planes, or (a link without contacts) a sphere
// that collides with nothing, there only because a joint limit on a link
// without a collider is ignored.
std::unique_ptr<btMultiBodyLinkCollider> make_collider(MbWorld& w, int link) {
  btMultiBody& b = *w.mb.body;
  auto col = std::make_unique<btMultiBodyLinkCollider>(&b, link);
  col->setActivationState(DISABLE_DEACTIVATION);
  const auto contact = w.contacts.shape_of.find(link);
  if (contact == w.contacts.shape_of.end()) {
    col->setCollisionShape(w.shape.get());
    // Mask 0: the broadphase pairs this collider with nothing.
    w.world->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter, 0);
    return col;
  }
  col->setCollisionShape(contact->second);
  col->setRestitution(w.contacts.restitution_of.at(link));
  col->setFriction(w.contacts.friction_of.at(link));
  col->setRollingFriction(0.0);
  col->setSpinningFriction(0.0);
  w.world->addCollisionObject(col.get(), kContactLinkGroup, kPlaneGroup);
  return col;
}

// The multibody of the scene's URDF (the coordinates' joints, then their
// mimics; a floating base's six coordinates are Bullet's base), each link
// with a collider, the planes.
void add_multibody(MbWorld& w, const scene::Scene& setup, const mech::MechanicalModel& m) {
  w.base = setup.base;
  w.nb = setup.base.floating ? 6 : 0;
  const std::vector<std::string> joints(m.coordinates.begin() + w.nb, m.coordinates.end());
  w.mimics = following_mimics(setup, joints);
  std::vector<std::string> moving = joints;
  for (const FollowingMimic& f : w.mimics) moving.push_back(f.joint);
  w.mb = build_urdf_multibody(*setup.urdf, moving, setup.q0, setup.base);
  for (std::size_t i = 0; i < w.mimics.size(); ++i) w.mimics[i].link = w.mb.link[joints.size() + i];
  w.contacts = make_contact_colliders(setup, w.mb, m);
  btMultiBody& b = *w.mb.body;
  add_pinned_multibody(*w.world, b);
  w.shape = std::make_unique<btSphereShape>(0.01);
  w.shape->setMargin(0.0);
  if (w.contacts.shape_of.count(-1) > 0) {
    w.base_collider = make_collider(w, -1);
    b.setBaseCollider(w.base_collider.get());
  }
  for (int i = 0; i < b.getNumLinks(); ++i) {
    w.colliders.push_back(make_collider(w, i));
    b.getLink(i).m_collider = w.colliders.back().get();
  }
  for (auto& p : w.contacts.planes)
    w.world->addCollisionObject(p.get(), kPlaneGroup, kContactLinkGroup);
}

// The gear's row is v_m + r v_J = 0 (Jacobian 1 on link A, r on link B):
// r = -a. ERP 0: no position correction; the velocity equality, solved
// every step, keeps q_m - a q_J at b up to the solver's residual.
void add_gears(MbWorld& w) {
  btMultiBody& b = *w.mb.body;
  for (const FollowingMimic& f : w.mimics) {
    const int leader = w.mb.link[static_cast<std::size_t>(f.leader)];
    auto g = std::make_unique<btMultiBodyGearConstraint>(
        &b, f.link, &b, leader, btVector3(0, 0, 0), btVector3(0, 0, 0), btMatrix3x3::getIdentity(),
        btMatrix3x3::getIdentity());
    g->setGearRatio(-f.a);
    g->setErp(0.0);
    g->finalizeMultiDof();
    g->setMaxAppliedImpulse(1e30);
    w.world->addMultiBodyConstraint(g.get());
    w.gears.push_back(std::move(g));
  }
}

// One btMultiBodyJointLimitConstraint per joint limit.
void add_limits(MbWorld& w, const std::vector<JointLimit>& limits, const WorldSettings& s) {
  for (const JointLimit& L : limits) {
    w.limits.push_back(add_joint_limit(*w.world, w.mb.body.get(), link_of(w, L.coordinate), L, s));
    w.limit_rows.push_back(L);
  }
}

std::unique_ptr<MbWorld> build(const scene::Scene& setup, const mech::MechanicalModel& m,
                               const std::vector<JointLimit>& limits, const VectorXd& q0,
                               const VectorXd& v0, const WorldSettings& s) {
  std::unique_ptr<MbWorld> w = make_world(setup, s, m.has_friction());
  add_multibody(*w, setup, m);
  set_state(*w, q0, v0);
  add_gears(*w);
  add_limits(*w, limits, s);
  return w;
}

// The scene's warnings: what Bullet does differently from lcsim's model
// beyond the step error.
void warn(sim::Trajectory& tr, const mech::MechanicalModel& m, const MatrixXd& K_s,
          const sim::Options& opt, const std::vector<JointLimit>& limits) {
  warn_explicit_damping(tr, m, opt.h, "joint torques");
  // Springs are explicit torques (symplectic Euler): stable for omega h <= 2,
  // omega^2 the largest eigenvalue of K_s x = omega^2 M(q0) x.
  if (K_s.norm() > 0.0) {
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(K_s, MatrixXd(m.M),
                                                                Eigen::EigenvaluesOnly);
    const double w = std::sqrt(std::max(0.0, es.eigenvalues().maxCoeff()));
    if (w * opt.h > 2.0)
      tr.warn("bullet-explicit-springs", 0.0,
              "bullet: springs are explicit joint torques, unstable for omega h > 2: omega = " +
                  short_number(w) + " rad/s gives omega h = " + short_number(w * opt.h) +
                  " at h = " + short_number(opt.h) + "; expect growth, or reduce h");
  }
  for (const JointLimit& L : limits)
    if (const int i = L.row; m.restitution(i) > 0.0) {
      tr.warn("bullet-restitution-lost", 0.0,
              "bullet: restitution is lost: Bullet's multibody joint limits are inelastic "
              "(btMultiBodyJointLimitConstraint has no bounce); constraint '" +
                  m.constraints[static_cast<std::size_t>(i)] +
                  "' has e = " + short_number(m.restitution(i)));
      break;
    }
}

// One Bullet step of length h under the generalised forces tau (joint
// torques; a floating base's six as its force and torque) from the state q;
// the state it reached.
void take_step(MbWorld& w, const VectorXd& q, const VectorXd& tau, double h, VectorXd& q_next,
               VectorXd& v_next) {
  btMultiBody& b = *w.mb.body;
  const auto N = static_cast<int>(tau.size());
  if (w.nb > 0) add_floating_base_force(b, w.mb, w.base, q.head<6>(), tau.head<6>());
  for (int c = w.nb; c < N; ++c) b.addJointTorque(link_of(w, c), tau(c));
  reset_limit_impulses(w.limits);
  // maxSubSteps = 0: exactly one step of length h (no interpolation).
  w.world->stepSimulation(h, 0, h);
  if (w.nb > 0) get_floating_base(b, w.mb, w.base, q_next.head<6>(), v_next.head<6>());
  for (int c = w.nb; c < N; ++c) {
    q_next(c) = b.getJointPos(link_of(w, c));
    v_next(c) = b.getJointVel(link_of(w, c));
  }
}

// The scene's own torques (SceneForces).
void step_forces(MbWorld& w, const VectorXd& q, const VectorXd& v, VectorXd& tau) {
  tau = w.torques.f_s - w.torques.K_s * q - w.torques.D * v;
}

// The step's impulses by row of E. Row 0 of a limit pushes +q (the lower
// bound), row 1 -q; lcsim's row is c e_j, so the impulse P on the joint is
// |c| h u. With friction, each contact's friction along its tangents.
bool step_impulses(MbWorld& w, const StepTaken& /*taken*/, VectorXd& impulse, VectorXd& t1,
                   VectorXd& t2) {
  if (w.contacts.rows > 0) {
    impulse.setZero();
    contact_impulses(*w.dispatcher, w.contacts, impulse);
  }
  for (std::size_t i = 0; i < w.limit_rows.size(); ++i) {
    const JointLimit& L = w.limit_rows[i];
    impulse(L.row) = w.limits[i]->getAppliedImpulse(L.lower ? 0 : 1) / std::abs(L.c);
  }
  if (w.contacts.friction) contact_friction_impulses(*w.dispatcher, w.contacts, t1, t2);
  return w.contacts.friction;
}

}  // namespace

void pin_solver_info(btContactSolverInfo& info, const WorldSettings& s, bool friction) {
  info.m_numIterations = s.solver_iterations;
  info.m_erp = s.limit_erp;
  info.m_erp2 = s.limit_erp;
  info.m_globalCfm = 0.0;
  info.m_sor = 1.0;
  info.m_splitImpulse = 0;
  info.m_leastSquaresResidualThreshold = 0.0;
  info.m_linearSlop = 0.0;  // Bullet's default; contacts: penetration = distance + slop
  info.m_solverMode = SOLVER_USE_WARMSTARTING | SOLVER_SIMD;  // no articulated warm start
  if (friction && s.friction != WorldSettings::Friction::kOneDirection)
    info.m_solverMode |= SOLVER_USE_2_FRICTION_DIRECTIONS;
  if (friction && s.friction == WorldSettings::Friction::kBox)
    info.m_solverMode |= SOLVER_DISABLE_IMPLICIT_CONE_FRICTION;
}

void add_pinned_multibody(btMultiBodyDynamicsWorld& world, btMultiBody& b) {
  b.setLinearDamping(0);
  b.setAngularDamping(0);
  b.setUseGyroTerm(true);
  b.setMaxCoordinateVelocity(1e30);
  b.setCanSleep(false);
  b.setHasSelfCollision(false);
  b.useGlobalVelocities(false);
  world.addMultiBody(&b, btBroadphaseProxy::DefaultFilter, 0);
}

void place_link_colliders(btMultiBody& b) {
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  world_to_local.resize(b.getNumLinks() + 1);
  local_origin.resize(b.getNumLinks() + 1);
  b.forwardKinematics(world_to_local, local_origin);
  b.updateCollisionObjectWorldTransforms(world_to_local, local_origin);
}

std::unique_ptr<btMultiBodyJointLimitConstraint> add_joint_limit(btMultiBodyDynamicsWorld& world,
                                                                 btMultiBody* b, int link,
                                                                 const JointLimit& L,
                                                                 const WorldSettings& s) {
  const double lo = L.lower ? L.bound : L.bound - s.limit_range;
  const double hi = L.lower ? L.bound + s.limit_range : L.bound;
  auto c = std::make_unique<btMultiBodyJointLimitConstraint>(b, link, lo, hi);
  // Allocates the rows' storage (else done lazily in the first step, after
  // the step loop has reset the applied impulses).
  c->finalizeMultiDof();
  c->setMaxAppliedImpulse(s.limit_max_impulse);
  world.addMultiBodyConstraint(c.get());
  return c;
}

void reset_limit_impulses(
    const std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>>& limits) {
  for (const auto& c : limits) {
    c->internalSetAppliedImpulse(0, 0.0);
    c->internalSetAppliedImpulse(1, 0.0);
  }
}

std::vector<JointLimit> joint_limits_of(const mech::MechanicalModel& m, const std::string& source,
                                        const scene::Scene* setup) {
  std::vector<JointLimit> out;
  std::vector<bool> contact(static_cast<std::size_t>(m.num_constraints()), false);
  const int nb = setup && setup->base.floating ? 6 : 0;
  if (setup)
    for (const scene::ContactFrame& cf : setup->contacts)
      contact[static_cast<std::size_t>(cf.row)] = true;
  for (int i = 0; i < m.num_constraints(); ++i) {
    if (contact[static_cast<std::size_t>(i)]) continue;
    std::vector<int> nz;
    for (int j = 0; j < m.dofs(); ++j)
      if (m.E.coeff(i, j) != 0.0) nz.push_back(j);
    if (nz.size() != 1)
      throw std::invalid_argument(
          "bullet: " + (source.empty() ? std::string() : source + ": ") + "constraint '" +
          m.constraints[static_cast<std::size_t>(i)] + "' (row " + std::to_string(i) +
          " of E) involves " + std::to_string(nz.size()) +
          " joints: Bullet's multibody expresses only joint limits (one joint each)");
    if (nz[0] < nb)
      throw std::invalid_argument("bullet: " + (source.empty() ? std::string() : source + ": ") +
                                  "constraint '" + m.constraints[static_cast<std::size_t>(i)] +
                                  "' (row " + std::to_string(i) + " of E) is a stop on the " +
                                  "floating base's coordinate '" +
                                  m.coordinates[static_cast<std::size_t>(nz[0])] +
                                  "': Bullet's multibody has limits on joints only");
    JointLimit L;
    L.row = i;
    L.coordinate = nz[0];
    L.c = m.E.coeff(i, nz[0]);
    L.bound = -m.g(i) / L.c;
    L.lower = L.c > 0.0;
    out.push_back(L);
  }
  return out;
}

// Bullet's friction at contacts as WorldSettings::friction sets it.
std::string friction_description(const WorldSettings& s) {
  switch (s.friction) {
    case WorldSettings::Friction::kBox:
      return "friction mu (link) x 1 (plane), SOLVER_USE_2_FRICTION_DIRECTIONS and "
             "SOLVER_DISABLE_IMPLICIT_CONE_FRICTION: two fixed tangents (btPlaneSpace1), each "
             "bounded by mu N alone (a square)";
    case WorldSettings::Friction::kOneDirection:
      return "friction mu (link) x 1 (plane), one friction row along the fixed first tangent "
             "(btPlaneSpace1), none across it";
    case WorldSettings::Friction::kCone:
      break;
  }
  return "friction mu (link) x 1 (plane), SOLVER_USE_2_FRICTION_DIRECTIONS with implicit cone "
         "friction: two fixed tangents (btPlaneSpace1), their impulse scaled back onto the "
         "circle mu N (a circular cone)";
}

std::string multibody_description(const WorldSettings& s, bool contacts, bool friction) {
  const std::string planes =
      contacts ? ", contact points as btSphereShape (radius 0 at a corner) against "
                 "btStaticPlaneShape planes (" +
                     (friction ? friction_description(s) : std::string("friction 0")) +
                     ", contact ERP " + short_number(s.limit_erp) +
                     ", slop 0, speculative within " + short_number(s.contact_threshold) + " m)"
               : std::string();
  return std::string("btMultiBody from the URDF, ") +
         (s.multibody_mlcp ? "btMultiBodyMLCPConstraintSolver (btDantzigSolver)"
                           : "btMultiBodyConstraintSolver (" + std::to_string(s.solver_iterations) +
                                 " iterations)") +
         ", btMultiBodyJointLimitConstraint limits (ERP " + short_number(s.limit_erp) +
         ", max impulse " + short_number(s.limit_max_impulse) + ")" + planes;
}

SceneForces scene_forces(const scene::Scene& setup, const mech::MechanicalModel& m) {
  const int N = m.dofs();
  const scene::UrdfLinearisation& lin = setup.lin;
  VectorXd q_ref = VectorXd::Zero(N);
  for (int j = 0; j < N; ++j)
    if (const auto it = setup.q0.find(m.coordinates[static_cast<std::size_t>(j)]);
        it != setup.q0.end())
      q_ref(j) = it->second;
  SceneForces out;
  out.K_s = MatrixXd(m.K) - lin.K_g;
  out.f_s = m.f - lin.tau_g - lin.K_g * q_ref;
  out.D = MatrixXd(m.D);
  return out;
}

sim::Trajectory simulate_multibody(const mech::Model& model, const scene::Scene& setup,
                                   const std::vector<JointLimit>& limits, const VectorXd& x0,
                                   const sim::Options& opt, const WorldSettings& s) {
  sim::Trajectory tr =
      started_run("bullet " + multibody_description(s, !setup.contacts.empty(),
                                                    model.mechanical->has_friction()),
                  x0, opt);
  tr.dynamics = "the URDF's nonlinear multibody (Bullet)";
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  SceneForces forces = scene_forces(setup, m);
  warn(tr, m, forces.K_s, opt, limits);
  std::unique_ptr<MbWorld> w;
  try {
    w = build(setup, m, limits, x0.head(N), x0.tail(N), s);
  } catch (const std::exception& e) {
    return failed_run(std::move(tr), std::string("bullet: ") + e.what());
  }
  w->torques = std::move(forces);
  return run_steps(*w, model, x0, opt, std::move(tr), w->contacts.friction);
}

}  // namespace lcsim::bullet
