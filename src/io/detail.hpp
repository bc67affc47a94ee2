// Internal helpers of src/io (not part of the public face, io/io.hpp).
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <filesystem>
#include <lcsim/io/io.hpp>
#include <map>
#include <string>

namespace lcsim::io {

// Shortest text that reads back as the same double ("2", "0.1", "-1e-300").
std::string format_number(double x);

// `text` made fit for a one-line message: control characters (newlines from
// a YAML scalar or a yaml-cpp message) become escapes such as \n or \x01,
// and anything beyond `max_chars` is cut to "...".
std::string one_line(const std::string& text, std::size_t max_chars = 1000);

// The whole text of a model file; InputError "<path>: cannot open: no such
// file" (or "is a directory", "permission denied or unreadable").
std::string read_file(const std::filesystem::path& path);

// A model file's YAML root (InputError for an empty file), whether it is a
// scene (a top-level `urdf:` key), and the model of a root that is not.
YAML::Node load_model_root(const std::string& yaml_text, const std::string& source);
bool is_scene(const YAML::Node& root);
mech::Model parse_model_root(const YAML::Node& root, const std::string& source);

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

}  // namespace lcsim::io
