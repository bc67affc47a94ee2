// A URDF scene with contacts run in MuJoCo (mj_step), beside lcsim.
//
// What MuJoCo integrates: the URDF's nonlinear multibody (MuJoCo's own URDF
// reader) with a free joint at the root for a floating base; the scene's
// springs and dampers as applied generalised forces (qfrc_applied) before
// every step, tau = f_s - K_s q - D v with K_s = K - K_g and
// f_s = f - tau_g(q0) - K_g q0 (the linearised gravity removed: MuJoCo has
// the nonlinear one), as Bullet's multibody does (src/bullet). MuJoCo's own
// joint damping, armature, friction loss, stiffness and joint ranges are set
// to 0 / off: the scene states its own.
//
// Contacts: the geoms of the links the scene's contacts name (the URDF's
// <collision> primitives: a box collides as a box, up to 4 contacts on a
// plane) collide with the scene's planes and nothing else (contype 1 /
// conaffinity 0 against 0 / 1), condim 1 (frictionless; with the scene's
// friction: condim 3, the link's mu on its geoms, Settings::cone), solref
// (time constant, damping ratio) and solimp from Settings. MuJoCo's contacts
// are soft by design: a contact force exists only with penetration (or
// within solimp's width), set by a spring-damper reference acceleration
// -b v - k r that the solver tracks with impedance d < 1. So a resting body
// sinks by a small steady depth instead of lcsim's zero gap, and an impact
// takes about one time constant instead of an instant.
//
// The floating base's coordinates map as in docs/contacts.md: MuJoCo's free
// joint holds the root origin p and the quaternion of exp([r]x) R0; its
// velocity is p' (world) and the angular velocity in the root's frame,
// R' J_l(r) r'.
#include <mujoco/mujoco.h>
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <map>
#include <optional>
#include <regex>
#include <stdexcept>

#include "mujoco/detail.hpp"

namespace lcsim::mujoco {

using Eigen::MatrixXd;

std::string version_string() { return std::string("MuJoCo ") + mj_versionString(); }

std::string settings_error(const Settings& s) {
  auto bad = [](const char* name, double v, const char* rule) {
    return std::string("mujoco setting ") + name + " must be " + rule + " (got " + short_number(v) +
           ")";
  };
  if (!(std::isfinite(s.time_constant) && s.time_constant >= 0.0))
    return bad("time_constant", s.time_constant, "finite and >= 0");
  if (!(std::isfinite(s.damping_ratio) && s.damping_ratio > 0.0))
    return bad("damping_ratio", s.damping_ratio, "finite and > 0");
  if (!(s.dmin > 0.0 && s.dmin < 1.0)) return bad("dmin", s.dmin, "in (0, 1)");
  if (!(s.dmax >= s.dmin && s.dmax < 1.0)) return bad("dmax", s.dmax, "in [dmin, 1)");
  if (!(std::isfinite(s.width) && s.width > 0.0)) return bad("width", s.width, "finite and > 0");
  return "";
}

namespace {

double time_constant(const Settings& s, double h) {
  return s.time_constant > 0.0 ? std::max(s.time_constant, 2.0 * h) : 2.0 * h;
}

}  // namespace

std::string cone_name(Settings::Cone c) {
  return c == Settings::Cone::kElliptic ? "elliptic" : "pyramidal";
}

Settings::Cone parse_cone(const std::string& name) {
  if (name == "pyramidal") return Settings::Cone::kPyramidal;
  if (name == "elliptic") return Settings::Cone::kElliptic;
  throw std::invalid_argument("mujoco: unknown friction cone '" + name + "' (pyramidal, elliptic)");
}

std::string settings_description(const Settings& s, double h, bool friction) {
  const std::string contact =
      !friction ? "condim 1 (frictionless)"
      : s.cone == Settings::Cone::kElliptic
          ? "condim 3 (sliding friction, mu the scene's on the link's geoms, 0 on the planes: "
            "MuJoCo takes the larger), elliptic cone (|f_t| <= mu f_n), impratio 1"
          : "condim 3 (sliding friction, mu the scene's on the link's geoms, 0 on the planes: "
            "MuJoCo takes the larger), pyramidal cone (edges n +- mu t1, n +- mu t2), impratio 1";
  return "mj_step (Euler integrator, Newton solver, 100 iterations, tolerance 1e-8), " + contact +
         ", solref (" + short_number(time_constant(s, h)) + " s, " + short_number(s.damping_ratio) +
         "), solimp (" + short_number(s.dmin) + ", " + short_number(s.dmax) + ", " +
         short_number(s.width) + " m)";
}

namespace {

// Why MuJoCo cannot hold the scene's friction, or "": a frictional row that
// is not a scene contact's (or a moving surface), or a link whose contact
// points differ in mu (MuJoCo's friction is per geom: every geom of the link
// gets it).
std::string friction_refusal(const mech::MechanicalModel& m, const scene::Scene& sc) {
  std::map<int, double> mu_of_row;
  for (const mech::FrictionalContact& f : m.friction) {
    if (f.velocity != 0.0 || !f.is_3d())
      return "constraint '" + m.constraints[static_cast<std::size_t>(f.contact)] +
             "' has friction that is not a scene contact's: MuJoCo runs the friction of "
             "contacts: only";
    mu_of_row[f.contact] = f.mu;
  }
  std::map<std::string, std::pair<double, std::string>> mu_of_link;  // link -> (mu, first contact)
  for (const auto& cf : sc.contacts) {
    const auto it = mu_of_row.find(static_cast<int>(cf.row));
    const double mu = it == mu_of_row.end() ? 0.0 : it->second;
    const auto [seen, fresh] = mu_of_link.emplace(cf.point.link, std::make_pair(mu, cf.point.name));
    if (!fresh && seen->second.first != mu)
      return "contact '" + cf.point.name + "' has friction mu = " + short_number(mu) +
             " but contact '" + seen->second.second + "' of the same link '" + cf.point.link +
             "' has mu = " + short_number(seen->second.first) +
             ": MuJoCo's friction is per geom (one mu per link)";
  }
  return "";
}

// What a scene of bodies cannot have in MuJoCo (mjcf_bodies.cpp), or "":
// a constraint that is neither a contact nor a stop on one joint (a joint
// range in MuJoCo), friction that is not a scene contact's, a mimic joint.
// Each contact point is a geom of its own, so explicit points, frozen joints
// and one mu per pair are fine.
std::string bodies_refusal(const mech::MechanicalModel& m, const scene::Scene& sc,
                           const std::vector<bool>& contact) {
  for (const mech::FrictionalContact& f : m.friction)
    if (f.velocity != 0.0 || !f.is_3d())
      return "constraint '" + m.constraints[static_cast<std::size_t>(f.contact)] +
             "' has friction that is not a scene contact's: MuJoCo runs the friction of "
             "contacts: only";
  for (int i = 0; i < m.num_constraints(); ++i) {
    if (contact[static_cast<std::size_t>(i)]) continue;
    std::vector<int> nz;
    for (int j = 0; j < m.dofs(); ++j)
      if (m.E.coeff(i, j) != 0.0) nz.push_back(j);
    bool on_base = false;
    for (const scene::SceneBody& b : sc.bodies)
      if (nz.size() == 1 && b.base.floating && nz[0] >= b.offset && nz[0] < b.offset + 6)
        on_base = true;
    if (nz.size() != 1 || on_base)
      return "constraint '" + m.constraints[static_cast<std::size_t>(i)] +
             "' is not a contact nor a stop on one joint: MuJoCo runs contacts and joint ranges "
             "only";
  }
  for (const scene::SceneBody& b : sc.bodies)
    for (const auto& [name, j] : b.urdf->joints_)
      if (j->mimic)
        return "body '" + b.name + "': joint '" + name +
               "' is a mimic: lcsim's MuJoCo model of a scene of bodies has none";
  return "";
}

// Where a one-URDF scene has what MuJoCo's own URDF reader cannot take, the
// same scene written as `bodies:` with one body can (mjcf_bodies.cpp).
constexpr const char* kAsBodies =
    " (write the scene as `bodies:` with this one body: lcsim then composes MuJoCo's model "
    "itself, with explicit points, stops and frozen joints)";

// What check_expressible refuses, or "" (the scene found).
std::string refusal(const mech::Model& model, std::optional<scene::Scene>& sc) {
  sc = scene::scene_of(model);
  if (!sc)
    return "mujoco: " + model.source +
           ": MuJoCo runs URDF scenes only (a model file with `urdf:`, unchanged since loading)";
  const mech::MechanicalModel& m = *model.mechanical;
  const std::string where = "mujoco: " + model.source + ": ";
  std::vector<bool> contact(static_cast<std::size_t>(m.num_constraints()), false);
  for (const auto& cf : sc->contacts) contact[static_cast<std::size_t>(cf.row)] = true;
  if (!sc->bodies.empty()) {
    const std::string why = bodies_refusal(m, *sc, contact);
    return why.empty() ? why : where + why;
  }
  if (std::string why = friction_refusal(m, *sc); !why.empty()) return where + why;
  for (int i = 0; i < m.num_constraints(); ++i)
    if (!contact[static_cast<std::size_t>(i)])
      return where + "constraint '" + m.constraints[static_cast<std::size_t>(i)] +
             "' is not a contact against a plane: MuJoCo runs contacts only" + kAsBodies;
  for (const auto& cf : sc->contacts)
    if (std::regex_search(cf.point.name, std::regex("\\.point[0-9]+$")))
      return where + "contact '" + cf.point.name +
             "' has explicit points: MuJoCo collides the URDF's <collision> geometry only" +
             kAsBodies;
  if (!sc->base.floating && !sc->base.pose.isApprox(Eigen::Isometry3d::Identity(), 0.0))
    return where + "a fixed base at a pose: MuJoCo runs a fixed root at the identity only";
  std::vector<std::string> coords(m.coordinates.begin() + (sc->base.floating ? 6 : 0),
                                  m.coordinates.end());
  for (const auto& [name, j] : sc->urdf->joints_) {
    if (j->type == urdf::Joint::FIXED) continue;
    if (j->mimic) return where + "joint '" + name + "' is a mimic: MuJoCo's URDF reader has none";
    if (std::find(coords.begin(), coords.end(), name) == coords.end())
      return where + "joint '" + name +
             "' is frozen in the scene: MuJoCo's URDF reader would move it" + kAsBodies;
  }
  return "";
}

}  // namespace

void check_expressible(const mech::Model& model) {
  std::optional<scene::Scene> sc;
  if (std::string why = refusal(model, sc); !why.empty()) throw std::invalid_argument(why);
}

}  // namespace lcsim::mujoco
