// How far a scene's linear contact gaps hold: each contact's exact signed
// distance against its row of E and g, along each coordinate alone
// (declarations and definitions in lcsim/scene/linearisation.hpp).
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/input_error.hpp>
#include <lcsim/mech/tolerances.hpp>
#include <lcsim/scene/bodies.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <limits>

#include "scene/detail.hpp"

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

// Marks the scene's coordinates that move link `link` of body b: the body's
// floating base, and each simulated joint on the link's path from the root,
// itself or as the leader of a mimic on it. No other coordinate enters the
// link's pose (link_pose reads none other), so none other moves a point of it.
void mark_moving(const Bodies& dyn, std::size_t b, const std::string& link,
                 std::vector<bool>& moves) {
  const SceneBody& body = dyn.bodies()[b];
  const auto at = [&](std::size_t k) { return static_cast<std::size_t>(body.offset) + k; };
  const std::size_t nb = base_coordinates(body.base).size();
  for (std::size_t k = 0; k < nb; ++k) moves[at(k)] = true;
  const auto mimics = mimic_joints(*body.urdf, body.urdf_source, body.joints);
  for (auto l = body.urdf->getLink(link); l && l->parent_joint;
       l = body.urdf->getLink(l->parent_joint->parent_link_name)) {
    const auto m = mimics.find(l->parent_joint->name);
    const std::string& j = m == mimics.end() ? l->parent_joint->name : m->second.leader;
    const auto it = std::find(body.joints.begin(), body.joints.end(), j);
    if (it != body.joints.end())
      moves[at(nb + static_cast<std::size_t>(it - body.joints.begin()))] = true;
  }
}

// Whether each of the scene's coordinates moves contact c's point as seen
// from what it touches (its link's, and the other body's link's).
std::vector<bool> moving_coordinates(const Bodies& dyn, const ContactFrame& c) {
  std::vector<bool> moves(static_cast<std::size_t>(dyn.size()), false);
  mark_moving(dyn, c.point.body, c.point.link, moves);
  if (c.against) mark_moving(dyn, c.against->body, c.against->link, moves);
  return moves;
}

// How far coordinate i can move either way (the smaller) before contact
// c's linear gap is off by `threshold` of the point's displacement, and
// what ends it.
struct Extent {
  double distance = std::numeric_limits<double>::infinity();
  std::string end = "search";
};
// Only a coordinate that moves the point is scanned (contact_ranges skips
// the others: they never end a range). A way it cannot move at all (q0 at
// its limit on that side: an extent of 0) is not scanned either: it would
// report 0 as the range although nothing was measured; a coordinate locked
// both ways keeps an infinite distance and is no candidate.
Extent reach_along(const Bodies& dyn, const ContactFrame& c, const std::vector<Plane>& planes,
                   const VectorXd& q0, Eigen::Index i, const Axis& a, double threshold) {
  Extent r;
  const Plane* plane = plane_of(c, planes);
  const Eigen::Vector3d p0 = probe_contact(dyn, c, plane, q0).seen;
  for (const double dir : {-1.0, 1.0}) {
    const double extent = dir < 0 ? a.lower : a.upper;
    if (!(extent > 0.0)) continue;
    const auto exceeds = [&](double step) {
      VectorXd q = q0;
      q(i) += dir * step;
      const ContactProbe at = probe_contact(dyn, c, plane, q);
      const double moved = (at.seen - p0).norm();
      const double exact = at.gap - c.gap;
      const double linear = c.normal_row(i) * dir * step;
      return moved > 0.0 && std::abs(exact - linear) > threshold * moved;
    };
    const Reach got = first_crossing(exceeds, extent);
    if (got.ok < r.distance) {
      r.distance = got.ok;
      const bool limit = dir < 0 ? a.limit_lower : a.limit_upper;
      r.end = got.crossed ? "threshold" : limit ? "limit" : "search";
    }
  }
  return r;
}

}  // namespace

ContactProbe probe_contact(const Bodies& dyn, const ContactFrame& c, const Plane* plane,
                           const VectorXd& q) {
  const Eigen::Vector3d w = dyn.link_pose(c.point.body, c.point.link, q) * c.point.local;
  if (plane) return {w, plane_distance(*plane, w, c.point.radius)};
  return {dyn.link_pose(c.against->body, c.against->link, q).inverse() * w,
          signed_distance(dyn, c.point, *c.against, q)};
}

const Plane* plane_of(const ContactFrame& c, const std::vector<Plane>& planes) {
  if (c.against) return nullptr;
  for (const Plane& p : planes)
    if (p.name == c.plane) return &p;
  throw InputError("contact '" + c.point.name + "': no plane '" + c.plane + "'");
}

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
    const std::vector<bool> moves = moving_coordinates(dyn, c);
    // The rotations that move the point; if none does (a point moved by
    // translations alone), the translations that move it (they never
    // cross: the gap is affine along them).
    for (const bool rotations_only : {true, false}) {
      for (std::size_t i = 0; i < s.lin.joints.size(); ++i) {
        const auto ii = static_cast<Eigen::Index>(i);
        const Axis a = axis_of(dyn, i, q0(ii));
        if (!moves[i] || (rotations_only && any_rad && a.unit != "rad")) continue;
        const Extent got = reach_along(dyn, c, s.planes, q0, ii, a, threshold);
        if (std::isfinite(got.distance) && (got.distance < r.range || r.coordinate.empty())) {
          r.coordinate = s.lin.joints[i];
          r.unit = a.unit;
          r.range = got.distance;
          r.end = got.end;
        }
      }
      if (!r.coordinate.empty()) break;
    }
    for (std::size_t i = 0; r.coordinate.empty() && i < s.lin.joints.size(); ++i)
      if (moves[i]) {  // every coordinate moving it is locked at its limits: it cannot move
        r.coordinate = s.lin.joints[i];
        r.unit = axis_of(dyn, i, q0(static_cast<Eigen::Index>(i))).unit;
        r.range = 0.0;
        r.end = "limit";
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
