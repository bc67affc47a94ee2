// `lcsim study` prints the study layer's messages with its own flags: the
// library names the fields of study::ExecOptions (jobs, out, resume), the
// command maps them (src/cli/flag_names.cpp).
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;
using lcsim::cli_test::private_temp;
using lcsim::cli_test::run_lcsim;

const std::string kStudy =
    "'" + std::string(LCSIM_SOURCE_DIR) + "/examples/studies/two_carts_work_precision.yaml'";

TEST(StudyFlags, JobsMessageNamesTheFlag) {
  const fs::path out = private_temp("jobs", ".csv");
  const CliRun r = run_lcsim("study " + kStudy + " --jobs -1 --out '" + out.string() + "'",
                             private_temp("jobs", ".err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "lcsim: error: --jobs: must be >= 0, 0 for one per core (got -1)\n");
  EXPECT_FALSE(fs::exists(out));
}

TEST(StudyFlags, AnEarlierJournalNamesResume) {
  const fs::path out = private_temp("resume", ".csv");
  std::ofstream(out.string() + ".journal") << "";
  const CliRun r = run_lcsim("study " + kStudy + " --out '" + out.string() + "'",
                             private_temp("resume", ".err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "lcsim: error: " + out.string() +
                       ".journal: a journal of an earlier run is here: --resume continues it, or "
                       "remove it to start again\n");
}

}  // namespace
