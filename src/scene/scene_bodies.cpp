// A scene of several URDFs (`bodies:`, docs/contacts.md, "Several
// bodies"): each body read as a one-URDF scene reads its robot (urdf, base,
// joints, q0, balance_inertia: the same stages, their messages at
// bodies[i]), linearised on its own, and the whole assembled: coordinates
// concatenated and named <body>.<joint> (a floating base's <body>.x ...
// .rz), M, K_g and the damping block diagonal, each body's stops named
// <body>.<joint>_lower / _upper. Springs, constraints, initial values and
// restitution name these coordinates and constraints; contacts name links
// as <body>/<link>.
#include <urdf_model/model.h>

#include <algorithm>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>
#include <lcsim/scene/scene.hpp>
#include <set>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::describe;
using io::yaml::fail;

namespace {

// One body, read and linearised on its own (its coordinates unprefixed but
// for a floating base's, which carry the body's name).
struct BodyPart {
  std::string name;
  SceneUrdf urdf;
  BasePose base;
  SceneJoints joints;
  std::map<std::string, double> q0;
  UrdfLinearisation lin;
  VectorXd q0v;
  SceneConstraints stops;
};

BodyPart read_body(const YAML::Node& n, const std::string& source, const std::string& k,
                   const Eigen::Vector3d& gravity, std::set<std::string>& names) {
  const Keys bk =
      io::yaml::mapping(n, source, k, {"name", "urdf", "base", "joints", "q0", "balance_inertia"});
  BodyPart b;
  if (!bk.count("name")) fail(source, k + ".name", "missing (a body is named)");
  b.name = name_of(bk.at("name"), source, k + ".name");
  if (b.name.find_first_of("/.") != std::string::npos)
    fail(source, k + ".name",
         "'" + b.name + "' holds '/' or '.', which separate a body from its links and joints");
  if (!names.insert(b.name).second) fail(source, k + ".name", "duplicate body '" + b.name + "'");
  if (bk.count("base") && bk.at("base").IsMap() && bk.at("base")["name"])
    fail(source, k + ".base.name", "a body's base is named by the body (" + k + ".name)");
  // The stages of a one-URDF scene, their messages at "<source>: bodies[i]"
  // (the URDF's path is relative to the directory of that text's file part).
  const std::string bsource = source + ": " + k;
  b.urdf = read_urdf(bk, bsource);
  b.base = read_base(bk, bsource, b.urdf);
  b.base.name = b.name;
  b.joints = read_joints(bk, bsource, b.urdf, b.base, true);
  b.q0 = read_q0(bk, bsource, b.urdf, b.joints);
  const UrdfDynamics exact(*b.urdf.model, b.joints.urdf_joints(), b.q0, gravity, b.urdf.path,
                           b.base);
  b.q0v = exact.reference();
  b.lin = linearise_urdf(*b.urdf.model, b.joints.urdf_joints(), b.q0, gravity, b.urdf.path, b.base);
  b.stops = joint_stops(bsource, b.urdf, b.joints);
  return b;
}

// Coordinate i of body b as the scene names it.
std::string coordinate_name(const BodyPart& b, std::size_t i) {
  return i < b.joints.base ? b.joints.names[i] : b.name + "." + b.joints.names[i];
}

// The bodies' linearisations as one: block diagonal.
UrdfLinearisation stacked(const std::vector<BodyPart>& parts, Eigen::Index N) {
  UrdfLinearisation lin;
  lin.M = MatrixXd::Zero(N, N);
  lin.K_g = MatrixXd::Zero(N, N);
  lin.tau_g = lin.damping = VectorXd::Zero(N);
  Eigen::Index o = 0;
  for (const BodyPart& b : parts) {
    const Eigen::Index n = b.joints.size();
    lin.M.block(o, o, n, n) = b.lin.M;
    lin.K_g.block(o, o, n, n) = b.lin.K_g;
    lin.tau_g.segment(o, n) = b.lin.tau_g;
    lin.damping.segment(o, n) = b.lin.damping;
    for (std::size_t i = 0; i < b.joints.names.size(); ++i)
      lin.joints.push_back(coordinate_name(b, i));
    o += n;
  }
  return lin;
}

// Each body's stops on the scene's coordinates, named <body>.<stop>.
SceneConstraints stacked_stops(const std::vector<BodyPart>& parts, Eigen::Index N) {
  SceneConstraints out;
  Eigen::Index o = 0;
  for (const BodyPart& b : parts) {
    for (std::size_t r = 0; r < b.stops.rows.size(); ++r) {
      VectorXd row = VectorXd::Zero(N);
      row.segment(o, b.joints.size()) = b.stops.rows[r];
      out.add(row, b.stops.gaps[r], b.name + "." + b.stops.names[r]);
    }
    o += b.joints.size();
  }
  return out;
}

std::vector<BodyPart> read_parts(const Keys& keys, const std::string& source,
                                 const Eigen::Vector3d& gravity) {
  const YAML::Node& bn = keys.at("bodies");
  if (!bn.IsSequence() || bn.size() == 0)
    fail(source, "bodies", "expected a non-empty list of bodies (got " + describe(bn) + ")");
  std::vector<BodyPart> parts;
  std::set<std::string> names;
  for (std::size_t i = 0; i < bn.size(); ++i)
    parts.push_back(read_body(bn[i], source, "bodies[" + std::to_string(i) + "]", gravity, names));
  return parts;
}

}  // namespace

// The stages of read_scene (scene.cpp) over the bodies, in the same order.
Scene read_bodies_scene(const YAML::Node& root, const std::string& source) {
  const Keys keys =
      io::yaml::mapping(root, source, "",
                        {"name", "bodies", "gravity", "springs", "constraints", "restitution",
                         "initial", "t_end", "planes", "contacts", "contact_options"});
  mech::Model model = named_model(keys, source);
  const Eigen::Vector3d gravity = read_gravity(keys, source);
  std::vector<BodyPart> parts = read_parts(keys, source, gravity);
  Eigen::Index N = 0;
  for (const BodyPart& b : parts) N += b.joints.size();
  if (N == 0)
    fail(source, "bodies",
         "no body has a coordinate (each has a fixed base and no joints): nothing moves; give "
         "a body a floating base or joints");
  const UrdfLinearisation lin = stacked(parts, N);
  SceneJoints joints;  // the scene's coordinates, by name (no base of its own)
  joints.names = lin.joints;
  std::set<std::string> unique(joints.names.begin(), joints.names.end());
  if (unique.size() != joints.names.size())
    fail(source, "bodies", "two coordinates share a name: rename a body or a joint");
  VectorXd q0v(N);
  std::map<std::string, double> q0;
  std::vector<SceneBody> bodies;
  std::vector<ContactBody> contact_bodies;
  Eigen::Index o = 0;
  for (const BodyPart& b : parts) {
    q0v.segment(o, b.joints.size()) = b.q0v;
    for (std::size_t i = 0; i < b.joints.names.size(); ++i)
      q0[coordinate_name(b, i)] = b.q0v(static_cast<Eigen::Index>(i));
    bodies.push_back({b.name, b.urdf.model, b.urdf.path, b.q0, b.base, b.joints.urdf_joints(), o});
    contact_bodies.push_back({b.name, &b.urdf});
    o += b.joints.size();
  }
  const NameCheck check = [&](const std::string& n) -> std::string {
    return joints.coord(n) < N
               ? ""
               : "no coordinate '" + n + "' (they are <body>.<joint>, <body>.x, ...)";
  };
  SceneDynamics dyn = linear_dynamics(lin, q0v);
  add_springs(keys, source, check, joints, dyn);
  SceneConstraints constraints = stacked_stops(parts, N);
  add_constraints(keys, source, check, joints, constraints);
  const std::vector<Plane> planes = read_planes(keys, source);
  const Bodies exact(bodies, gravity);
  SceneContacts contacts =
      add_contacts(keys, source, contact_bodies, planes, exact, q0v, constraints);
  check_unique_names(constraints, source);
  mech::MechanicalModel m = assemble(lin, dyn, constraints, joints);
  add_contact_friction(contacts, m);  // as a one-URDF scene's (scene.cpp): it was dropped
  m.restitution = read_restitution(keys, source, m.constraints);
  check_mass_matrix(lin.M, joints, source);
  model.initial = read_initial(keys, source, check, joints, q0v);
  read_t_end(keys, source, model);
  mech::fill_defaults(m);
  model.mechanical = m;
  std::vector<std::string> notes;
  for (BodyPart& b : parts)
    for (std::string& n : b.urdf.repairs.notes) notes.push_back(std::move(n));
  for (std::string& n : contacts.notes) notes.push_back(std::move(n));
  return Scene{std::move(model),
               nullptr,
               "",
               q0,
               gravity,
               lin,
               std::move(notes),
               BasePose{},
               planes,
               std::move(contacts.frames),
               std::move(bodies)};
}

}  // namespace lcsim::scene
