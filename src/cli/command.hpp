// Sub-commands of the `lcsim` command line. Each src/cli/cmd_*.cpp registers
// one with LCSIM_REGISTER_COMMAND; main.cpp adds them all to the app.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <vector>

namespace lcsim::cli {

using CommandSetup = std::function<void(CLI::App& app)>;
std::vector<CommandSetup>& command_registry();

struct CommandRegistration {
  explicit CommandRegistration(CommandSetup setup) {
    command_registry().push_back(std::move(setup));
  }
};

// Failures that are not input errors but numerical trouble (LCP ray
// termination, singular Delassus matrix, ...): printed as one line, exit 3.
class NumericalError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace lcsim::cli

#define LCSIM_CONCAT_INNER(a, b) a##b
#define LCSIM_CONCAT(a, b) LCSIM_CONCAT_INNER(a, b)
#define LCSIM_REGISTER_COMMAND(fn) \
  static ::lcsim::cli::CommandRegistration LCSIM_CONCAT(lcsim_cmd_, __LINE__)(fn)
