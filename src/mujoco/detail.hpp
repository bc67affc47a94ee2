// Internal to src/mujoco: the scene's MuJoCo model (mjcf.cpp) and the run
// (mujoco.cpp).
#pragma once

#include <mujoco/mujoco.h>

#include <lcsim/scene/scene.hpp>
#include <memory>

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

}  // namespace lcsim::mujoco
