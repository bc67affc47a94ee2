// A scratch directory for URDF and scene files written by a test (removed
// afterwards), shared by the scene tests (test_scene.cpp,
// test_urdf_robustness.cpp).
#pragma once

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
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
  std::filesystem::path dir_;
};

}  // namespace lcsim::test_support
