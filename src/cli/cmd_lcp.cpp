// `lcsim lcp FILE.yaml [--solver NAME] [--json]`: solve one LCP
// w = M z + q, 0 <= z ⟂ w >= 0 (eq. (3.11)-(3.12)) read from a file.
// Exit 0 when solved, 3 (NumericalError) when the solver did not solve it,
// 2 on bad input.
#include <cstdio>
#include <iostream>
#include <lcsim/core/format.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <memory>
#include <string>

#include "cli/command.hpp"

namespace lcsim::cli {
namespace {

struct LcpArgs {
  std::string file;
  std::string solver = "lemke";
  bool json = false;
};

std::string vector_text(const Eigen::VectorXd& v) { return "[" + number_list(v, 17) + "]"; }

// Iterative solvers count sweeps, pivoting ones count pivots.
bool counts_iterations(const std::string& solver, const lcp::Result& r) {
  return solver == "pgs" || (r.pivots == 0 && r.iterations > 0);
}

void run_lcp(const LcpArgs& args) {
  const io::LcpProblem p = io::load_lcp(args.file);
  const std::unique_ptr<lcp::Solver> solver = lcp::make_solver(args.solver);
  const lcp::Result r = solver->solve(p.M, p.q, lcp::Options{});
  const bool iterative = counts_iterations(solver->name(), r);
  if (args.json) {
    nlohmann::json j;
    j["solver"] = solver->name();
    j["status"] = std::string(lcp::to_string(r.status, "solved"));
    j["z"] = io::to_json(r.z);
    j["w"] = io::to_json(r.w);
    j["residual"] = r.residual;
    if (iterative)
      j["iterations"] = r.iterations;
    else
      j["pivots"] = r.pivots;
    if (!r.message.empty()) j["message"] = r.message;
    std::cout << j.dump(2) << "\n";
  } else {
    const std::string res = format_number(r.residual, 3);
    std::cout << "solver:   " << solver->name() << "\n"
              << "status:   " << lcp::to_string(r.status, "solved") << "\n"
              << "z =       " << vector_text(r.z) << "\n"
              << "w =       " << vector_text(r.w) << "\n"
              << "residual: " << res << "  (||min(z, w)||_inf)\n"
              << (iterative ? "iterations: " + std::to_string(r.iterations)
                            : "pivots:   " + std::to_string(r.pivots))
              << "\n";
    if (!r.message.empty()) std::cout << "message:  " << r.message << "\n";
  }
  std::cout.flush();
  check_status(r.status, args.file + ": LCP not solved by " + solver->name() + ": " +
                             std::string(lcp::to_string(r.status, "solved")) +
                             (r.message.empty() ? "" : " (" + r.message + ")"));
}

}  // namespace

LCSIM_REGISTER_COMMAND([](CLI::App& app) {
  auto args = std::make_shared<LcpArgs>();
  CLI::App* cmd = app.add_subcommand(
      "lcp", "Solve the LCP w = M z + q, 0 <= z _|_ w >= 0 given by `M` and `q` in a YAML file");
  cmd->add_option("file", args->file, "LCP file (YAML with M: list of rows, q: list)")->required();
  cmd->add_option("--solver", args->solver,
                  "LCP solver (default lemke): " + name_list(lcp::solver_names()));
  cmd->add_flag("--json", args->json, "print one JSON object");
  cmd->callback([args] { run_lcp(*args); });
});

}  // namespace lcsim::cli
