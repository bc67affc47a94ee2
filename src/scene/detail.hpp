// Internal helpers of src/scene (not part of its public face, lcsim/scene/).
#pragma once

#include <map>
#include <string>

namespace lcsim::scene {

// URDF text without its <visual>, <collision> and <material> elements
// (urdf_geometry.cpp): lcsim reads no geometry, and urdfdom refuses a whole
// robot for an error in one of them (Bullet's capsule or plane geometry, a
// malformed mesh scale, two materials of one name).
std::string without_geometry(const std::string& xml);

// The joints whose <limit> lacks lower or upper, and which ("lower",
// "upper" or "lower and upper"), from the URDF text (the same scanner). The
// URDF default for both is 0, which urdfdom applies without a trace: as
// stops they would lock the joint at 0 (bullet3's Minitaur knees, whose
// <limit> gives only effort and velocity), so a scene refuses them there.
std::map<std::string, std::string> limits_without_bounds(const std::string& xml);

}  // namespace lcsim::scene
