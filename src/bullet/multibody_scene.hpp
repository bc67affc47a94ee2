// Internal to src/bullet: the multibody scene of multibody_world.cpp, chosen
// by simulate_bullet (world.cpp) for models from URDF scenes.
#pragma once

#include <BulletDynamics/ConstraintSolver/btContactSolverInfo.h>

#include <Eigen/Dense>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

class btMultiBody;
class btMultiBodyDynamicsWorld;
class btMultiBodyJointLimitConstraint;

namespace lcsim::bullet {

// Row `row` of E, c q_j + g >= 0 with j = coordinate: the bound -g/c on q_j
// from below (c > 0) or above (c < 0).
struct JointLimit {
  int row = 0;
  int coordinate = 0;
  double c = 1.0;
  double bound = 0.0;
  bool lower = true;
};

// One JointLimit per row of E that is not one of setup's contacts;
// std::invalid_argument naming the file `source` (the scene's path; omitted
// when empty) and the first row that involves more or fewer than one
// coordinate (0-based), or a floating base's coordinate.
std::vector<JointLimit> joint_limits_of(const mech::MechanicalModel& m, const std::string& source,
                                        const scene::Scene* setup = nullptr);

// "btMultiBody from the URDF, btMultiBodyConstraintSolver (100 iterations), ..."
// With `contacts`, the contact settings too; with `friction` (the scene's
// contacts have friction:) WorldSettings::friction's.
std::string multibody_description(const WorldSettings& s, bool contacts = false,
                                  bool friction = false);

// The scene's own forces, tau = f_s - K_s q - D v: K and f without the
// linearised gravity (Bullet's world has the nonlinear one), for the
// one-URDF multibody and the scene of bodies (multibody_world.cpp).
struct SceneForces {
  Eigen::MatrixXd K_s, D;
  Eigen::VectorXd f_s;
};
SceneForces scene_forces(const scene::Scene& setup, const mech::MechanicalModel& m);

// The scene run as a btMultiBody (multibody_world.cpp); `limits` from
// joint_limits_of. Never throws.
sim::Trajectory simulate_multibody(const mech::Model& model, const scene::Scene& setup,
                                   const std::vector<JointLimit>& limits, const Eigen::VectorXd& x0,
                                   const sim::Options& opt, const WorldSettings& s);

// The solver settings both multibody scenes pin (multibody_world.cpp's
// header): iterations, ERP = limit_erp, CFM 0, SOR 1, no split impulse, no
// early exit, slop 0, warm starting without the articulated one, and with
// `friction` WorldSettings::friction's flags.
void pin_solver_info(btContactSolverInfo& info, const WorldSettings& s, bool friction);

// Adds b to `world` colliding with nothing (mask 0), with the settings both
// multibody scenes pin (multibody_world.cpp's header): damping 0, the
// gyroscopic term, max coordinate velocity 1e30, no sleeping, no
// self-collision, local velocities.
void add_pinned_multibody(btMultiBodyDynamicsWorld& world, btMultiBody& b);
// Places b's link colliders at its joint positions (Bullet's forward
// kinematics), as after a step.
void place_link_colliders(btMultiBody& b);
// Adds the btMultiBodyJointLimitConstraint of L on Bullet link `link` of b to
// `world`: the bound on its side, the other side limit_range away, max
// impulse limit_max_impulse.
std::unique_ptr<btMultiBodyJointLimitConstraint> add_joint_limit(btMultiBodyDynamicsWorld& world,
                                                                 btMultiBody* b, int link,
                                                                 const JointLimit& L,
                                                                 const WorldSettings& s);
// Zeroes both rows' applied impulses of each limit before a step: a limit
// row exists only in steps that start at or past its bound, and its impulse
// from an earlier step would otherwise be read again.
void reset_limit_impulses(
    const std::vector<std::unique_ptr<btMultiBodyJointLimitConstraint>>& limits);

// ---- A scene of several bodies (bodies_world.cpp) ----

// Why Bullet cannot run the scene of bodies, or "": a mimic joint.
std::string bodies_refusal(const scene::Scene& setup);
// The scene's rows that are not contacts as joint limits (joint_limits_of);
// std::invalid_argument for a row on a floating base's coordinate.
std::vector<JointLimit> bodies_joint_limits(const mech::MechanicalModel& m,
                                            const scene::Scene& setup);
// "one btMultiBody per body, ..." with the solver's and the contacts' settings.
std::string bodies_description(const WorldSettings& s, bool friction);
// The scene of bodies run in Bullet (bodies_world.cpp says how). Never throws.
sim::Trajectory simulate_bodies(const mech::Model& model, const scene::Scene& setup,
                                const std::vector<JointLimit>& limits, const Eigen::VectorXd& x0,
                                const sim::Options& opt, const WorldSettings& s);

}  // namespace lcsim::bullet

// ---- Floating bases and contacts (multibody_contacts.cpp) ----

#include <BulletCollision/CollisionDispatch/btCollisionDispatcher.h>
#include <BulletCollision/CollisionDispatch/btCollisionObject.h>
#include <BulletCollision/CollisionShapes/btCollisionShape.h>

#include "bullet/urdf_multibody.hpp"

namespace lcsim::bullet {

// A floating base's six coordinates (docs/contacts.md: the root origin p and
// a rotation vector r, orientation exp([r]x) R0) and their rates, set on and
// read from Bullet's base (its centre of mass, world-frame velocity and
// angular velocity omega = J_l(r) r').
void set_floating_base(btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                       const Eigen::Matrix<double, 6, 1>& q, const Eigen::Matrix<double, 6, 1>& v);
void get_floating_base(const btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                       Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> v);
// The generalised force Q on the six coordinates applied to Bullet's base:
// the force Q_p at the root origin and the torque J_l(r)^-T Q_r (so that
// their virtual work is Q . dq).
void add_floating_base_force(btMultiBody& b, const UrdfMultiBody& mb, const scene::BasePose& base,
                             const Eigen::Matrix<double, 6, 1>& q,
                             const Eigen::Matrix<double, 6, 1>& Q);

// The scene's contact points as Bullet colliders: per Bullet link (the base
// is -1) one btCompoundShape of spheres, one per contact point at its place
// in that link's frame with the point's radius (a box corner: radius 0, a
// point), and one btStaticPlaneShape object per plane. Links collide only
// with planes (and not with each other).
struct ContactColliders {
  std::vector<std::unique_ptr<btCollisionShape>> shapes;
  std::map<int, btCollisionShape*> shape_of;  // Bullet link -> its compound
  std::vector<std::unique_ptr<btCollisionObject>> planes;
  std::map<std::pair<int, int>, int> row_of;    // (Bullet link, compound child) -> row of E
  std::map<int, double> restitution_of;         // Bullet link -> the largest e of its points
  std::map<int, double> friction_of;            // Bullet link -> its points' mu (one per link)
  bool friction = false;                        // some contact has friction
  int rows = 0;                                 // contact rows
  std::map<int, Eigen::Vector3d> t1_of, t2_of;  // row -> its world tangents (scene::ContactFrame)
};
// Collision filter groups of links with contacts and of planes.
constexpr int kContactLinkGroup = 1 << 6, kPlaneGroup = 1 << 7;
// The colliders of setup.contacts (restitution: the largest of a link's
// points, Bullet's product with the planes' 1; friction: the scene's mu of
// the link's points, times the planes' 1, or 0 when no contact has friction).
// Throws std::invalid_argument naming the contact whose link Bullet does not
// hold, or a contact whose mu differs from another point's of its link
// (Bullet's friction is per collider).
ContactColliders make_contact_colliders(const scene::Scene& setup, const UrdfMultiBody& mb,
                                        const mech::MechanicalModel& m);
// "" when every link's contact points have one friction coefficient (mu,
// or none), else why not, naming the two contacts and their mu (Bullet's
// friction belongs to a link's collider): the input check of a contact
// scene, before Bullet builds anything.
std::string link_friction_error(const scene::Scene& setup, const mech::MechanicalModel& m);
// Adds the step's normal impulses of every contact point (N s) to `impulse`
// (size k, by row of E), from the dispatcher's manifolds.
void contact_impulses(btCollisionDispatcher& d, const ContactColliders& c,
                      Eigen::VectorXd& impulse);
// The step's friction impulses on each contact point along its row's
// tangents t1, t2 (N s, by row of E; zero elsewhere): Bullet's lateral
// impulses act on the manifold's body A along its friction directions.
void contact_friction_impulses(btCollisionDispatcher& d, const ContactColliders& c,
                               Eigen::VectorXd& t1, Eigen::VectorXd& t2);

// A btCollisionDispatcher whose manifolds keep points up to `threshold` (m)
// apart (Bullet's default is 0.02 times the shapes' bounding radius): a
// point within it is a speculative contact row of the solver.
std::unique_ptr<btCollisionDispatcher> make_dispatcher(btCollisionConfiguration* config,
                                                       double threshold);

}  // namespace lcsim::bullet
