// A scene's `springs:` key: linear springs and dampers on one simulated
// joint (c = e_a) or between two (c = e_a - e_b), the force -k (c'q - rest) c
// - d c c' q' on the coordinates.
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::yaml::describe;
using io::yaml::fail;
using io::yaml::number;

void add_springs(const Keys& keys, const std::string& source, const NameCheck& check,
                 const SceneJoints& joints, SceneDynamics& dyn) {
  if (!keys.count("springs")) return;
  const YAML::Node& sn = keys.at("springs");
  if (!sn.IsSequence()) fail(source, "springs", "expected a list (got " + describe(sn) + ")");
  for (std::size_t i = 0; i < sn.size(); ++i) {
    const std::string k = "springs[" + std::to_string(i) + "]";
    const Keys sk = io::yaml::mapping(sn[i], source, k,
                                      {"name", "joint", "other", "stiffness", "damping", "rest"});
    if (!sk.count("joint")) fail(source, k + ".joint", "missing");
    VectorXd c = VectorXd::Zero(joints.size());
    for (const char* role : {"joint", "other"}) {
      if (!sk.count(role)) continue;
      const std::string rk = k + "." + role;
      const std::string jn = name_of(sk.at(role), source, rk);
      const std::string why = check(jn);
      if (!why.empty()) fail(source, rk, why);
      c(joints.coord(jn)) += std::string(role) == "joint" ? 1.0 : -1.0;
    }
    if (c.isZero()) fail(source, k + ".other", "a spring between a joint and itself");
    double stiffness = 0.0, damping = 0.0, rest = 0.0;
    if (sk.count("stiffness")) stiffness = number(sk.at("stiffness"), source, k + ".stiffness");
    if (sk.count("damping")) damping = number(sk.at("damping"), source, k + ".damping");
    if (sk.count("rest")) rest = number(sk.at("rest"), source, k + ".rest");
    if (stiffness < 0.0)
      fail(source, k + ".stiffness", "must be >= 0 (got " + format_number(stiffness) + ")");
    if (damping < 0.0)
      fail(source, k + ".damping", "must be >= 0 (got " + format_number(damping) + ")");
    dyn.K += stiffness * c * c.transpose();
    dyn.D += damping * c * c.transpose();
    dyn.f += stiffness * rest * c;
  }
}

}  // namespace lcsim::scene
