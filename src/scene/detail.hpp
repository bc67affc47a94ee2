// Internal helpers of src/scene (not part of its public face, lcsim/scene/).
#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Dense>
#include <functional>
#include <lcsim/io/yaml.hpp>
#include <lcsim/scene/bodies.hpp>
#include <lcsim/scene/contacts.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/scene/urdf.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace urdf {
class Joint;
}

namespace lcsim::scene {

// URDF text without its <visual>, <collision> and <material> elements
// (urdf_geometry.cpp): lcsim reads no geometry, and urdfdom refuses a whole
// robot for an error in one of them (Bullet's capsule or plane geometry, a
// malformed mesh scale, two materials of one name).
std::string without_geometry(const std::string& xml);

// The joints whose <limit> lacks lower or upper, and which ("lower",
// "upper" or "lower and upper"), from the URDF text (the same scanner). The
// URDF default for both is 0, which urdfdom applies without a trace: as
// stops they would lock the joint at 0 (bullet3's Minitaur knees, whose
// <limit> gives only effort and velocity), so a scene refuses them there.
std::map<std::string, std::string> limits_without_bounds(const std::string& xml);

// A link's <collision> element as the URDF text has it (the same scanner):
// the shape inside <geometry> and its size attributes, and its <origin>.
// Nothing is checked here: contact_geometry.cpp checks the elements a
// scene's contacts use, so an error in another link's geometry (which
// urdfdom never sees) stops nothing.
struct CollisionElement {
  std::string link;
  std::size_t index = 0;  // the link's n-th <collision> (0-based)
  std::string shape;      // box, sphere, cylinder, capsule, mesh, ... ("" if none)
  std::map<std::string, std::string> attributes;  // size, radius, length (those present)
  std::string xyz, rpy;                           // of its <origin> ("" when absent)
};
std::vector<CollisionElement> collision_elements(const std::string& xml);
// The contact points of `link`'s collision primitives, named
// <prefix>.corner<k> (box), .sphere<k>, .cap<k> (capsule), .rim<k>
// (cylinder), k counted per kind over the link; InputError naming the link
// and the element for a mesh or any other shape, or a bad size.
std::vector<ContactPoint> collision_points(const std::vector<CollisionElement>& elements,
                                           const std::string& link, const std::string& prefix,
                                           const std::string& urdf);
// The sphere, box, capsule and cylinder <collision> primitives of `link` as
// shapes (its frame in the link's; a radius, a box's half sizes or a
// capsule's and cylinder's half length as half.z(), m; index counted per
// kind); InputError naming the link and the element for another shape.
struct CollisionShape {
  std::string kind;
  std::size_t index = 0;
  Eigen::Isometry3d origin = Eigen::Isometry3d::Identity();
  double radius = 0.0;
  Eigen::Vector3d half = Eigen::Vector3d::Zero();
};
std::vector<CollisionShape> collision_shapes(const std::vector<CollisionElement>& elements,
                                             const std::string& link, const std::string& urdf);

// ---------------------------------------------------------------------------
// Reading a scene file. read_scene (scene.cpp) is a driver that calls one
// stage per top-level key, in the order the file is checked: a file with two
// errors reports the one of the earlier stage. A new key gets a stage here
// (declared below, defined in src/scene/scene_<key>.cpp when it is a concept
// of its own), its name in read_scene's list of keys, and its call in
// read_scene after the stages whose results it needs (a key that adds
// constraints adds them to SceneConstraints before the names are checked).
// Every stage throws InputError "<scene>: <key>: <what>" (io::yaml::fail).

using io::yaml::Keys;

// The values a scene's keys hold (scene_values.cpp).
// A non-empty scalar.
std::string name_of(const YAML::Node& n, const std::string& source, const std::string& key);
// true or false (YAML 1.2's booleans only: yaml-cpp would also read yes,
// on, y, which a typo can produce).
bool boolean(const YAML::Node& n, const std::string& source, const std::string& key);
// Why a name may not be used ("" when it may).
using NameCheck = std::function<std::string(const std::string&)>;
// {name: number} with every name passing `check` (a joint of the URDF for
// q0, a simulated joint for springs and initial, a constraint for
// restitution); a name that fails is an error at `key`.`name`.
std::map<std::string, double> by_name(const YAML::Node& n, const std::string& source,
                                      const std::string& key, const NameCheck& check);

// `urdf:` and `balance_inertia:` (scene_urdf.cpp): the robot, its path
// relative to the scene's directory, the joints whose <limit> lacks a bound
// and what loading repaired.
struct SceneUrdf {
  std::shared_ptr<urdf::ModelInterface> model;
  std::string path;                              // for messages
  std::map<std::string, std::string> unbounded;  // limits_without_bounds
  std::vector<CollisionElement> collisions;      // collision_elements
  UrdfRepairs repairs;
};
SceneUrdf read_urdf(const Keys& keys, const std::string& source);

// Three numbers (x, y, z) in `unit`, at `key` (scene_values.cpp).
Eigen::Vector3d vector3(const YAML::Node& n, const std::string& source, const std::string& key,
                        const std::string& unit);

// `base:` (scene_base.cpp): `fixed` (the default, at the identity pose),
// `floating`, or {type: fixed | floating, pose: {xyz, rpy}, name}.
BasePose read_base(const Keys& keys, const std::string& source, const SceneUrdf& urdf);

// `joints:` (scene_joints.cpp): the coordinates: a floating base's six
// (base_coordinates) and then the simulated joints, in file order (a
// floating base may have none), each with the stops it asked for ("lower", "upper") on its own
// limits and on those of the joints that mimic it; and the URDF's mimic
// joints that follow them.
struct SceneJoints {
  std::vector<std::string> names;  // every coordinate: the base's, then the joints
  std::size_t base = 0;            // how many of names are the base's (0 or 6)
  std::vector<std::vector<std::string>> stops, mimic_stops;  // per joint, as names
  std::map<std::string, Mimic> mimics;
  Eigen::Index size() const { return static_cast<Eigen::Index>(names.size()); }
  // The coordinate of joint `name` (size() when it is not simulated).
  Eigen::Index coord(const std::string& name) const;
  // The joints' values in `values` as a vector over the coordinates (0 for
  // a joint not named).
  VectorXd vector_of(const std::map<std::string, double>& values) const;
  // The simulated URDF joints (names after the base's).
  std::vector<std::string> urdf_joints() const;
};
// Revolute, continuous or prismatic: a joint with a position.
bool has_position(const urdf::Joint& j);
// `obstacle`: a body of a scene of bodies, which may have no coordinates at
// all (a fixed base and no `joints:`: a table, a wall, a fixture that other
// bodies touch); a one-URDF scene's robot must have one.
SceneJoints read_joints(const Keys& keys, const std::string& source, const SceneUrdf& urdf,
                        const BasePose& base, bool obstacle = false);
// The check of a joint named where only simulated joints may be (springs,
// constraints, initial): "" for a simulated joint, else why not.
NameCheck simulated(const SceneJoints& joints, const SceneUrdf& urdf);

// Stops (scene_stops.cpp): a joint's <limit> as unilateral constraints.
// The `stops:` or `mimic_stops:` list at `key`.
std::vector<std::string> stop_list(const YAML::Node& s, const std::string& source,
                                   const std::string& key);
// Whether joint j (entry `key` of joints:) can have the stops `st` (cleared
// for a continuous joint without explicit ones); InputError if not.
void check_stops(const urdf::Joint& j, bool explicit_stops, std::vector<std::string>& st,
                 const std::string& source, const std::string& key, const SceneUrdf& urdf);

// `q0:` (scene_state.cpp): the reference configuration the scene is
// linearised about, by joint of the URDF (a mimic's value checked against
// its leader's and dropped); `initial:`: the state a run starts from.
std::map<std::string, double> read_q0(const Keys& keys, const std::string& source,
                                      const SceneUrdf& urdf, const SceneJoints& joints);
// x = (q, v): q0 at rest, but for the positions and velocities `initial`
// names.
// `check` says which names may be given (simulated(joints, urdf) in a
// one-URDF scene, the coordinates in a scene of bodies).
VectorXd read_initial(const Keys& keys, const std::string& source, const NameCheck& check,
                      const SceneJoints& joints, const VectorXd& q0);

// The dynamics being assembled, dense (scenes are small: one coordinate per
// simulated joint; stored sparse in mech::MechanicalModel at the end).
struct SceneDynamics {
  MatrixXd D, K;  // damping, stiffness
  VectorXd f;     // constant generalised force
};
// `springs:` (scene_springs.cpp), added to K, D and f.
// `check` as for read_initial.
void add_springs(const Keys& keys, const std::string& source, const NameCheck& check,
                 const SceneJoints& joints, SceneDynamics& dyn);

// The unilateral constraints E q + g >= 0 being assembled, one row each, in
// the model's order: the joint stops first, then the scene's constraints.
struct SceneConstraints {
  std::vector<VectorXd> rows;
  std::vector<double> gaps;
  std::vector<std::string> names;
  void add(VectorXd row, double gap, std::string name);
  MatrixXd E(Eigen::Index coordinates) const;
  VectorXd g() const;
};
// The stops of every simulated joint (joint order, lower before upper),
// each followed by those on the joints that mimic it (scene_stops.cpp).
SceneConstraints joint_stops(const std::string& source, const SceneUrdf& urdf,
                             const SceneJoints& joints);
// `constraints:` (scene_constraints.cpp), in file order; then the check that
// no two constraints share a name.
void add_constraints(const Keys& keys, const std::string& source, const NameCheck& check,
                     const SceneJoints& joints, SceneConstraints& out);
void check_unique_names(const SceneConstraints& c, const std::string& source);
// `planes:` (scene_contacts.cpp): the world planes contacts may touch.
std::vector<Plane> read_planes(const Keys& keys, const std::string& source);
// `contacts:` and `contact_options:` (scene_contacts.cpp): each contact
// point's row added to `out` (after the joint stops and constraints), its
// frame returned with its row; a note when points were dropped.
// A contact's friction (`friction:` mu and `d:` per entry of `contacts:` or
// in `contact_options:`, scene_contact_friction.cpp): mu < 0 frictionless.
struct ContactFriction {
  double mu = -1.0;
  int d = 0;  // 0: the model's default
};
struct SceneContacts {
  std::vector<ContactFrame> frames;
  std::vector<ContactFriction> friction;  // per frame
  std::vector<std::string> notes;
};
// The `friction:` and `d:` keys of `ck` (at `k`: a contacts entry, or
// contact_options), `dflt` where absent; checked (mu >= 0 finite, d a whole
// number in [1, 1024], d only with friction).
ContactFriction read_contact_friction(const Keys& ck, const std::string& source,
                                      const std::string& k, const ContactFriction& dflt);
// The 3-D frictional contacts of the frames with friction (mech::FrictionalContact:
// the frame's tangent rows, world_frame), appended to m.friction.
void add_contact_friction(const SceneContacts& sc, mech::MechanicalModel& m);
// A body as contacts name it: "" in a one-URDF scene (a link is named
// alone), else its name (a link is named "<body>/<link>").
struct ContactBody {
  std::string name;
  const SceneUrdf* urdf = nullptr;
};
SceneContacts add_contacts(const Keys& keys, const std::string& source,
                           const std::vector<ContactBody>& bodies, const std::vector<Plane>& planes,
                           const Bodies& dyn, const VectorXd& q0, SceneConstraints& out);

// Body against body (scene_body_contacts.cpp). A link as a contact names it
// at `key`: its body's index and the link's name in its URDF; InputError
// naming the body, or the link and its body, when not found.
struct LinkRef {
  std::size_t body = 0;
  std::string link;
  std::string label;  // as written: "link" or "body/link"
};
LinkRef find_link(const std::vector<ContactBody>& bodies, const YAML::Node& n,
                  const std::string& source, const std::string& key);
// The sphere and box <collision> primitives of `ref`'s link, each a shape a
// point may touch (its face chosen later); InputError naming the link and
// the element for any other shape, or when it has none.
std::vector<BodyShape> body_shapes(const std::vector<ContactBody>& bodies, const LinkRef& ref,
                                   const std::string& source, const std::string& key);

// The frames of `points` (on `ref`'s link) against each shape of the link
// named at `key`.against: a point-against-shape contact each, named
// <point> when the link has one shape, else <point>_<shape kind><k>.
// InputError when the two links are of one body.
std::vector<ContactFrame> against_frames(const std::vector<ContactBody>& bodies, const LinkRef& ref,
                                         const YAML::Node& against, const std::string& source,
                                         const std::string& key,
                                         const std::vector<ContactPoint>& points, const Bodies& dyn,
                                         const VectorXd& q0);

// A sphere of `radius` about the world point `centre` against `plane`: its
// signed distance normal . (centre - plane.point) - radius (m), the one
// formula of signed_distance on a plane (contact_pairs.cpp), for a caller
// that has the point's centre already (the contact ranges).
double plane_distance(const Plane& plane, const Eigen::Vector3d& centre, double radius);

// Contact c at q (contact_ranges.cpp; the contact ranges and the run's
// linearisation check): its point seen from what it touches (in the world
// for a plane, in the frame of the other body's link for a body's shape, so
// the shape's own motion counts as the point's) and its exact gap phi(q)
// (signed_distance, m). On a plane (`plane` set) both come from one pose of
// the link.
struct ContactProbe {
  Eigen::Vector3d seen;
  double gap = 0.0;  // m
};
ContactProbe probe_contact(const Bodies& dyn, const ContactFrame& c, const Plane* plane,
                           const VectorXd& q);
// The plane contact c touches (nullptr for a body's shape); InputError as
// signed_distance's when the scene has no plane of its name.
const Plane* plane_of(const ContactFrame& c, const std::vector<Plane>& planes);

// A scene of several URDFs (`bodies:`, scene_bodies.cpp): read_scene's
// counterpart when the file has that key instead of `urdf:`.
Scene read_bodies_scene(const YAML::Node& root, const std::string& source);

// The stages both kinds of scene share (scene.cpp).
mech::Model named_model(const Keys& keys, const std::string& source);
Eigen::Vector3d read_gravity(const Keys& keys, const std::string& source);
SceneDynamics linear_dynamics(const UrdfLinearisation& lin, const VectorXd& q0);
void check_mass_matrix(const MatrixXd& M, const SceneJoints& joints, const std::string& source);
void read_t_end(const Keys& keys, const std::string& source, mech::Model& model);
mech::MechanicalModel assemble(const UrdfLinearisation& lin, const SceneDynamics& dyn,
                               const SceneConstraints& con, const SceneJoints& joints);
// `restitution:` by constraint name (0 for those not named).
VectorXd read_restitution(const Keys& keys, const std::string& source,
                          const std::vector<std::string>& constraints);

}  // namespace lcsim::scene
