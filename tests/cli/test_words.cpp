// The words a user reads (issue 24, item 8), through the command line: the
// impact laws' names and the alias "moreau", the text event list naming its
// contacts, the --map syntax in --help, the empty-file message, and the
// library's option names printed as the command's flags.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args, lcsim::cli_test::private_temp("words_err", ".txt"));
}

bool has(const std::string& text, const std::string& what) {
  return text.find(what) != std::string::npos;
}

const std::string kAliasNote = "'moreau' is an alias of 'newton'";

TEST(Words, ImpactsRunsTheAliasUnderItsLawsNameWithANote) {
  const std::string model = kRobots + "two_carts_hook.yaml";
  const CliRun t = lcsim("impacts " + model + " --rules moreau,newton");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_TRUE(has(t.out, "note: " + kAliasNote)) << t.out;
  EXPECT_TRUE(has(t.out, "\nnewton ")) << t.out;
  EXPECT_FALSE(has(t.out, "\nmoreau ")) << t.out;  // one row, by the law's name
  const CliRun j = lcsim("impacts " + model + " --rules moreau --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto doc = nlohmann::json::parse(j.out);
  EXPECT_TRUE(doc["rules"].contains("newton")) << j.out;
  EXPECT_FALSE(doc["rules"].contains("moreau")) << j.out;
  ASSERT_TRUE(doc.contains("notes")) << j.out;
  EXPECT_TRUE(has(doc["notes"][0].get<std::string>(), kAliasNote)) << j.out;
  // Example 3.8.3 with the model's e = 0: the hook alone, v+ = (1/2, 1/2).
  EXPECT_EQ(doc["rules"]["newton"]["mode"], nlohmann::json::array({"hook"}));
}

TEST(Words, SimulateWithTheAliasSaysWhatItMeans) {
  const CliRun t =
      lcsim("simulate " + kRobots + "two_carts_hook.yaml --t-end 0.1 --impact moreau --json");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_EQ(nlohmann::json::parse(t.out)["impact_law"], "newton") << t.out;
  EXPECT_TRUE(has(t.err, "lcsim: note: " + kAliasNote)) << t.err;
  const CliRun plain = lcsim("simulate " + kRobots + "two_carts_hook.yaml --t-end 0.1");
  ASSERT_EQ(plain.exit_code, 0) << plain.err;
  EXPECT_FALSE(has(plain.err, "alias")) << plain.err;
}

// Example 3.8.3: the impact at t = 0 leaves the hook alone active.
TEST(Words, TextEventListNamesItsContacts) {
  const CliRun t = lcsim("simulate " + kRobots + "two_carts_hook.yaml --t-end 0.1");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_TRUE(has(t.out, "mode {1 hook}")) << t.out;
}

TEST(Words, ImpactsHelpGivesTheMapSyntax) {
  const CliRun t = lcsim("impacts --help");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_TRUE(has(t.out, "lo:hi[:n]")) << t.out;
  EXPECT_TRUE(has(t.out, "default 41")) << t.out;
}

TEST(Words, EmptyFileMessageMentionsScenes) {
  const fs::path f = lcsim::cli_test::private_temp("empty", ".yaml");
  std::ofstream(f).close();
  const CliRun t = lcsim("simulate '" + f.string() + "'");
  fs::remove(f);
  EXPECT_EQ(t.exit_code, 2);
  EXPECT_TRUE(has(t.err, "empty file")) << t.err;
  EXPECT_TRUE(has(t.err, "scene: `urdf:`")) << t.err;
}

// The run refuses dt_out < 0 and max_output_bytes <= 0 with the library's
// field names; the command prints its own flags.
TEST(Words, SimulateNamesItsFlagsNotTheLibrarysFields) {
  const std::string model = kRobots + "two_carts.yaml";
  const CliRun dt = lcsim("simulate " + model + " --dt-out -1");
  EXPECT_EQ(dt.exit_code, 2);
  EXPECT_TRUE(has(dt.err, "--dt-out must be a finite number >= 0")) << dt.err;
  EXPECT_FALSE(has(dt.err, "dt_out")) << dt.err;
  const CliRun mo = lcsim("simulate " + model + " --max-output 0");
  EXPECT_EQ(mo.exit_code, 2);
  EXPECT_TRUE(has(mo.err, "--max-output must be > 0")) << mo.err;
  const fs::path csv = lcsim::cli_test::private_temp("big", ".csv");
  const CliRun big = lcsim("simulate " + model + " --dt-out 1e-9 --out '" + csv.string() + "'");
  EXPECT_FALSE(fs::exists(csv));
  EXPECT_EQ(big.exit_code, 2);
  EXPECT_TRUE(has(big.err, "more than --max-output = ")) << big.err;
  EXPECT_TRUE(has(big.err, ": raise --dt-out, or --max-output")) << big.err;
  EXPECT_FALSE(has(big.err, "max_output_bytes")) << big.err;
  const CliRun h = lcsim("simulate " + model + " --h 0.01");
  EXPECT_EQ(h.exit_code, 2);
  EXPECT_TRUE(has(h.err, "does not use --h (got 0.01)")) << h.err;
}

}  // namespace
