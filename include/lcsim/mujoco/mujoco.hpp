// The MuJoCo layer (optional, Debian's libmujoco-dev 2.2.2): a URDF scene
// with contacts run in MuJoCo beside lcsim (docs/contacts.md, "Peers on
// contact scenes").
//
// Public face of src/mujoco. A one-URDF scene: MuJoCo loads the scene's URDF
// itself (its own URDF reader: bodies, joints, inertias, the <collision>
// primitives as geoms); lcsim then adds a free joint at the root (a floating
// base) and one plane geom per scene plane, and sets the contact parameters
// below. A scene of several bodies (`bodies:`): lcsim writes the whole MJCF
// from the scene it parsed, each contact point a geom and each contact row an
// explicit <pair> (src/mujoco/mjcf_bodies.cpp; docs/contacts.md, "Scenes of
// several bodies").
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::mujoco {

// "MuJoCo 2.2.2", from mj_version().
std::string version_string();

// Every MuJoCo setting that affects accuracy, pinned (MuJoCo's defaults
// stated where they differ).
struct Settings {
  // solref's time constant (s) of every contact: the contact is a damped
  // spring reaching the constraint in about this time. 0: 2 h, the smallest
  // MuJoCo keeps stable (below 2 h it is raised to 2 h anyway; MuJoCo's
  // default is 0.02 s, soft). The resting penetration grows with its square.
  double time_constant = 0.0;
  // solref's damping ratio (MuJoCo's default 1: critically damped).
  double damping_ratio = 1.0;
  // solimp (MuJoCo's defaults): the impedance d rises from dmin to dmax over
  // `width` m of penetration; d near 1 is a hard contact.
  double dmin = 0.9, dmax = 0.95, width = 0.001;
  // The friction cone of a scene whose contacts have `friction:` (condim 3:
  // sliding friction in MuJoCo's two contact tangents; mjOption::cone).
  // Pyramidal (MuJoCo's default): 4 edges n +- mu t1, n +- mu t2, so the
  // friction force lies in the square with its corners at mu N on the
  // tangents, lcsim's d = 2 cone. Elliptic: the circular cone |f_t| <= mu N.
  // impratio (the friction rows' impedance relative to the normal's) is
  // pinned at MuJoCo's default 1.
  enum class Cone { kPyramidal, kElliptic };
  Cone cone = Cone::kPyramidal;
};

// "pyramidal" or "elliptic" (mjOption::cone's XML names).
std::string cone_name(Settings::Cone c);
// The cone named `name` ("pyramidal", "elliptic"); std::invalid_argument
// naming it and the choices otherwise.
Settings::Cone parse_cone(const std::string& name);

// "" when usable, else one line naming the first bad setting and its value.
std::string settings_error(const Settings& s);

// "mj_step (Euler), condim 1 (frictionless), solref (0.002 s, 1), ..." at step h;
// with `friction` (the scene's contacts have friction:) condim 3 and the cone.
std::string settings_description(const Settings& s, double h, bool friction = false);

// Throws std::invalid_argument naming what MuJoCo cannot run here: a model
// that is not a URDF scene (or changed since it was loaded), a scene
// constraint that is not a contact (a joint stop), a mimic joint; in a
// one-URDF scene also a contact with explicit points, a link whose contact
// points differ in their friction coefficient (MuJoCo's friction is per
// geom), a movable URDF joint the scene does not simulate, a fixed base at a
// pose other than the identity.
void check_expressible(const mech::Model& model);

// The scene run by mj_step at fixed step opt.h (the last step shortened to
// land on opt.t_end), filling a Trajectory as the time-stepping methods do:
// samples (every step, or on the opt.dt_out grid; x = q then v in the
// model's coordinate order), u = each contact point's normal force (its own
// geom's in a scene of bodies; the MuJoCo contact nearest to that point on
// its link in a one-URDF scene, N), u_t and u_t2 = the friction force on
// each friction entry's point along its contact's tangents t1, t2 (N; zero
// at t = 0, empty without friction), mode = the contact
// points with a force, events at every mode change, energies of lcsim's
// model at MuJoCo's states, max_violation (lcsim's linear gaps there: the
// soft contacts penetrate). Not expressible: std::invalid_argument before
// anything runs. MuJoCo failing to load the URDF: kInvalidInput with its
// message. A run that diverges (non-finite state, MuJoCo's bad-acceleration
// warning, sim::DivergenceGuard): kNumericalFailure, never a completed run.
sim::Trajectory simulate_mujoco(const mech::Model& model, const Eigen::VectorXd& x0,
                                const sim::Options& opt, const Settings& s = {});

// For bench/: the wall time of one mj_step (s), the mean over `steps` steps
// of the scene's MuJoCo model (as simulate_mujoco sets it up) from x0 at
// step h, the scene's forces at x0 applied throughout; nothing else timed.
// Throws as check_expressible.
double mj_step_time(const mech::Model& model, const Eigen::VectorXd& x0, double h, long steps,
                    const Settings& s = {});

// Adds the "mujoco" integrator to sim::integrators(). Called by the
// registration source compiled into every program linking lcsim::mujoco.
void register_backends();

}  // namespace lcsim::mujoco
