// The Bullet layer: the same scene built in Bullet (double precision) for
// side-by-side runs, and Bullet's MLCP solvers as optional LCP back-ends.
//
// Public face of src/bullet. Bullet is linked in double precision
// (pkg-config bullet-float64, BT_USE_DOUBLE_PRECISION).
#pragma once

#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::bullet {

// "Bullet <major>.<minor> (double precision)", from btGetVersion().
std::string version_string();

}  // namespace lcsim::bullet

// ---------------------------------------------------------------------------
// Side-by-side runs (src/bullet/world.cpp), comparison (compare.cpp), MLCP
// back-ends (mlcp.cpp). See docs/bullet-comparison.md for what was measured.
#include <Eigen/Dense>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <vector>

namespace lcsim::bullet {

// Every Bullet setting that affects accuracy, pinned (Bullet's defaults are
// stated where they differ). Three scenes (docs/bullet-comparison.md; a
// scene of several bodies, `bodies:`, is one btMultiBody per body with its
// contact points as colliders of their own, src/bullet/bodies_world.cpp and
// docs/contacts.md, "Scenes of several bodies"):
// - a model from a URDF scene whose constraints are all joint limits is the
//   URDF itself: a Featherstone btMultiBody (src/bullet/multibody_world.cpp)
//   with btMultiBodyJointLimitConstraint limits, the scene's springs and
//   dampers as joint torques applied before every step;
// - any other model is "rb6" of ../shared/notes/bullet.md: one btRigidBody per
//   coordinate, constraints as btGeneric6DofSpring2Constraint linear limits,
//   springs/dampers/f as forces applied before every step.
struct WorldSettings {
  // btSequentialImpulseConstraintSolver sweeps per step (Bullet default 10).
  // Two coupled rows (stop and hook on one cart) need more than 3 sweeps to
  // converge; 100 sweeps of 1-2 rows cost little.
  int solver_iterations = 100;
  // Per-limit BT_CONSTRAINT_STOP_ERP / _STOP_CFM of the 6DOF2 limits (Bullet's
  // defaults 0.2 and 0). 6DOF2 keeps a limit row in the solver at every step
  // (m_currentLimit = 4) whose target velocity is stop_erp * gap / h, so a
  // limit is approached without ever being crossed (speculative), and a
  // penetration is corrected by stop_erp of it per step.
  double stop_erp = 0.2;
  double stop_cfm = 0.0;
  // The "infinite" side of a one-sided limit (m): a stop x >= a is the range
  // [a, a + limit_range]. Valid while |q| stays well below it.
  double limit_range = 1e6;

  // ---- the multibody scene ----
  // btContactSolverInfo::m_erp (and m_erp2), the Baumgarte factor of
  // btMultiBodyJointLimitConstraint (Bullet's default 0.2): a limit row
  // exists only once the joint is at or past its bound, and asks for the
  // joint velocity limit_erp * penetration / h. 0: an impact stops the joint
  // where it is (at most |v| h past the bound) and nothing pushes it back;
  // see docs/bullet-comparison.md for why not 0.2.
  double limit_erp = 0.0;
  // btMultiBodyConstraint::setMaxAppliedImpulse of every limit (Bullet's
  // default 100 N s, which a heavy arm at its stop exceeds).
  double limit_max_impulse = 1e30;
  // btMultiBodyMLCPConstraintSolver with btDantzigSolver instead of the
  // sequential-impulse btMultiBodyConstraintSolver. Off: with two limit rows
  // active at once it builds a wrong coupling between them
  // (../shared/notes/bullet.md, measured in docs/bullet-comparison.md); kept
  // only to measure that.
  bool multibody_mlcp = false;
  // ---- contact scenes (docs/contacts.md, "Peers on contact scenes") ----
  // The contact points are spheres (radius 0 for a corner) on their links'
  // colliders against btStaticPlaneShape planes; restitution the scene's
  // (0 by default), friction 0. Contact rows use limit_erp too
  // (btContactSolverInfo::m_erp2) and a linear slop of 0. A manifold keeps a
  // point while it is closer than contact_threshold (m; Bullet's default is
  // 0.02 times the shape's bounding radius, 4 mm for the box): such a point
  // is a speculative row of the solver (target velocity -distance / h), so
  // a point approaching at up to contact_threshold / h stops at the plane
  // without crossing it (50 m/s at h = 1e-3).
  double contact_threshold = 0.05;
  // Friction at a contact scene's contacts with `friction:` (docs/contacts.md,
  // "Peers on contact scenes"): Coulomb's mu on each link's collider (the
  // scene's, one per link) times 1 on the planes (Bullet multiplies them).
  // btMultiBodyConstraintSolver has one friction row per contact along the
  // first of btPlaneSpace1(n)'s tangents, fixed (its velocity-aligned
  // direction is disabled for multibodies), bounded by mu times the normal
  // impulse; SOLVER_USE_2_FRICTION_DIRECTIONS adds the second tangent's row.
  //  - kCone: two directions, solved together, their impulse scaled back
  //    onto the circle of radius mu N when outside it (Bullet's "implicit
  //    cone friction", the default with two directions): the circular cone;
  //  - kBox: two directions, each bounded alone (SOLVER_DISABLE_IMPLICIT_CONE_
  //    FRICTION): the square |f_1|, |f_2| <= mu N, whose corners reach
  //    sqrt(2) mu N;
  //  - kOneDirection: Bullet's default single row: no friction across it.
  enum class Friction { kCone, kBox, kOneDirection };
  Friction friction = Friction::kCone;
};

// "cone", "box", "one-direction".
std::string friction_name(WorldSettings::Friction f);
// The friction model named `name`; std::invalid_argument naming it and the
// choices otherwise.
WorldSettings::Friction parse_friction(const std::string& name);

// "" when every setting is usable, else one line naming the first bad one
// and its value (solver_iterations >= 1; stop_erp in (0, 1]; stop_cfm,
// limit_erp finite >= 0; limit_range, limit_max_impulse finite > 0).
// simulate_bullet refuses such settings with kInvalidInput.
std::string settings_error(const WorldSettings& s);

// What runs for `model` with these settings: "btSequentialImpulseConstraintSolver
// (100 iterations)" for rb6, "btMultiBody from the URDF, ..." for a scene.
// Throws as check_expressible.
std::string solver_description(const mech::Model& model, const WorldSettings& s = {});

// Throws std::invalid_argument naming the first part of the model Bullet
// cannot express (0-based indices): a general LCS; for a URDF scene, a
// constraint that is not a joint limit when the scene's matrices are not
// rb6's either; otherwise a non-diagonal M ("M(1, 0) = 0.1") or a row of E
// that is neither a stop (c e_j) nor a hook (c (e_a - e_b)).
void check_expressible(const mech::Model& model);

// The model run in Bullet with fixed step opt.h (the last step shortened to
// land on opt.t_end), filling the same Trajectory as the time-stepping
// methods: samples (every step, or on the opt.dt_out grid; x = q then v in the
// model's coordinate order), u = constraint impulse / h (rb6: from the
// momentum balance; multibody: Bullet's limit and contact impulses; a
// contact scene with friction: u_t, u_t2 = the friction impulse / h on each
// friction entry's point along its contact's tangents t1, t2, zero at
// t = 0), mode = constraints
// with a nonzero impulse in the step, events at every mode change, energy
// (of lcsim's model at Bullet's states), max_violation. A model Bullet cannot
// express throws std::invalid_argument (an input error, as
// check_expressible) before anything runs; everything else, numerical
// trouble included, ends the run with kFailed and a message.
sim::Trajectory simulate_bullet(const mech::Model& model, const Eigen::VectorXd& x0,
                                const sim::Options& opt, const WorldSettings& s = {});

// One constraint switching on (activation) or off, matched between the exact
// run and another run.
struct EventShift {
  int constraint = 0;
  bool activation = true;
  double t_exact = 0.0;
  double t_other = 0.0;  // NaN when the other run has no matching switch
  double shift = 0.0;    // t_other - t_exact (NaN when unmatched)
};

struct Comparison {
  double deviation_max = 0.0;            // max over common sample times of max-abs state difference
  double deviation_t = 0.0;              // where it occurs (s)
  double error_final = 0.0;              // max-abs difference of the final states
  std::vector<EventShift> event_shifts;  // one per switch of the exact run, in time order
  int unmatched_other = 0;               // switches of the other run that match no exact switch
  double energy_drift = 0.0;   // (E_f - E_0) of the other run minus that of the exact run (J)
  double max_violation = 0.0;  // the other run's most negative gap
  long samples_compared = 0;   // samples of `other` with an exact sample at the same time
};

// Compares `other` with `exact` (the event-driven run sampled on the same time
// grid: samples closer than time_tol in time are paired; at a jump the exact
// run has two samples and the nearer state counts). Switches are taken from
// the mode sets (the first sample's mode, then each event's mode_after); each
// exact switch is matched with the other run's switch of the same constraint
// and direction nearest in time, in order (never before the previous match).
Comparison compare_trajectories(const sim::Trajectory& exact, const sim::Trajectory& other,
                                double time_tol = 1e-9);

// Bullet's MLCP solvers on the LCP w = M z + q, 0 <= z ⟂ w >= 0, through
// btMLCPSolverInterface::solveMLCP with A = M, b = -q, lo = 0, hi = BT_INFINITY.
// Every answer passes lcsim's residual check (opt.tolerance, as the built-in
// solvers): Bullet's Dantzig reports success on wrong answers for
// nonsymmetric matrices; a failed check gives kNumericalFailure with a message.
enum class MlcpSolver { kDantzig, kLemke, kPgs };
lcp::Result solve_bullet_mlcp(MlcpSolver which, const Eigen::MatrixXd& M, const Eigen::VectorXd& q,
                              const lcp::Options& opt = {});

// Adds the "bullet" integrator to sim::integrators() and the LCP back-ends
// bullet-dantzig, bullet-lemke, bullet-pgs to lcp::solvers(). Called by the
// registration source that CMake compiles into every program linking
// lcsim::bullet (src/bullet/autoregister/); calling it again is harmless.
void register_backends();

}  // namespace lcsim::bullet

// ---- Featherstone multibody from a URDF (multibody.cpp) ----

#include <Eigen/Dense>
#include <map>
#include <vector>

namespace urdf {
class ModelInterface;
}

namespace lcsim::bullet {

// The joint-space mass matrix of `model` at the configuration q0 (positions
// by joint name, 0 where not given), computed by Bullet: a btMultiBody with a
// fixed base is built for the simulated `joints` (revolute or prismatic), every
// other joint frozen at q0 and its child merged into the parent body (mass,
// centre of mass and inertia combined, principal axes by Bullet's Jacobi
// diagonalisation). Column j of M^{-1} is the joint acceleration that Bullet's
// articulated-body algorithm (calcAccelerationDeltasMultiDof) gives for a unit
// force on joint j at zero velocity without gravity; M is its inverse. The
// model must be valid (scene::load_urdf) with mass on every simulated body.
Eigen::MatrixXd multibody_mass_matrix(const urdf::ModelInterface& model,
                                      const std::vector<std::string>& joints,
                                      const std::map<std::string, double>& q0);

}  // namespace lcsim::bullet

// ---- A block sliding on a rough floor in Bullet (friction_box.cpp) ----
//
// Issue 17's "Bullet side by side": a btBoxShape on a btStaticPlaneShape with
// Coulomb friction, stepped by btDiscreteDynamicsWorld and
// btSequentialImpulseConstraintSolver at a fixed step, against the closed form
// of a block on a floor (robots/block_on_floor_friction.yaml): from v0 it
// decelerates at mu g and sticks at t* = |v0| / (mu g) after sliding
// d = v0^2 / (2 mu g). docs/friction.md has the measured table.

#include <lcsim/core/status.hpp>
#include <limits>

namespace lcsim::bullet {

// The block's parameters (SI units).
struct FrictionBlock {
  double mass = 1.0;           // kg, > 0
  double mu = 0.4;             // Coulomb coefficient, in [0, 10] (Bullet clamps at 10)
  double gravity = 9.81;       // m/s^2, > 0, pressing the block onto the floor
  double x0 = 0.0;             // m, position along the floor
  double v0 = 2.0;             // m/s, velocity along the floor
  double t_end = 1.0;          // s, horizon of a run
  int tangent_coordinate = 0;  // which model coordinate runs along the floor
  int normal_coordinate = 1;   // which one is normal to it
  // The closed form: |v0| / (mu g) and v0^2 / (2 mu g) (infinite for mu = 0).
  double stop_time() const;
  double slide_distance() const;
};
// "" when usable, else one line naming the first bad field and its value.
std::string friction_block_error(const FrictionBlock& b);

// A model read as a block on a floor, or why it is not one.
// kInvalidInput with the message when not a block on a floor.
struct FrictionBlockOf : Outcome {
  FrictionBlock block;
};
// Reads the block from a mechanical model with two coordinates (q_t along
// the floor, q_n normal to it), one row of E, c e_n with c > 0 (the floor
// c q_n + g >= 0), one frictional contact on it with tangent s e_t, s != 0
// (so the physical coefficient is mu |s| / c), M = m I, D = K = 0 and
// f = (0, -m g) in (t, n) order with g > 0; the state x0 (the model's
// initial when empty) must start on the floor (gap 0, normal velocity 0).
// Restitution is irrelevant (the block never leaves the floor). t_end is
// the model's, or FrictionBlock's default 1 s when it has none. A model of
// any other shape gets kInvalidInput and a message naming the first field
// that differs (0-based indices) and why.
FrictionBlockOf friction_block_of(const mech::Model& model, const Eigen::VectorXd& x0 = {});

// Every Bullet setting of the scene that is not pinned in friction_box.cpp.
struct FrictionBoxSettings {
  double h = 1e-3;  // fixed step (s), > 0, at most 1e8 steps over t_end
  // btSequentialImpulseConstraintSolver sweeps per step (Bullet's default
  // 10): 4 contact points x (normal + 2 friction rows) converge well within 100.
  int solver_iterations = 100;
  // Box half extents (m); the block's footprint does not enter the closed form.
  double half_width = 0.1;    // along the floor (x) and across it (z)
  double half_height = 0.05;  // normal to the floor (y)
  // |v| at or below this (m/s) counts as stuck (slide_stop).
  double stop_velocity = 1e-9;
  // btDefaultCollisionConfiguration::setPlaneConvexMultipointIterations(n, n):
  // every step, besides the deepest corner, the box-plane algorithm collides
  // n copies of the box tilted towards directions 360/n degrees apart (while
  // the manifold holds fewer than n points: always, for n > 4). 8 finds the
  // 4 corners of the bottom face at every step (measured in
  // docs/friction.md; 3 or 4 leave the box on 1 to 4 points). 0: not
  // called (Bullet's default, one point per step).
  int multipoint_iterations = 8;
  // The box rotates freely (a btBoxShape rigid body); false: angular factor
  // 0, the box only translates, as the model's two coordinates do.
  bool free_rotation = true;
};
// "" when usable, else one line naming the first bad setting and its value.
std::string friction_box_settings_error(const FrictionBoxSettings& s, double t_end);

// The state after each step (and at t = 0): forces are the step's impulses
// divided by its length, as Bullet's solver applied them to the box.
struct FrictionBoxSample {
  double t = 0.0;
  double x = 0.0;               // box centre along the floor (m), = q_t of the model
  double v = 0.0;               // its velocity along the floor (m/s)
  double gap = 0.0;             // lowest corner's height above the floor (m)
  double normal_force = 0.0;    // sum of the contact points' normal impulses / h (N)
  double friction_force = 0.0;  // sum of their friction impulses along x / h (N)
  int contact_points = 0;       // points in the box-plane manifold
  double tilt = 0.0;            // rotation angle of the box (rad)
};

// Where a sliding run sticks: the first sample from which |v| <= v_tol to the
// end of the run, its time and the distance |x - x(0)| slid until then; NaN
// time and distance when it still slides at the end.
struct SlideStop {
  double time = std::numeric_limits<double>::quiet_NaN();
  double distance = std::numeric_limits<double>::quiet_NaN();
};
// t, x, v: one entry per sample, equal sizes >= 1, t increasing; throws
// std::invalid_argument naming the size or v_tol (finite >= 0) otherwise.
SlideStop slide_stop(const std::vector<double>& t, const std::vector<double>& x,
                     const std::vector<double>& v, double v_tol);

// kInvalidInput (nothing ran) or kNumericalFailure, with the message.
struct FrictionBoxRun : Outcome {
  FrictionBlock block;
  std::vector<FrictionBoxSample> samples;
  SlideStop stop;  // of the samples, with settings.stop_velocity
};
// The block run in Bullet for block.t_end (the last step shortened to land
// on it). Bad block or settings: kInvalidInput, nothing run; a non-finite
// state: kNumericalFailure.
FrictionBoxRun simulate_friction_box(const FrictionBlock& block, const FrictionBoxSettings& s = {});
// The same from a model (friction_block_of; its message when not a block on
// a floor).
FrictionBoxRun simulate_friction_box(const mech::Model& model, const FrictionBoxSettings& s = {});

// `lcsim compare` on a block on a floor: the box run in Bullet beside an
// exact run of the same model (the tangential coordinate and velocity only;
// the box's own normal motion and tilt are Bullet's, reported apart).
// kInvalidInput / kNumericalFailure, with the message.
struct FrictionComparison : Outcome {
  FrictionBlock block;    // as read from the model (t_end: the exact run's)
  SlideStop closed_form;  // block.stop_time(), block.slide_distance() (NaN: never sticks)
  SlideStop exact;        // slide_stop of the exact run's samples
  SlideStop bullet;       // slide_stop of Bullet's samples
  // Over Bullet's samples paired in time (within time_tol) with exact
  // samples: max of |x_b - x| and |v_b - v| along the floor, and where.
  double deviation_max = 0.0;
  double deviation_t = 0.0;
  double error_final = 0.0;  // the same at t_end
  long samples_compared = 0;
  double max_tilt = 0.0;       // Bullet's largest rotation of the box (rad)
  int min_contact_points = 0;  // fewest box-plane points after the first step
  long steps = 0;              // Bullet steps
};
// Reads the block from `model` at x0 (friction_block_of), runs it in Bullet
// for exact.t_end with `s`, and compares with `exact` (an event-driven run of
// the same model and x0, sampled on a grid that is a multiple of s.h). Stops
// use s.stop_velocity on both runs. Not a block on a floor, or bad settings:
// kInvalidInput naming why; Bullet's failure: its status and message.
FrictionComparison compare_friction_box(const mech::Model& model, const Eigen::VectorXd& x0,
                                        const sim::Trajectory& exact,
                                        const FrictionBoxSettings& s = {}, double time_tol = 1e-9);

}  // namespace lcsim::bullet
