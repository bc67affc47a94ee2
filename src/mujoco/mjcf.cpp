// The scene's MuJoCo model: MuJoCo's own URDF reader, then a free joint at
// the root and the scene's planes, written into the MJCF MuJoCo saves.
//
// Steps (files in a fresh temporary directory, removed when done):
// 1. the URDF text with <mujoco><compiler fusestatic="false" .../></mujoco>
//    after <robot ...> (MuJoCo's URDF default fuses a body without joints
//    into the world: the box would be static) and meshdir the URDF's folder;
// 2. mj_loadXML reads it, mj_saveLastXML writes its MJCF;
// 3. into that MJCF: one <geom type="plane"> per scene plane in <worldbody>,
//    and a <freejoint> in the root body for a floating base;
// 4. mj_loadXML reads the result.
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <lcsim/core/format.hpp>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "mujoco/detail.hpp"

namespace lcsim::mujoco {

namespace {

namespace fs = std::filesystem;

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::string triple(const Eigen::Vector3d& v) {
  return format_number(v.x()) + " " + format_number(v.y()) + " " + format_number(v.z());
}

// The planes as MJCF geoms, and the free joint in the root body.
std::string edit_mjcf(std::string xml, const scene::Scene& setup) {
  std::string planes;
  for (std::size_t i = 0; i < setup.planes.size(); ++i)
    planes += "<geom name=\"" + std::string(kPlanePrefix) + std::to_string(i) +
              "\" type=\"plane\" size=\"0 0 1\" pos=\"" + triple(setup.planes[i].point) +
              "\" zaxis=\"" + triple(setup.planes[i].normal) + "\"/>\n";
  const auto world = xml.find("<worldbody>");
  if (world == std::string::npos) throw std::runtime_error("MuJoCo's MJCF has no <worldbody>");
  const auto body = xml.find("<body", world);
  if (setup.base.floating) {
    if (body == std::string::npos) throw std::runtime_error("MuJoCo's MJCF has no root body");
    const auto end = xml.find('>', body);
    const std::string joint = "<freejoint name=\"" + std::string(kFreeJoint) + "\"/>";
    if (xml[end - 1] == '/')
      xml.replace(end - 1, 2, ">" + joint + "</body>");
    else
      xml.insert(end + 1, joint);
  }
  xml.insert(world + std::string("<worldbody>").size(), "\n" + planes);
  return xml;
}

}  // namespace

TempDir::TempDir() {
  static std::atomic<long> counter{0};
  path = fs::temp_directory_path() /
         ("lcsim-mujoco-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  fs::create_directories(path);
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path, ec);
}

MjModelPtr load_scene_model(const scene::Scene& setup) {
  const fs::path urdf = setup.urdf_source;
  std::string text = read_text(urdf);
  std::smatch robot;
  if (!std::regex_search(text, robot, std::regex("<robot[^>]*>")))
    throw std::invalid_argument("mujoco: " + setup.urdf_source + ": no <robot> element");
  const std::string dir = fs::absolute(urdf).parent_path().string();
  text.insert(static_cast<std::size_t>(robot.position(0) + robot.length(0)),
              "<mujoco><compiler fusestatic=\"false\" discardvisual=\"true\" strippath=\"false\" "
              "meshdir=\"" +
                  dir + "\"/></mujoco>");
  const TempDir tmp;
  const fs::path in = tmp.path / "robot.urdf", saved = tmp.path / "robot.xml",
                 scene = tmp.path / "scene.xml";
  std::ofstream(in) << text;
  char err[1000] = "";
  mjModel* m = mj_loadXML(in.c_str(), nullptr, err, sizeof err);
  if (!m)
    throw std::invalid_argument("mujoco: " + setup.urdf_source +
                                ": MuJoCo cannot load it: " + std::string(err));
  const int saved_ok = mj_saveLastXML(saved.c_str(), m, err, sizeof err);
  mj_deleteModel(m);
  if (!saved_ok) throw std::runtime_error("mujoco: mj_saveLastXML: " + std::string(err));
  std::ofstream(scene) << edit_mjcf(read_text(saved), setup);
  m = mj_loadXML(scene.c_str(), nullptr, err, sizeof err);
  if (!m)
    throw std::invalid_argument("mujoco: " + setup.urdf_source +
                                ": MuJoCo cannot load the scene's MJCF: " + std::string(err));
  return MjModelPtr(m);
}

}  // namespace lcsim::mujoco
