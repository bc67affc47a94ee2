// A block sliding on a rough floor in Bullet: a btBoxShape rigid body on a
// btStaticPlaneShape, btDiscreteDynamicsWorld with
// btSequentialImpulseConstraintSolver at a fixed step (issue 17). The block's
// parameters come from friction_block.cpp.
//
// Scene. Bullet's y is up: the floor is the plane y = 0 (normal (0, 1, 0));
// the box (half extents w, hh, w) starts with its bottom face on it, centre
// at (x0, hh, 0), velocity (v0, 0, 0); gravity (0, -g, 0). x is the model's
// q_t, the lowest corner's height its gap.
//
// Every Bullet setting that matters, and why (Bullet 3.24 sources,
// btSequentialImpulseConstraintSolver.cpp, btManifoldResult.cpp,
// btConvexPlaneCollisionAlgorithm.cpp):
// - Friction. Each contact point gets m_combinedFriction = the PRODUCT of the
//   two bodies' m_friction (calculateCombinedFriction, clamped to 10): the box
//   has mu and the plane 1, so the point's coefficient is mu (mu on both
//   would be mu^2). A friction row's impulse is clamped to
//   +-m_combinedFriction x the normal impulse of the same point in the same
//   sweep, so with every point sliding the total friction is mu x the total
//   normal impulse: Coulomb's law of the model.
// - Friction directions: velocity dependent (Bullet's default): the first
//   direction is the sliding direction (x) whenever |v_lat|^2 > SIMD_EPSILON;
//   SOLVER_USE_2_FRICTION_DIRECTIONS adds the second (z) so that the box is
//   held across the floor too (a pyramid: each direction clamped on its own;
//   the motion is along x, where the bound is exactly mu N).
// - Rolling and spinning friction 0 (m_rollingFriction, m_spinningFriction):
//   the model has none (with 0 Bullet adds no torsional rows).
// - Restitution 0 on both bodies (the product is 0): the block never bounces.
// - Split impulse on with m_splitImpulsePenetrationThreshold 0: a penetration
//   (round-off here) is corrected by Bullet's pseudo velocities, never by
//   adding ERP x depth / h to the real normal impulse, which would raise the
//   friction bound mu N above mu m g h. m_erp2 (0.2, Bullet's default) then
//   only scales those pseudo velocities.
// - Contact points: btDefaultCollisionConfiguration's convex-plane algorithm
//   adds one point per step (the deepest support vertex; a flat box has four
//   equally deep), and the persistent manifold drops its points together once
//   the box has slid the breaking threshold (0.02 m) past them.
//   setPlaneConvexMultipointIterations(n, n) (settings.multipoint_iterations,
//   8) also collides n copies of the box tilted towards directions 360/n
//   degrees apart whenever the manifold holds fewer than n points: with
//   n = 8 > 4 at every step, and the diagonal tilts find each corner, so the
//   bottom face is held at its 4 corners at every step. Measured
//   (docs/friction.md): n = 8 gives 4 points at every step and a box
//   that never tilts; n = 3 or 4 leave it on 1 to 4 points, on one corner for
//   a step every 0.02 m, where friction below the centre tips it (tilt 0.034
//   rad at h = 1e-2; it then rocks and does not stop within the horizon).
// - Rotation: free (a btBoxShape rigid body) unless settings.free_rotation is
//   false (angular factor 0: the model's two coordinates only).
// - Contact processing threshold: Bullet's default (BT_LARGE_FLOAT): points
//   up to the breaking threshold (0.02 m) above the floor stay in the solver as
//   speculative rows (approach at most distance / h), so a corner lifted by
//   round-off is still held rather than dropped for a step.
// - Collision margin: btBoxShape's default 0.04 m lies inside the half
//   extents (the box keeps its size; its edges are rounded), hence half
//   extents > 0.04 (friction_box_settings_error).
// - Solver: m_numIterations from the settings, m_leastSquaresResidualThreshold
//   0 (no early exit), m_sor 1, m_globalCfm 0, warm starting (Bullet's
//   default, factor 0.85; friction rows start from 0 every step).
// - Step: stepSimulation(h, 0, h): exactly one step of h, no substeps and no
//   interpolation; the last step is shortened to land on t_end (sim::StepGrid).
// - No damping, no sleeping (DISABLE_DEACTIVATION): a block at rest would
//   otherwise be frozen by Bullet rather than held by friction.
#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletCollision/NarrowPhaseCollision/btPersistentManifold.h>
#include <btBulletDynamicsCommon.h>

#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/core/format.hpp>
#include <memory>
#include <string>

#include "bullet/pipeline.hpp"

namespace lcsim::bullet {

namespace {

// btBoxShape's collision margin (Bullet's default, CONVEX_DISTANCE_MARGIN).
constexpr double kBoxMargin = 0.04;

// Members in construction order, so that destruction runs bodies, then the
// Pipeline's world -> solver -> broadphase -> dispatcher -> config.
struct BoxWorld : Pipeline<btSequentialImpulseConstraintSolver, btDiscreteDynamicsWorld> {
  std::unique_ptr<btStaticPlaneShape> plane_shape;
  std::unique_ptr<btBoxShape> box_shape;
  std::unique_ptr<btRigidBody> plane, box;
  ~BoxWorld() {
    if (box) world->removeRigidBody(box.get());
    if (plane) world->removeRigidBody(plane.get());
  }
};

void pin_solver(btContactSolverInfo& info, int iterations) {
  info.m_numIterations = iterations;
  info.m_splitImpulse = 1;
  info.m_splitImpulsePenetrationThreshold = 0.0;
  info.m_erp2 = 0.2;
  info.m_globalCfm = 0.0;
  info.m_sor = 1.0;
  info.m_restitution = 0.0;
  info.m_leastSquaresResidualThreshold = 0.0;
  info.m_solverMode = SOLVER_USE_WARMSTARTING | SOLVER_SIMD | SOLVER_USE_2_FRICTION_DIRECTIONS;
}

std::unique_ptr<btRigidBody> body(double mass, btCollisionShape* shape, const btVector3& origin,
                                  double friction) {
  btVector3 inertia(0, 0, 0);
  if (mass > 0.0) shape->calculateLocalInertia(mass, inertia);
  btRigidBody::btRigidBodyConstructionInfo ci(mass, nullptr, shape, inertia);
  ci.m_startWorldTransform.setIdentity();
  ci.m_startWorldTransform.setOrigin(origin);
  ci.m_friction = friction;
  ci.m_rollingFriction = 0.0;
  ci.m_spinningFriction = 0.0;
  ci.m_restitution = 0.0;
  ci.m_linearDamping = 0.0;
  ci.m_angularDamping = 0.0;
  auto b = std::make_unique<btRigidBody>(ci);
  b->setActivationState(DISABLE_DEACTIVATION);
  return b;
}

std::unique_ptr<BoxWorld> build(const FrictionBlock& b, const FrictionBoxSettings& s) {
  auto w = std::make_unique<BoxWorld>();
  w->config = std::make_unique<btDefaultCollisionConfiguration>();
  if (s.multipoint_iterations > 0)
    w->config->setPlaneConvexMultipointIterations(s.multipoint_iterations, s.multipoint_iterations);
  w->dispatcher = std::make_unique<btCollisionDispatcher>(w->config.get());
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  w->solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  w->world = std::make_unique<btDiscreteDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                       w->solver.get(), w->config.get());
  // Bodies copy the world's gravity when added: set it first.
  w->world->setGravity(btVector3(0, -b.gravity, 0));
  pin_solver(w->world->getSolverInfo(), s.solver_iterations);
  w->plane_shape = std::make_unique<btStaticPlaneShape>(btVector3(0, 1, 0), 0.0);
  w->box_shape = std::make_unique<btBoxShape>(btVector3(s.half_width, s.half_height, s.half_width));
  w->plane = body(0.0, w->plane_shape.get(), btVector3(0, 0, 0), 1.0);
  w->box = body(b.mass, w->box_shape.get(), btVector3(b.x0, s.half_height, 0), b.mu);
  w->box->setLinearVelocity(btVector3(b.v0, 0, 0));
  if (!s.free_rotation) w->box->setAngularFactor(btVector3(0, 0, 0));
  w->world->addRigidBody(w->plane.get());
  w->world->addRigidBody(w->box.get());
  return w;
}

// The box's state and the step's contact impulses on it.
FrictionBoxSample observe(const BoxWorld& w, const FrictionBoxSettings& s, double t, double h) {
  FrictionBoxSample out;
  out.t = t;
  const btTransform& tf = w.box->getWorldTransform();
  out.x = tf.getOrigin().x();
  out.v = w.box->getLinearVelocity().x();
  const btMatrix3x3& R = tf.getBasis();
  out.gap =
      tf.getOrigin().y() - (std::abs(R[1][0]) * s.half_width + std::abs(R[1][1]) * s.half_height +
                            std::abs(R[1][2]) * s.half_width);
  out.tilt = tf.getRotation().getAngle();
  if (h <= 0.0) return out;
  btVector3 impulse(0, 0, 0);
  for (int i = 0; i < w.dispatcher->getNumManifolds(); ++i) {
    const btPersistentManifold* mf = w.dispatcher->getManifoldByIndexInternal(i);
    // Impulses act on body 0 along +normal/+directions, on body 1 opposite.
    const double sign = mf->getBody0() == w.box.get() ? 1.0 : -1.0;
    for (int p = 0; p < mf->getNumContacts(); ++p) {
      const btManifoldPoint& cp = mf->getContactPoint(p);
      impulse += sign * (cp.m_normalWorldOnB * cp.m_appliedImpulse +
                         cp.m_lateralFrictionDir1 * cp.m_appliedImpulseLateral1 +
                         cp.m_lateralFrictionDir2 * cp.m_appliedImpulseLateral2);
    }
    out.contact_points += mf->getNumContacts();
  }
  out.normal_force = impulse.y() / h;
  out.friction_force = impulse.x() / h;
  return out;
}

FrictionBoxRun refused(const FrictionBlock& b, std::string why) {
  FrictionBoxRun r;
  r.block = b;
  r.status = Status::kInvalidInput;
  r.message = std::move(why);
  return r;
}

}  // namespace

std::string friction_box_settings_error(const FrictionBoxSettings& s, double t_end) {
  auto bad = [](const char* name, double value, const std::string& rule) {
    return std::string("bullet friction box: setting ") + name + " must be " + rule + " (got " +
           short_number(value) + ")";
  };
  if (!(std::isfinite(s.h) && s.h > 0.0)) return bad("h", s.h, "finite and > 0");
  if (std::isfinite(t_end) && t_end / s.h > 1e8)
    return bad("h", s.h, "at least t_end / 1e8 = " + short_number(t_end / 1e8));
  if (s.solver_iterations < 1) return bad("solver_iterations", s.solver_iterations, ">= 1");
  const std::string above_margin = "finite and > btBoxShape's margin " + short_number(kBoxMargin);
  if (!(std::isfinite(s.half_width) && s.half_width > kBoxMargin))
    return bad("half_width", s.half_width, above_margin);
  if (!(std::isfinite(s.half_height) && s.half_height > kBoxMargin))
    return bad("half_height", s.half_height, above_margin);
  if (s.multipoint_iterations < 0 || s.multipoint_iterations > 64)
    return bad("multipoint_iterations", s.multipoint_iterations, "in [0, 64]");
  if (!(std::isfinite(s.stop_velocity) && s.stop_velocity >= 0.0))
    return bad("stop_velocity", s.stop_velocity, "finite and >= 0");
  return "";
}

FrictionBoxRun simulate_friction_box(const FrictionBlock& b, const FrictionBoxSettings& s) {
  if (std::string why = friction_block_error(b); !why.empty()) return refused(b, why);
  if (std::string why = friction_box_settings_error(s, b.t_end); !why.empty())
    return refused(b, why);
  FrictionBoxRun r;
  r.block = b;
  const sim::StepGrid grid = sim::StepGrid::of(b.t_end, s.h);
  const std::unique_ptr<BoxWorld> w = build(b, s);
  r.samples.reserve(static_cast<std::size_t>(grid.n) + 1);
  r.samples.push_back(observe(*w, s, 0.0, 0.0));
  for (long j = 1; j <= grid.n; ++j) {
    const double h = j == grid.n ? grid.h_last : grid.h;
    // maxSubSteps = 0: exactly one step of length h.
    w->world->stepSimulation(h, 0, h);
    const FrictionBoxSample smp = observe(*w, s, j == grid.n ? b.t_end : j * grid.h, h);
    if (!std::isfinite(smp.x) || !std::isfinite(smp.v) || !std::isfinite(smp.gap)) {
      r.status = Status::kNumericalFailure;
      r.message = "bullet friction box: non-finite state at t = " + short_number(smp.t);
      return r;
    }
    r.samples.push_back(smp);
  }
  std::vector<double> t, x, v;
  for (const FrictionBoxSample& smp : r.samples) {
    t.push_back(smp.t);
    x.push_back(smp.x);
    v.push_back(smp.v);
  }
  r.stop = slide_stop(t, x, v, s.stop_velocity);
  return r;
}

FrictionBoxRun simulate_friction_box(const mech::Model& model, const FrictionBoxSettings& s) {
  const FrictionBlockOf of = friction_block_of(model);
  if (of.status != Status::kOk) return refused(of.block, of.message);
  return simulate_friction_box(of.block, s);
}

}  // namespace lcsim::bullet
