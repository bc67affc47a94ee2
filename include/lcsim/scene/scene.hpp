// Scenes: a robot from its URDF with springs, stops and a reference
// configuration (docs/model-format.md, "Scenes"), linearised into a mechanical
// model; and the one entry that reads any model file.
#pragma once

#include <Eigen/Dense>
#include <filesystem>
#include <lcsim/circuit/circuit.hpp>
#include <lcsim/io/input_error.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/bodies.hpp>
#include <lcsim/scene/contacts.hpp>
#include <lcsim/scene/urdf.hpp>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace lcsim::scene {

using io::InputError;

// Any model file: a matrix model (io::parse_matrix_model), with a top-level
// `urdf:` key a scene (load_scene), or by its extension (.cir, .sp, .net,
// ...) a SPICE netlist (circuit::load_circuit). Every command reads its model
// through these. InputError names the file, the key and the value.
mech::Model load_model(const std::filesystem::path& path);
// The same from YAML text; `source` names it in messages (and a scene's URDF
// path is relative to its directory).
mech::Model parse_model(const std::string& yaml_text, const std::string& source);

// Scenes: a YAML file with a top-level `urdf:` key. `load_model` and
// `parse_model` dispatch to these, so every command accepts a scene. The URDF
// path is relative to the directory of `source` (the scene's path). The
// coordinates are the joint positions (not deviations from q0); format and
// linearisation in docs/model-format.md, "Scenes".
mech::Model load_scene(const std::filesystem::path& path);
mech::Model parse_scene(const std::string& yaml_text, const std::string& source);

// A scene's model with what it was linearised from, so that the exact
// dynamics can be evaluated away from q0 (check_linearisation).
struct Scene {
  mech::Model model;
  std::shared_ptr<urdf::ModelInterface> urdf;
  std::string urdf_source;           // the URDF's path, for messages
  std::map<std::string, double> q0;  // as the scene gives it (joints not named: 0), and
                                     // a floating base's reference coordinates by name
  Eigen::Vector3d gravity;           // m/s^2, world frame (the root frame at the identity base)
  UrdfLinearisation lin;             // M, tau_g, K_g, damping at q0 (coordinates: lin.joints)
  std::vector<std::string> notes;    // what loading repaired (UrdfRepairs::notes), dropped contacts
  BasePose base;                     // where the URDF's root sits (fixed or floating)
  std::vector<Plane> planes;         // the world planes of `planes:`
  std::vector<ContactFrame> contacts;  // one per contact row of E (ContactFrame::row)
  // A scene of several URDFs (`bodies:`, docs/contacts.md): each body, its
  // coordinates at its offset. Then `urdf` is null, `q0` and `lin.joints`
  // name the coordinates (`<body>.<joint>`, `<body>.x`, ...), `lin` is the
  // bodies' block-diagonal whole and `base` is unused. Empty in a one-URDF
  // scene.
  std::vector<SceneBody> bodies;
};
// The exact dynamics of the scene's bodies (its one URDF as body "" when
// `bodies` is empty): what its linear model is checked against.
Bodies scene_bodies(const Scene& scene);
Scene read_scene(const std::string& yaml_text, const std::string& source);
// The scene in `path`, or nullopt when the file is a model, not a scene (no
// top-level `urdf:` key). Errors as load_model.
std::optional<Scene> load_scene_details(const std::filesystem::path& path);
// The scene `model` was loaded from (model.source), while `model` is still
// what that file gives up to the restitution (a parameter of the
// constraints, which the Scene then takes from `model`); else nullopt (a
// matrix model, a changed model, a file that no longer loads). What a peer
// that rebuilds the URDF starts from.
std::optional<Scene> scene_of(const mech::Model& model);
// The model in `path` (as load_model) and, for a scene, the Scene: the file
// is read and parsed once (a 10000-cart model's YAML tree is 75 MB).
struct LoadedModel {
  mech::Model model;
  std::optional<Scene> scene;
  // For a SPICE netlist (.cir, .sp, .net, ...): the circuit the model was
  // reduced from (names, diode forms, passivity; docs/circuits.md).
  std::shared_ptr<const circuit::Circuit> circuit = nullptr;
};
LoadedModel load_model_and_scene(const std::filesystem::path& path);
// model_notes of the model, after the scene's notes (what loading repaired):
// the notes `analyze` prints.
std::vector<std::string> model_notes(const LoadedModel& loaded);

// The scene `model` was loaded from (model.source, read again), for building
// it again from its URDF (src/bullet); std::nullopt when model.source is not
// a readable, valid scene file or when `model` is not what that file gives
// (changed after loading: M, D, K, E, g, f or the names differ). The
// restitution may differ: the returned scene's model carries `model`'s (a
// study's restitution axis changes a parameter, not the kind of model).
std::optional<Scene> scene_setup(const mech::Model& model);

}  // namespace lcsim::scene
