// Internal to src/mujoco: the scene's MuJoCo model (mjcf.cpp) and the run
// (mujoco.cpp).
#pragma once

#include <mujoco/mujoco.h>

#include <filesystem>
#include <lcsim/scene/scene.hpp>
#include <map>
#include <memory>
#include <string>

namespace lcsim::mujoco {

struct MjModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct MjDataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using MjModelPtr = std::unique_ptr<mjModel, MjModelDeleter>;
using MjDataPtr = std::unique_ptr<mjData, MjDataDeleter>;

// Names lcsim gives what it adds to MuJoCo's model.
inline constexpr const char* kPlanePrefix = "lcsim_plane";
inline constexpr const char* kFreeJoint = "lcsim_base";

// The scene's URDF loaded by MuJoCo, with its planes and (floating base) a
// free joint at the root; nothing set yet (mjcf.cpp's steps).
// std::invalid_argument with MuJoCo's message when it cannot load it.
MjModelPtr load_scene_model(const scene::Scene& setup);

// A scene of several bodies (`bodies:`) as one MuJoCo model, composed by
// lcsim (mjcf_bodies.cpp says how): its MJCF text, and the model MuJoCo
// compiles from it (std::invalid_argument naming the body and the joint or
// shape it cannot hold, or with MuJoCo's message).
std::string bodies_mjcf(const scene::Scene& setup);
// A joint stop of a scene of bodies as a MuJoCo joint range: the rows of E
// that are not contacts and hold one coordinate, c q_j + g >= 0, the bound
// -g / c below (c > 0) or above (c < 0); the other side 1e6 away (m or rad)
// when the scene has none. By coordinate name (the MJCF joint's).
struct JointRange {
  double lower = -1e6, upper = 1e6;
  int lower_row = -1, upper_row = -1;           // rows of E, -1: none
  double lower_scale = 1.0, upper_scale = 1.0;  // |c|: the row's multiplier is the force / |c|
};
std::map<std::string, JointRange> joint_ranges(const scene::Scene& setup);
MjModelPtr load_bodies_model(const scene::Scene& setup);
// The names of what that model adds: contact row r's point geom, another
// body's shape's geom (scene::BodyShape::name), a floating body's free joint.
std::string row_geom_name(Eigen::Index row);
std::string shape_geom_name(const std::string& shape);
std::string base_joint_name(const std::string& body);

// A directory of its own under the system's temporary one, removed with it.
struct TempDir {
  std::filesystem::path path;
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
};

}  // namespace lcsim::mujoco
