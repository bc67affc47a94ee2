// Scenes: a URDF plus the joints to simulate, springs, extra unilateral
// constraints, the reference configuration, gravity, restitution, the initial
// state and the horizon (docs/model-format.md, "Scenes"). The scene becomes a
// mechanical model linearised about q0 (urdf_model.cpp).
//
// Coordinates are the joint positions themselves (not deviations from q0):
//   M q'' + D q' + K q = f + E' u,   E q + g >= 0,
//   K = K_springs + K_g,  f = tau_g(q0) + K_g q0 + sum_s k_s rest_s c_s,
// from tau_g(q) ~ tau_g(q0) - K_g (q - q0) and a spring force
// -k (c'q - rest) c on the coordinates (c = e_a or e_a - e_b).
//
// read_scene is a driver calling one stage per key (declared in
// scene/detail.hpp): urdf and balance_inertia (scene_urdf.cpp), joints
// (scene_joints.cpp, their stops in scene_stops.cpp), q0 and initial
// (scene_state.cpp), springs (scene_springs.cpp), constraints and
// restitution (scene_constraints.cpp); name, gravity, t_end and the mass
// matrix's check here.
#include <urdf_model/model.h>
#include <yaml-cpp/yaml.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <lcsim/io/json.hpp>
#include <lcsim/io/model_file.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <limits>
#include <set>
#include <sstream>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::is_scene;
using io::load_model_root;
using io::one_line;
using io::read_file;
namespace yaml = io::yaml;

using yaml::describe;
using yaml::fail;
using yaml::join;
using yaml::load;
using yaml::mapping;
using yaml::number;

// The name (the file's stem unless `name:` gives one) and source.
mech::Model named_model(const Keys& keys, const std::string& source) {
  mech::Model model;
  model.source = source;
  model.name = std::filesystem::path(source).stem().string();
  if (keys.count("name")) model.name = name_of(keys.at("name"), source, "name");
  return model;
}

// `gravity:` (m/s^2, URDF root frame; default (0, 0, -9.81)).
Eigen::Vector3d read_gravity(const Keys& keys, const std::string& source) {
  Eigen::Vector3d gravity(0.0, 0.0, -9.81);
  if (keys.count("gravity")) {
    const YAML::Node& g = keys.at("gravity");
    if (!g.IsSequence() || g.size() != 3)
      fail(source, "gravity", "expected a vector of 3 numbers in m/s^2 (got " + describe(g) + ")");
    for (std::size_t i = 0; i < 3; ++i)
      gravity(static_cast<Eigen::Index>(i)) =
          number(g[i], source, "gravity[" + std::to_string(i) + "]");
  }
  return gravity;
}

// The linearised dynamics at q0: the joints' damping, K = K_g and
// f = tau_g(q0) + K_g q0 (the springs add to them).
SceneDynamics linear_dynamics(const UrdfLinearisation& lin, const VectorXd& q0) {
  SceneDynamics dyn;
  dyn.D = MatrixXd(lin.damping.asDiagonal());
  dyn.K = lin.K_g;
  dyn.f = lin.tau_g + lin.K_g * q0;
  return dyn;
}

// M must be symmetric positive definite (the CRBA makes it symmetric by
// construction; a massless subtree makes it singular).
void check_mass_matrix(const MatrixXd& M, const SceneJoints& joints, const std::string& source) {
  const Eigen::SelfAdjointEigenSolver<MatrixXd> es(M);
  const double eps = std::numeric_limits<double>::epsilon();
  const Eigen::Index N = joints.size();
  if (es.eigenvalues().minCoeff() <=
      static_cast<double>(N) * eps * std::abs(es.eigenvalues().maxCoeff())) {
    // The joints that move along the null direction (its largest
    // components: a unit vector has one of at least 1/sqrt(N)).
    const VectorXd v = es.eigenvectors().col(0).cwiseAbs();
    std::vector<std::string> which;
    bool base_only = true;
    for (Eigen::Index i = 0; i < N; ++i)
      if (v(i) >= 0.5 * v.maxCoeff()) {
        which.push_back("'" + joints.names[static_cast<std::size_t>(i)] + "'");
        base_only = base_only && static_cast<std::size_t>(i) < joints.base;
      }
    // A floating body with zero <inertia> (bullet3's
    // sphere_small_zeroinertia.urdf, a point mass) cannot turn: say so, not
    // "joint", since no joint is involved.
    if (base_only)
      fail(source, "base",
           "the mass matrix at q0 is not positive definite (smallest eigenvalue " +
               format_number(es.eigenvalues().minCoeff()) + ", along the floating base's " +
               join(which) +
               "): the floating body has no rotational inertia about that axis (its links' "
               "<inertia> is zero: a point mass); give its root link a rotational inertia");
    fail(source, "joints",
         "the mass matrix at q0 is not positive definite (smallest eigenvalue " +
             format_number(es.eigenvalues().minCoeff()) + ", along joint " + join(which) +
             "): the joint moves no inertia about its axis (a point mass or massless links on "
             "the axis)");
  }
}

// `t_end:` (s), > 0.
void read_t_end(const Keys& keys, const std::string& source, mech::Model& model) {
  if (!keys.count("t_end")) return;
  model.t_end = number(keys.at("t_end"), source, "t_end");
  if (!(model.t_end > 0.0))
    fail(source, "t_end", "must be > 0 (got " + format_number(model.t_end) + ")");
}

// The mechanical model, stored sparse, from the stages' dense parts.
mech::MechanicalModel assemble(const UrdfLinearisation& lin, const SceneDynamics& dyn,
                               const SceneConstraints& con, const SceneJoints& joints) {
  mech::MechanicalModel m;
  m.f = dyn.f;
  m.coordinates = joints.names;
  m.constraints = con.names;
  m.g = con.g();
  m.M = lin.M.sparseView();
  m.D = dyn.D.sparseView();
  m.K = dyn.K.sparseView();
  m.E = con.E(joints.size()).sparseView();
  return m;
}

// One stage per key (scene/detail.hpp), in the order the file is checked:
// a new key's stage goes after those whose results it needs.
Scene read_scene(const std::string& yaml_text, const std::string& source) {
  const YAML::Node root = load(yaml_text, source);
  if (root.IsMap() && root["bodies"]) return read_bodies_scene(root, source);
  const Keys keys = mapping(
      root, source, "",
      {"name", "urdf", "joints", "q0", "gravity", "springs", "constraints", "restitution",
       "initial", "t_end", "balance_inertia", "base", "planes", "contacts", "contact_options"});
  mech::Model model = named_model(keys, source);
  SceneUrdf urdf = read_urdf(keys, source);
  const BasePose base = read_base(keys, source, urdf);
  const SceneJoints joints = read_joints(keys, source, urdf, base);
  std::map<std::string, double> q0 = read_q0(keys, source, urdf, joints);
  const Eigen::Vector3d gravity = read_gravity(keys, source);
  const UrdfDynamics exact(*urdf.model, joints.urdf_joints(), q0, gravity, urdf.path, base);
  const VectorXd q0v = exact.reference();
  for (std::size_t i = 0; i < joints.base; ++i)
    q0[joints.names[i]] = q0v(static_cast<Eigen::Index>(i));
  const UrdfLinearisation lin =
      linearise_urdf(*urdf.model, joints.urdf_joints(), q0, gravity, urdf.path, base);

  SceneDynamics dyn = linear_dynamics(lin, q0v);
  add_springs(keys, source, simulated(joints, urdf), joints, dyn);
  SceneConstraints constraints = joint_stops(source, urdf, joints);
  add_constraints(keys, source, simulated(joints, urdf), joints, constraints);
  const std::vector<Plane> planes = read_planes(keys, source);
  const Bodies bodies({{"", urdf.model, urdf.path, q0, base, joints.urdf_joints(), 0}}, gravity);
  SceneContacts contacts =
      add_contacts(keys, source, {{"", &urdf}}, planes, bodies, q0v, constraints);
  check_unique_names(constraints, source);
  mech::MechanicalModel m = assemble(lin, dyn, constraints, joints);
  add_contact_friction(contacts, m);
  m.restitution = read_restitution(keys, source, m.constraints);
  check_mass_matrix(lin.M, joints, source);
  model.initial = read_initial(keys, source, simulated(joints, urdf), joints, q0v);
  read_t_end(keys, source, model);

  mech::fill_defaults(m);
  model.mechanical = m;
  std::vector<std::string> notes = std::move(urdf.repairs.notes);
  for (std::string& n : contacts.notes) notes.push_back(std::move(n));
  return Scene{std::move(model),
               urdf.model,
               urdf.path,
               q0,
               gravity,
               lin,
               std::move(notes),
               base,
               planes,
               std::move(contacts.frames),
               {}};
}

Bodies scene_bodies(const Scene& s) {
  if (!s.bodies.empty()) return Bodies(s.bodies, s.gravity);
  const std::size_t nb = base_coordinates(s.base).size();
  const std::vector<std::string> joints(s.lin.joints.begin() + static_cast<std::ptrdiff_t>(nb),
                                        s.lin.joints.end());
  return Bodies({{"", s.urdf, s.urdf_source, s.q0, s.base, joints, 0}}, s.gravity);
}

mech::Model parse_scene(const std::string& yaml_text, const std::string& source) {
  return read_scene(yaml_text, source).model;
}

mech::Model parse_model(const std::string& yaml_text, const std::string& source) {
  // A SPICE netlist (.cir, .sp, .net, ...) is a circuit (docs/circuits.md).
  if (circuit::is_netlist_path(source)) return circuit::parse_circuit(yaml_text, source).model;
  const YAML::Node root = io::load_model_root(yaml_text, source);
  // A top-level `urdf:` key makes the file a scene.
  if (io::is_scene(root)) {
    try {
      return parse_scene(yaml_text, source);
    } catch (const InputError& e) {
      throw InputError(io::one_line(e.what()));  // URDF names and values may hold newlines
    }
  }
  return io::parse_matrix_model(root, source);
}

mech::Model load_model(const std::filesystem::path& path) {
  return parse_model(io::read_file(path), path.string());
}

LoadedModel load_model_and_scene(const std::filesystem::path& path) {
  const std::string text = read_file(path);
  if (circuit::is_netlist_path(path)) {
    auto c = std::make_shared<const circuit::Circuit>(circuit::parse_circuit(text, path.string()));
    return {c->model, std::nullopt, c};
  }
  const YAML::Node root = load_model_root(text, path.string());
  if (!is_scene(root)) return {io::parse_matrix_model(root, path.string()), std::nullopt, nullptr};
  try {
    Scene scene = read_scene(text, path.string());
    mech::Model model = scene.model;
    return {std::move(model), std::move(scene), nullptr};
  } catch (const InputError& e) {
    throw InputError(one_line(e.what()));  // as load_model: URDF names may hold newlines
  }
}

std::vector<std::string> model_notes(const LoadedModel& loaded) {
  std::vector<std::string> notes = loaded.scene ? loaded.scene->notes : std::vector<std::string>{};
  for (std::string& n : io::model_notes(loaded.model)) notes.push_back(std::move(n));
  return notes;
}

std::optional<Scene> load_scene_details(const std::filesystem::path& path) {
  return load_model_and_scene(path).scene;
}

namespace {

bool same_matrix(const mech::SparseMatrix& a, const mech::SparseMatrix& b) {
  return a.rows() == b.rows() && a.cols() == b.cols() && MatrixXd(a) == MatrixXd(b);
}

bool same_vector(const VectorXd& a, const VectorXd& b) { return a.size() == b.size() && a == b; }

// The same model up to the restitution: a restitution is a parameter of the
// constraints, not of the scene's bodies (the URDF has none; a study's
// restitution axis changes it, issue 24), so a scene with another one is
// still that scene.
bool same_model(const mech::MechanicalModel& a, const mech::MechanicalModel& b) {
  return same_matrix(a.M, b.M) && same_matrix(a.D, b.D) && same_matrix(a.K, b.K) &&
         same_matrix(a.E, b.E) && same_vector(a.g, b.g) && same_vector(a.f, b.f) &&
         a.restitution.size() == b.restitution.size() && a.coordinates == b.coordinates &&
         a.constraints == b.constraints;
}

}  // namespace

std::optional<Scene> scene_of(const mech::Model& model) {
  if (!model.is_mechanical()) return std::nullopt;
  try {
    std::optional<Scene> scene = load_scene_details(model.source);
    if (!scene || !same_model(*scene->model.mechanical, *model.mechanical)) return std::nullopt;
    scene->model.mechanical->restitution = model.mechanical->restitution;  // the model's own
    return scene;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

std::optional<Scene> scene_setup(const mech::Model& model) {
  std::optional<Scene> scene = scene_of(model);
  // Joint limits only, on one URDF with its root fixed at the identity
  // (Bullet's joint-limit multibody; its contact scenes: src/bullet/world.cpp).
  if (!scene || !scene->bodies.empty() || scene->base.floating ||
      scene->base.pose.matrix() != Eigen::Matrix4d::Identity() || !scene->contacts.empty())
    return std::nullopt;
  return scene;
}

mech::Model load_scene(const std::filesystem::path& path) {
  return parse_scene(read_file(path), path.string());
}

}  // namespace lcsim::scene
