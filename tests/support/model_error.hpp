// Shared by the io tests: the message of the InputError that parse_model
// throws for a model text, or "(accepted)" when it reads the text.
#pragma once

#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::test_support {

inline std::string model_error(const std::string& yaml) {
  try {
    scene::parse_model(yaml, "bad.yaml");
  } catch (const io::InputError& e) {
    return e.what();
  }
  return "(accepted)";
}

}  // namespace lcsim::test_support
