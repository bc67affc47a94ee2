// A scene's contacts against world planes (docs/contacts.md): each contact
// point of a link's collision geometry becomes one unilateral constraint,
// its signed distance to the plane linearised about q0,
//   gap(q) ~ phi(q0) + J_n(q0) (q - q0)   (a row of E, an entry of g),
// with the contact's normal and two tangent directions kept (ContactFrame)
// for a friction law to use.
#pragma once

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

namespace lcsim::scene {

class UrdfDynamics;
class Bodies;

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
  std::size_t body = 0;  // its body in a scene of several (Bodies), 0 in a one-URDF scene
};

// The exact (nonlinear) signed distance of `p` to `plane` at coordinates q:
//   phi(q) = normal . (X_link(q) local - plane.point) - radius   (m).
double signed_distance(const UrdfDynamics& dyn, const ContactPoint& p, const Plane& plane,
                       const Eigen::VectorXd& q);

// Another body's collision primitive that a contact point may touch
// (docs/contacts.md, "Body against body"): a sphere, a box, a capsule or a
// cylinder.
struct BodyShape {
  std::string name;  // "<body>/<link>" (and ".<kind><k>" when the link has several)
  std::size_t body = 0;
  std::string link;
  std::string kind;  // "sphere", "box", "capsule" or "cylinder" (the last two along z)
  Eigen::Isometry3d local = Eigen::Isometry3d::Identity();  // its frame in the link's
  double radius = 0.0;                                      // sphere, capsule, cylinder: m
  Eigen::Vector3d half =
      Eigen::Vector3d::Zero();  // box: half sizes; capsule, cylinder: (0, 0, l/2) (m)
};
// The exact signed distances at the scene's coordinates q (m):
//   plane:  phi = normal . (X_link(q) local - plane.point) - radius;
//   sphere: phi = |w - c| - R - radius (w the point, c the sphere's centre, world);
//   box:    with y = X_box(q)^-1 w and y_c = y clamped to the half sizes h:
//           |y - y_c| - radius beyond an edge or a corner (y_c differs from
//           y in more than one coordinate); else n_f . (w - X_box(q) (h_f
//           n_f^box)) - radius, n_f = R_box(q) n_f^box the face whose plane
//           y is farthest outside of (inside: least deep under; the first
//           of -x, +x, -y, +y, -z, +z on a tie), h_f its half size;
//   capsule: phi = |y - (0, 0, clamp(y_z, -l/2, l/2))| - R - radius, y = X_shape(q)^-1 w;
//   cylinder: with dr = |(y_x, y_y)| - R and dz = |y_z| - l/2, hypot(dr, dz)
//           beyond the rim (dr, dz > 0), else max(dr, dz), less radius.
//   The feature nearest at q is used at every q.
double signed_distance(const Bodies& bodies, const ContactPoint& p, const Plane& plane,
                       const Eigen::VectorXd& q);
double signed_distance(const Bodies& bodies, const ContactPoint& p, const BodyShape& s,
                       const Eigen::VectorXd& q);
// A contact point against a plane at q0: one row of the scene's E and g.
// The tangents: t1 = normal x e / |normal x e| with e the world axis least
// aligned with the normal (the first of x, y, z on a tie), t2 = normal x t1,
// so (normal, t1, t2) is a right-handed orthonormal frame.
struct ContactFrame {
  ContactPoint point;
  std::string plane;  // the plane's name, or the other body's shape's (BodyShape::name)
  std::optional<BodyShape> against;  // set for a contact against another body
  Eigen::Index row = -1;             // its row of E and g (and its constraint name is point.name)
  double gap = 0.0;                  // phi(q0) (m)
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
// The same on a scene's bodies (the rows over all its coordinates).
ContactFrame contact_frame(const Bodies& bodies, const ContactPoint& p, const Plane& plane,
                           const Eigen::VectorXd& q);
// A point against another body's shape at q: the normal n points from the
// shape to the point (sphere: along w - c; box: the face's outward normal),
// the tangents as for a plane, and each row is d/dq of the relative
// velocity along it of the two material points touching first, the
// point's (w - radius n) and the shape's (c + R n, or w's projection on
// the face): row = dir' (J_point - J_shape). The normal row is the exact
// gradient of phi (the other terms of phi's derivative vanish along n).
// InputError when the point is at the sphere's centre (no normal).
ContactFrame contact_frame(const Bodies& bodies, const ContactPoint& p, const BodyShape& s,
                           const Eigen::VectorXd& q);
// The signed distance of the contact `c` describes (its plane among
// `planes`, or its other body's shape) at q.
double signed_distance(const Bodies& bodies, const ContactFrame& c,
                       const std::vector<Plane>& planes, const Eigen::VectorXd& q);

}  // namespace lcsim::scene
