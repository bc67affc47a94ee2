// Inputs through the command line (docs/inputs.md): a shipped model with a
// PWL force lists its breakpoints as `schedule` events, and bad inputs are
// refused with one line naming the file and the entry, exit 2, nothing
// written.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;
using lcsim::cli_test::count_lines;

fs::path model_file(const std::string& text) {
  const fs::path p = lcsim::cli_test::private_temp("inputs", ".yaml");
  std::ofstream(p) << text;
  return p;
}

CliRun lcsim_run(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args, lcsim::cli_test::private_temp("inputs_err", ".txt"));
}

TEST(InputsCli, BreakpointsAreScheduleEvents) {
  const CliRun r =
      lcsim_run("simulate " + std::string(LCSIM_SOURCE_DIR) + "/robots/pwl_lift.yaml --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The release at 30 t / 2 = 9.81 (t = 0.654 s), then the two breakpoints.
  const auto release = r.out.find("\"release\"");
  const auto first = r.out.find("\"schedule\"");
  ASSERT_NE(release, std::string::npos) << r.out;
  ASSERT_NE(first, std::string::npos) << r.out;
  EXPECT_LT(release, first);
  EXPECT_NE(r.out.find("\"schedule\"", first + 1), std::string::npos);
  EXPECT_NE(r.out.find("breakpoint of input 'lift'"), std::string::npos);
}

// analyze states the augmented state with the inputs' exosystem (x = (q, v,
// 1, w): N = 1, so 2N + 1 = 3 plus the PWL's two states p, r), not 2N + 1.
TEST(InputsCli, AnalyzeNamesTheExosystemStates) {
  const CliRun r = lcsim_run("analyze " + std::string(LCSIM_SOURCE_DIR) + "/robots/pwl_lift.yaml");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("x = (q, v, 1, w) of size 5, w the inputs' exosystem states (lift: 2)"),
            std::string::npos)
      << r.out;
}

// One line, exit 2, naming each of `names`; no output file.
void expect_refused(const std::string& model, std::initializer_list<std::string> names) {
  const fs::path f = model_file(model);
  const fs::path out = lcsim::cli_test::private_temp("inputs_out", ".csv");
  const CliRun r = lcsim_run("simulate '" + f.string() + "' --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find(f.string()), std::string::npos) << r.err;
  for (const auto& n : names) EXPECT_NE(r.err.find(n), std::string::npos) << n << " in " << r.err;
  EXPECT_FALSE(fs::exists(out));
  fs::remove(f);
}

TEST(InputsCli, BadInputsAreRefused) {
  const std::string mech =
      "mechanical:\n  M: [[1, 0], [0, 1]]\n  force_inputs: [{input: push, gain: [1, 0]}]\n"
      "t_end: 1\n";
  expect_refused("inputs:\n  - {name: push, kind: pwl, points: [[0, 0], [2, 1], [1, 2]]}\n" + mech,
                 {"inputs[0]", "'push'", "times decrease (1 s after 2 s)"});
  expect_refused("inputs:\n  - {name: pull, kind: constant, value: 1}\n" + mech,
                 {"mechanical.force_inputs[0].input", "no input named 'push'", "pull"});
  expect_refused(
      "inputs:\n  - {name: push, kind: ramp, slope: 1}\nmechanical:\n  M: [[1, 0], [0, 1]]\n"
      "  force_inputs: [{input: push, gain: [1]}]\n",
      {"mechanical.force_inputs[0].gain", "expected 2 entries", "got 1"});
  expect_refused("inputs:\n  - {name: push, kind: square, value: 1}\n" + mech,
                 {"inputs[0].kind", "unknown kind 'square'"});
  expect_refused("inputs: {name: push}\n" + mech, {"inputs", "expected a list"});
}

}  // namespace
