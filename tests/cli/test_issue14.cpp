// Issue 14 through the command line: the trajectory CSV streamed to disk is
// the CSV of the same run held in memory; SIGINT and SIGTERM leave neither a
// temporary nor a half-written output; help lists every registered method,
// solver and impact law; a scene without `initial` starts at q0 at rest.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <thread>
#include <vector>

#include "support/run_lcsim.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;
using lcsim::cli_test::slurp;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

std::string quote(const fs::path& p) { return "'" + p.string() + "'"; }

// A fresh empty folder private to the test process.
fs::path fresh_dir(const std::string& stem) {
  const fs::path d = lcsim::cli_test::private_temp(stem, "");
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

CliRun lcsim(const fs::path& dir, const std::string& args) {
  return lcsim::cli_test::run_lcsim(args, dir / "stderr.txt");
}

// What `simulate --out` streams is byte for byte io::trajectory_csv of the
// same run with its samples kept in memory (the format before streaming).
void expect_streamed_equals_in_memory(const std::string& model_file, const std::string& method,
                                      double dt_out) {
  SCOPED_TRACE(model_file + " " + method);
  const fs::path d = fresh_dir("stream");
  const lcsim::mech::Model model = lcsim::scene::load_model(kRobots + model_file);
  lcsim::sim::Options opt;
  opt.dt_out = dt_out;
  opt.t_end = model.t_end;  // the model's horizon, as the command takes it
  const auto tr = lcsim::sim::make_integrator(method)->run(model, model.initial, opt);
  ASSERT_EQ(tr.status, lcsim::sim::RunStatus::kCompleted) << tr.message;
  ASSERT_FALSE(tr.samples.empty());
  const std::string expected = lcsim::io::trajectory_csv(model, tr);
  const fs::path csv = d / "t.csv";
  const CliRun r = lcsim(d, "simulate " + quote(kRobots + model_file) + " --method " + method +
                                " --dt-out " + std::to_string(dt_out) + " --out " + quote(csv));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(slurp(csv), expected);
  int files = 0;
  for (const auto& e : fs::directory_iterator(d)) files += e.path().filename() != "stderr.txt";
  EXPECT_EQ(files, 1);  // the CSV, no temporary beside it
  fs::remove_all(d);
}

TEST(Issue14, StreamedCsvIsTheInMemoryCsv) {
  expect_streamed_equals_in_memory("two_carts.yaml", "moreau-jean", 0.0);
  expect_streamed_equals_in_memory("two_carts.yaml", "event", 0.01);
  expect_streamed_equals_in_memory("two_carts_hook.yaml", "event", 0.0);
  expect_streamed_equals_in_memory("two_carts.yaml", "euler", 0.05);
}

// Starts lcsim with `args` (no shell), stdout and stderr to /dev/null.
pid_t spawn_lcsim(std::vector<std::string> args) {
  args.insert(args.begin(), LCSIM_BINARY);
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&fa, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  pid_t pid = -1;
  const int err = ::posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  return err == 0 ? pid : -1;
}

// The temporary beside `dir`/x.csv once it holds data, or "" after `limit`.
fs::path wait_for_temporary(const fs::path& dir, std::chrono::seconds limit) {
  const auto until = std::chrono::steady_clock::now() + limit;
  while (std::chrono::steady_clock::now() < until) {
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(dir, ec))
      if (e.path().filename().string().rfind(".x.csv.tmp-", 0) == 0 &&
          fs::file_size(e.path(), ec) > 0 && !ec)
        return e.path();
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return {};
}

// A long streamed run (5e6 Moreau–Jean steps, every one a CSV row, about
// 0.5 GB) stopped by `signo` once its temporary holds data: the child exits
// 128 + signo and leaves nothing in its folder.
void expect_signal_leaves_nothing(int signo) {
  SCOPED_TRACE(signo);
  const fs::path d = fresh_dir("signal" + std::to_string(signo));
  const pid_t pid =
      spawn_lcsim({"simulate", kRobots + "two_carts.yaml", "--method", "moreau-jean", "--h", "1e-8",
                   "--t-end", "0.05", "--no-progress", "--out", (d / "x.csv").string()});
  ASSERT_GT(pid, 0);
  const fs::path tmp = wait_for_temporary(d, std::chrono::seconds(60));
  EXPECT_FALSE(tmp.empty()) << "no temporary appeared";
  ASSERT_EQ(::kill(pid, signo), 0);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << status;
  EXPECT_EQ(WEXITSTATUS(status), 128 + signo);
  EXPECT_TRUE(fs::is_empty(d)) << (fs::is_empty(d) ? ""
                                                   : fs::directory_iterator(d)->path().string());
  fs::remove_all(d);
}

TEST(Issue14, SigtermLeavesNoTemporaryAndNoOutput) { expect_signal_leaves_nothing(SIGTERM); }
TEST(Issue14, SigintLeavesNoTemporaryAndNoOutput) { expect_signal_leaves_nothing(SIGINT); }

// Help is built from the registries: every name this test program sees
// registered (the core ones; it links neither Bullet nor Ipopt) and the
// Bullet integrator, which the lcsim executable links.
TEST(Issue14, HelpListsEveryRegisteredName) {
  const fs::path d = fresh_dir("help");
  const CliRun sim = lcsim(d, "simulate --help");
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  for (const auto& n : lcsim::sim::integrator_names())
    EXPECT_NE(sim.out.find(n), std::string::npos) << n;
  EXPECT_NE(sim.out.find("bullet"), std::string::npos);
  for (const auto& n : lcsim::lcp::solver_names())
    EXPECT_NE(sim.out.find(n), std::string::npos) << n;
  for (const auto& n : lcsim::impact::impact_law_names())
    EXPECT_NE(sim.out.find(n), std::string::npos) << n;
  EXPECT_NE(sim.out.find("--max-output"), std::string::npos);
  const CliRun sweep = lcsim(d, "sweep --help");
  ASSERT_EQ(sweep.exit_code, 0) << sweep.err;
  for (const auto& n : lcsim::lcp::solver_names())
    EXPECT_NE(sweep.out.find(n), std::string::npos) << n;
  EXPECT_NE(sweep.out.find("bullet"), std::string::npos);
  const CliRun lcp = lcsim(d, "lcp --help");
  ASSERT_EQ(lcp.exit_code, 0) << lcp.err;
  for (const auto& n : lcsim::lcp::solver_names())
    EXPECT_NE(lcp.out.find(n), std::string::npos) << n;
  fs::remove_all(d);
}

// A scene without `initial` starts at q0 at rest (docs/model-format.md):
// two free carts (no springs, no stops, gravity across the rails) stay where
// q0 puts them. Were the start the zero vector they would stay at 0. The
// exact method propagates (q0, 0) by e^{At} with A = [[0, I], [0, 0]];
// 1e-12 allows the rounding of the matrix exponential.
TEST(Issue14, SceneWithoutInitialStartsAtQ0AtRest) {
  const fs::path d = fresh_dir("scene");
  const fs::path scene = d / "free_carts.yaml";
  std::ofstream(scene) << "urdf: " << kRobots << "two_carts.urdf\n"
                       << "joints:\n  - {name: x1, stops: []}\n  - {name: x2, stops: []}\n"
                       << "q0: {x1: 0.25, x2: -0.5}\nt_end: 1\n";
  const CliRun r = lcsim(d, "simulate " + quote(scene) + " --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  const std::vector<double> x = j.at("final_state");
  ASSERT_EQ(x.size(), 4u);
  EXPECT_NEAR(x[0], 0.25, 1e-12);
  EXPECT_NEAR(x[1], -0.5, 1e-12);
  EXPECT_NEAR(x[2], 0.0, 1e-12);
  EXPECT_NEAR(x[3], 0.0, 1e-12);
  fs::remove_all(d);
}

// The command line only parses: the library's checks decide, and their
// status picks the exit code. An infeasible start refused by the sweep's
// reference run is input (2), not numerical trouble; a step longer than the
// horizon and an unusable Bullet setting are input too. A run's warnings
// come out per kind, counted (backward Euler on the bouncing ball ignores
// its e = 0.5 once per run: one warning of one kind).
TEST(Issue14, LibraryChecksDecideTheExitCode) {
  const fs::path d = fresh_dir("checks");
  const std::string carts = quote(kRobots + "two_carts.yaml");
  const CliRun sweep = lcsim(d, "sweep " + carts + " --x0 -0.5,0,0,0 --h 1e-2 --repeat 1");
  EXPECT_EQ(sweep.exit_code, 2) << sweep.err;
  EXPECT_NE(sweep.err.find("constraint 'stop' is violated at t = 0"), std::string::npos)
      << sweep.err;
  EXPECT_NE(sweep.err.find("mech::project_feasible"), std::string::npos) << sweep.err;
  const CliRun infeasible = lcsim(d, "simulate " + carts + " --x0 -0.5,0,0,0");
  EXPECT_EQ(infeasible.exit_code, 2) << infeasible.err;
  EXPECT_NE(infeasible.err.find("hint: --project"), std::string::npos) << infeasible.err;
  const CliRun h = lcsim(d, "simulate " + carts + " --method moreau-jean --t-end 0.5 --h 0.6");
  EXPECT_EQ(h.exit_code, 2) << h.err;
  EXPECT_NE(h.err.find("step h = 0.6 exceeds t_end = 0.5"), std::string::npos) << h.err;
  // A value that does not parse is input too (CLI11 alone would exit 104/105).
  for (const char* bad : {" --h abc", " --t-end", " --no-such-flag"}) {
    const CliRun r = lcsim(d, "simulate " + carts + bad);
    EXPECT_EQ(r.exit_code, 2) << bad << ": " << r.err;
  }
  const CliRun erp = lcsim(d, "compare " + carts + " --t-end 0.1 --stop-erp 0");
  EXPECT_EQ(erp.exit_code, 2) << erp.err;
  EXPECT_NE(erp.err.find("stop_erp must be in (0, 1] (got 0)"), std::string::npos) << erp.err;
  const CliRun euler =
      lcsim(d, "simulate " + quote(kRobots + "ball.yaml") + " --method euler --json");
  ASSERT_EQ(euler.exit_code, 0) << euler.err;
  const auto w = nlohmann::json::parse(euler.out).at("warnings");
  ASSERT_EQ(w.size(), 1u) << w.dump();
  EXPECT_EQ(w[0].at("kind"), "restitution-ignored");
  EXPECT_EQ(w[0].at("count"), 1);
  fs::remove_all(d);
}

}  // namespace
