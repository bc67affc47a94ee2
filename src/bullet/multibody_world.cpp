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

#include "bullet/multibody_scene.hpp"
#include "bullet/run_recorder.hpp"
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

// Members in construction order, so that destruction runs limits ->
// colliders -> multibody -> world -> solvers.
struct MbWorld {
  std::unique_ptr<btDefaultCollisionConfiguration> config;
  std::unique_ptr<btCollisionDispatcher> dispatcher;
  std::unique_ptr<btDbvtBroadphase> broadphase;
  std::unique_ptr<btDantzigSolver> dantzig;
  std::unique_ptr<btMultiBodyConstraintSolver> solver;
  std::unique_ptr<btMultiBodyDynamicsWorld> world;
  std::unique_ptr<btSphereShape> shape;
  UrdfMultiBody mb;
  std::vector<std::unique_ptr<btMultiBodyLinkCollider>> colliders;
  std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>> limits;
  std::vector<FollowingMimic> mimics;
  std::vector<std::unique_ptr<btMultiBodyGearConstraint>> gears;  // one per mimic
  ~MbWorld() {
    for (auto& c : gears) world->removeMultiBodyConstraint(c.get());
    for (auto& c : limits) world->removeMultiBodyConstraint(c.get());
    for (auto& c : colliders) world->removeCollisionObject(c.get());
    if (mb.body) world->removeMultiBody(mb.body.get());
  }
};

void set_state(btMultiBody& b, const UrdfMultiBody& mb, const std::vector<FollowingMimic>& mimics,
               const VectorXd& q, const VectorXd& v) {
  for (int c = 0; c < q.size(); ++c) {
    b.setJointPos(mb.link[static_cast<std::size_t>(c)], q(c));
    b.setJointVel(mb.link[static_cast<std::size_t>(c)], v(c));
  }
  for (const FollowingMimic& f : mimics) {
    b.setJointPos(f.link, f.a * q(f.leader) + f.b);
    b.setJointVel(f.link, f.a * v(f.leader));
  }
  btAlignedObjectArray<btQuaternion> world_to_local;
  btAlignedObjectArray<btVector3> local_origin;
  world_to_local.resize(b.getNumLinks() + 1);
  local_origin.resize(b.getNumLinks() + 1);
  b.forwardKinematics(world_to_local, local_origin);
  b.updateCollisionObjectWorldTransforms(world_to_local, local_origin);
}

// An empty world with the scene's gravity and the pinned settings (the
// file's header comment).
std::unique_ptr<MbWorld> make_world(const scene::Scene& setup, const WorldSettings& s) {
  auto w = std::make_unique<MbWorld>();
  w->config = std::make_unique<btDefaultCollisionConfiguration>();
  w->dispatcher = std::make_unique<btCollisionDispatcher>(w->config.get());
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  if (s.multibody_mlcp) {
    w->dantzig = std::make_unique<btDantzigSolver>();
    w->solver = std::make_unique<btMultiBodyMLCPConstraintSolver>(w->dantzig.get());
  } else {
    w->solver = std::make_unique<btMultiBodyConstraintSolver>();
  }
  w->world = std::make_unique<btMultiBodyDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                        w->solver.get(), w->config.get());
  w->world->setGravity(btVector3(setup.gravity.x(), setup.gravity.y(), setup.gravity.z()));
  btContactSolverInfo& info = w->world->getSolverInfo();
  info.m_numIterations = s.solver_iterations;
  info.m_erp = s.limit_erp;
  info.m_erp2 = s.limit_erp;
  info.m_globalCfm = 0.0;
  info.m_sor = 1.0;
  info.m_splitImpulse = 0;
  info.m_leastSquaresResidualThreshold = 0.0;
  info.m_solverMode = SOLVER_USE_WARMSTARTING | SOLVER_SIMD;  // no articulated warm start
  return w;
}

// The multibody of the scene's URDF (the coordinates' joints, then their
// mimics), each link with a collider that collides with nothing.
void add_multibody(MbWorld& w, const scene::Scene& setup, const mech::MechanicalModel& m) {
  w.mimics = following_mimics(setup, m.coordinates);
  std::vector<std::string> moving = m.coordinates;
  for (const FollowingMimic& f : w.mimics) moving.push_back(f.joint);
  w.mb = build_urdf_multibody(*setup.urdf, moving, setup.q0);
  for (std::size_t i = 0; i < w.mimics.size(); ++i)
    w.mimics[i].link = w.mb.link[m.coordinates.size() + i];
  btMultiBody& b = *w.mb.body;
  b.setLinearDamping(0);
  b.setAngularDamping(0);
  b.setUseGyroTerm(true);
  b.setMaxCoordinateVelocity(1e30);
  b.setCanSleep(false);
  b.setHasSelfCollision(false);
  b.useGlobalVelocities(false);
  w.world->addMultiBody(&b, btBroadphaseProxy::DefaultFilter, 0);
  w.shape = std::make_unique<btSphereShape>(0.01);
  w.shape->setMargin(0.0);
  for (int i = 0; i < b.getNumLinks(); ++i) {
    auto col = std::make_unique<btMultiBodyLinkCollider>(&b, i);
    col->setCollisionShape(w.shape.get());
    col->setActivationState(DISABLE_DEACTIVATION);
    // Mask 0: the broadphase pairs this collider with nothing.
    w.world->addCollisionObject(col.get(), btBroadphaseProxy::DefaultFilter, 0);
    b.getLink(i).m_collider = col.get();
    w.colliders.push_back(std::move(col));
  }
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

// One btMultiBodyJointLimitConstraint per joint limit: the bound on its side,
// the other side limit_range away.
void add_limits(MbWorld& w, const std::vector<JointLimit>& limits, const WorldSettings& s) {
  for (const JointLimit& L : limits) {
    const double lo = L.lower ? L.bound : L.bound - s.limit_range;
    const double hi = L.lower ? L.bound + s.limit_range : L.bound;
    auto c = std::make_unique<btMultiBodyJointLimitConstraint>(
        w.mb.body.get(), w.mb.link[static_cast<std::size_t>(L.coordinate)], lo, hi);
    // Allocates the rows' storage (else done lazily in the first step, after
    // simulate_multibody has reset the applied impulses).
    c->finalizeMultiDof();
    c->setMaxAppliedImpulse(s.limit_max_impulse);
    w.world->addMultiBodyConstraint(c.get());
    w.limits.push_back(std::move(c));
  }
}

std::unique_ptr<MbWorld> build(const scene::Scene& setup, const mech::MechanicalModel& m,
                               const std::vector<JointLimit>& limits, const VectorXd& q0,
                               const VectorXd& v0, const WorldSettings& s) {
  std::unique_ptr<MbWorld> w = make_world(setup, s);
  add_multibody(*w, setup, m);
  set_state(*w->mb.body, w->mb, w->mimics, q0, v0);
  add_gears(*w);
  add_limits(*w, limits, s);
  return w;
}

// The scene's warnings: what Bullet does differently from lcsim's model
// beyond the step error.
void warn(sim::Trajectory& tr, const mech::MechanicalModel& m, const MatrixXd& K_s,
          const sim::Options& opt) {
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
  for (int i = 0; i < m.num_constraints(); ++i)
    if (m.restitution(i) > 0.0) {
      tr.warn("bullet-restitution-lost", 0.0,
              "bullet: restitution is lost: Bullet's multibody joint limits are inelastic "
              "(btMultiBodyJointLimitConstraint has no bounce); constraint '" +
                  m.constraints[static_cast<std::size_t>(i)] +
                  "' has e = " + short_number(m.restitution(i)));
      break;
    }
}

// The scene's own forces, tau = f_s - K_s q - D v: K and f without the
// linearised gravity (Bullet's world has the nonlinear one).
struct SceneForces {
  MatrixXd K_s, D;
  VectorXd f_s;
};

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

// One Bullet step of length h under the joint torques tau; the state it
// reached.
void step(MbWorld& w, const VectorXd& tau, double h, VectorXd& q_next, VectorXd& v_next) {
  btMultiBody& b = *w.mb.body;
  const auto N = static_cast<int>(tau.size());
  for (int c = 0; c < N; ++c) b.addJointTorque(w.mb.link[static_cast<std::size_t>(c)], tau(c));
  // A limit row exists only in steps that start at or past its bound;
  // its impulse from an earlier step would otherwise be read again.
  for (auto& c : w.limits) {
    c->internalSetAppliedImpulse(0, 0.0);
    c->internalSetAppliedImpulse(1, 0.0);
  }
  // maxSubSteps = 0: exactly one step of length h (no interpolation).
  w.world->stepSimulation(h, 0, h);
  for (int c = 0; c < N; ++c) {
    q_next(c) = b.getJointPos(w.mb.link[static_cast<std::size_t>(c)]);
    v_next(c) = b.getJointVel(w.mb.link[static_cast<std::size_t>(c)]);
  }
}

// The step's impulses by row of E. Row 0 of a limit pushes +q (the lower
// bound), row 1 -q; lcsim's row is c e_j, so the impulse P on the joint is
// |c| h u.
void limit_impulses(const MbWorld& w, const std::vector<JointLimit>& limits, VectorXd& impulse) {
  for (std::size_t i = 0; i < limits.size(); ++i)
    impulse(limits[i].row) =
        w.limits[i]->getAppliedImpulse(limits[i].lower ? 0 : 1) / std::abs(limits[i].c);
}

}  // namespace

std::vector<JointLimit> joint_limits_of(const mech::MechanicalModel& m, const std::string& source) {
  std::vector<JointLimit> out;
  for (int i = 0; i < m.num_constraints(); ++i) {
    std::vector<int> nz;
    for (int j = 0; j < m.dofs(); ++j)
      if (m.E.coeff(i, j) != 0.0) nz.push_back(j);
    if (nz.size() != 1)
      throw std::invalid_argument(
          "bullet: " + (source.empty() ? std::string() : source + ": ") + "constraint '" +
          m.constraints[static_cast<std::size_t>(i)] + "' (row " + std::to_string(i) +
          " of E) involves " + std::to_string(nz.size()) +
          " joints: Bullet's multibody expresses only joint limits (one joint each)");
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

std::string multibody_description(const WorldSettings& s) {
  return std::string("btMultiBody from the URDF, ") +
         (s.multibody_mlcp ? "btMultiBodyMLCPConstraintSolver (btDantzigSolver)"
                           : "btMultiBodyConstraintSolver (" + std::to_string(s.solver_iterations) +
                                 " iterations)") +
         ", btMultiBodyJointLimitConstraint limits (ERP " + short_number(s.limit_erp) +
         ", max impulse " + short_number(s.limit_max_impulse) + ")";
}

sim::Trajectory simulate_multibody(const mech::Model& model, const scene::Scene& setup,
                                   const std::vector<JointLimit>& limits, const VectorXd& x0,
                                   const sim::Options& opt, const WorldSettings& s) {
  sim::Trajectory tr;
  tr.method = "bullet " + multibody_description(s);
  tr.dynamics = "the URDF's nonlinear multibody (Bullet)";
  tr.t_end = *opt.t_end;
  tr.final_state = x0;
  auto fail = [&](const std::string& msg) {
    tr.status = sim::RunStatus::kNumericalFailure;
    tr.message = msg;
    return std::move(tr);  // only ever returned from the run: no copy of the samples
  };
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs(), k = m.num_constraints();

  const SceneForces forces = scene_forces(setup, m);
  const MatrixXd &K_s = forces.K_s, &D = forces.D;
  const VectorXd& f_s = forces.f_s;
  warn(tr, m, K_s, opt);

  VectorXd q = x0.head(N), v = x0.tail(N);
  std::unique_ptr<MbWorld> w;
  try {
    w = build(setup, m, limits, q, v, s);
  } catch (const std::exception& e) {
    return fail(std::string("bullet: ") + e.what());
  }
  RunRecorder rec(model, opt, tr, q, v);
  const sim::StepGrid grid = sim::StepGrid::of(*opt.t_end, opt.h);
  VectorXd tau(N), q_next(N), v_next(N), impulse(k);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    if (opt.progress && j % sim::Options::kProgressSteps == 0) opt.progress(j * opt.h);
    const double h = last ? grid.h_last : grid.h;
    tau = f_s - K_s * q - D * v;
    step(*w, tau, h, q_next, v_next);
    limit_impulses(*w, limits, impulse);
    // Round-off in an impulse is ~1e-16 of the momentum; real ones are O(h).
    const double tiny =
        1e-10 * (1.0 + (m.M * v).cwiseAbs().maxCoeff() + h * tau.cwiseAbs().maxCoeff());
    if (std::string why =
            rec.step(last ? *opt.t_end : j * opt.h, h, last, q_next, v_next, impulse, tiny);
        !why.empty())
      return fail("bullet: " + why);
    q = q_next;
    v = v_next;
  }
  rec.finish();
  return tr;
}

}  // namespace lcsim::bullet
