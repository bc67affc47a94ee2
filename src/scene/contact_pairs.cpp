// Contact points on a scene's bodies: against a world plane, and against
// another body's sphere, box, capsule or cylinder (docs/contacts.md, "Body
// against body"):
// exact signed distances and, at a configuration, the contact frame with
// the exact derivatives of the relative motion along its directions.
#include <algorithm>
#include <cmath>
#include <lcsim/io/input_error.hpp>
#include <lcsim/scene/bodies.hpp>
#include <lcsim/scene/contacts.hpp>
#include <limits>

#include "scene/detail.hpp"

namespace lcsim::scene {

using Eigen::Vector3d;

namespace {

// t1 = n x e / |n x e|, e the world axis least aligned with n (first on a
// tie), as for a plane (contacts.cpp).
Vector3d first_tangent(const Vector3d& n) {
  Eigen::Index k = 0;
  n.cwiseAbs().minCoeff(&k);
  const Vector3d t = n.cross(Vector3d::Unit(k));
  return t / t.norm();
}

void set_directions(ContactFrame& c, const Vector3d& n) {
  c.normal = n;
  c.tangent1 = first_tangent(n);
  c.tangent2 = n.cross(c.tangent1);
}

// The box face's outward unit normal in the box's frame.
Vector3d face_normal(int face) { return (face % 2 ? 1.0 : -1.0) * Vector3d::Unit(face / 2); }

// The shape's frame in the world at q.
Eigen::Isometry3d shape_pose(const Bodies& b, const BodyShape& s, const Eigen::VectorXd& q) {
  return b.link_pose(s.body, s.link, q) * s.local;
}

// The point's centre in the world at q.
Vector3d point_at(const Bodies& b, const ContactPoint& p, const Eigen::VectorXd& q) {
  return b.link_pose(p.body, p.link, q) * p.local;
}

// A capsule's or a cylinder's outward unit normal at the nearest feature to
// y (the point in the shape's frame; axis z, radius s.radius, half length
// s.half.z()) and the signed distance from its surface; a zero normal where
// none exists (y on a capsule's axis segment, or on a cylinder's axis where
// its side is nearest). Capsule: y less its nearest point on the axis
// segment, less the radius. Cylinder: beyond the rim (radially out and past
// an end) towards the rim's nearest point; else the side or the end cap,
// whichever y is farther outside of (inside: the nearer surface).
Vector3d round_normal(const BodyShape& s, const Vector3d& y, double& distance) {
  const double hl = s.half.z();
  if (s.kind == "capsule") {
    const Vector3d d = y - Vector3d(0.0, 0.0, std::clamp(y.z(), -hl, hl));
    distance = d.norm() - s.radius;
    return d.norm() > 0.0 ? Vector3d(d / d.norm()) : Vector3d::Zero();
  }
  const double r = y.head<2>().norm();
  const double dr = r - s.radius, dz = std::abs(y.z()) - hl;
  const Vector3d radial = r > 0.0 ? Vector3d(y.x() / r, y.y() / r, 0.0) : Vector3d::Zero();
  const Vector3d axial(0.0, 0.0, y.z() >= 0.0 ? 1.0 : -1.0);
  if (dr > 0.0 && dz > 0.0) {
    distance = std::hypot(dr, dz);
    return (dr * radial + dz * axial) / distance;
  }
  distance = std::max(dr, dz);
  return dr > dz ? radial : axial;
}

// The face of box `s` whose plane y (the point in the box's frame) is
// farthest outside of: the largest sign * y_axis - half_axis; inside the
// box, the face it is least deep under; the first on a tie.
int nearest_face(const BodyShape& s, const Vector3d& y) {
  int best = 0;
  double most = -std::numeric_limits<double>::infinity();
  for (int f = 0; f < 6; ++f) {
    const double d = face_normal(f).dot(y) - s.half(f / 2);
    if (d > most) most = d, best = f;
  }
  return best;
}

// The unit normal (shape to point), the distance of the point's centre from
// the shape's surface along it, and the shape's material point there.
struct Separation {
  Vector3d normal, surface;
  double distance = 0.0;  // m, before the point's radius
};

// A point w against a box in the frame X: beyond an edge or a corner
// (more than one coordinate of y = X^-1 w outside the half sizes), from the
// box's nearest point, y clamped to the box; else from the nearest face's
// plane (outside one face, or inside).
Separation box_separation(const BodyShape& s, const Eigen::Isometry3d& X, const Vector3d& w) {
  Separation out;
  const Vector3d y = X.inverse() * w;
  const Vector3d nearest = y.cwiseMax(-s.half).cwiseMin(s.half);
  if ((y - nearest).cwiseAbs().count() > 1) {
    out.distance = (y - nearest).norm();
    out.normal = X.linear() * ((y - nearest) / out.distance);
    out.surface = X * nearest;
    return out;
  }
  const int f = nearest_face(s, y);
  out.normal = X.linear() * face_normal(f);
  out.distance = out.normal.dot(w - X.translation()) - s.half(f / 2);
  out.surface = w - out.distance * out.normal;
  return out;
}

Separation separation(const Bodies& b, const ContactPoint& p, const BodyShape& s,
                      const Eigen::VectorXd& q) {
  const Vector3d w = point_at(b, p, q);
  const Eigen::Isometry3d X = shape_pose(b, s, q);
  Separation out;
  if (s.kind == "sphere") {
    const Vector3d d = w - X.translation();
    if (!(d.norm() > 0.0))
      throw InputError("contact '" + p.name + "' is at the centre of sphere '" + s.name +
                       "': no normal");
    out.normal = d / d.norm();
    out.distance = d.norm() - s.radius;
    out.surface = X.translation() + s.radius * out.normal;
  } else if (s.kind == "box") {
    out = box_separation(s, X, w);
  } else {  // capsule or cylinder, along the shape frame's z
    const Vector3d n = round_normal(s, X.inverse() * w, out.distance);
    if (!(n.norm() > 0.0))
      throw InputError("contact '" + p.name + "' is on the axis of " + s.kind + " '" + s.name +
                       "': no normal");
    out.normal = X.linear() * n;
    out.surface = w - out.distance * out.normal;
  }
  return out;
}

}  // namespace

double plane_distance(const Plane& plane, const Vector3d& centre, double radius) {
  return plane.normal.dot(centre - plane.point) - radius;
}

double signed_distance(const Bodies& bodies, const ContactPoint& p, const Plane& plane,
                       const Eigen::VectorXd& q) {
  return plane_distance(plane, point_at(bodies, p, q), p.radius);
}

double signed_distance(const Bodies& bodies, const ContactPoint& p, const BodyShape& s,
                       const Eigen::VectorXd& q) {
  return separation(bodies, p, s, q).distance - p.radius;
}

ContactFrame contact_frame(const Bodies& bodies, const ContactPoint& p, const Plane& plane,
                           const Eigen::VectorXd& q) {
  ContactFrame c;
  c.point = p;
  c.plane = plane.name;
  set_directions(c, plane.normal);
  const Eigen::Isometry3d X = bodies.link_pose(p.body, p.link, q);
  const Vector3d w = X * p.local;
  c.gap = plane.normal.dot(w - plane.point) - p.radius;
  c.position = w - p.radius * plane.normal;
  // As contacts.cpp: the rows of the link's material point at `position`.
  const Eigen::Matrix3Xd J = bodies.point_jacobian(p.body, p.link, X.inverse() * c.position, q);
  c.normal_row = (c.normal.transpose() * J).transpose();
  c.tangent1_row = (c.tangent1.transpose() * J).transpose();
  c.tangent2_row = (c.tangent2.transpose() * J).transpose();
  return c;
}

ContactFrame contact_frame(const Bodies& bodies, const ContactPoint& p, const BodyShape& s,
                           const Eigen::VectorXd& q) {
  ContactFrame c;
  c.point = p;
  c.plane = s.name;
  c.against = s;
  const Separation sep = separation(bodies, p, s, q);
  set_directions(c, sep.normal);
  c.gap = sep.distance - p.radius;
  c.position = point_at(bodies, p, q) - p.radius * sep.normal;
  // The relative velocity of the point's material point at `position` and
  // the shape's at `surface`. Along n it is d phi/dt: a sphere's centre
  // moves its surface point by omega x R n, normal to n; a box face's
  // normal turns with omega, and (omega x n) . (w - o) = -n . (omega x
  // (w - o)), the box's material point at w, which moves along n as the
  // one at `surface` (they differ by a multiple of n).
  const Eigen::Isometry3d Xp = bodies.link_pose(p.body, p.link, q);
  const Eigen::Isometry3d Xs = bodies.link_pose(s.body, s.link, q);
  const Eigen::Matrix3Xd J = bodies.point_jacobian(p.body, p.link, Xp.inverse() * c.position, q) -
                             bodies.point_jacobian(s.body, s.link, Xs.inverse() * sep.surface, q);
  c.normal_row = (c.normal.transpose() * J).transpose();
  c.tangent1_row = (c.tangent1.transpose() * J).transpose();
  c.tangent2_row = (c.tangent2.transpose() * J).transpose();
  return c;
}

double signed_distance(const Bodies& bodies, const ContactFrame& c,
                       const std::vector<Plane>& planes, const Eigen::VectorXd& q) {
  if (c.against) return signed_distance(bodies, c.point, *c.against, q);
  for (const Plane& p : planes)
    if (p.name == c.plane) return signed_distance(bodies, c.point, p, q);
  throw InputError("contact '" + c.point.name + "': no plane '" + c.plane + "'");
}

}  // namespace lcsim::scene
