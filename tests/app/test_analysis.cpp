// The analysis report (app::analysis_report, `lcsim analyze` and Python's
// `lcsim.analyze`): the thesis's numbers of small models computed by hand,
// the summary against the full report, the text naming the option `full`
// (never a flag), and the scene's linear ranges.
#include <gtest/gtest.h>

#include <lcsim/app/analysis.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::app {
namespace {

using nlohmann::json;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

scene::LoadedModel robot(const std::string& file) {
  return scene::load_model_and_scene(kRobots + file);
}

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// Example 3.8.3's carts: M = I, E = [[1, 0], [1, -1]], so E M^-1 E' =
// [[1, 1], [1, 2]] (exact in floating point), a P-matrix (minors 1, 2, 1).
TEST(AnalysisReport, TwoCartsWithTheHookByHand) {
  const AnalysisReport r = analysis_report(robot("two_carts_hook.yaml"));
  const json& j = r.json;
  EXPECT_EQ(j["kind"], "mechanical");
  EXPECT_EQ(j["dofs"], 2);
  EXPECT_EQ(j["state_size"], 4);
  EXPECT_EQ(j["lcs_state_size"], 5);  // x = (q, v, 1), (3.65)
  EXPECT_EQ(j["E_rank"], 2);
  EXPECT_EQ(j["M_min_eigenvalue"], 1.0);  // M = I: exact
  EXPECT_EQ(j["M_max_eigenvalue"], 1.0);
  EXPECT_EQ(j["delassus"], json::parse("[[1.0, 1.0], [1.0, 2.0]]"));
  EXPECT_EQ(j["delassus_p_matrix"], true);
  EXPECT_EQ(j["constraint_names"], json::parse(R"(["stop", "hook"])"));
  EXPECT_EQ(j["well_posedness"]["k"], 2);
  EXPECT_EQ(j["well_posedness"]["n"], 5);
  EXPECT_TRUE(j["linear_ranges"].is_null());  // a matrix model, not a scene
  EXPECT_EQ(j["left_out"], json::array());
  EXPECT_EQ(j["full"], false);
  EXPECT_TRUE(contains(r.text, "rank E:      2 of 2\n")) << r.text;
  EXPECT_TRUE(contains(r.text, "  P-matrix: yes  (unique impulse)\n")) << r.text;
}

// The triple integrator x''' = u, y = x1: leading indices rho = eta = 3
// (C A^2 B = 1 is the first non-zero Markov parameter), so backward Euler is
// at risk (Example 7.3.3).
TEST(AnalysisReport, TripleIntegratorIsAnLcs) {
  const AnalysisReport r = analysis_report(robot("triple_integrator.yaml"));
  const json& j = r.json;
  EXPECT_EQ(j["kind"], "lcs");
  EXPECT_EQ(j["lcs_augmented"], false);
  EXPECT_EQ(j["B_rank"], 1);
  EXPECT_EQ(j["C_rank"], 1);
  EXPECT_FALSE(j.contains("E_rank"));
  EXPECT_EQ(j["well_posedness"]["rho"], json::parse("[3]"));
  EXPECT_EQ(j["well_posedness"]["eta"], json::parse("[3]"));
  EXPECT_EQ(j["well_posedness"]["row_coefficients"], json::parse("[[1.0]]"));
  EXPECT_EQ(j["well_posedness"]["backward_euler_risky"], true);
  EXPECT_TRUE(contains(r.text, "backward Euler (§7.3): RISKY")) << r.text;
}

// 21 carts with a stop each: E = I, M = I, so the Delassus matrix is I (21 x
// 21 = 441 numbers, over the summary's 400) and so is each leading
// coefficient matrix; the summary leaves them out and says how to get them.
TEST(AnalysisReport, SummaryLeavesOutWhatFullPrints) {
  mech::ChainSpec spec;
  spec.n = 21;
  const scene::LoadedModel chain{mech::chain_model(spec), std::nullopt};
  const AnalysisReport s = analysis_report(chain);
  EXPECT_TRUE(s.json["delassus"].is_null());
  EXPECT_EQ(s.json["delassus_p_matrix"], true);
  EXPECT_EQ(s.json["left_out"],
            json::parse(R"(["delassus", "well_posedness.markov", "well_posedness.row_coefficients",
                            "well_posedness.column_coefficients"])"));
  EXPECT_TRUE(contains(s.text, "(21 x 21: left out of the summary; full = true prints it)"))
      << s.text;
  EXPECT_TRUE(contains(s.text, "left out of this summary (full = true prints them): delassus, "))
      << s.text;
  EXPECT_FALSE(contains(s.text, "--")) << s.text;  // the library names no flag

  const AnalysisReport f = analysis_report(chain, {.full = true});
  EXPECT_EQ(f.json["full"], true);
  EXPECT_EQ(f.json["left_out"], json::array());
  const Eigen::MatrixXd I = Eigen::MatrixXd::Identity(21, 21);
  EXPECT_EQ(f.json["delassus"], io::to_json(I));
  EXPECT_EQ(f.json["well_posedness"]["markov"].size(), 44u);  // H^0..H^n, n = 2 * 21 + 1
  EXPECT_FALSE(contains(f.text, "left out"));
}

TEST(AnalysisReport, SceneLinearRangesUseTheThreshold) {
  const scene::LoadedModel scene = robot("two_carts_scene.yaml");
  const AnalysisReport r = analysis_report(scene, {.linearisation_threshold = 0.05});
  EXPECT_EQ(r.json["linearisation_threshold"], 0.05);
  ASSERT_TRUE(r.json["linear_ranges"].is_array());
  EXPECT_FALSE(r.json["linear_ranges"].empty());
  EXPECT_TRUE(contains(r.text, "linear model: error <= 5 % ")) << r.text;
}

TEST(AnalysisReport, ABadThresholdIsAnInputError) {
  const scene::LoadedModel scene = robot("two_carts_scene.yaml");
  for (const double t : {-1.0, 0.0, std::numeric_limits<double>::infinity()}) {
    try {
      (void)analysis_report(scene, {.linearisation_threshold = t});
      ADD_FAILURE() << t << " accepted";
    } catch (const io::InputError& e) {
      EXPECT_TRUE(contains(e.what(), "linearisation_threshold must be a finite number > 0"))
          << e.what();
    }
  }
}

}  // namespace
}  // namespace lcsim::app
