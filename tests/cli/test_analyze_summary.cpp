// `lcsim analyze` at robot scale (issue 24, item 7): a summary by default,
// the full report with --full, and plain words for what was not judged when
// the sets that can be active together are not enumerated.
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;

CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_analyze_stderr", ".txt"));
}

// `lcsim generate chain 33 --stops --hooks`: 33 carts, 33 stops and 32
// hooks, k = 65 > 64 (the enumeration bound), rank E = 33. Written once.
const fs::path& chain() {
  static const fs::path p = [] {
    const fs::path f = fs::path(::testing::TempDir()) / "analyze_chain33.yaml";
    const CliRun g = lcsim("generate chain 33 --stops --hooks --out '" + f.string() + "'");
    EXPECT_EQ(g.exit_code, 0) << g.err;
    return f;
  }();
  return p;
}

// The summary holds no matrix of the 65 x 65 report (the full text is ~3.5
// MB: 68 Markov parameters of 65 x 65 at 12 characters a number); what is
// left is the verdicts, the names and the sentences, a few kB. 32 kB bounds
// it with room for longer names, far below any one matrix left out (50 kB).
constexpr std::size_t kSummaryBytes = 32 * 1024;

TEST(AnalyzeSummary, RobotScaleTextIsASummaryThatSaysWhatWasNotJudged) {
  const CliRun r = lcsim("analyze '" + chain().string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(r.out.size(), kSummaryBytes);
  EXPECT_NE(r.out.find("rank E:      33 of 65  (not judged: dependent constraints or rows that "
                       "cannot be active together"),
            std::string::npos)
      << r.out;
  // Before: "rank E: 33 of 65  (dependent constraints)" for rows that are
  // merely a cart's stop and the hooks that cannot all close together.
  EXPECT_EQ(r.out.find("(dependent constraints)"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("dependent constraints: E"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("has rank 33 < 65: dependent constraints or rows that cannot be active "
                       "together (e.g. both limits of one joint), not told apart (the sets that "
                       "can be active together are enumerated for k <= 64 only)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("not judged:\n  - the sets of constraints that can be active together were "
                       "not enumerated (k = 65 > 64)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("rank E = 33 < k = 65 was not explained"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("(68 matrices of 65 x 65: left out of the summary; --full prints them)"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("left out of this summary (--full prints them): delassus, "
                       "well_posedness.markov, well_posedness.row_coefficients, "
                       "well_posedness.column_coefficients"),
            std::string::npos)
      << r.out;
  EXPECT_NE(r.out.find("D there is its feedthrough in y = C x + D u"), std::string::npos) << r.out;
}

TEST(AnalyzeSummary, JsonSummaryNamesWhatItLeftOutAndFullHasIt) {
  const CliRun r = lcsim("analyze '" + chain().string() + "' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(r.out.size(), kSummaryBytes);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["full"], false);
  EXPECT_TRUE(j["well_posedness"]["markov"].is_null());
  EXPECT_TRUE(j["delassus"].is_null());
  EXPECT_EQ(j["left_out"], nlohmann::json::parse(
                               R"(["delassus", "well_posedness.markov",
                                   "well_posedness.row_coefficients",
                                   "well_posedness.column_coefficients"])"));
  ASSERT_EQ(j["not_judged"].size(), 2u);
  EXPECT_TRUE(j["coactive"].is_null());
  // The verdicts stay.
  EXPECT_TRUE(j["delassus_p_matrix"].is_boolean());
  EXPECT_TRUE(j["well_posedness"]["locally_well_posed"].is_boolean());

  const CliRun f = lcsim("analyze '" + chain().string() + "' --json --full");
  ASSERT_EQ(f.exit_code, 0) << f.err;
  const auto jf = nlohmann::json::parse(f.out);
  EXPECT_EQ(jf["full"], true);
  EXPECT_EQ(jf["left_out"].size(), 0u);
  ASSERT_EQ(jf["well_posedness"]["markov"].size(), 68u);  // H^0..H^n, n = 2 * 33 + 1
  EXPECT_EQ(jf["well_posedness"]["markov"][0].size(), 65u);
  EXPECT_EQ(jf["delassus"].size(), 65u);
}

}  // namespace
