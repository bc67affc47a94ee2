// `lcsim impacts` and `lcsim simulate` on the shipped friction models
// (issue 17): the friction impulse and outcome per contact, laws and methods
// without friction refused as input errors (exit 2).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "support/run_lcsim.hpp"

namespace {

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";
using lcsim::cli_test::CliRun;

CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_fric_stderr", ".txt"));
}

TEST(FrictionCli, ImpactsShowTheFrictionImpulseAndOutcome) {
  // robots/spinning_disk_friction.yaml: sticks, P_N = 9, P_T = -8/3 N s.
  const CliRun r = lcsim("impacts '" + kRobots + "spinning_disk_friction.yaml' --rules moreau");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("friction at floor: P_T = -2.66667, stick"), std::string::npos) << r.out;
  const CliRun j = lcsim("impacts '" + kRobots + "spinning_disk_friction.yaml' --rules all --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  const auto doc = nlohmann::json::parse(j.out);
  // "all" on a model with friction: the three laws that handle it.
  EXPECT_EQ(doc["rules"].size(), 3u) << j.out;
  const auto& m = doc["rules"]["newton"];
  // A 3 x 3 LCP with a diagonal mass matrix: a few ulps (1e-12).
  EXPECT_NEAR(m["friction_impulse"][0].get<double>(), -8.0 / 3, 1e-12);
  EXPECT_NEAR(m["impulse"][0].get<double>(), 9.0, 1e-12);
  EXPECT_EQ(m["friction_outcome"]["floor"], "stick");
  EXPECT_EQ(m["painleve"], false);
}

TEST(FrictionCli, LawsAndMethodsWithoutFrictionAreInputErrors) {
  const CliRun r = lcsim("impacts '" + kRobots + "spinning_disk_friction.yaml' --rules flip");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("impact law 'flip' does not handle friction"), std::string::npos) << r.err;
  // 'euler' simulates friction (tests/sim/test_euler_friction.cpp); Bullet
  // takes it at a URDF scene's contacts only, not on a model of matrices.
  const CliRun s = lcsim("simulate '" + kRobots + "block_on_floor_friction.yaml' --method bullet");
  EXPECT_EQ(s.exit_code, 2);
  EXPECT_NE(s.err.find("mechanical.friction on a model that is not a URDF contact scene"),
            std::string::npos)
      << s.err;
}

TEST(FrictionCli, SimulateRecordsTheFrictionForce) {
  // The block on the floor, h = 0.01 (t_end 1): while it slides the mean
  // friction force is -mu m g = -0.4 * 9.81 = -3.924 N, after the stick
  // (t* = 0.51 s) zero. 1e-12 per row: a 2 x 2 model, rounding of a few
  // products of numbers of size 4.
  const auto out = lcsim::cli_test::private_temp("fric_block", ".csv");
  const CliRun r = lcsim("simulate '" + kRobots +
                         "block_on_floor_friction.yaml' --method moreau-jean --h 0.01 --out '" +
                         out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = lcsim::cli_test::slurp(out);
  std::filesystem::remove(out);
  ASSERT_EQ(csv.rfind("t,x,y,v_x,v_y,u_floor,y_floor,ut_floor,fm_floor,mode\n", 0), 0u)
      << csv.substr(0, 80);
  std::istringstream rows(csv);
  std::string line;
  std::getline(rows, line);
  int sliding = 0, stuck = 0, slip_mode = 0, stick_mode = 0;
  double sliding_sum = 0.0;
  while (std::getline(rows, line)) {
    std::vector<std::string> cell;
    std::istringstream cells(line);
    for (std::string c; std::getline(cells, c, ',');) cell.push_back(c);
    ASSERT_GE(cell.size(), 9u) << line;
    const double t = std::stod(cell[0]), ut = cell[7].empty() ? 0.0 : std::stod(cell[7]);
    // The mode column: slip+ while sliding, stick after; "open" in the
    // steps the activation rule below leaves the contact out.
    const std::string& fm = cell[8];
    if (t > 0 && t < 0.5) {
      sliding_sum += ut;
      ++sliding;
      EXPECT_TRUE(fm == "slip+" || fm == "open") << line;
      slip_mode += fm == "slip+";
    }
    if (t > 0.52) {
      EXPECT_NEAR(ut, 0.0, 1e-12) << line;
      ++stuck;
      EXPECT_TRUE(fm == "stick" || fm == "open") << line;
      stick_mode += fm == "stick";
    }
  }
  EXPECT_GT(slip_mode, 20);
  EXPECT_GT(stick_mode, 20);
  // The friction impulse over the sliding steps is -mu m g per step on the
  // whole: a step whose normal rate came out +1e-17 leaves the contact out of
  // the next step's active set (no force there), and the step after catches
  // up with twice the force (the activation rule of moreau_jean.cpp).
  EXPECT_NEAR(sliding_sum, -0.4 * 9.81 * sliding, 1e-12 * sliding * 4);
  EXPECT_GT(sliding, 40);
  EXPECT_GT(stuck, 40);
}

// Backward Euler on the block (issue 27, tests/sim/test_euler_friction.cpp):
// the CSV carries the friction columns, and `lcsim sweep` runs the three
// methods. Euler's final position errs by -h v0/2 + r, 0 <= r <= mu g h^2/8
// (v0 = 2 m/s, mu g = 3.924 m/s^2; the derivation is the sim test's); the
// sweep's error_final is its absolute value (the final velocity is zero in
// both runs), so it lies in [h - mu g h^2/8, h] for v0/2 = 1 (1e-15:
// rounding of positions of size 0.5).
TEST(FrictionCli, EulerSimulatesAndSweepsTheBlock) {
  const auto out = lcsim::cli_test::private_temp("fric_euler", ".csv");
  const CliRun r =
      lcsim("simulate '" + kRobots +
            "block_on_floor_friction.yaml' --method euler --h 0.01 --out '" + out.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string csv = lcsim::cli_test::slurp(out);
  std::filesystem::remove(out);
  EXPECT_EQ(csv.rfind("t,x,y,v_x,v_y,u_floor,y_floor,ut_floor,fm_floor,mode\n", 0), 0u)
      << csv.substr(0, 80);
  EXPECT_NE(csv.find(",slip+,"), std::string::npos);
  EXPECT_NE(csv.find(",stick,"), std::string::npos);
  const CliRun s = lcsim("sweep '" + kRobots +
                         "block_on_floor_friction.yaml' --methods event,euler,moreau-jean "
                         "--h 1e-2,1e-3 --repeat 1 --json");
  ASSERT_EQ(s.exit_code, 0) << s.err;
  const auto doc = nlohmann::json::parse(s.out);
  int euler_rows = 0;
  for (const auto& row : doc["rows"]) {
    EXPECT_EQ(row["status"], "completed") << row.dump();
    if (row["method"] != "euler") continue;
    ++euler_rows;
    const double h = row["h"].get<double>(), err = row["error_final"].get<double>();
    EXPECT_LE(err, h + 1e-15) << h;
    EXPECT_GE(err, h - 3.924 * h * h / 8 - 1e-15) << h;
  }
  EXPECT_EQ(euler_rows, 2);
  EXPECT_EQ(doc["rows"].size(), 5u);
}

TEST(FrictionCli, FrictionlessImpactsPrintNoFriction) {
  const CliRun r = lcsim("impacts '" + kRobots + "two_carts_hook.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out.find("friction"), std::string::npos) << r.out;
}

}  // namespace
