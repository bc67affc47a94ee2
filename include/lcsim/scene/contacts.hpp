// A scene's contacts against world planes (docs/contacts.md): each contact
// point of a link's collision geometry becomes one unilateral constraint,
// its signed distance to the plane linearised about q0,
//   gap(q) ~ phi(q0) + J_n(q0) (q - q0)   (a row of E, an entry of g),
// with the contact's normal and two tangent directions kept (ContactFrame)
// for a friction law to use.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace lcsim::scene {

class UrdfDynamics;

// A world plane: the points x with normal . (x - point) = 0; the free side
// is where normal . (x - point) > 0. `normal` is a unit vector (the scene's
// is normalised; a zero normal is an input error).
struct Plane {
  std::string name;
  Eigen::Vector3d point = Eigen::Vector3d::Zero();    // m, world frame
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit, world frame
};

// One contact point of a link: a point fixed in the link's frame with a
// radius (a sphere of that radius about the point; 0 for a corner).
struct ContactPoint {
  std::string name;  // "<link>.corner3", "<link>.sphere0", "<link>.point1", ...
  std::string link;
  Eigen::Vector3d local = Eigen::Vector3d::Zero();  // m, link frame
  double radius = 0.0;                              // m, >= 0
};

// The exact (nonlinear) signed distance of `p` to `plane` at coordinates q:
//   phi(q) = normal . (X_link(q) local - plane.point) - radius   (m).
double signed_distance(const UrdfDynamics& dyn, const ContactPoint& p, const Plane& plane,
                       const Eigen::VectorXd& q);

// A contact point against a plane at q0: one row of the scene's E and g.
// The tangents: t1 = normal x e / |normal x e| with e the world axis least
// aligned with the normal (the first of x, y, z on a tie), t2 = normal x t1,
// so (normal, t1, t2) is a right-handed orthonormal frame.
struct ContactFrame {
  ContactPoint point;
  std::string plane;
  Eigen::Index row = -1;  // its row of E and g (and its constraint name is point.name)
  double gap = 0.0;       // phi(q0) (m)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // the point nearest the plane at q0 (m)
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ(), tangent1 = Eigen::Vector3d::UnitX(),
                  tangent2 = Eigen::Vector3d::UnitY();  // world frame, unit
  // d phi / dq at q0 (the row of E) and t_k' J_p(q0), with J_p the world
  // Jacobian of the link point: the velocity of the contact point along
  // each direction is row . q' (m/s per coordinate velocity).
  Eigen::VectorXd normal_row, tangent1_row, tangent2_row;
};

// The frame of `p` against `plane` at q (usually q0): the rows are exact
// derivatives (UrdfDynamics::point_jacobian), row left -1.
ContactFrame contact_frame(const UrdfDynamics& dyn, const ContactPoint& p, const Plane& plane,
                           const Eigen::VectorXd& q);

}  // namespace lcsim::scene
