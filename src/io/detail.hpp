// Internal helpers of src/io (not part of the public face, io/io.hpp).
#pragma once

#include <cstddef>
#include <filesystem>
#include <string>

#include "io/io.hpp"

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

}  // namespace lcsim::io
