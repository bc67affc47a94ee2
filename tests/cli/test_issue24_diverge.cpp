// Issue 24 through the command line: a diverged run is never "completed"
// (item 1) in `simulate`, `compare`, `sweep` and `study`; a sweep keeps the
// other rows when a method refuses the model (item 4) and says what its
// error measures (item 9).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;

CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args, lcsim::cli_test::private_temp("lcsim_i24", ".txt"));
}

bool has(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Explicit dampers in Bullet's rb6 scene: 2 / lambda_max(M^-1 D) = 6.28e-3 s
// (tests/bullet/test_divergence.cpp derives it), so h = 1e-2 diverges.
fs::path damped_model() {
  // A folder private to this test process (ctest runs tests in parallel).
  const fs::path dir = lcsim::cli_test::private_temp("lcsim_i24", "");
  fs::create_directories(dir);
  const fs::path p = dir / "damped_pair.yaml";
  std::ofstream(p) << "name: damped_pair\nmechanical:\n  M: [[1, 0], [0, 2]]\n"
                      "  D: [[300, -100], [-100, 100]]\n  K: [[10, 0], [0, 10]]\n"
                      "  E: [[1, 0]]\n  g: [1]\n  constraints: [stop]\n  coordinates: [a, b]\n"
                      "initial: [0.1, 0, 0, 1]\nt_end: 2\n";
  return p;
}

TEST(Issue24Cli, ADivergedBulletRunExitsThreeInSimulateAndCompare) {
  const std::string model = "'" + damped_model().string() + "'";
  const CliRun sim = lcsim("simulate " + model + " --method bullet --h 1e-2");
  EXPECT_EQ(sim.exit_code, 3) << sim.err;
  EXPECT_TRUE(has(sim.err, "numerical failure: bullet: diverged at t = ")) << sim.err;
  EXPECT_TRUE(has(sim.err, "stable only for h <= 2 / lambda_max(M^-1 D) = 0.00627719 s"))
      << sim.err;
  const CliRun cmp = lcsim("compare " + model + " --h 1e-2");
  EXPECT_EQ(cmp.exit_code, 3) << cmp.err;
  EXPECT_TRUE(has(cmp.err, "the Bullet run failed: bullet: diverged")) << cmp.err;
  // Below the bound both complete.
  EXPECT_EQ(lcsim("simulate " + model + " --method bullet --h 1e-3").exit_code, 0);
}

// The sweep: the diverged row is a failure with no error (null in JSON, not
// a point at 1e30), the other rows are measured, the sweep's own exit is 0
// (failed runs are rows, as in a study), and the JSON says what the errors
// measure.
TEST(Issue24Cli, SweepShowsTheDivergedRowAsFailed) {
  const CliRun r = lcsim("sweep '" + damped_model().string() +
                         "' --methods event,bullet --h 1e-2,1e-3 --repeat 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 3u);
  const auto& diverged = j["rows"][1];
  EXPECT_EQ(diverged["h"], 1e-2);
  EXPECT_EQ(diverged["status"].get<std::string>().rfind("failed: bullet: diverged at t = ", 0), 0u)
      << diverged;
  EXPECT_TRUE(diverged["error_max"].is_null()) << diverged;
  EXPECT_TRUE(diverged["error_final"].is_null()) << diverged;
  EXPECT_EQ(j["rows"][2]["status"], "completed");
  EXPECT_TRUE(j["rows"][2]["error_max"].is_number());
  EXPECT_TRUE(has(j["error_measures"].get<std::string>(), "whole run")) << j;
}

// A study row whose run diverged says "numerical failure", with the message.
TEST(Issue24Cli, AStudyRowThatDivergedIsANumericalFailure) {
  const fs::path model = damped_model();
  const fs::path study = model.parent_path() / "damped_study.yaml";
  const fs::path out = model.parent_path() / "damped_study.csv";
  std::ofstream(study) << "model: damped_pair.yaml\nmethod: bullet\nreference: none\n"
                          "axes:\n  - h: [1e-2, 1e-3]\n";
  fs::remove(out);
  fs::remove(out.string() + ".journal");
  const CliRun r = lcsim("study '" + study.string() + "' --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;  // failed runs are rows, not an exit code
  std::ifstream in(out);
  std::string header, row0, row1;
  std::getline(in, header);
  std::getline(in, row0);
  std::getline(in, row1);
  EXPECT_TRUE(has(row0, "numerical failure")) << header << "\n" << row0;
  EXPECT_TRUE(has(row0, "diverged at t = ")) << row0;
  EXPECT_TRUE(has(row1, "completed")) << row1;
}

// Item 4 through the CLI: a method that refuses the model is a refused row
// and the table, JSON and exit 0 remain (it exited 2 after nine runs).
TEST(Issue24Cli, SweepKeepsItsTableWhenAMethodRefuses) {
  const fs::path p = lcsim::cli_test::private_temp("lcsim_i24_nondiagonal", ".yaml");
  std::ofstream(p) << "name: nondiagonal\nmechanical:\n  M: [[1, 0.1], [0.1, 1]]\n"
                      "  K: [[1, 0], [0, 1]]\n  E: [[1, 0]]\n  g: [0.5]\n"
                      "initial: [0.2, 0, 0, 0]\nt_end: 1\n";
  const CliRun r = lcsim("sweep '" + p.string() +
                         "' --methods event,moreau-jean,bullet --h 1e-2 --repeat 1 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 3u);
  EXPECT_EQ(j["rows"][1]["status"], "completed");
  const std::string refused = j["rows"][2]["status"];
  EXPECT_EQ(refused.rfind("refused: ", 0), 0u) << refused;
  EXPECT_TRUE(has(refused, "M(1, 0) = 0.1")) << refused;
}

}  // namespace
