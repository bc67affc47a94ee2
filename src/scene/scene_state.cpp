// The joint values a scene gives: `q0:`, the reference configuration it is
// linearised about (any joint of the URDF with a position), and `initial:`,
// the state a run starts from (simulated joints only).
#include <urdf_model/model.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::yaml::fail;

namespace {

// Tolerance of a mimic's q0 against its leader's (rad or m, relative to
// max(1, |value|)): published reference poses (SRDF, robot descriptions)
// list every joint with 4 to 6 decimals, so a consistent value is off by
// up to 5e-5 of a unit from rounding; an inconsistent one by a real angle.
constexpr double kMimicQ0Tolerance = 1e-4;

// q0 may name a mimic joint m (robots' reference poses list every joint)
// when it agrees with its leader J: q_m = a q_J + b (J's q0, 0 if not
// named). The value then says nothing new and is dropped (m follows J);
// another value is an error naming both joints.
void check_mimic_q0(std::map<std::string, double>& q0, const std::map<std::string, Mimic>& mimics,
                    const std::string& source) {
  for (const auto& [name, mm] : mimics) {
    const auto it = q0.find(name);
    if (it == q0.end()) continue;
    const auto lead = q0.find(mm.leader);
    const double q_leader = lead == q0.end() ? 0.0 : lead->second;
    const double follows = mm.multiplier * q_leader + mm.offset;
    if (std::abs(it->second - follows) > kMimicQ0Tolerance * std::max(1.0, std::abs(follows)))
      fail(source, "q0." + name,
           "joint '" + name + "' mimics '" + mm.leader + "' (q = " + format_number(mm.multiplier) +
               " q_" + mm.leader + " + " + format_number(mm.offset) + " = " +
               format_number(follows) + " at q0." + mm.leader + " = " + format_number(q_leader) +
               "), got " + format_number(it->second) + "; give q0 for '" + mm.leader +
               "' only, or a value that follows it");
    q0.erase(it);
  }
}

}  // namespace

std::map<std::string, double> read_q0(const Keys& keys, const std::string& source,
                                      const SceneUrdf& urdf, const SceneJoints& joints) {
  std::map<std::string, double> q0;
  if (keys.count("q0"))
    q0 = by_name(keys.at("q0"), source, "q0", [&](const std::string& n) -> std::string {
      const auto j = urdf.model->getJoint(n);
      if (!j) return "no joint '" + n + "' in " + urdf.path;
      if (!has_position(*j))
        return "joint '" + n + "' has no position (not revolute, continuous or prismatic)";
      return "";
    });
  check_mimic_q0(q0, joints.mimics, source);
  return q0;
}

VectorXd read_initial(const Keys& keys, const std::string& source, const NameCheck& check,
                      const SceneJoints& joints, const VectorXd& q0) {
  const Eigen::Index N = joints.size();
  VectorXd x(2 * N);
  x << q0, VectorXd::Zero(N);
  const Keys ik = keys.count("initial")
                      ? io::yaml::mapping(keys.at("initial"), source, "initial", {"q", "v"})
                      : Keys{};
  for (const char* part : {"q", "v"}) {
    if (!ik.count(part)) continue;
    for (const auto& [jname, val] :
         by_name(ik.at(part), source, std::string("initial.") + part, check))
      x(joints.coord(jname) + (std::string(part) == "v" ? N : 0)) = val;
  }
  return x;
}

}  // namespace lcsim::scene
