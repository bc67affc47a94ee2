// The values a scene's keys hold, read by every stage of read_scene
// (scene/detail.hpp): names, booleans, numbers by joint or constraint.
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::describe;
using io::yaml::fail;

std::string name_of(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsScalar() || n.Scalar().empty())
    fail(source, key, "expected a non-empty name (got " + describe(n) + ")");
  return n.Scalar();
}

bool boolean(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (n.IsScalar() && (n.Scalar() == "true" || n.Scalar() == "false")) return n.Scalar() == "true";
  fail(source, key, "expected true or false (got " + describe(n) + ")");
}

std::map<std::string, double> by_name(const YAML::Node& n, const std::string& source,
                                      const std::string& key, const NameCheck& check) {
  std::map<std::string, double> out;
  for (const auto& [name, value] : io::yaml::mapping(n, source, key, {})) {
    const std::string why = check(name);
    if (!why.empty()) fail(source, key + "." + name, why);
    out[name] = io::yaml::number(value, source, key + "." + name);
  }
  return out;
}

Eigen::Vector3d vector3(const YAML::Node& n, const std::string& source, const std::string& key,
                        const std::string& unit) {
  const VectorXd v = io::yaml::vector(n, source, key);
  io::yaml::expect_size(v, 3, source, key, "(x, y, z in " + unit + ")");
  return v;
}

}  // namespace lcsim::scene
