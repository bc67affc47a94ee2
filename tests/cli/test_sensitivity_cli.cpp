// `lcsim simulate --sensitivity`: the second CSV beside --out (as many rows
// as the trajectory's, its header naming each derivative, empty fields where
// one does not exist), the losses in the summary, and the library's refusal
// with the flag's name. The numbers are tested in tests/sim/test_sensitivity.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;
using lcsim::cli_test::CliRun;
using lcsim::cli_test::private_temp;
using lcsim::cli_test::run_lcsim;
using lcsim::cli_test::slurp;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

long lines(const std::string& s) { return std::count(s.begin(), s.end(), '\n'); }

TEST(SimulateSensitivity, SecondCsvBesideOut) {
  const fs::path dir = private_temp("sens", "");
  fs::create_directories(dir);
  const fs::path out = dir / "ball.csv";
  const CliRun r = run_lcsim("simulate '" + kRobots + "ball.yaml' --t-end 1.1 --dt-out 0.1 " +
                                 "--sensitivity 'x0,e[ground]' --out '" + out.string() + "'",
                             private_temp("sens", ".err"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string traj = slurp(out), sens = slurp(dir / "ball.sensitivity.csv");
  EXPECT_EQ(lines(sens), lines(traj));
  EXPECT_EQ(sens.substr(0, sens.find('\n')),
            "t,dheight/dx0[0],dv_height/dx0[0],dheight/dx0[1],dv_height/dx0[1],"
            "dheight/de[ground],dv_height/de[ground]");
  EXPECT_NE(r.out.find("sensitivities written to"), std::string::npos);
}

// The ball resting on the ground: no derivative in x0 from t = 0, said in
// the summary and left empty in the CSV.
TEST(SimulateSensitivity, LossInSummaryAndEmptyFields) {
  const fs::path dir = private_temp("rest", "");
  fs::create_directories(dir);
  const fs::path out = dir / "rest.csv";
  const CliRun r = run_lcsim("simulate '" + kRobots + "ball.yaml' --x0 0,0 --t-end 0.5 " +
                                 "--sensitivity x0 --out '" + out.string() + "'",
                             private_temp("rest", ".err"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("sensitivity: no derivative from t = 0 (ground: zero gap at the start"),
            std::string::npos)
      << r.out;
  const std::string sens = slurp(dir / "rest.sensitivity.csv");
  EXPECT_NE(sens.find("\n0,,,,\n"), std::string::npos) << sens;
}

TEST(SimulateSensitivity, RefusalNamesTheFlag) {
  const CliRun r =
      run_lcsim("simulate '" + kRobots + "two_carts.yaml' --method euler " +
                    "--sensitivity 'x0,e[stop]'",  // euler computes x0, not e (no restitution)
                private_temp("refuse", ".err"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "lcsim: error: --sensitivity 'e[stop]': method 'euler' does not compute it "
            "(backward Euler ignores restitution; the method 'event' computes it)\n");
}

}  // namespace
