// Text the readers and the commands share: numbers written to read back
// exactly, one-line messages, comma lists.
#pragma once

#include <Eigen/Dense>
#include <cstddef>
#include <lcsim/core/format.hpp>
#include <lcsim/io/input_error.hpp>
#include <string>
#include <vector>

namespace lcsim::io {

// Shortest text that reads back as the same double ("2", "0.1", "-1e-300"):
// lcsim::format_number (core/format.hpp), under the name io's callers use.
using lcsim::format_number;

// `text` made fit for a one-line message: control characters (newlines from
// a YAML scalar or a yaml-cpp message) become escapes such as \n or \x01,
// and anything beyond `max_chars` is cut to "...".
std::string one_line(const std::string& text, std::size_t max_chars = 1000);

// Parses "a,b,c" into a vector; InputError names `what` and the bad token.
Eigen::VectorXd parse_vector(const std::string& text, const std::string& what);

// `text` cut at every `sep` ("a,,b" gives "a", "", "b"; "" gives none): the
// comma lists of names and ranges the commands take.
std::vector<std::string> split(const std::string& text, char sep);

}  // namespace lcsim::io
