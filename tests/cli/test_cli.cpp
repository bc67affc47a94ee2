// The `lcsim lcp` and `lcsim analyze` commands, run as a user would: through
// the shell, checking exit codes, stdout and the one-line error on stderr.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

using lcsim::cli_test::CliRun;
using lcsim::cli_test::count_lines;

// Runs `lcsim <args>`; stderr through a file private to this test process
// (a shared name raced between tests that ctest runs in parallel).
CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_cli_stderr", ".txt"));
}

fs::path write_temp(const std::string& name, const std::string& text) {
  const fs::path p = fs::path(::testing::TempDir()) / name;
  std::ofstream(p) << text;
  return p;
}

// robots/lcp_example.yaml: M = [[4,1,0],[1,4,1],[0,1,4]], q = (-8,-1,-4).
// By hand (in the file): z = (2, 0, 1), w = (0, 2, 0); M is a P-matrix, so
// this is the only solution. Tolerance 1e-14 for the pivoting solvers: a few
// eliminations on entries of size <= 8 with pivots >= 4 (|M^{-1}| <= 1/3
// on the active block) err by a few eps times |q| ≈ 2e-15; 1e-14 leaves a
// margin of five.
TEST(LcpCommand, JsonGivesTheHandDerivedSolution) {
  for (const std::string solver : {"lemke", "pivot", "enum"}) {
    const CliRun r = lcsim("lcp '" + kRobots + "lcp_example.yaml' --json --solver " + solver);
    ASSERT_EQ(r.exit_code, 0) << solver << ": " << r.err;
    EXPECT_EQ(r.err, "");
    const nlohmann::json j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["solver"], solver);
    EXPECT_EQ(j["status"], "solved");
    const std::vector<double> z = j["z"], w = j["w"];
    const std::vector<double> z_exact{2, 0, 1}, w_exact{0, 2, 0};
    ASSERT_EQ(z.size(), 3u);
    ASSERT_EQ(w.size(), 3u);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(z[i], z_exact[i], 1e-14) << solver << " z" << i;
      EXPECT_NEAR(w[i], w_exact[i], 1e-14) << solver << " w" << i;
    }
    EXPECT_LE(j["residual"].get<double>(), 1e-14);
    // Pivoting solvers count pivots; the enumeration counts the bases it tried.
    EXPECT_TRUE(j.contains(solver == "enum" ? "iterations" : "pivots")) << j.dump();
    EXPECT_FALSE(j.contains("pivots") && j.contains("iterations")) << j.dump();
  }
}

TEST(LcpCommand, ProjectedGaussSeidelReportsIterations) {
  const CliRun r = lcsim("lcp '" + kRobots + "lcp_example.yaml' --json --solver pgs");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "solved");
  EXPECT_TRUE(j.contains("iterations"));
  // PGS stops at residual <= 1e-12 (1 + ||q||_inf) = 9e-12; the error in z is
  // at most ||(M_AA)^{-1}|| (<= 1/3 here) times that, so 1e-11 bounds it.
  const std::vector<double> z = j["z"];
  EXPECT_NEAR(z[0], 2.0, 1e-11);
  EXPECT_NEAR(z[1], 0.0, 1e-11);
  EXPECT_NEAR(z[2], 1.0, 1e-11);
}

TEST(LcpCommand, HumanReadable) {
  const CliRun r = lcsim("lcp '" + kRobots + "lcp_example.yaml'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("status:   solved"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("z =       ["), std::string::npos) << r.out;
}

TEST(LcpCommand, BadFileExitsTwoWithOneLineNamingTheFile) {
  const fs::path bad = write_temp("lcsim_bad_lcp.yaml", "M: [[1, 0], [0, 1]]\nq: [1, 2, 3]\n");
  const CliRun r = lcsim("lcp '" + bad.string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err,
            "lcsim: error: " + bad.string() + ": q: expected 2 entries (k, from M) (got 3)\n");

  const CliRun missing = lcsim("lcp /nonexistent/lcp.yaml");
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_EQ(missing.err, "lcsim: error: /nonexistent/lcp.yaml: cannot open: no such file\n");

  const fs::path yaml = write_temp("lcsim_malformed_lcp.yaml", "M: [[1]\nq: [1]\n");
  const CliRun malformed = lcsim("lcp '" + yaml.string() + "'");
  EXPECT_EQ(malformed.exit_code, 2);
  EXPECT_EQ(count_lines(malformed.err), 1);
  EXPECT_NE(malformed.err.find(yaml.string() + ": malformed YAML at line "), std::string::npos)
      << malformed.err;
}

TEST(LcpCommand, UnknownSolverExitsTwo) {
  const CliRun r = lcsim("lcp '" + kRobots + "lcp_example.yaml' --solver simplex");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("simplex"), std::string::npos) << r.err;
}

TEST(LcpCommand, UnsolvableLcpExitsThree) {
  // w = -z - 1 >= 0 needs z <= -1 < 0: infeasible, Lemke ends on a ray.
  const fs::path p = write_temp("lcsim_infeasible_lcp.yaml", "M: [[-1]]\nq: [-1]\n");
  const CliRun r = lcsim("lcp '" + p.string() + "' --json");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_EQ(count_lines(r.err), 1) << r.err;
  EXPECT_EQ(r.err.rfind("lcsim: numerical failure: " + p.string() + ": LCP not solved by lemke", 0),
            0u)
      << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);  // the result is still printed
  EXPECT_NE(j["status"], "solved");
}

TEST(AnalyzeCommand, TwoCartsJson) {
  const CliRun r = lcsim("analyze '" + kRobots + "two_carts.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["name"], "two_carts");
  EXPECT_EQ(j["kind"], "mechanical");
  EXPECT_EQ(j["dofs"], 2);
  EXPECT_EQ(j["constraints"], 1);
  EXPECT_EQ(j["state_size"], 4);
  EXPECT_EQ(j["lcs_state_size"], 5);  // (q, v, 1): augmented for f and g
  EXPECT_EQ(j["lcs_augmented"], true);
  EXPECT_EQ(j["E_rank"], 1);
  // M = I: eigenvalues exactly 1; Delassus E M^{-1} E' = [[1]] exactly.
  EXPECT_EQ(j["M_min_eigenvalue"].get<double>(), 1.0);
  EXPECT_EQ(j["delassus"], nlohmann::json::parse("[[1.0]]"));
  EXPECT_EQ(j["delassus_p_matrix"], true);
  // y = x1: y' = v1, y'' = -2x1 + x2 + u, so rho = 2 with coefficient 1
  // (Markov parameters 0, 0, 1, 0, -2, ... of §3.7).
  const nlohmann::json& w = j["well_posedness"];
  EXPECT_EQ(w["rho"], nlohmann::json::parse("[2]"));
  EXPECT_EQ(w["eta"], nlohmann::json::parse("[2]"));
  EXPECT_EQ(w["row_coefficients"], nlohmann::json::parse("[[1.0]]"));
  EXPECT_EQ(w["row_p_matrix"], true);
  EXPECT_EQ(w["locally_well_posed"], true);
  EXPECT_EQ(w["backward_euler_risky"], false);
  ASSERT_GE(w["markov"].size(), 3u);
  EXPECT_EQ(w["markov"][2], nlohmann::json::parse("[[1.0]]"));
}

TEST(AnalyzeCommand, TripleIntegratorIsFlaggedForBackwardEuler) {
  // Example 7.3.3: y''' = u, relative degree 3.
  const CliRun r = lcsim("analyze '" + kRobots + "triple_integrator.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["kind"], "lcs");
  EXPECT_EQ(j["lcs_augmented"], false);
  EXPECT_EQ(j["well_posedness"]["rho"], nlohmann::json::parse("[3]"));
  EXPECT_EQ(j["well_posedness"]["backward_euler_risky"], true);
}

TEST(AnalyzeCommand, HumanReadableMentionsAugmentationAndDependentConstraints) {
  const fs::path p = write_temp("lcsim_dependent.yaml",
                                "name: dep\nmechanical:\n  M: [[1, 0], [0, 1]]\n"
                                "  E: [[1, 0], [1, 0]]\n");
  const CliRun r = lcsim("analyze '" + p.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("augmented with a constant state"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("size 2N+1 = 5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("dependent constraints"), std::string::npos) << r.out;
  // Delassus [[1, 1], [1, 1]] is singular, so not a P-matrix.
  EXPECT_NE(r.out.find("P-matrix: no"), std::string::npos) << r.out;
}

TEST(AnalyzeCommand, BadModelExitsTwoWithOneLineNamingTheFile) {
  const fs::path p =
      write_temp("lcsim_bad_model.yaml", "name: bad\nmechanical:\n  M: [[1, 2], [1, 3]]\n");
  const CliRun r = lcsim("analyze '" + p.string() + "'");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_EQ(r.err, "lcsim: error: " + p.string() +
                       ": mechanical.M: not symmetric (M[0][1] = 2 but M[1][0] = 1)\n");
}

// Progress on stderr: --progress writes a line at the start and the 100 %
// line at the end (a short run: nothing in between), each on its own line;
// stdout is untouched; without a terminal and without --progress, nothing.
TEST(SimulateCommand, ProgressLinesOnStderr) {
  const std::string model = std::string("'") + LCSIM_SOURCE_DIR + "/robots/two_carts.yaml'";
  const CliRun r = lcsim("simulate " + model + " --method moreau-jean --h 1e-3 --json --progress");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.rfind("lcsim: t = 0 of 3 (0 %)", 0), 0u) << r.err;
  EXPECT_NE(r.err.find("\nlcsim: t = 3 of 3 (100 %)"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.back(), '\n');
  EXPECT_TRUE(nlohmann::json::accept(r.out)) << r.out;
  const CliRun quiet = lcsim("simulate " + model + " --json");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_EQ(quiet.err.find("lcsim: t ="), std::string::npos) << quiet.err;
  EXPECT_NE(lcsim("simulate " + model + " --progress --no-progress").exit_code, 0);
}

}  // namespace
