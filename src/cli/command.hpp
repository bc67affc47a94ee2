// Sub-commands of the `lcsim` command line. Each src/cli/cmd_*.cpp registers
// one with LCSIM_REGISTER_COMMAND; main.cpp adds them all to the app.
#pragma once

#include <CLI/CLI.hpp>
#include <functional>
#include <lcsim/core/status.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace lcsim::cli {

using CommandSetup = std::function<void(CLI::App& app)>;
std::vector<CommandSetup>& command_registry();

struct CommandRegistration {
  explicit CommandRegistration(CommandSetup setup) {
    command_registry().push_back(std::move(setup));
  }
};

// A library result that did not end ok (a run, an LCP solve, ...), with its
// status: main.cpp prints the message as one line and exits with
// exit_code(status()), so every subcommand maps statuses the same way.
class StatusError : public std::runtime_error {
 public:
  StatusError(lcsim::Status status, const std::string& message)
      : std::runtime_error(message), status_(status) {}
  lcsim::Status status() const { return status_; }

 private:
  lcsim::Status status_;
};

// Numerical trouble found by a command itself (LCP ray termination in a
// table of impact rules, ...): a StatusError with kNumericalFailure.
class NumericalError : public StatusError {
 public:
  explicit NumericalError(const std::string& message)
      : StatusError(lcsim::Status::kNumericalFailure, message) {}
};

// The one map from a status to the exit code: 0 ok, 2 invalid input (as an
// io::InputError), 3 every other failure (numerical trouble).
int exit_code(lcsim::Status status);

// Throws StatusError(status, message) unless status is kOk.
void check_status(lcsim::Status status, const std::string& message);

// "a, b, c": the names of a registry (sim::integrator_names(), ...) for a
// help text, so that help lists whatever is registered.
std::string name_list(const std::vector<std::string>& names);

}  // namespace lcsim::cli

#define LCSIM_CONCAT_INNER(a, b) a##b
#define LCSIM_CONCAT(a, b) LCSIM_CONCAT_INNER(a, b)
#define LCSIM_REGISTER_COMMAND(fn) \
  static ::lcsim::cli::CommandRegistration LCSIM_CONCAT(lcsim_cmd_, __LINE__)(fn)
