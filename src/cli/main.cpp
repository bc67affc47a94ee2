// The `lcsim` command line. Input errors are exceptions caught once here and
// printed as one clear line with a non-zero exit (DESIGN.md, Conventions);
// exit_code() is the one map from a status to the exit code.
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <csignal>
#include <iostream>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>
#include <string>

#include "cli/command.hpp"

namespace lcsim::cli {
std::vector<CommandSetup>& command_registry() {
  static std::vector<CommandSetup> registry;
  return registry;
}

int exit_code(lcsim::Status status) {
  switch (status) {
    case lcsim::Status::kOk:
      return 0;
    case lcsim::Status::kInvalidInput:
      return 2;
    default:
      return 3;
  }
}

void check_status(lcsim::Status status, const std::string& message) {
  if (status != lcsim::Status::kOk) throw StatusError(status, message);
}

std::string name_list(const std::vector<std::string>& names) {
  std::string s;
  for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
  return s;
}

namespace {

// SIGINT, SIGTERM: no temporary file and no half-written output remain
// (outputs are renamed into place only when complete), exit 128 + signo.
extern "C" void on_signal(int signo) {
  io::remove_temporary_files();
  ::_exit(128 + signo);
}

void install_signal_handlers() {
  struct sigaction sa {};
  sa.sa_handler = on_signal;
  sigemptyset(&sa.sa_mask);
  for (int s : {SIGINT, SIGTERM}) sigaction(s, &sa, nullptr);
}

int report(lcsim::Status status, const char* what) {
  std::cerr << (status == lcsim::Status::kInvalidInput ? "lcsim: error: "
                                                       : "lcsim: numerical failure: ")
            << what << "\n";
  return exit_code(status);
}

// A first word that is no command (`lcsim check model.yaml`): one line
// naming it and the commands, where CLI11 would say only "A subcommand is
// required". Empty when argv[1] is an option or a known command.
std::string unknown_command(const CLI::App& app, int argc, char** argv) {
  if (argc < 2 || argv[1][0] == '-') return "";
  std::string names;
  for (const CLI::App* sub : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (sub->check_name(argv[1])) return "";
    names += (names.empty() ? "" : ", ") + sub->get_name();
  }
  return "unknown command '" + std::string(argv[1]) + "' (the commands are " + names +
         "; lcsim --help)";
}

}  // namespace
}  // namespace lcsim::cli

int main(int argc, char** argv) {
  using lcsim::Status;
  lcsim::cli::install_signal_handlers();
  CLI::App app{"lcsim: linear complementarity systems and unilaterally constrained mechanics"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lcsim 0.1.0");
  for (auto& setup : lcsim::cli::command_registry()) setup(app);
  if (const std::string why = lcsim::cli::unknown_command(app, argc, argv); !why.empty())
    return lcsim::cli::report(Status::kInvalidInput, why.c_str());
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0 (CLI11 prints them); a malformed command
    // line is an input error like any other: one line "lcsim: error: ...",
    // exit 2, not CLI11's own codes (104, 105, ...) nor its two lines.
    if (e.get_exit_code() == 0) return app.exit(e);
    const std::string what = std::string(e.what()) + " (lcsim --help lists the options)";
    return lcsim::cli::report(Status::kInvalidInput, what.c_str());
  } catch (const lcsim::io::InputError& e) {
    return lcsim::cli::report(Status::kInvalidInput, e.what());
  } catch (const std::invalid_argument& e) {
    return lcsim::cli::report(Status::kInvalidInput, e.what());
  } catch (const lcsim::cli::StatusError& e) {
    return lcsim::cli::report(e.status(), e.what());
  } catch (const std::exception& e) {
    std::cerr << "lcsim: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
