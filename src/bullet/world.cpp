// The lcsim mechanical model built in Bullet ("rb6" of ../shared/notes/bullet.md)
// and run with Bullet's fixed step. simulate_bullet (at the end) chooses
// between this scene and the multibody of a URDF scene (multibody_world.cpp).
//
// Scene. One btRigidBody per coordinate q_j, mass M_jj, linear factor (1,0,0),
// angular factor 0, placed at x = q_j; bodies never collide (broadphase mask 0),
// so only the constraints below act. A stop c q_j + g >= 0 is a 6DOF2 linear
// limit between btTypedConstraint::getFixedBody() (at the world origin) and body
// j on q_j; a hook c (q_a - q_b) + g >= 0 (c > 0) is a 6DOF2 limit between
// bodies a and b on q_b - q_a <= g / c. The other five axes are free (lower >
// upper).
//
// Forces. Before every step each body j gets the force
//   F_j = (f - K q - D v)_j,
// the generalised force of the model. Since each body moves only along x and
// body j's position is q_j, the virtual work of a force F on body j is F δq_j:
// the generalised force of coordinate j is the x-force on body j. A spring of
// stiffness k between coordinates a and b (or a and the wall) has potential
// ½ k (q_a - q_b)^2, and the sum of these potentials is ½ q'Kq for the
// assembled K; its forces are -∂V/∂q = -K q, entry j being the sum of the
// spring forces on body j. So -K q applied to the bodies is exactly the spring
// network (and for a general symmetric K, the force of the potential ½ q'Kq),
// -D v the dampers, f the constant forces (gravity included: the world's
// gravity is set to zero before any body is added, since bodies copy it).
//
// Step. Bullet's btDiscreteDynamicsWorld step is semi-implicit Euler:
// v+ = v + h M^{-1} F(q, v) + constraint impulse / m, q+ = q + h v+; forces are
// explicit, hence first order in h (notes: S1 2.09e-4 at h = 1e-3).
//
// Settings pinned (WorldSettings and below): solver
// btSequentialImpulseConstraintSolver, iterations, stop ERP/CFM per limit,
// global ERP 0.2 and CFM 0 (the 6DOF2 limits use their own stop ERP/CFM),
// split impulse off, restitution threshold 0, contact processing threshold 0
// (speculative contacts off), least-squares early exit off, no sleeping, no
// damping. The last four only matter for contacts, of which there are none:
// they are pinned so that the scene does not depend on Bullet's defaults.
// Restitution: a limit's bounce is the model's coefficient e_i (6DOF2 bounce is
// applied without velocity threshold).
#include <BulletCollision/CollisionDispatch/btSimulationIslandManager.h>
#include <BulletDynamics/ConstraintSolver/btGeneric6DofSpring2Constraint.h>
#include <BulletDynamics/ConstraintSolver/btSequentialImpulseConstraintSolver.h>
#include <btBulletDynamicsCommon.h>

#include <Eigen/SparseQR>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/core/format.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <memory>
#include <optional>
#include <stdexcept>
#include <utility>

#include "bullet/multibody_scene.hpp"
#include "bullet/pipeline.hpp"
#include "bullet/run_recorder.hpp"
#include "bullet/step_loop.hpp"

namespace lcsim::bullet {

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// Messages print numbers as every integrator does.

// One row of E as Bullet sees it.
struct Limit {
  int a = -1, b = -1;         // stop: body b against the world (a = -1); hook: bodies a, b
  double lo = 0.0, hi = 0.0;  // range of (x_b - x_a) (stop: x_b)
};

Limit classify(const mech::MechanicalModel& m, int i, double range) {
  const int N = m.dofs();
  std::vector<int> nz;
  double scale = 0.0;
  for (int j = 0; j < N; ++j)
    if (m.E.coeff(i, j) != 0.0) {
      nz.push_back(j);
      scale = std::max(scale, std::abs(m.E.coeff(i, j)));
    }
  const std::string who =
      "constraint '" + m.constraints[i] + "' (row " + std::to_string(i) + " of E)";
  Limit L;
  if (nz.size() == 1) {
    const int j = nz[0];
    const double c = m.E.coeff(i, j), bound = -m.g(i) / c;
    L.b = j;
    if (c > 0) {  // q_j >= -g/c
      L.lo = bound;
      L.hi = bound + range;
    } else {  // q_j <= -g/c
      L.lo = bound - range;
      L.hi = bound;
    }
    return L;
  }
  if (nz.size() == 2) {
    const double c0 = m.E.coeff(i, nz[0]), c1 = m.E.coeff(i, nz[1]);
    if (std::abs(c0 + c1) <= 1e-12 * scale) {
      // c (q_a - q_b) + g >= 0 with c > 0  <=>  q_b - q_a <= g / c.
      const int a = c0 > 0 ? nz[0] : nz[1], b = c0 > 0 ? nz[1] : nz[0];
      const double c = std::abs(c0);
      L.a = a;
      L.b = b;
      L.hi = m.g(i) / c;
      L.lo = L.hi - range;
      return L;
    }
    throw std::invalid_argument(
        "bullet: " + who + " has coefficients " + short_number(c0) + " and " + short_number(c1) +
        ": a Bullet limit needs opposite coefficients (a hook c (q_a - q_b) + g >= 0)");
  }
  throw std::invalid_argument("bullet: " + who + " involves " + std::to_string(nz.size()) +
                              " coordinates: a Bullet limit takes one (a stop) or two (a hook)");
}

std::vector<Limit> limits_of(const mech::Model& model, double range) {
  if (!model.is_mechanical())
    throw std::invalid_argument("bullet: '" + model.name +
                                "' is a general LCS: the Bullet scene needs a mechanical model");
  const mech::MechanicalModel& m = *model.mechanical;
  double mscale = 0.0;
  for (int c = 0; c < m.M.outerSize(); ++c)
    for (mech::SparseMatrix::InnerIterator it(m.M, c); it; ++it)
      mscale = std::max(mscale, std::abs(it.value()));
  for (int c = 0; c < m.M.outerSize(); ++c)
    for (mech::SparseMatrix::InnerIterator it(m.M, c); it; ++it)
      if (it.row() != c && std::abs(it.value()) > 1e-14 * mscale)
        throw std::invalid_argument(
            "bullet: M(" + std::to_string(it.row()) + ", " + std::to_string(c) +
            ") = " + short_number(it.value()) +
            ": one rigid body per coordinate needs a diagonal M (a non-diagonal M runs in "
            "Bullet only as a URDF scene, whose multibody Bullet builds from the URDF)");
  std::vector<Limit> out;
  for (int i = 0; i < m.num_constraints(); ++i) out.push_back(classify(m, i, range));
  return out;
}

// Multipliers from the momentum balance M (v+ - v) = h F + E' (h u):
// h u = least-squares solution of E' x = M (v+ - v) - h F, exact when E has
// full row rank (with dependent rows, one basic solution: the split of an
// impulse among them is not unique). A sparse QR of E' (O(nnz) per step
// for a chain); the dense decomposition it replaces cost O(N k) per step
// and O(N k^2) to set up, and was most of the "Bullet" time at N = 1000.
using TransposeQR = Eigen::SparseQR<mech::SparseMatrix, Eigen::COLAMDOrdering<int>>;

// The Bullet world (the step loop's calls, step_loop.hpp, just before
// simulate_rb6: the model's forces, Bullet's step, the multipliers from the
// momentum balance); members in construction order so that destruction
// runs constraints -> bodies, then the Pipeline's world -> solver -> ... .
struct World : Pipeline<btSequentialImpulseConstraintSolver, btDiscreteDynamicsWorld> {
  std::unique_ptr<btSphereShape> shape;
  std::vector<std::unique_ptr<btRigidBody>> bodies;
  std::vector<std::unique_ptr<btGeneric6DofSpring2Constraint>> constraints;
  const mech::MechanicalModel* m = nullptr;  // the model the world is built from
  TransposeQR Et;                            // E' factored (factor_transpose)
  ~World() {
    for (auto& c : constraints) world->removeConstraint(c.get());
    for (auto& b : bodies) world->removeRigidBody(b.get());
  }
};

// An empty world with the pinned settings (the file's header comment).
std::unique_ptr<World> make_world(const WorldSettings& s) {
  auto w = std::make_unique<World>();
  w->config = std::make_unique<btDefaultCollisionConfiguration>();
  w->dispatcher = std::make_unique<btCollisionDispatcher>(w->config.get());
  w->broadphase = std::make_unique<btDbvtBroadphase>();
  w->solver = std::make_unique<btSequentialImpulseConstraintSolver>();
  w->world = std::make_unique<btDiscreteDynamicsWorld>(w->dispatcher.get(), w->broadphase.get(),
                                                       w->solver.get(), w->config.get());
  // One solver group for the whole world. With split islands (the default)
  // btDiscreteDynamicsWorld scans every constraint for each island to find
  // its own, O(islands x constraints) per step; in a chain with stops but no
  // hooks every cart is an island (limits to the fixed body join nothing), so
  // that was O(N^2): 46% of the time at N = 1000. Islands are decoupled, so
  // solving them as one group does the same sequential-impulse sweeps.
  w->world->getSimulationIslandManager()->setSplitIslands(false);
  // Gravity first: bodies copy the world's gravity when added (default -10 y).
  w->world->setGravity(btVector3(0, 0, 0));
  btContactSolverInfo& info = w->world->getSolverInfo();
  info.m_numIterations = s.solver_iterations;
  info.m_erp = 0.2;
  info.m_erp2 = 0.2;
  info.m_globalCfm = 0.0;
  info.m_sor = 1.0;
  info.m_splitImpulse = 0;
  info.m_restitutionVelocityThreshold = 0.0;
  info.m_leastSquaresResidualThreshold = 0.0;
  info.m_solverMode = SOLVER_USE_WARMSTARTING | SOLVER_SIMD;
  return w;
}

// One body per coordinate j, of mass M_jj, at x = q0_j moving at v0_j.
void add_bodies(World& w, const mech::MechanicalModel& m, const VectorXd& q0, const VectorXd& v0) {
  w.shape = std::make_unique<btSphereShape>(0.05);
  w.shape->setMargin(0.0);
  for (int j = 0; j < m.dofs(); ++j) {
    btTransform tf;
    tf.setIdentity();
    // Coordinate j moves along x only; bodies sit 1 m apart in y so that no
    // two bounding spheres overlap and the dynamic AABB tree
    // (btDbvtBroadphase) finds no pairs: with every body near the origin it
    // walked and cached all N^2/2 overlapping pairs each step (mask 0 only
    // rejects them afterwards). y is free in every limit and never read back.
    tf.setOrigin(btVector3(q0(j), static_cast<double>(j), 0));
    btRigidBody::btRigidBodyConstructionInfo ci(m.M.coeff(j, j), nullptr, w.shape.get(),
                                                btVector3(1, 1, 1));
    ci.m_startWorldTransform = tf;
    ci.m_linearDamping = 0.0;
    ci.m_angularDamping = 0.0;
    ci.m_friction = 0.0;
    ci.m_restitution = 0.0;
    auto body = std::make_unique<btRigidBody>(ci);
    body->setLinearFactor(btVector3(1, 0, 0));
    body->setAngularFactor(btVector3(0, 0, 0));
    body->setLinearVelocity(btVector3(v0(j), 0, 0));
    body->setActivationState(DISABLE_DEACTIVATION);
    body->setSleepingThresholds(0.0, 0.0);
    body->setContactProcessingThreshold(0.0);
    // Mask 0: the broadphase pairs this body with nothing.
    w.world->addRigidBody(body.get(), btBroadphaseProxy::DefaultFilter, 0);
    w.bodies.push_back(std::move(body));
  }
}

// One 6DOF2 limit per row of E, on x only, bouncing with the row's e.
void add_limits(World& w, const mech::MechanicalModel& m, const std::vector<Limit>& limits,
                const WorldSettings& s) {
  const int k = static_cast<int>(limits.size());
  for (int i = 0; i < k; ++i) {
    const Limit& L = limits[i];
    btTransform id;
    id.setIdentity();
    btRigidBody& A = L.a < 0 ? btTypedConstraint::getFixedBody() : *w.bodies[L.a];
    auto c = std::make_unique<btGeneric6DofSpring2Constraint>(A, *w.bodies[L.b], id, id);
    c->setLinearLowerLimit(btVector3(L.lo, 1, 1));  // y, z free (lower > upper)
    c->setLinearUpperLimit(btVector3(L.hi, 0, 0));
    c->setAngularLowerLimit(btVector3(1, 1, 1));  // rotations free
    c->setAngularUpperLimit(btVector3(0, 0, 0));
    c->setParam(BT_CONSTRAINT_STOP_ERP, s.stop_erp, 0);
    c->setParam(BT_CONSTRAINT_STOP_CFM, s.stop_cfm, 0);
    const double e = m.restitution.size() == k ? m.restitution(i) : 0.0;
    c->setBounce(0, e);
    w.world->addConstraint(c.get(), true);
    w.constraints.push_back(std::move(c));
  }
}

std::unique_ptr<World> build(const mech::MechanicalModel& m, const std::vector<Limit>& limits,
                             const VectorXd& q0, const VectorXd& v0, const WorldSettings& s) {
  std::unique_ptr<World> w = make_world(s);
  add_bodies(*w, m, q0, v0);
  add_limits(*w, m, limits, s);
  return w;
}

// The scene `model` was loaded from when it has a floating or placed base or
// contacts (which scene::scene_setup leaves out) and `model` is still what
// that file gives (M, D, K, E, g, f and the names; the restitution is the
// model's own); else nullopt.
std::optional<scene::Scene> contact_scene_of(const mech::Model& model) {
  std::optional<scene::Scene> sc = scene::scene_of(model);
  // One URDF (a scene of bodies runs as its matrices, or is refused), with a
  // floating or placed base or contacts (else scene_setup's multibody).
  if (!sc || !sc->bodies.empty() ||
      (!sc->base.floating && sc->base.pose.matrix() == Eigen::Matrix4d::Identity() &&
       sc->contacts.empty()))
    return std::nullopt;
  return sc;
}

// The scene of several bodies `model` was loaded from (and still is), else
// nullopt.
std::optional<scene::Scene> bodies_scene_of(const mech::Model& model) {
  std::optional<scene::Scene> sc = scene::scene_of(model);
  if (!sc || sc->bodies.empty()) return std::nullopt;
  return sc;
}

// Which scene runs a model: the multibody for a URDF scene whose rows are
// all joint limits; else rb6 (a scene's matrices included, with a warning);
// std::invalid_argument when neither can express it.
struct Plan {
  std::optional<scene::Scene> scene;   // set: the multibody
  std::optional<scene::Scene> bodies;  // set: a scene of several bodies (bodies_world.cpp)
  std::vector<JointLimit> joint_limits;
  std::vector<Limit> rb6_limits;
  std::string warning;
};

Plan plan_of(const mech::Model& model, const WorldSettings& s) {
  Plan p;
  std::optional<scene::Scene> setup =
      model.is_mechanical() ? scene::scene_setup(model) : std::nullopt;
  if (!setup && model.is_mechanical()) {
    if (std::optional<scene::Scene> b = bodies_scene_of(model)) {
      if (std::string why = bodies_refusal(*b); !why.empty())
        throw std::invalid_argument("bullet: " + model.source + ": " + why);
      p.joint_limits = bodies_joint_limits(*model.mechanical, *b);
      p.bodies = std::move(b);
      return p;
    }
    // scene::scene_setup hands over scenes with a fixed root at the identity
    // and no contacts only; the multibody builds the others too.
    if (std::optional<scene::Scene> c = contact_scene_of(model)) {
      if (std::string why = link_friction_error(*c, *model.mechanical); !why.empty())
        throw std::invalid_argument("bullet: " + model.source + ": " + why);
      p.joint_limits = joint_limits_of(*model.mechanical, model.source, &*c);
      p.scene = std::move(c);
      return p;
    }
  }
  // Friction is Bullet's own at a contact scene's contacts (above); the
  // rigid bodies of a matrix model and a scene without contacts have no
  // place for it, and would drop it silently.
  if (model.is_mechanical() && model.mechanical->has_friction())
    throw std::invalid_argument(
        "bullet: " + (model.source.empty() ? "model '" + model.name + "'" : model.source) +
        ": mechanical.friction on a model that is not a URDF contact scene: Bullet runs "
        "friction at a scene's contacts only (methods 'event', 'moreau-jean' and 'euler' simulate "
        "it)");
  if (!setup) {
    p.rb6_limits = limits_of(model, s.limit_range);
    return p;
  }
  try {
    p.joint_limits = joint_limits_of(*model.mechanical, model.source);
    p.scene = std::move(setup);
    return p;
  } catch (const std::invalid_argument& not_limits) {
    try {
      p.rb6_limits = limits_of(model, s.limit_range);
    } catch (const std::invalid_argument&) {
      throw not_limits;  // the scene's own reason
    }
    p.warning = std::string(not_limits.what()) +
                "; Bullet runs the scene's linearised matrices instead (one rigid body per "
                "coordinate), not the URDF's dynamics";
    return p;
  }
}

std::string rb6_description(const WorldSettings& s) {
  return "btSequentialImpulseConstraintSolver (" + std::to_string(s.solver_iterations) +
         " iterations), btGeneric6DofSpring2Constraint limits (stop ERP " +
         short_number(s.stop_erp) + ")";
}

}  // namespace

std::string solver_description(const mech::Model& model, const WorldSettings& s) {
  const Plan p = plan_of(model, s);
  if (p.bodies) return bodies_description(s, model.mechanical->has_friction());
  return p.scene ? multibody_description(s, !p.scene->contacts.empty(),
                                         model.mechanical->has_friction())
                 : rb6_description(s);
}

void check_expressible(const mech::Model& model) { (void)plan_of(model, WorldSettings{}); }

namespace {

// Springs are explicit forces too (symplectic Euler): stable for omega h <= 2
// with omega the fastest frequency, bounded here by Gershgorin on M^-1 K
// (M is diagonal in this scene).
void warn_explicit_springs(sim::Trajectory& tr, const mech::MechanicalModel& m, double h) {
  double w2 = 0.0;
  for (int j = 0; j < m.dofs(); ++j) {
    double row = 0.0;
    for (mech::SparseMatrix::InnerIterator it(m.K, j); it; ++it) row += std::abs(it.value());
    w2 = std::max(w2, row / m.M.coeff(j, j));  // K symmetric: column sums = row sums
  }
  if (std::sqrt(w2) * h > 2.0)
    tr.warn("bullet-explicit-springs", 0.0,
            "bullet: springs are explicit forces -K q, unstable for omega h > 2: omega <= " +
                short_number(std::sqrt(w2)) + " rad/s gives omega h up to " +
                short_number(std::sqrt(w2) * h) + " at h = " + short_number(h) +
                "; expect growth, or reduce h");
}

// Measured (a ball dropped on a 6DOF2 lower limit, e = 0.5, h = 1e-3,
// Bullet 3.24 from Debian): no rebound at the pinned stop ERP 0.2 (nor at
// e = 0.9 or 1), 1.71 m/s of the 2.22 expected at ERP 0.8, 2.11 at ERP 1.
// lcsim keeps ERP 0.2 (what the comparisons were measured with) and says so.
void warn_restitution_lost(sim::Trajectory& tr, const mech::MechanicalModel& m,
                           const WorldSettings& s) {
  for (int i = 0; i < m.num_constraints(); ++i)
    if (m.restitution(i) > 0.0 && s.stop_erp < 1.0) {
      tr.warn("bullet-restitution-lost", 0.0,
              "bullet: restitution is lost or reduced: Bullet 3.24 applies a limit's bounce "
              "only near stop ERP 1 (this scene uses " +
                  short_number(s.stop_erp) + "; at 0.2 nothing rebounds); constraint '" +
                  m.constraints[i] + "' has e = " + short_number(m.restitution(i)));
      break;
    }
}

// Factors E' into `Et` (nothing without constraints); false if it fails.
bool factor_transpose(const mech::MechanicalModel& m, TransposeQR& Et) {
  const int N = m.dofs(), k = m.num_constraints();
  if (k == 0) return true;
  const mech::SparseMatrix Etm = m.E.transpose();
  Et.setPivotThreshold(static_cast<double>(std::max(N, k)) * 1e-12 *
                       (m.E.norm() > 0.0 ? m.E.norm() : 1.0));
  Et.compute(Etm);
  return Et.info() == Eigen::Success;
}

// The step loop's calls (step_loop.hpp).

void step_forces(World& w, const VectorXd& q, const VectorXd& v, VectorXd& F) {
  F = w.m->f - w.m->K * q - w.m->D * v;
}

// One Bullet step of length h under the forces F; the state it reached.
void take_step(World& w, const VectorXd& /*q*/, const VectorXd& F, double h, VectorXd& q_next,
               VectorXd& v_next) {
  const auto N = static_cast<int>(F.size());
  for (int i = 0; i < N; ++i) w.bodies[i]->applyCentralForce(btVector3(F(i), 0, 0));
  // maxSubSteps = 0: exactly one step of length h (no interpolation).
  w.world->stepSimulation(h, 0, h);
  for (int i = 0; i < N; ++i) {
    q_next(i) = w.bodies[i]->getCenterOfMassPosition().x();
    v_next(i) = w.bodies[i]->getLinearVelocity().x();
  }
}

// The multipliers of the momentum balance (TransposeQR); no friction.
bool step_impulses(World& w, const StepTaken& s, VectorXd& impulse, VectorXd& /*t1*/,
                   VectorXd& /*t2*/) {
  impulse.setZero();
  if (w.m->num_constraints() > 0)
    impulse = w.Et.solve(VectorXd(w.m->M * (s.v_next - s.v) - s.h * s.F));
  return false;
}

sim::Trajectory simulate_rb6(const mech::Model& model, const std::vector<Limit>& limits,
                             const VectorXd& x0, const sim::Options& opt, const WorldSettings& s) {
  sim::Trajectory tr = started_run("bullet " + rb6_description(s), x0, opt);
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs();
  warn_explicit_damping(tr, m, opt.h, "forces");
  warn_explicit_springs(tr, m, opt.h);
  warn_restitution_lost(tr, m, s);
  std::unique_ptr<World> w = build(m, limits, x0.head(N), x0.tail(N), s);
  w->m = &m;
  if (!factor_transpose(m, w->Et))
    return failed_run(std::move(tr), "bullet: cannot factor E' for the multipliers");
  return run_steps(*w, model, x0, opt, std::move(tr), false);
}

}  // namespace

std::string settings_error(const WorldSettings& s) {
  auto bad = [](const char* name, double value, const char* rule) {
    return std::string("bullet setting ") + name + " must be " + rule + " (got " +
           short_number(value) + ")";
  };
  if (s.solver_iterations < 1) return bad("solver_iterations", s.solver_iterations, ">= 1");
  if (!(s.stop_erp > 0.0 && s.stop_erp <= 1.0)) return bad("stop_erp", s.stop_erp, "in (0, 1]");
  if (!(std::isfinite(s.stop_cfm) && s.stop_cfm >= 0.0))
    return bad("stop_cfm", s.stop_cfm, "finite and >= 0");
  if (!(std::isfinite(s.limit_erp) && s.limit_erp >= 0.0))
    return bad("limit_erp", s.limit_erp, "finite and >= 0");
  if (!(std::isfinite(s.limit_range) && s.limit_range > 0.0))
    return bad("limit_range", s.limit_range, "finite and > 0");
  if (!(std::isfinite(s.limit_max_impulse) && s.limit_max_impulse > 0.0))
    return bad("limit_max_impulse", s.limit_max_impulse, "finite and > 0");
  if (!(std::isfinite(s.contact_threshold) && s.contact_threshold > 0.0))
    return bad("contact_threshold", s.contact_threshold, "finite and > 0");
  return "";
}

std::string friction_name(WorldSettings::Friction f) {
  switch (f) {
    case WorldSettings::Friction::kBox:
      return "box";
    case WorldSettings::Friction::kOneDirection:
      return "one-direction";
    case WorldSettings::Friction::kCone:
      break;
  }
  return "cone";
}

WorldSettings::Friction parse_friction(const std::string& name) {
  for (auto f : {WorldSettings::Friction::kCone, WorldSettings::Friction::kBox,
                 WorldSettings::Friction::kOneDirection})
    if (friction_name(f) == name) return f;
  throw std::invalid_argument("bullet: unknown friction model '" + name +
                              "' (cone, box, one-direction)");
}

namespace {
// Bullet's own contact solver, restitution and friction (a contact scene's
// friction only: plan_of refuses it elsewhere, naming why).
sim::OptionsUsed bullet_options_used() {
  sim::OptionsUsed u;
  u.h = u.needs_mechanical = u.friction = u.friction_3d = true;
  return u;
}
}  // namespace

sim::Trajectory simulate_bullet(const mech::Model& model, const VectorXd& x0,
                                const sim::Options& options, const WorldSettings& s) {
  // The library's one check of a run's input, as sim::Integrator::run makes.
  sim::Options opt = options;
  // Friction at a contact scene's contacts is Bullet's own (WorldSettings::
  // friction); plan_of refuses it on any other model.
  if (auto refused = sim::refuse_invalid_run(model, x0, opt, "bullet", bullet_options_used()))
    return std::move(*refused);
  if (std::string why = settings_error(s); !why.empty()) {
    sim::Trajectory tr;
    tr.method = "bullet";
    tr.status = sim::RunStatus::kInvalidInput;
    tr.message = std::move(why);
    return tr;
  }
  const auto wall0 = std::chrono::steady_clock::now();
  const Plan p = plan_of(model, s);  // throws for an inexpressible model
  sim::Trajectory tr = p.bodies  ? simulate_bodies(model, *p.bodies, p.joint_limits, x0, opt, s)
                       : p.scene ? simulate_multibody(model, *p.scene, p.joint_limits, x0, opt, s)
                                 : simulate_rb6(model, p.rb6_limits, x0, opt, s);
  if (!p.warning.empty()) tr.warn("bullet-scene", 0.0, p.warning);
  sim::check_diverged(model, x0, tr);  // what the scenes report at their end, as run() checks it
  tr.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return tr;
}

namespace {

class BulletIntegrator : public sim::Integrator {
 public:
  std::string name() const override { return "bullet"; }
  sim::OptionsUsed options_used() const override { return bullet_options_used(); }

 protected:
  // A model Bullet cannot express is refused before anything runs (a sweep
  // keeps the other methods' rows), with check_expressible's message.
  std::string refusal(const mech::Model& model) const override {
    try {
      check_expressible(model);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "";
  }

  sim::Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                            const sim::Options& opt) const override {
    return simulate_bullet(model, x0, opt);
  }
};

}  // namespace

void register_mlcp_backends();  // src/bullet/mlcp.cpp

void register_backends() {
  sim::integrators().add("bullet", [] { return std::make_unique<BulletIntegrator>(); });
  register_mlcp_backends();
}

}  // namespace lcsim::bullet
