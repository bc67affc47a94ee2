// The `lcsim` command line. Input errors are exceptions caught once here and
// printed as one clear line with a non-zero exit (DESIGN.md, Conventions).
#include <CLI/CLI.hpp>
#include <iostream>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/io/io.hpp>

#include "cli/command.hpp"

namespace lcsim::cli {
std::vector<CommandSetup>& command_registry() {
  static std::vector<CommandSetup> registry;
  return registry;
}
}  // namespace lcsim::cli

int main(int argc, char** argv) {
  CLI::App app{"lcsim: linear complementarity systems and unilaterally constrained mechanics"};
  app.require_subcommand(1);
  app.set_version_flag("--version", "lcsim 0.1.0");
  for (auto& setup : lcsim::cli::command_registry()) setup(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  } catch (const lcsim::io::InputError& e) {
    std::cerr << "lcsim: error: " << e.what() << "\n";
    return 2;
  } catch (const std::invalid_argument& e) {
    std::cerr << "lcsim: error: " << e.what() << "\n";
    return 2;
  } catch (const lcsim::cli::NumericalError& e) {
    std::cerr << "lcsim: numerical failure: " << e.what() << "\n";
    return 3;
  } catch (const std::exception& e) {
    std::cerr << "lcsim: error: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
