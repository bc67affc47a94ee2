// The error every reader throws on bad input: one line that names the file,
// the key or element, and the value.
#pragma once

#include <stdexcept>

namespace lcsim::io {

// One clear line: "<file>: <key>: <what is wrong> (got <value>)".
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace lcsim::io
