// Compiled into every program that links lcsim::mujoco (an INTERFACE source
// of that target): adds the "mujoco" integrator before main runs.
#include <lcsim/mujoco/mujoco.hpp>

namespace {
const bool kRegistered = (lcsim::mujoco::register_backends(), true);
}  // namespace
