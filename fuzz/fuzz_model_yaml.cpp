// libFuzzer target: scene::parse_model on arbitrary text. A model file is input
// from a user: the only exception that may escape is io::InputError (one line
// naming the file, key and value); a crash, a sanitizer report or any other
// exception is a bug. A valid model also goes through model_notes and
// as_lcs, which the commands call next.
#include <cstddef>
#include <cstdint>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    // The source names a file in a directory without URDFs: a `urdf:` key
    // makes this a scene whose URDF is not found (fuzz_scene covers scenes).
    const lcsim::mech::Model model = lcsim::scene::parse_model(text, "/nonexistent/fuzz.yaml");
    (void)lcsim::io::model_notes(model);
    (void)model.as_lcs();
  } catch (const lcsim::io::InputError& e) {
    // One line: a newline inside the message would break the CLI's contract.
    const std::string what = e.what();
    if (what.empty() || what.find('\n') != std::string::npos) __builtin_trap();
  }
  return 0;
}
