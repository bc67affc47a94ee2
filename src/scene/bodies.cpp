// The exact dynamics of a scene's bodies, each a UrdfDynamics at its offset
// of the scene's coordinates (declarations in lcsim/scene/bodies.hpp).
#include <urdf_model/model.h>

#include <lcsim/scene/bodies.hpp>

namespace lcsim::scene {

Bodies::Bodies(std::vector<SceneBody> bodies, const Eigen::Vector3d& gravity)
    : bodies_(std::move(bodies)) {
  for (SceneBody& b : bodies_) {
    dyn_.emplace_back(*b.urdf, b.joints, b.q0, gravity, b.urdf_source, b.base);
    b.offset = size_;
    size_ += static_cast<Eigen::Index>(dyn_.back().joints().size());
  }
}

Eigen::Index Bodies::body_size(std::size_t b) const {
  return static_cast<Eigen::Index>(dyn_[b].joints().size());
}

VectorXd Bodies::reference() const {
  VectorXd q(size_);
  for (std::size_t b = 0; b < dyn_.size(); ++b)
    q.segment(bodies_[b].offset, body_size(b)) = dyn_[b].reference();
  return q;
}

MatrixXd Bodies::mass_matrix(const VectorXd& q) const {
  MatrixXd M = MatrixXd::Zero(size_, size_);
  for (std::size_t b = 0; b < dyn_.size(); ++b) {
    const Eigen::Index o = bodies_[b].offset, n = body_size(b);
    M.block(o, o, n, n) = dyn_[b].mass_matrix(q.segment(o, n));
  }
  return M;
}

VectorXd Bodies::gravity_force(const VectorXd& q) const {
  VectorXd t(size_);
  for (std::size_t b = 0; b < dyn_.size(); ++b) {
    const Eigen::Index o = bodies_[b].offset, n = body_size(b);
    t.segment(o, n) = dyn_[b].gravity_force(q.segment(o, n));
  }
  return t;
}

VectorXd Bodies::damping() const {
  VectorXd d(size_);
  for (std::size_t b = 0; b < dyn_.size(); ++b)
    d.segment(bodies_[b].offset, body_size(b)) = dyn_[b].damping();
  return d;
}

Eigen::Isometry3d Bodies::link_pose(std::size_t b, const std::string& link,
                                    const VectorXd& q) const {
  return dyn_[b].link_pose(link, q.segment(bodies_[b].offset, body_size(b)));
}

Eigen::Matrix3Xd Bodies::point_jacobian(std::size_t b, const std::string& link,
                                        const Eigen::Vector3d& local, const VectorXd& q) const {
  const Eigen::Index o = bodies_[b].offset, n = body_size(b);
  Eigen::Matrix3Xd J = Eigen::Matrix3Xd::Zero(3, size_);
  J.middleCols(o, n) = dyn_[b].point_jacobian(link, local, q.segment(o, n));
  return J;
}

std::size_t Bodies::body_of(Eigen::Index i) const {
  std::size_t b = 0;
  while (b + 1 < bodies_.size() && bodies_[b + 1].offset <= i) ++b;
  return b;
}

std::shared_ptr<const urdf::Joint> Bodies::joint_of(Eigen::Index i) const {
  const std::size_t b = body_of(i);
  const auto k = static_cast<std::size_t>(i - bodies_[b].offset);
  const std::size_t nb = base_coordinates(bodies_[b].base).size();
  if (k < nb) return nullptr;
  return bodies_[b].urdf->getJoint(bodies_[b].joints[k - nb]);
}

bool Bodies::in_metres(Eigen::Index i) const {
  const std::size_t b = body_of(i);
  const auto k = static_cast<std::size_t>(i - bodies_[b].offset);
  const std::size_t nb = base_coordinates(bodies_[b].base).size();
  if (k < nb) return k < 3;
  return joint_of(i)->type == urdf::Joint::PRISMATIC;
}

}  // namespace lcsim::scene
