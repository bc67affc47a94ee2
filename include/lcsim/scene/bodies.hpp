// The bodies of a scene: one URDF (today's scenes) or several (`bodies:`,
// docs/contacts.md, "Several bodies"), each with its own base, joints and
// reference configuration. The scene's coordinates are the concatenation of
// the bodies' coordinates, so the exact dynamics are block diagonal: each
// body's mass matrix and gravity force at its own coordinates.
#pragma once
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <lcsim/scene/urdf.hpp>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace urdf {
class Joint;
}

namespace lcsim::scene {

// One body of a scene: a URDF with its base and simulated joints. Its
// coordinates are the scene's offset .. offset + size - 1: a floating
// base's six (named <name>.x ... .rz), then its simulated joints.
struct SceneBody {
  std::string name;  // "" in a one-URDF scene (names unprefixed)
  std::shared_ptr<urdf::ModelInterface> urdf;
  std::string urdf_source;           // the URDF's path, for messages
  std::map<std::string, double> q0;  // by the URDF's joint names (joints not named: 0)
  BasePose base;
  std::vector<std::string> joints;  // the simulated URDF joints (the URDF's names)
  Eigen::Index offset = 0;          // the body's first coordinate in the scene's q
};

// The exact (nonlinear) dynamics of a scene's bodies as functions of the
// scene's coordinates q (UrdfDynamics per body, placed at its offset). No
// coupling between bodies but through contacts: M(q) and the damping are
// block diagonal, tau_g(q) the bodies' forces stacked.
class Bodies {
 public:
  Bodies(std::vector<SceneBody> bodies, const Eigen::Vector3d& gravity);
  const std::vector<SceneBody>& bodies() const { return bodies_; }
  Eigen::Index size() const { return size_; }  // coordinates of the scene
  Eigen::Index body_size(std::size_t b) const;
  VectorXd reference() const;  // q0 of every coordinate (bases at their poses)
  MatrixXd mass_matrix(const VectorXd& q) const;
  VectorXd gravity_force(const VectorXd& q) const;  // N or N m
  VectorXd damping() const;
  // World pose of link `link` of body b at q; InputError for a link not in it.
  Eigen::Isometry3d link_pose(std::size_t b, const std::string& link, const VectorXd& q) const;
  // d(X_link(q) local)/dq over all the scene's coordinates (3 x size(); zero
  // outside body b's columns), world axes, m per coordinate unit.
  Eigen::Matrix3Xd point_jacobian(std::size_t b, const std::string& link,
                                  const Eigen::Vector3d& local, const VectorXd& q) const;
  // The URDF joint of coordinate i (nullptr for a floating base's), and
  // whether the coordinate is a length (m) rather than an angle (rad).
  std::shared_ptr<const urdf::Joint> joint_of(Eigen::Index i) const;
  bool in_metres(Eigen::Index i) const;

 private:
  std::size_t body_of(Eigen::Index i) const;
  std::vector<SceneBody> bodies_;
  std::vector<UrdfDynamics> dyn_;
  Eigen::Index size_ = 0;
};

}  // namespace lcsim::scene
