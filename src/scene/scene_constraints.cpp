// A scene's unilateral constraints E q + g >= 0: the rows the stages add
// (joint stops, then `constraints:`), their names, each unique, and their
// `restitution:`.
#include <algorithm>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
#include <set>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::yaml::describe;
using io::yaml::fail;
using io::yaml::join;

void SceneConstraints::add(VectorXd row, double gap, std::string name) {
  rows.push_back(std::move(row));
  gaps.push_back(gap);
  names.push_back(std::move(name));
}

MatrixXd SceneConstraints::E(Eigen::Index coordinates) const {
  const auto k = static_cast<Eigen::Index>(rows.size());
  MatrixXd out = MatrixXd::Zero(k, coordinates);
  for (Eigen::Index i = 0; i < k; ++i) out.row(i) = rows[static_cast<std::size_t>(i)].transpose();
  return out;
}

VectorXd SceneConstraints::g() const {
  const auto k = static_cast<Eigen::Index>(gaps.size());
  VectorXd out = VectorXd::Zero(k);
  for (Eigen::Index i = 0; i < k; ++i) out(i) = gaps[static_cast<std::size_t>(i)];
  return out;
}

void add_constraints(const Keys& keys, const std::string& source, const NameCheck& check,
                     const SceneJoints& joints, SceneConstraints& out) {
  if (!keys.count("constraints")) return;
  const YAML::Node& cn = keys.at("constraints");
  if (!cn.IsSequence()) fail(source, "constraints", "expected a list (got " + describe(cn) + ")");
  for (std::size_t i = 0; i < cn.size(); ++i) {
    const std::string k = "constraints[" + std::to_string(i) + "]";
    const Keys ck = io::yaml::mapping(cn[i], source, k, {"name", "coefficients", "g"});
    if (!ck.count("name")) fail(source, k + ".name", "missing");
    if (!ck.count("coefficients")) fail(source, k + ".coefficients", "missing");
    const std::string name = name_of(ck.at("name"), source, k + ".name");
    VectorXd r = VectorXd::Zero(joints.size());
    for (const auto& [jname, c] :
         by_name(ck.at("coefficients"), source, k + ".coefficients", check))
      r(joints.coord(jname)) = c;
    if (r.isZero()) fail(source, k + ".coefficients", "all zero (the constraint says nothing)");
    out.add(r, ck.count("g") ? io::yaml::number(ck.at("g"), source, k + ".g") : 0.0, name);
  }
}

void check_unique_names(const SceneConstraints& c, const std::string& source) {
  std::set<std::string> seen;
  for (const auto& name : c.names)
    if (!seen.insert(name).second)
      fail(source, "constraints", "duplicate constraint name '" + name + "'");
}

VectorXd read_restitution(const Keys& keys, const std::string& source,
                          const std::vector<std::string>& constraints) {
  VectorXd out = VectorXd::Zero(static_cast<Eigen::Index>(constraints.size()));
  if (!keys.count("restitution")) return out;
  const NameCheck check = [&](const std::string& n) -> std::string {
    if (!std::count(constraints.begin(), constraints.end(), n))
      return "no constraint '" + n + "' (the constraints are " + join(constraints) + ")";
    return "";
  };
  for (const auto& [name, e] : by_name(keys.at("restitution"), source, "restitution", check)) {
    if (e < 0.0 || e > 1.0)
      fail(source, "restitution." + name, "outside [0, 1] (got " + format_number(e) + ")");
    out(std::find(constraints.begin(), constraints.end(), name) - constraints.begin()) = e;
  }
  return out;
}

}  // namespace lcsim::scene
