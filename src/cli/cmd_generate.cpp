// `lcsim generate chain N [--stops] [--hooks] [--out FILE]`: writes the YAML
// model (docs/model-format.md) of N carts in a row, the scaling benchmark of
// bench/bench_chain.cpp and tests/sim/test_scale.cpp.
//
// Carts i = 0..N-1 (coordinate q_i, m), unit masses (kg), unit springs (N/m)
// between neighbours and from cart 0 to the wall, so
// K = tridiag(-1, 2, -1) with K(N-1, N-1) = 1.
// --stops: one stop per cart at q_i = -1, the constraint q_i + 1 >= 0
//   (E = I, g = 1); the start positions q_i = 0.1 (i mod 3) >= 0 are feasible.
// --hooks: one hook per neighbouring pair, q_i - q_{i+1} + 0.5 >= 0 (cart i+1
//   at most 0.5 m ahead of cart i); the start has q_{i+1} - q_i <= 0.1.
// Initial state x_i = 0.1 (i mod 3) m, v_i = -1 m/s; t_end = 10 s.
// The model is mech::chain_model, written by io::model_yaml: matrices by
// their non-zeros, so the file grows as N (N = 10000: about 0.5 MB).
#include <cstdio>
#include <iostream>
#include <lcsim/io/io.hpp>
#include <string>

#include "cli/command.hpp"

namespace lcsim::cli {
namespace {

struct GenerateArgs {
  int n = 0;
  bool stops = false;
  bool hooks = false;
  std::string out;
};

std::string chain_yaml(const GenerateArgs& a) {
  const std::string header = "lcsim generate chain " + std::to_string(a.n) +
                             (a.stops ? " --stops" : "") + (a.hooks ? " --hooks" : "") +
                             "\nUnit masses and springs; stops q_i + 1 >= 0; hooks q_i - "
                             "q_{i+1} + 0.5 >= 0.";
  return io::model_yaml(mech::chain_model({a.n, a.stops, a.hooks, true}), header);
}

void setup(CLI::App& app) {
  auto* gen = app.add_subcommand("generate", "Write a generated benchmark model as YAML");
  gen->require_subcommand(1);
  auto args = std::make_shared<GenerateArgs>();
  auto* ch = gen->add_subcommand(
      "chain",
      "N carts in a row: unit masses, unit springs between neighbours and to the wall; "
      "x_i = 0.1 (i mod 3), v_i = -1, t_end = 10");
  ch->add_option("N", args->n, "number of carts")->required()->check(CLI::Range(1, 100000));
  ch->add_flag("--stops", args->stops, "a stop per cart: q_i + 1 >= 0");
  ch->add_flag("--hooks", args->hooks, "a hook per neighbouring pair: q_i - q_{i+1} + 0.5 >= 0");
  ch->add_option("--out", args->out, "output file (default: standard output)");
  ch->callback([args]() {
    const std::string yaml = chain_yaml(*args);
    if (args->out.empty())
      std::cout << yaml;
    else
      io::write_file_atomic(args->out, yaml);
  });
}

LCSIM_REGISTER_COMMAND(setup);

}  // namespace
}  // namespace lcsim::cli
