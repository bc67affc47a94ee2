// How far a scene's linear contact gaps hold: each contact's exact signed
// distance against its row of E and g, along each coordinate alone
// (declarations and definitions in lcsim/scene/linearisation.hpp).
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <lcsim/mech/tolerances.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <limits>

namespace lcsim::scene {

namespace {

struct Axis {
  std::string unit;
  double lower = 0.0, upper = 0.0;  // how far it may go each way (m or rad)
  bool limit_lower = false, limit_upper = false;
};

// Coordinate i's unit and search extent: a floating base's position (m) or
// rotation (rad); a joint's own, bounded by its limits where it has them.
Axis axis_of(const Bodies& b, std::size_t i, double q0) {
  Axis a;
  const auto j = b.joint_of(static_cast<Eigen::Index>(i));
  const bool metres = b.in_metres(static_cast<Eigen::Index>(i));
  a.unit = metres ? "m" : "rad";
  a.lower = a.upper = metres ? 1.0 : M_PI;
  if (j && j->limits && j->type != urdf::Joint::CONTINUOUS &&
      j->limits->lower <= j->limits->upper) {
    if (q0 - j->limits->lower >= 0.0) a.lower = q0 - j->limits->lower, a.limit_lower = true;
    if (j->limits->upper - q0 >= 0.0) a.upper = j->limits->upper - q0, a.limit_upper = true;
  }
  return a;
}

// Where contact c's point is, seen from what it touches: in the world for a
// plane, in the frame of the other body's link for a body's shape (so the
// shape's own motion counts as the point's, relative to it).
Eigen::Vector3d seen_point(const Bodies& dyn, const ContactFrame& c, const VectorXd& q) {
  const Eigen::Vector3d w = dyn.link_pose(c.point.body, c.point.link, q) * c.point.local;
  if (!c.against) return w;
  return dyn.link_pose(c.against->body, c.against->link, q).inverse() * w;
}

// How far coordinate i can move either way (the smaller) before contact
// c's linear gap is off by `threshold` of the point's displacement, and
// what ends it.
struct Extent {
  double distance = std::numeric_limits<double>::infinity();
  std::string end = "search";
};
Extent reach_along(const Bodies& dyn, const ContactFrame& c, const std::vector<Plane>& planes,
                   const VectorXd& q0, Eigen::Index i, const Axis& a, double threshold) {
  Extent r;
  const Eigen::Vector3d p0 = seen_point(dyn, c, q0);
  for (const double dir : {-1.0, 1.0}) {
    const auto exceeds = [&](double step) {
      VectorXd q = q0;
      q(i) += dir * step;
      const double moved = (seen_point(dyn, c, q) - p0).norm();
      const double exact = signed_distance(dyn, c, planes, q) - c.gap;
      const double linear = c.normal_row(i) * dir * step;
      return moved > 0.0 && std::abs(exact - linear) > threshold * moved;
    };
    const Reach got = first_crossing(exceeds, dir < 0 ? a.lower : a.upper);
    if (got.ok < r.distance) {
      r.distance = got.ok;
      const bool limit = dir < 0 ? a.limit_lower : a.limit_upper;
      r.end = got.crossed ? "threshold" : limit ? "limit" : "search";
    }
  }
  return r;
}

}  // namespace

std::vector<ContactRange> contact_ranges(const Scene& s, double threshold) {
  check_linearisation_threshold(threshold);
  const Bodies dyn = scene_bodies(s);
  const VectorXd q0 = dyn.reference();
  const mech::MechanicalModel& m = *s.model.mechanical;
  const VectorXd gaps = m.E * q0 + m.g;
  const VectorXd scale = mech::gap_scale(m.E, q0, m.g);
  bool any_rad = false;
  for (std::size_t i = 0; i < s.lin.joints.size(); ++i)
    any_rad |= axis_of(dyn, i, q0(static_cast<Eigen::Index>(i))).unit == "rad";
  std::vector<ContactRange> out;
  for (const ContactFrame& c : s.contacts) {
    ContactRange r;
    r.contact = c.point.name;
    r.plane = c.plane;
    r.gap = gaps(c.row);
    r.closed = mech::gap_is_zero(r.gap, scale(c.row));
    r.range = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < s.lin.joints.size(); ++i) {
      const auto ii = static_cast<Eigen::Index>(i);
      const Axis a = axis_of(dyn, i, q0(ii));
      if (any_rad && a.unit != "rad") continue;  // rotations bend the gap; report theirs
      const Extent got = reach_along(dyn, c, s.planes, q0, ii, a, threshold);
      if (got.distance < r.range || r.coordinate.empty()) {
        r.coordinate = s.lin.joints[i];
        r.unit = a.unit;
        r.range = got.distance;
        r.end = got.end;
      }
    }
    out.push_back(r);
  }
  return out;
}

nlohmann::json to_json(const std::vector<ContactRange>& ranges) {
  nlohmann::json a = nlohmann::json::array();
  for (const ContactRange& r : ranges)
    a.push_back({{"contact", r.contact},
                 {"plane", r.plane},
                 {"gap", r.gap},
                 {"closed", r.closed},
                 {"coordinate", r.coordinate},
                 {"unit", r.unit},
                 {"range", r.range},
                 {"end", r.end}});
  return a;
}

}  // namespace lcsim::scene
