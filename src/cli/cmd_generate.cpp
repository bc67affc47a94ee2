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
// The format is dense (lists of rows), so the file grows as N^2: about
// 8 N^2 bytes per matrix (N = 1000: 24 MB). Large benchmarks build the model in
// memory instead.
#include <cstdio>
#include <iostream>
#include <string>

#include "cli/command.hpp"
#include "io/io.hpp"

namespace lcsim::cli {
namespace {

constexpr double kHookGap = 0.5;  // m

struct GenerateArgs {
  int n = 0;
  bool stops = false;
  bool hooks = false;
  std::string out;
};

void put_row(std::string& s, int n, int a, double va, int b = -1, double vb = 0.0, int c = -1,
             double vc = 0.0) {
  s += "    - [";
  for (int j = 0; j < n; ++j) {
    if (j) s += ", ";
    if (j == a)
      s += std::to_string(static_cast<int>(va));
    else if (j == b)
      s += std::to_string(static_cast<int>(vb));
    else if (j == c)
      s += std::to_string(static_cast<int>(vc));
    else
      s += "0";
  }
  s += "]\n";
}

std::string chain_yaml(const GenerateArgs& a) {
  const int n = a.n;
  std::string s = "# lcsim generate chain " + std::to_string(n) + (a.stops ? " --stops" : "") +
                  (a.hooks ? " --hooks" : "") +
                  "\n# Unit masses and springs; stops q_i + 1 >= 0; hooks q_i - q_{i+1} + 0.5 "
                  ">= 0.\nname: chain" +
                  std::to_string(n) + "\nmechanical:\n  M:\n";
  for (int i = 0; i < n; ++i) put_row(s, n, i, 1.0);
  s += "  K:\n";
  for (int i = 0; i < n; ++i) {
    const double d = (i + 1 < n ? 1.0 : 0.0) + 1.0;  // wall or left neighbour, right neighbour
    put_row(s, n, i, d, i > 0 ? i - 1 : -1, -1.0, i + 1 < n ? i + 1 : -1, -1.0);
  }
  std::string g, names;
  int k = 0;
  if (a.stops || a.hooks) {
    s += "  E:\n";
    if (a.stops)
      for (int i = 0; i < n; ++i, ++k) {
        put_row(s, n, i, 1.0);
        g += std::string(k ? ", " : "") + "1";
        names += std::string(k ? ", " : "") + "stop" + std::to_string(i);
      }
    if (a.hooks)
      for (int i = 0; i + 1 < n; ++i, ++k) {
        put_row(s, n, i, 1.0, i + 1, -1.0);
        char buf[32];
        std::snprintf(buf, sizeof buf, "%s%.17g", k ? ", " : "", kHookGap);
        g += buf;
        names += std::string(k ? ", " : "") + "hook" + std::to_string(i);
      }
    s += "  g: [" + g + "]\n  constraints: [" + names + "]\n";
  }
  s += "initial: [";
  for (int i = 0; i < n; ++i) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%s%.17g", i ? ", " : "", 0.1 * (i % 3));
    s += buf;
  }
  for (int i = 0; i < n; ++i) s += ", -1";
  s += "]\nt_end: 10\n";
  return s;
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
