// `lcsim simulate` prints the library's messages with its own flags (the
// library names fields: app::run_model, scene::check_linearisation_threshold),
// and keeps its order: nothing runs, nor draws progress, before an input
// error found by its checks.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;
using lcsim::cli_test::private_temp;
using lcsim::cli_test::run_lcsim;

const std::string kTwoCarts = "'" + std::string(LCSIM_SOURCE_DIR) + "/robots/two_carts.yaml'";

TEST(SimulateFlags, ThresholdMessageNamesTheFlag) {
  const CliRun r = run_lcsim("simulate " + kTwoCarts + " --linearisation-threshold nan",
                             private_temp("threshold", ".err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "lcsim: error: --linearisation-threshold must be a finite number > 0 (got nan)\n");
}

// --progress draws its first line when the run starts, after --out is open:
// an unwritable --out is the only line.
TEST(SimulateFlags, UnwritableOutBeforeAnyProgress) {
  const fs::path out = private_temp("no_such_folder", "") / "x.csv";
  const CliRun r = run_lcsim("simulate " + kTwoCarts + " --progress --out '" + out.string() + "'",
                             private_temp("out", ".err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "lcsim: error: " + out.string() + ": cannot write: No such file or directory\n");
}

}  // namespace
