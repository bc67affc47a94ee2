// URDF robots (urdfdom): parsing with lcsim's checks, mimic joints, the exact
// joint-space dynamics and their linearisation about a reference configuration.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <filesystem>
#include <lcsim/io/input_error.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace urdf {
class ModelInterface;
}

namespace lcsim::scene {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using io::InputError;

// Parses a URDF file with urdfdom and checks what lcsim relies on: finite
// numbers in every <origin>, <axis>, <inertial>, <limit> and <dynamics>;
// masses >= 0; inertia tensors positive semi-definite with I1 + I2 >= I3
// (refused, or repaired: UrdfRepairs); non-zero axes on revolute,
// continuous and prismatic joints.
// <visual>, <collision> and <material> are dropped before urdfdom parses
// (a scene reads the <collision> primitives its contacts use from the text
// itself: docs/contacts.md). A <limit> with lower > upper is no limit; a scene refuses it only
// where it would become a stop. InputError names the file, the element and
// the value.
std::shared_ptr<urdf::ModelInterface> load_urdf(const std::filesystem::path& path);
// The same from URDF text; `source` names it in messages.
std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source);

// What parse_urdf repairs instead of refusing (a scene's `balance_inertia:
// true`), and what it repaired. An inertia tensor that is not positive
// semi-definite or breaks the triangle inequality I1 + I2 >= I3 (beyond the
// check's 1e-4 of the largest moment) is refused unless balance_inertia;
// then it is replaced, in its principal frame, by the moments with each
// negative one set to 0 and, if still I1 + I2 < I3, I1 and I2 each raised by
// half the deficit (I3, the principal axes and the mass kept; the result is
// positive semi-definite with I1 + I2 = I3). Valid tensors are never
// changed. Each repair adds a note naming the URDF, the link and the
// moments before and after.
struct UrdfRepairs {
  bool balance_inertia = false;
  std::vector<std::string> notes;
};
std::shared_ptr<urdf::ModelInterface> parse_urdf(const std::string& xml, const std::string& source,
                                                 UrdfRepairs& repairs);

// Where the URDF's root link sits in the world. Fixed: at `pose` (the
// identity by default: the root frame is the world). Floating: the root
// moves with six coordinates, named <name>.x, .y, .z (the root origin's
// world position, m) and <name>.rx, .ry, .rz (a rotation vector r, rad, in
// world axes, about the reference orientation: the root's orientation is
// exp([r]x) R0), with the reference pose `pose` = (R0, p0) at q = (p0, 0).
// Its angular velocity is J_l(r) r' (J_l the left Jacobian of SO(3), the
// identity at r = 0), so the model is exact at every r and the linear model
// about q0 uses r' as the angular velocity.
struct BasePose {
  bool floating = false;
  std::string name;  // floating: prefix of the coordinate names
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
};
// The six coordinate names of a floating base, none for a fixed one.
std::vector<std::string> base_coordinates(const BasePose& base);

// The rigid-body part of a scene linearised about a reference configuration.
// Coordinates are the joint positions themselves (rad for revolute, m for
// prismatic joints), in the order of `joints`, after a floating base's six.
struct UrdfLinearisation {
  std::vector<std::string> joints;  // the coordinates: a floating base's, then the joints
  MatrixXd M;        // joint-space mass matrix at q0 (composite-rigid-body algorithm)
  VectorXd tau_g;    // gravity generalised force at q0 (N or N m)
  MatrixXd K_g;      // gravity stiffness -d tau_g / dq at q0 (symmetric)
  VectorXd damping;  // <dynamics damping> of each simulated joint (N s/m or N m s/rad)
};

// <mimic joint="J" multiplier="a" offset="b"> on joint m: q_m = a q_J + b
// (urdfdom's defaults a = 1, b = 0). Chains are followed to the first joint
// that mimics nothing, composing the maps: the result's `leader` is never a
// mimic itself. Returns every revolute, continuous or prismatic joint that
// carries a <mimic> (a <mimic> on a fixed joint means nothing and is
// skipped). InputError naming the joint when a leader is missing or has no
// position (fixed, floating, planar), and for a cycle of mimics.
struct Mimic {
  std::string leader;
  double multiplier = 1.0;
  double offset = 0.0;
};
// `simulated`: joints a scene simulates. Such a joint is its own coordinate
// even if it carries a <mimic> (the scene's explicit choice wins: the NAO
// legs of issue 12 simulate RHipYawPitch, which the URDF ties to
// LHipYawPitch), so it is not returned, and a chain stops at it.
std::map<std::string, Mimic> mimic_joints(const urdf::ModelInterface& model,
                                          const std::string& source,
                                          const std::vector<std::string>& simulated = {});

// The exact (nonlinear) joint-space dynamics of a scene's URDF as functions
// of the coordinates q (the simulated joints, in the order of `joints`):
// every other joint sits at its `q0` (0 if not named), fixed joints are
// merged, and a mimic joint follows its leader (q_m = a q_J + b; when J is
// frozen, m is frozen there too). A mimic of a simulated joint moves with it:
// its motion enters the Jacobian of every body below it, so its mass,
// gravity and damping act through J. A simulated joint that is itself a
// mimic is refused (InputError naming both joints). `model` must outlive
// this object. Errors as linearise_urdf. With a floating `base`, q starts
// with its six coordinates (BasePose) and joints() with their names; a
// fixed base at a pose places the whole tree there (gravity stays in world
// axes).
class UrdfDynamics {
 public:
  UrdfDynamics(const urdf::ModelInterface& model, const std::vector<std::string>& joints,
               const std::map<std::string, double>& q0, const Eigen::Vector3d& gravity,
               const std::string& source, const BasePose& base = {});
  const std::vector<std::string>& joints() const { return joints_; }  // every coordinate
  VectorXd reference() const;  // q0 of the coordinates (a floating base at its pose: (p0, 0))
  MatrixXd mass_matrix(const VectorXd& q) const;    // M(q), composite-rigid-body algorithm
  VectorXd gravity_force(const VectorXd& q) const;  // tau_g(q) (N or N m)
  VectorXd damping() const;                         // diagonal of T' diag(<dynamics damping>) T
  // World pose of link `link` at q; InputError for a link not in the URDF.
  Eigen::Isometry3d link_pose(const std::string& link, const VectorXd& q) const;
  // d(X_link(q) local)/dq (3 x N, world axes, m per coordinate unit): the
  // world velocity of the link point `local` (link frame, m) is J q'.
  Eigen::Matrix3Xd point_jacobian(const std::string& link, const Eigen::Vector3d& local,
                                  const VectorXd& q) const;
  struct Impl;

 private:
  std::vector<std::string> joints_;
  std::shared_ptr<const Impl> impl_;
};

// Linearises `model` about q0 (positions by joint name; joints not named sit
// at 0) through UrdfDynamics: every joint not in `joints` is frozen at its
// q0, fixed joints are merged, mimics follow their leaders. `gravity` in the URDF root frame
// (m/s^2). `source` names the URDF in messages. K_g by central differences of tau_g, step 6e-6 (see
// urdf_model.cpp).
UrdfLinearisation linearise_urdf(const urdf::ModelInterface& model,
                                 const std::vector<std::string>& joints,
                                 const std::map<std::string, double>& q0,
                                 const Eigen::Vector3d& gravity, const std::string& source,
                                 const BasePose& base = {});

}  // namespace lcsim::scene
