// Issue 13 through the command line: `sweep --impact` with reference laws and
// warnings per row, `analyze` on the sets of constraints that can be active
// together, `impacts --map --closed`.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcsim/app/impact_map.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_i13_stderr", ".txt"));
}

fs::path write_model(const std::string& text) {
  const fs::path p = lcsim::cli_test::private_temp("lcsim_i13_model", ".yaml");
  std::ofstream(p) << text;
  return p;
}

// The coupled stops of tests/app/test_sweep.cpp (e = 0.9 and 0.1, both closing at t = 0).
const char* const kCoupled =
    "name: coupled_stops\nmechanical:\n  M: [[2, 1], [1, 2]]\n  K: [[0, 0], [0, 4]]\n"
    "  E: [[1, 0], [0, 1]]\n  g: [0, 0.5]\n  f: [-1, 0]\n  restitution: [0.9, 0.1]\n"
    "  constraints: [stop1, stop2]\ninitial: [0, -0.5, -1, -2]\nt_end: 2\n";

// Each row names its reference law and carries the warnings: backward Euler
// warns once per run that it ignores restitution (time_stepping.cpp) and is
// measured against the inelastic law, whose exact run warns nothing;
// Moreau–Jean warns nothing and is measured against moreau-restitution.
TEST(SweepCommand, RowsNameTheirReferenceLawAndCarryWarnings) {
  const fs::path p = write_model(kCoupled);
  const CliRun r = lcsim("sweep '" + p.string() +
                         "' --methods event,euler,moreau-jean --h 1e-2 --repeat 1 --json "
                         "--impact moreau-restitution");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["impact"], "moreau-restitution");
  ASSERT_EQ(j["rows"].size(), 3u);
  const nlohmann::json &ev = j["rows"][0], &eu = j["rows"][1], &mj = j["rows"][2];
  EXPECT_EQ(ev["reference_law"], "moreau-restitution");
  EXPECT_EQ(eu["reference_law"], "inelastic");
  EXPECT_EQ(eu["reference_inelastic"], true);
  EXPECT_EQ(eu["warnings"], 1);
  EXPECT_EQ(eu["first_warning"], "backward Euler ignores restitution: every impact is inelastic");
  EXPECT_EQ(eu["reference_warnings"], 0);
  EXPECT_EQ(mj["reference_law"], "moreau-restitution");
  EXPECT_EQ(mj["warnings"], 0);
  EXPECT_TRUE(mj["first_warning"].is_null());
  // Two distinct laws, so two exact reference runs.
  EXPECT_EQ(j["references"].size(), 2u);
  // The text output names the laws and the warning.
  const CliRun t = lcsim("sweep '" + p.string() +
                         "' --methods euler --h 1e-2 --repeat 1 --impact moreau-restitution");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NE(t.out.find("inelastic"), std::string::npos) << t.out;
  EXPECT_NE(t.out.find("warnings: 1 (backward Euler ignores restitution"), std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("nearest exact law is inelastic"), std::string::npos) << t.out;
}

// With --impact moreau the event row is Newton's law, whose jump at t = 0 is
// not admissible (one warning, named); Moreau–Jean's reference stays its own
// law, which warns nothing.
TEST(SweepCommand, TheReferenceWarningsTravelWithTheRow) {
  const fs::path p = write_model(kCoupled);
  const CliRun r =
      lcsim("sweep '" + p.string() +
            "' --methods event,moreau-jean --h 1e-2 --repeat 1 --json --impact moreau");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["rows"].size(), 2u);
  EXPECT_EQ(j["rows"][0]["warnings"], 1);
  EXPECT_NE(j["rows"][0]["first_warning"].get<std::string>().find("non-admissible jump"),
            std::string::npos);
  EXPECT_EQ(j["rows"][1]["reference_law"], "moreau-restitution");
  EXPECT_EQ(j["rows"][1]["reference_warnings"], 0);
}

// A refused row is drawn, not dropped: the plot is written and the row's
// status says why (backward Euler on the triple integrator, rho = 3).
TEST(SweepCommand, PlotWithARefusedRow) {
  const fs::path png = lcsim::cli_test::private_temp("lcsim_i13_wp", ".png");
  const CliRun r = lcsim("sweep '" + kRobots +
                         "triple_integrator.yaml' --methods event,euler --h 1e-2 --repeat 1 "
                         "--json --plot '" +
                         png.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["rows"][1]["status"].get<std::string>().rfind("refused: ", 0), 0u);
  EXPECT_GT(fs::file_size(png), 1000u);
  fs::remove(png);
}

TEST(SweepCommand, UnknownImpactLawExitsTwo) {
  const CliRun r = lcsim("sweep '" + kRobots + "two_carts.yaml' --impact bounce --h 1e-2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("impact: unknown impact law"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("bounce"), std::string::npos) << r.err;
  EXPECT_EQ(r.out, "");
}

// arm_gripper_scene: rows shoulder_lower, shoulder_upper, elbow_lower,
// elbow_upper (E = [1 0; -1 0; 0 1; 0 -1], rank 2 of 4). Each joint's two
// limits never close together (lower < upper), so the maximal sets are one
// limit per joint, four of them; each E_J is the identity up to signs, so
// E_J M^-1 E_J' is M^-1 up to a sign similarity: positive definite, a
// P-matrix, and Theorem 3.6.3 applies on every set.
TEST(AnalyzeCommand, JointLimitsAreNotDependentConstraints) {
  const CliRun r = lcsim("analyze '" + kRobots + "arm_gripper_scene.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["E_rank"], 2);
  const nlohmann::json& c = j["coactive"];
  ASSERT_EQ(c["maximal_sets"].size(), 4u);
  EXPECT_EQ(c["maximal_sets"][0]["constraints"],
            nlohmann::json::parse(R"(["shoulder_lower", "elbow_lower"])"));
  EXPECT_EQ(c["exclusive_pairs"],
            nlohmann::json::parse(
                R"([["shoulder_lower", "shoulder_upper"], ["elbow_lower", "elbow_upper"]])"));
  EXPECT_EQ(c["dependent"], false);
  EXPECT_EQ(c["delassus_p_matrix"], true);
  EXPECT_EQ(c["locally_well_posed"], true);
  // On all four rows at once the old verdicts stand (a state closing both
  // limits of a joint would be needed): the Delassus matrix is singular.
  EXPECT_EQ(j["delassus_p_matrix"], false);
  EXPECT_EQ(j["well_posedness"]["locally_well_posed"], false);
  for (const auto& n : j["notes"])
    EXPECT_EQ(n.get<std::string>().find("dependent constraints"), std::string::npos) << n;
  const CliRun t = lcsim("analyze '" + kRobots + "arm_gripper_scene.yaml'");
  ASSERT_EQ(t.exit_code, 0) << t.err;
  EXPECT_NE(t.out.find("(rows that cannot be active together, not dependent constraints)"),
            std::string::npos)
      << t.out;
  EXPECT_NE(t.out.find("on these sets: Delassus P-matrix yes, Theorem 3.6.3 applies"),
            std::string::npos)
      << t.out;
}

// double_pendulum_scene: one stop (shoulder_lower), E of rank 1: one set.
TEST(AnalyzeCommand, SingleStopSceneHasOneSet) {
  const CliRun r = lcsim("analyze '" + kRobots + "double_pendulum_scene.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  const nlohmann::json& c = j["coactive"];
  ASSERT_EQ(c["maximal_sets"].size(), 1u);
  EXPECT_EQ(c["maximal_sets"][0]["constraints"], nlohmann::json::parse(R"(["shoulder_lower"])"));
  EXPECT_EQ(c["locally_well_posed"], true);
  EXPECT_EQ(c["delassus_p_matrix"], true);
  EXPECT_EQ(j["well_posedness"]["locally_well_posed"], true);
}

// A repeated stop is truly dependent and can close: still reported so.
TEST(AnalyzeCommand, RepeatedStopStaysDependent) {
  const fs::path p =
      write_model("name: dep\nmechanical:\n  M: [[1, 0], [0, 1]]\n  E: [[1, 0], [1, 0]]\n");
  const CliRun r = lcsim("analyze '" + p.string() + "' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["coactive"]["dependent"], true);
  EXPECT_EQ(j["coactive"]["delassus_p_matrix"], false);
  EXPECT_EQ(j["coactive"]["locally_well_posed"], false);
}

// --closed on the arm scene: q placed on shoulder_upper and elbow_lower
// (without --x0), the map over their approach velocities. Each cell is
// checked against app::impact_map called directly with the same spec (the
// library the command prints), and the corner cell by hand: both contacts
// separating (rates +1, +1) is unconstrained with unchanged rates.
TEST(ImpactsCommand, ClosedMapMatchesTheLibraryAndTheFreeCorner) {
  const CliRun r = lcsim("impacts '" + kRobots +
                         "arm_gripper_scene.yaml' --map=-1:1:3,-1:1:3 --closed shoulder_upper,2");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::istringstream in(r.out);
  std::string line;
  std::getline(in, line);
  EXPECT_EQ(line, "rate_1,rate_2,mode,rate_1+,rate_2+");
  std::vector<std::string> lines;
  while (std::getline(in, line)) lines.push_back(line);
  ASSERT_EQ(lines.size(), 9u);
  EXPECT_EQ(lines[8], "1,1,unconstrained,1,1");
  const lcsim::mech::Model model = lcsim::scene::load_model(kRobots + "arm_gripper_scene.yaml");
  const auto& m = *model.mechanical;
  lcsim::app::ImpactMapSpec spec;
  spec.closed = {1, 2};
  spec.q = lcsim::app::close_contacts(m, Eigen::VectorXd::Zero(2), spec.closed, "--closed");
  spec.v0 = Eigen::VectorXd::Zero(2);
  spec.axis1 = spec.axis2 = lcsim::app::parse_map_range("-1:1:3", "--map");
  const lcsim::app::ImpactMap map = lcsim::app::impact_map(m, spec);
  EXPECT_EQ(lcsim::app::impact_map_csv(m, map), r.out);
  // Both approaching (-1, -1) at e = 0 (this scene): the rates after are
  // non-negative, and zero where an impulse acts (complementarity).
  ASSERT_EQ(map.cells.size(), 9u);
  const auto& c0 = map.cells[0];
  EXPECT_GE(c0.after(0), -1e-12);
  EXPECT_GE(c0.after(1), -1e-12);
  // 1e-12: rates of size 1 after one small LCP solve (rounding ~1e-16).
  ASSERT_FALSE(c0.mode.empty());
  for (int i : c0.mode) EXPECT_NEAR(c0.after(i == 1 ? 0 : 1), 0.0, 1e-12) << i;
}

TEST(ImpactsCommand, ClosedRefusesAnUnknownNameAndAnOpenGap) {
  const std::string arm = "impacts '" + kRobots + "arm_gripper_scene.yaml' --map=-1:1:3,-1:1:3";
  CliRun r = lcsim(arm + " --closed shoulder_upper,wrist_lower");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--closed: unknown constraint 'wrist_lower'"), std::string::npos) << r.err;
  // --x0 with the shoulder at 0.2: shoulder_upper's gap is 1.5 - 0.2 = 1.3.
  r = lcsim(arm + " --closed shoulder_upper,elbow_lower --x0 0.2,-2,0,0");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'shoulder_upper' (1) is open at q = (0.2, -2) (gap = 1.3)"),
            std::string::npos)
      << r.err;
  r = lcsim("impacts '" + kRobots + "arm_gripper_scene.yaml' --closed 0,2");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--closed: only with --map"), std::string::npos) << r.err;
}

}  // namespace
