// A scratch directory for URDF and scene files written by a test (removed
// afterwards), shared by the scene tests (test_scene.cpp,
// test_urdf_robustness.cpp).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcsim/core/format.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <random>
#include <string>

namespace lcsim::test_support {

class SceneFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("lcsim_scene_" + std::to_string(std::random_device{}()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string write(const std::string& name, const std::string& text) {
    const auto p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  // Loads scene text (s.yaml) beside `urdf` text (r.urdf, unless empty);
  // returns the error message.
  std::string error(const std::string& urdf, const std::string& scene) {
    if (!urdf.empty()) write("r.urdf", urdf);
    const std::string path = write("s.yaml", scene);
    try {
      scene::load_model(path);
    } catch (const io::InputError& e) {
      return e.what();
    }
    ADD_FAILURE() << "no error for:\n" << scene;
    return "";
  }
  // robots/vision60_drop_scene.yaml (and its URDF) with friction mu, d on
  // its four toes and a horizontal velocity (vx, vy) m/s: the scene path.
  std::string vision60_friction(double mu, int d, double vx, double vy) {
    const std::string robots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
    write("vision60.urdf", io::read_file(robots + "vision60.urdf"));
    std::string t = io::read_file(robots + "vision60_drop_scene.yaml");
    for (int k = 0; k < 4; ++k) {
      const std::string toe = "toe" + std::to_string(k), entry = "name: " + toe + "}";
      const size_t at = t.find(entry);
      EXPECT_NE(at, std::string::npos) << toe;
      t.replace(
          at, entry.size(),
          "name: " + toe + ", friction: " + format_number(mu) + ", d: " + std::to_string(d) + "}");
    }
    const std::string init = "  q: {vision60.z: 0.463372545558797}";
    const size_t at = t.find(init);
    EXPECT_NE(at, std::string::npos);
    t.replace(at, init.size(),
              init + "\n  v: {vision60.x: " + format_number(vx) +
                  ", vision60.y: " + format_number(vy) + "}");
    return write("v60.yaml", t);
  }
  std::filesystem::path dir_;
};

}  // namespace lcsim::test_support
