// A scene's `planes:`, `contacts:` and `contact_options:` keys: world
// planes, and the links whose contact points (their URDF collision
// primitives, or points the scene gives) may touch them, each point one
// unilateral constraint linearised about q0 (docs/contacts.md).
#include <urdf_model/model.h>

#include <algorithm>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>
#include <limits>
#include <set>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::describe;
using io::yaml::fail;
using io::yaml::join;
using io::yaml::number;

namespace {

// Default of contact_options.penetration_tolerance (m): a body placed on a
// plane by a pose written with six decimals in metres (as URDF origins and
// reference poses are) sits up to 5e-7 m off it; 1e-6 m accepts that
// rounding and refuses any penetration a user could mean.
constexpr double kPenetrationTolerance = 1e-6;

struct ContactOptions {
  double max_distance = std::numeric_limits<double>::infinity();  // m
  double penetration_tolerance = kPenetrationTolerance;           // m
  ContactFriction friction;  // every contact's default (scene_contact_friction.cpp)
};

ContactOptions read_options(const Keys& keys, const std::string& source) {
  ContactOptions o;
  if (!keys.count("contact_options")) return o;
  const Keys ok = io::yaml::mapping(keys.at("contact_options"), source, "contact_options",
                                    {"max_distance", "penetration_tolerance", "friction", "d"});
  o.friction = read_contact_friction(ok, source, "contact_options", ContactFriction{});
  for (const auto& [key, value] : {std::pair<const char*, double*>{"max_distance", &o.max_distance},
                                   {"penetration_tolerance", &o.penetration_tolerance}}) {
    if (!ok.count(key)) continue;
    const std::string k = std::string("contact_options.") + key;
    *value = number(ok.at(key), source, k);
    if (!(*value >= 0.0)) fail(source, k, "must be >= 0 m (got " + format_number(*value) + ")");
  }
  return o;
}

// The points a contact entry gives itself: `points: [[x, y, z], ...]` in
// the link's frame (m) with one `radius` (m, default 0).
std::vector<ContactPoint> given_points(const Keys& ck, const std::string& source,
                                       const std::string& k, const std::string& link,
                                       const std::string& prefix) {
  const Eigen::MatrixXd P = io::yaml::matrix(ck.at("points"), source, k + ".points", 3);
  if (P.rows() == 0 || P.cols() != 3)
    fail(source, k + ".points",
         "expected a non-empty list of points [x, y, z] in the link's frame (m) (got " +
             describe(ck.at("points")) + ")");
  double r = 0.0;
  if (ck.count("radius")) r = number(ck.at("radius"), source, k + ".radius");
  if (!(r >= 0.0)) fail(source, k + ".radius", "must be >= 0 m (got " + format_number(r) + ")");
  std::vector<ContactPoint> out;
  for (Eigen::Index i = 0; i < P.rows(); ++i)
    out.push_back({prefix + ".point" + std::to_string(i), link, P.row(i).transpose(), r, 0});
  return out;
}

// The contact points of entry `k`: given, or from the link's <collision>.
std::vector<ContactPoint> entry_points(const Keys& ck, const std::string& source,
                                       const std::string& k, const SceneUrdf& urdf,
                                       const std::string& link, const std::string& prefix) {
  if (ck.count("points")) return given_points(ck, source, k, link, prefix);
  if (ck.count("radius"))
    fail(source, k + ".radius", "only with points (a primitive's radius is the URDF's)");
  std::vector<ContactPoint> pts = collision_points(urdf.collisions, link, prefix, urdf.path);
  if (pts.empty())
    fail(source, k,
         "link '" + link + "' has no <collision> in " + urdf.path +
             " (give its contact points: points: [[x, y, z], ...])");
  return pts;
}

const Plane& plane_named(const Keys& ck, const std::string& source, const std::string& k,
                         const std::vector<Plane>& planes) {
  if (!ck.count("plane")) fail(source, k + ".plane", "missing");
  const std::string name = name_of(ck.at("plane"), source, k + ".plane");
  std::vector<std::string> names;
  for (const Plane& p : planes) {
    if (p.name == name) return p;
    names.push_back(p.name);
  }
  fail(source, k + ".plane",
       "no plane '" + name + "' (the planes are " + (names.empty() ? "none" : join(names)) + ")");
}

// The frames of entry `k`'s points: against its plane, or against each
// sphere or box of the link its `against:` names (body_contacts.cpp).
std::vector<ContactFrame> entry_frames(const Keys& ck, const std::string& source,
                                       const std::string& k, const std::vector<ContactBody>& bodies,
                                       const LinkRef& ref, const std::vector<ContactPoint>& points,
                                       const std::vector<Plane>& planes, const Bodies& dyn,
                                       const VectorXd& q0) {
  std::vector<ContactFrame> out;
  if (ck.count("against")) {
    if (ck.count("plane"))
      fail(source, k + ".against", "a contact has a plane or against, not both");
    for (const ContactFrame& f :
         against_frames(bodies, ref, ck.at("against"), source, k, points, dyn, q0))
      out.push_back(f);
    return out;
  }
  const Plane& plane = plane_named(ck, source, k, planes);
  for (const ContactPoint& p : points) out.push_back(contact_frame(dyn, p, plane, q0));
  return out;
}

}  // namespace

std::vector<Plane> read_planes(const Keys& keys, const std::string& source) {
  std::vector<Plane> out;
  if (!keys.count("planes")) return out;
  const YAML::Node& pn = keys.at("planes");
  if (!pn.IsSequence()) fail(source, "planes", "expected a list (got " + describe(pn) + ")");
  std::set<std::string> seen;
  for (std::size_t i = 0; i < pn.size(); ++i) {
    const std::string k = "planes[" + std::to_string(i) + "]";
    const Keys pk = io::yaml::mapping(pn[i], source, k, {"name", "point", "normal"});
    if (!pk.count("name")) fail(source, k + ".name", "missing");
    if (!pk.count("normal")) fail(source, k + ".normal", "missing");
    Plane p;
    p.name = name_of(pk.at("name"), source, k + ".name");
    if (!seen.insert(p.name).second) fail(source, k + ".name", "duplicate plane '" + p.name + "'");
    if (pk.count("point")) p.point = vector3(pk.at("point"), source, k + ".point", "m");
    const Eigen::Vector3d n = vector3(pk.at("normal"), source, k + ".normal", "any unit");
    if (!(n.norm() > 0.0) || !std::isfinite(n.norm()))
      fail(source, k + ".normal",
           "must be non-zero (got " + number_list(n, 17) + "): it says which side is free");
    p.normal = n / n.norm();
    out.push_back(p);
  }
  return out;
}

SceneContacts add_contacts(const Keys& keys, const std::string& source,
                           const std::vector<ContactBody>& bodies, const std::vector<Plane>& planes,
                           const Bodies& dyn, const VectorXd& q0, SceneConstraints& out) {
  SceneContacts sc;
  const ContactOptions opt = read_options(keys, source);
  if (!keys.count("contacts")) return sc;
  const YAML::Node& cn = keys.at("contacts");
  if (!cn.IsSequence()) fail(source, "contacts", "expected a list (got " + describe(cn) + ")");
  std::size_t dropped = 0, total = 0;
  for (std::size_t i = 0; i < cn.size(); ++i) {
    const std::string k = "contacts[" + std::to_string(i) + "]";
    const Keys ck = io::yaml::mapping(
        cn[i], source, k,
        {"link", "plane", "against", "points", "radius", "name", "friction", "d"});
    const ContactFriction friction = read_contact_friction(ck, source, k, opt.friction);
    if (!ck.count("link")) fail(source, k + ".link", "missing");
    const LinkRef ref = find_link(bodies, ck.at("link"), source, k + ".link");
    if (!ck.count("against")) plane_named(ck, source, k, planes);  // checked before the points
    const std::string prefix =
        ck.count("name") ? name_of(ck.at("name"), source, k + ".name")
                         : (bodies.size() > 1 ? bodies[ref.body].name + "." : "") + ref.link;
    std::vector<ContactPoint> points =
        entry_points(ck, source, k, *bodies[ref.body].urdf, ref.link, prefix);
    for (ContactPoint& p : points) p.body = ref.body;
    for (ContactFrame& f : entry_frames(ck, source, k, bodies, ref, points, planes, dyn, q0)) {
      ++total;
      const std::string other = f.against ? "'" + f.plane + "'" : "plane '" + f.plane + "'";
      if (f.normal_row.isZero())
        fail(source, k + ".link",
             "contact '" + f.point.name + "' does not move toward or away from " + other +
                 " at q0 (no coordinate moves it along the normal: its row of E would be zero)");
      if (f.gap < -opt.penetration_tolerance)
        fail(source, k,
             "contact '" + f.point.name + "' penetrates " + other + " by " + format_number(-f.gap) +
                 " m at q0 (more than contact_options.penetration_tolerance = " +
                 format_number(opt.penetration_tolerance) + " m)");
      if (f.gap > opt.max_distance) {
        ++dropped;
        continue;
      }
      f.row = static_cast<Eigen::Index>(out.rows.size());
      out.add(f.normal_row, f.gap - f.normal_row.dot(q0), f.point.name);
      sc.frames.push_back(std::move(f));
      sc.friction.push_back(friction);
    }
  }
  if (dropped > 0)
    sc.notes.push_back(source + ": contacts: dropped " + std::to_string(dropped) + " of " +
                       std::to_string(total) + " contact points farther than " +
                       "contact_options.max_distance = " + format_number(opt.max_distance) +
                       " m from their plane at q0");
  return sc;
}

}  // namespace lcsim::scene
