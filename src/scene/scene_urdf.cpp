// A scene's `urdf:` key (and `balance_inertia:`, what parsing it may
// repair): the robot, read relative to the scene's directory.
#include <filesystem>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::fail;

SceneUrdf read_urdf(const Keys& keys, const std::string& source) {
  if (!keys.count("urdf")) fail(source, "urdf", "missing (a scene names its URDF file)");
  const std::string urdf_name = name_of(keys.at("urdf"), source, "urdf");
  const std::filesystem::path urdf_path =
      std::filesystem::path(source).parent_path() / std::filesystem::path(urdf_name);
  SceneUrdf out;
  if (keys.count("balance_inertia"))
    out.repairs.balance_inertia = boolean(keys.at("balance_inertia"), source, "balance_inertia");
  std::error_code ec;
  if (!std::filesystem::is_regular_file(urdf_path, ec))
    fail(source, "urdf",
         "no such file (got '" + urdf_name + "', looked for '" + urdf_path.string() + "')");
  const std::string xml = io::read_file(urdf_path);
  out.model = parse_urdf(xml, urdf_path.string(), out.repairs);
  out.unbounded = limits_without_bounds(xml);
  out.collisions = collision_elements(xml);
  out.path = urdf_path.string();
  return out;
}

}  // namespace lcsim::scene
