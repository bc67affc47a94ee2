// Internal helpers of src/io (not part of the public face, io/io.hpp).
#pragma once

#include <string>

namespace lcsim::io {

// Shortest text that reads back as the same double ("2", "0.1", "-1e-300").
std::string format_number(double x);

}  // namespace lcsim::io
