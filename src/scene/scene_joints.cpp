// A scene's `joints:` key: the joints to simulate (the coordinates), each a
// name or {name, stops, mimic_stops}; every other joint is frozen.
#include <urdf_model/model.h>

#include <algorithm>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::describe;
using io::yaml::fail;

namespace {

// Entry `k` of joints:, added to `out` with its stops.
void read_joint(const YAML::Node& n, const std::string& source, const std::string& k,
                const SceneUrdf& urdf, SceneJoints& out) {
  std::string name;
  std::vector<std::string> st{"lower", "upper"}, mst{"lower", "upper"};
  bool explicit_stops = false;
  if (n.IsMap()) {
    const Keys jk = io::yaml::mapping(n, source, k, {"name", "stops", "mimic_stops"});
    if (!jk.count("name")) fail(source, k + ".name", "missing");
    name = name_of(jk.at("name"), source, k + ".name");
    explicit_stops = jk.count("stops") > 0;
    if (explicit_stops) st = stop_list(jk.at("stops"), source, k + ".stops");
    if (jk.count("mimic_stops")) mst = stop_list(jk.at("mimic_stops"), source, k + ".mimic_stops");
  } else {
    name = name_of(n, source, k);
  }
  const auto j = urdf.model->getJoint(name);
  if (!j) fail(source, k, "no joint '" + name + "' in " + urdf.path);
  if (!has_position(*j))
    fail(source, k,
         "joint '" + name +
             "' is not revolute, continuous or prismatic (only those can be simulated; leave "
             "it out to freeze it)");
  if (std::count(out.names.begin(), out.names.end(), name))
    fail(source, k, "duplicate joint '" + name + "'");
  check_stops(*j, explicit_stops, st, source, k, urdf);
  out.names.push_back(name);
  out.stops.push_back(st);
  out.mimic_stops.push_back(mst);
}

}  // namespace

SceneJoints read_joints(const Keys& keys, const std::string& source, const SceneUrdf& urdf,
                        const BasePose& base, bool obstacle) {
  SceneJoints out;
  out.names = base_coordinates(base);
  out.base = out.names.size();
  out.stops.assign(out.base, {});
  out.mimic_stops.assign(out.base, {});
  // A floating body may have no joints at all (a box); a fixed one must,
  // unless it is an obstacle in a scene of bodies (no coordinates).
  if (!keys.count("joints") && (out.base > 0 || obstacle)) {
    out.mimics = mimic_joints(*urdf.model, urdf.path, out.names);
    return out;
  }
  if (!keys.count("joints")) fail(source, "joints", "missing (name the joints to simulate)");
  const YAML::Node& jn = keys.at("joints");
  if (!jn.IsSequence() || (jn.size() == 0 && out.base == 0))
    fail(source, "joints", "expected a non-empty list of joint names (got " + describe(jn) + ")");
  for (std::size_t i = 0; i < jn.size(); ++i)
    read_joint(jn[i], source, "joints[" + std::to_string(i) + "]", urdf, out);
  out.mimics = mimic_joints(*urdf.model, urdf.path, out.names);
  return out;
}

bool has_position(const urdf::Joint& j) {
  return j.type == urdf::Joint::REVOLUTE || j.type == urdf::Joint::PRISMATIC ||
         j.type == urdf::Joint::CONTINUOUS;
}

Eigen::Index SceneJoints::coord(const std::string& name) const {
  return std::find(names.begin(), names.end(), name) - names.begin();
}

std::vector<std::string> SceneJoints::urdf_joints() const {
  return {names.begin() + static_cast<std::ptrdiff_t>(base), names.end()};
}

VectorXd SceneJoints::vector_of(const std::map<std::string, double>& values) const {
  VectorXd v = VectorXd::Zero(size());
  for (Eigen::Index i = 0; i < size(); ++i)
    if (values.count(names[static_cast<std::size_t>(i)]))
      v(i) = values.at(names[static_cast<std::size_t>(i)]);
  return v;
}

namespace {

// For a name written as a floating base's coordinate (`<name>.z`) that is
// none: the base's coordinates, as the user is likely to have guessed the
// base's name (bullet3's a1.urdf is <robot name="a1_description">).
std::string base_hint(const SceneJoints& joints, const std::string& n) {
  const auto dot = n.rfind('.');
  if (joints.base == 0 || dot == std::string::npos) return "";
  const std::string tail = n.substr(dot + 1);
  for (const char* c : {"x", "y", "z", "rx", "ry", "rz"})
    if (tail == c)
      return " (the floating base's coordinates are " + joints.names.front() + " ... " +
             joints.names[joints.base - 1] + ": base.name, by default the URDF's <robot name>)";
  return "";
}

}  // namespace

NameCheck simulated(const SceneJoints& joints, const SceneUrdf& urdf) {
  return [&](const std::string& n) -> std::string {
    if (static_cast<std::size_t>(joints.coord(n)) < joints.base) return "";  // a floating base's
    if (!urdf.model->getJoint(n))
      return "no joint '" + n + "' in " + urdf.path + base_hint(joints, n);
    if (joints.mimics.count(n))
      return "joint '" + n + "' mimics '" + joints.mimics.at(n).leader +
             "' (it follows its leader and is not a coordinate)";
    if (joints.coord(n) == joints.size())
      return "joint '" + n +
             "' is frozen (not in joints:); only simulated joints can carry springs, constraints "
             "and initial values";
    return "";
  };
}

}  // namespace lcsim::scene
