// A scene of several bodies (`bodies:`) as one MuJoCo model, its MJCF
// composed by lcsim from the scene it parsed (docs/contacts.md, "Peers on
// contact scenes"), since MuJoCo 2.2 has no way to attach one URDF to
// another model:
// - each body's URDF tree as nested <body>s named <body>/<link>: a URDF
//   joint's origin is its child's pos/quat in the parent (MJCF's body frame at
//   joint value 0), a simulated revolute/continuous joint a hinge, a
//   prismatic one a slide, named as the scene's coordinate (<body>.<joint>),
//   about its axis; a joint the scene does not simulate is frozen at its q0
//   (its motion folded into the child's pos/quat); fixed joints keep their
//   child as a body without a joint;
// - a floating base a <freejoint> in its root body, a fixed base the root
//   body at the base's pose; an obstacle (fixed, no joints) is the same;
// - inertials as the URDF gives them (pos, quat, mass, fullinertia);
//   `inertiafromgeom` false, so the contact geoms below weigh nothing; a
//   link without <inertial> gets a speck (1e-9 kg, 1e-12 kg m^2);
// - the contacts exactly as lcsim's rows: one sphere geom per contact point
//   (its radius; 1e-9 m for a corner, which MuJoCo needs > 0), one geom per
//   other body's shape the scene names (sphere, box, capsule, cylinder) and
//   one plane geom per scene plane; every geom has contype = conaffinity = 0
//   and each contact row is one explicit <pair> (its point's geom, its plane's
//   or shape's geom), so only the scene's named pairs collide.
#include <mujoco/mujoco.h>
#include <urdf_model/model.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <lcsim/core/format.hpp>
#include <map>
#include <set>
#include <stdexcept>

#include "mujoco/detail.hpp"

namespace lcsim::mujoco {

namespace {

using Eigen::Isometry3d;
using Eigen::Vector3d;

std::string triple(const Vector3d& v) {
  return format_number(v.x()) + " " + format_number(v.y()) + " " + format_number(v.z());
}

std::string quat(const Eigen::Matrix3d& R) {
  const Eigen::Quaterniond q(R);
  return format_number(q.w()) + " " + format_number(q.x()) + " " + format_number(q.y()) + " " +
         format_number(q.z());
}

std::string frame(const Isometry3d& X) {
  return " pos=\"" + triple(X.translation()) + "\" quat=\"" + quat(X.linear()) + "\"";
}

Isometry3d pose(const urdf::Pose& p) {
  Isometry3d X = Isometry3d::Identity();
  X.translation() = Vector3d(p.position.x, p.position.y, p.position.z);
  X.linear() = Eigen::Quaterniond(p.rotation.w, p.rotation.x, p.rotation.y, p.rotation.z)
                   .normalized()
                   .toRotationMatrix();
  return X;
}

// The geoms lcsim puts on each (body, link): contact points and shapes.
using LinkGeoms = std::map<std::pair<std::size_t, std::string>, std::string>;

// The link's inertia about its centre of mass in the link's axes (MJCF's
// fullinertia takes no orientation besides it).
std::string inertial(const urdf::Link& link) {
  if (!link.inertial || !(link.inertial->mass > 0.0))
    return "<inertial pos=\"0 0 0\" mass=\"1e-9\" diaginertia=\"1e-12 1e-12 1e-12\"/>\n";
  const urdf::Inertial& in = *link.inertial;
  const Isometry3d X = pose(in.origin);
  Eigen::Matrix3d I;
  I << in.ixx, in.ixy, in.ixz, in.ixy, in.iyy, in.iyz, in.ixz, in.iyz, in.izz;
  I = X.linear() * I * X.linear().transpose();
  return "<inertial pos=\"" + triple(X.translation()) + "\" mass=\"" + format_number(in.mass) +
         "\" fullinertia=\"" + format_number(I(0, 0)) + " " + format_number(I(1, 1)) + " " +
         format_number(I(2, 2)) + " " + format_number(I(0, 1)) + " " + format_number(I(0, 2)) +
         " " + format_number(I(1, 2)) + "\"/>\n";
}

struct Composer {
  const scene::Scene& setup;
  const LinkGeoms& geoms;
  const std::map<std::string, JointRange>& ranges;  // by coordinate name
  std::string xml;

  // The link `name` of body b and its subtree; `X` its frame in the parent's.
  void link(std::size_t b, const std::string& name, const Isometry3d& X, const std::string& joint) {
    const scene::SceneBody& body = setup.bodies[b];
    const urdf::LinkConstSharedPtr l = body.urdf->getLink(name);
    xml +=
        "<body name=\"" + body.name + "/" + name + "\"" + frame(X) + ">\n" + joint + inertial(*l);
    if (const auto g = geoms.find({b, name}); g != geoms.end()) xml += g->second;
    for (const urdf::JointSharedPtr& j : l->child_joints) child(b, *j);
    xml += "</body>\n";
  }

  void child(std::size_t b, const urdf::Joint& j) {
    const scene::SceneBody& body = setup.bodies[b];
    if (j.mimic)
      throw std::invalid_argument(
          "mujoco: body '" + body.name + "': joint '" + j.name +
          "' is a mimic: lcsim's MuJoCo model of a scene of bodies has none");
    Isometry3d X = pose(j.parent_to_joint_origin_transform);
    const Vector3d axis(j.axis.x, j.axis.y, j.axis.z);
    const bool moves = j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::CONTINUOUS ||
                       j.type == urdf::Joint::PRISMATIC;
    if (j.type != urdf::Joint::FIXED && !moves)
      throw std::invalid_argument("mujoco: body '" + body.name + "': joint '" + j.name +
                                  "' is neither fixed, revolute, continuous nor prismatic");
    const bool simulated =
        moves && std::find(body.joints.begin(), body.joints.end(), j.name) != body.joints.end();
    std::string joint;
    if (simulated) {
      const std::string name = body.name + "." + j.name;
      std::string range;
      if (const auto r = ranges.find(name); r != ranges.end())
        range = " limited=\"true\" range=\"" + format_number(r->second.lower) + " " +
                format_number(r->second.upper) + "\"";
      joint = "<joint name=\"" + name + "\" type=\"" +
              (j.type == urdf::Joint::PRISMATIC ? "slide" : "hinge") + "\" pos=\"0 0 0\" axis=\"" +
              triple(axis) + "\"" + range + "/>\n";
    } else if (moves) {  // frozen at its q0
      const auto it = body.q0.find(j.name);
      const double q = it == body.q0.end() ? 0.0 : it->second;
      if (j.type == urdf::Joint::PRISMATIC)
        X.translate(q * axis);
      else
        X.rotate(Eigen::AngleAxisd(q, axis.normalized()));
    }
    link(b, j.child_link_name, X, joint);
  }
};

// Each contact row's point geom, each named shape's geom, on their links.
LinkGeoms contact_geoms(const scene::Scene& setup) {
  LinkGeoms out;
  std::set<std::string> shapes;
  for (const scene::ContactFrame& cf : setup.contacts) {
    const scene::ContactPoint& p = cf.point;
    out[{p.body, p.link}] += "<geom name=\"" + row_geom_name(cf.row) +
                             "\" type=\"sphere\" size=\"" +
                             format_number(std::max(p.radius, 1e-9)) + "\" pos=\"" +
                             triple(p.local) + "\" contype=\"0\" conaffinity=\"0\"/>\n";
    if (!cf.against || !shapes.insert(cf.against->name).second) continue;
    const scene::BodyShape& s = *cf.against;
    std::string type = s.kind, size;
    if (s.kind == "sphere")
      size = format_number(s.radius);
    else if (s.kind == "box")
      size = triple(s.half);
    else if (s.kind == "capsule" || s.kind == "cylinder")
      size = format_number(s.radius) + " " + format_number(s.half.z());
    else
      throw std::invalid_argument("mujoco: shape '" + s.name + "' is a " + s.kind +
                                  ": lcsim's MuJoCo model has spheres, boxes, capsules and "
                                  "cylinders only");
    out[{s.body, s.link}] += "<geom name=\"" + shape_geom_name(s.name) + "\" type=\"" + type +
                             "\" size=\"" + size + "\"" + frame(s.local) +
                             " contype=\"0\" conaffinity=\"0\"/>\n";
  }
  return out;
}

}  // namespace

std::string row_geom_name(Eigen::Index row) { return "lcsim_c" + std::to_string(row); }
std::string shape_geom_name(const std::string& shape) { return "lcsim_s:" + shape; }
std::string base_joint_name(const std::string& body) { return "lcsim_base:" + body; }

std::map<std::string, JointRange> joint_ranges(const scene::Scene& setup) {
  const mech::MechanicalModel& m = *setup.model.mechanical;
  std::vector<bool> contact(static_cast<std::size_t>(m.num_constraints()), false);
  for (const scene::ContactFrame& cf : setup.contacts)
    contact[static_cast<std::size_t>(cf.row)] = true;
  std::map<std::string, JointRange> out;
  for (int i = 0; i < m.num_constraints(); ++i) {
    if (contact[static_cast<std::size_t>(i)]) continue;
    int coordinate = -1, count = 0;
    for (int j = 0; j < m.dofs(); ++j)
      if (m.E.coeff(i, j) != 0.0) {
        coordinate = j;
        ++count;
      }
    if (count != 1) continue;  // refused by check_expressible
    const double c = m.E.coeff(i, coordinate), bound = -m.g(i) / c;
    JointRange& r = out[m.coordinates[static_cast<std::size_t>(coordinate)]];
    if (c > 0.0) {
      r.lower = bound;
      r.lower_row = i;
      r.lower_scale = c;
    } else {
      r.upper = bound;
      r.upper_row = i;
      r.upper_scale = -c;
    }
  }
  return out;
}

std::string bodies_mjcf(const scene::Scene& setup) {
  const LinkGeoms geoms = contact_geoms(setup);
  const std::map<std::string, JointRange> ranges = joint_ranges(setup);
  Composer c{setup, geoms, ranges, ""};
  c.xml =
      "<mujoco model=\"lcsim\">\n<compiler angle=\"radian\" inertiafromgeom=\"false\" "
      "fusestatic=\"false\"/>\n<worldbody>\n";
  for (std::size_t i = 0; i < setup.planes.size(); ++i)
    c.xml += "<geom name=\"" + std::string(kPlanePrefix) + std::to_string(i) +
             "\" type=\"plane\" size=\"0 0 1\" pos=\"" + triple(setup.planes[i].point) +
             "\" zaxis=\"" + triple(setup.planes[i].normal) +
             "\" contype=\"0\" conaffinity=\"0\"/>\n";
  for (std::size_t b = 0; b < setup.bodies.size(); ++b) {
    const scene::SceneBody& body = setup.bodies[b];
    const std::string joint = body.base.floating
                                  ? "<freejoint name=\"" + base_joint_name(body.name) + "\"/>\n"
                                  : std::string();
    c.link(b, body.urdf->getRoot()->name, body.base.pose, joint);
  }
  c.xml += "</worldbody>\n<contact>\n";
  std::map<std::string, std::size_t> plane_of;
  for (std::size_t i = 0; i < setup.planes.size(); ++i) plane_of[setup.planes[i].name] = i;
  for (const scene::ContactFrame& cf : setup.contacts) {
    const std::string other = cf.against ? shape_geom_name(cf.against->name)
                                         : kPlanePrefix + std::to_string(plane_of.at(cf.plane));
    c.xml += "<pair geom1=\"" + other + "\" geom2=\"" + row_geom_name(cf.row) + "\"/>\n";
  }
  c.xml += "</contact>\n</mujoco>\n";
  return c.xml;
}

MjModelPtr load_bodies_model(const scene::Scene& setup) {
  const std::string xml = bodies_mjcf(setup);
  const TempDir tmp;
  const std::filesystem::path path = tmp.path / "scene.xml";
  std::ofstream(path) << xml;
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof err);
  if (!m)
    throw std::invalid_argument("mujoco: " + setup.model.source +
                                ": MuJoCo cannot load the scene's MJCF: " + std::string(err));
  return MjModelPtr(m);
}

}  // namespace lcsim::mujoco
