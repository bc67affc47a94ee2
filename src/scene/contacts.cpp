// A contact point against a world plane: its exact signed distance and, at
// a configuration, its contact frame (normal and tangents) with the exact
// derivatives of the point's motion along each (docs/contacts.md).
#include <cmath>
#include <lcsim/scene/contacts.hpp>
#include <lcsim/scene/urdf.hpp>

namespace lcsim::scene {

using Eigen::Vector3d;

double signed_distance(const UrdfDynamics& dyn, const ContactPoint& p, const Plane& plane,
                       const Eigen::VectorXd& q) {
  const Vector3d w = dyn.link_pose(p.link, q) * p.local;
  return plane.normal.dot(w - plane.point) - p.radius;
}

namespace {

// t1 = n x e / |n x e|, e the world axis least aligned with n (first on a tie).
Vector3d first_tangent(const Vector3d& n) {
  Eigen::Index k = 0;
  n.cwiseAbs().minCoeff(&k);
  const Vector3d t = n.cross(Vector3d::Unit(k));
  return t / t.norm();
}

}  // namespace

ContactFrame contact_frame(const UrdfDynamics& dyn, const ContactPoint& p, const Plane& plane,
                           const Eigen::VectorXd& q) {
  ContactFrame c;
  c.point = p;
  c.plane = plane.name;
  c.normal = plane.normal;
  c.tangent1 = first_tangent(plane.normal);
  c.tangent2 = plane.normal.cross(c.tangent1);
  const Eigen::Isometry3d X = dyn.link_pose(p.link, q);
  const Vector3d w = X * p.local;
  c.gap = plane.normal.dot(w - plane.point) - p.radius;
  c.position = w - p.radius * plane.normal;
  // The rows are those of the material point of the link at `position`
  // (for a radius > 0, the point of the sphere touching first): its normal
  // velocity equals the centre's (omega x (-radius n) has no component
  // along n), so the normal row is the gradient of phi; its tangential
  // velocity includes rolling, as friction needs.
  const Eigen::Matrix3Xd J = dyn.point_jacobian(p.link, X.inverse() * c.position, q);
  c.normal_row = (c.normal.transpose() * J).transpose();
  c.tangent1_row = (c.tangent1.transpose() * J).transpose();
  c.tangent2_row = (c.tangent2.transpose() * J).transpose();
  return c;
}

}  // namespace lcsim::scene
