// libFuzzer target: scenes (a URDF and the scene YAML that names it). The
// input is a URDF, then a line "%%", then a scene; the URDF is written to
// robot.urdf in a private temporary folder and the scene is parsed as if it
// were scene.yaml beside it (so `urdf: robot.urdf` finds it). Independently
// the URDF alone goes through parse_urdf and linearise_urdf with every
// revolute and prismatic joint simulated, at q0 = 0. Only io::InputError may
// escape; a crash, a sanitizer report or another exception is a bug.
#include <unistd.h>
#include <urdf_model/model.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace {

const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    std::string t = (std::filesystem::temp_directory_path() / "lcsim_fuzz_scene_XXXXXX").string();
    if (!::mkdtemp(t.data())) std::abort();
    return std::filesystem::path(t);
  }();
  return dir;
}

// One line per error (urdfdom's own text is folded by io::one_line).
void one_line(const lcsim::io::InputError& e) {
  const std::string what = e.what();
  if (what.empty() || what.find('\n') != std::string::npos) __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  const std::size_t sep = text.find("\n%%\n");
  const std::string urdf_text = text.substr(0, sep);
  const std::string scene_text = sep == std::string::npos ? "" : text.substr(sep + 4);

  try {
    const auto model = lcsim::scene::parse_urdf(urdf_text, "fuzz.urdf");
    std::vector<std::string> joints;
    for (const auto& [name, j] : model->joints_)
      if (j && (j->type == urdf::Joint::REVOLUTE || j->type == urdf::Joint::PRISMATIC))
        joints.push_back(name);
    if (joints.size() <= 8)
      (void)lcsim::scene::linearise_urdf(*model, joints, {}, Eigen::Vector3d(0.0, 0.0, -9.81),
                                         "fuzz.urdf");
  } catch (const lcsim::io::InputError& e) {
    one_line(e);
  }

  if (sep == std::string::npos) return 0;
  {
    std::ofstream out(folder() / "robot.urdf", std::ios::binary | std::ios::trunc);
    out << urdf_text;
  }
  try {
    const lcsim::mech::Model m =
        lcsim::scene::parse_model(scene_text, (folder() / "scene.yaml").string());
    (void)lcsim::io::model_notes(m);
  } catch (const lcsim::io::InputError& e) {
    one_line(e);
  }
  return 0;
}
