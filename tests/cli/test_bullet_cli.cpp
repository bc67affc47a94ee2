// `lcsim simulate --method bullet`, `lcsim compare` and `lcsim sweep --methods
// bullet` on what Bullet can and cannot express, run as a user would.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <nlohmann/json.hpp>
#include <string>

#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

lcsim::cli_test::CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_bullet_stderr", ".txt"));
}

// A matrix model with M = [[1, 0.1], [0.1, 1]]: no URDF, so no multibody, and
// not one rigid body per coordinate. Refused the same way by every command:
// exit 2 (an input error), one line, 0-based "M(1, 0)".
TEST(BulletCli, NonDiagonalMatrixModelExitsTwoEverywhere) {
  const fs::path p = fs::path(::testing::TempDir()) / "lcsim_nondiagonal_m.yaml";
  std::ofstream(p) << "name: nondiagonal\nmechanical:\n  M: [[1, 0.1], [0.1, 1]]\n"
                      "  K: [[1, 0], [0, 1]]\n  E: [[1, 0]]\n  g: [0]\n"
                      "initial: [1, 0, 0, 0]\nt_end: 1\n";
  for (const std::string& cmd :
       {"simulate '" + p.string() + "' --method bullet", "compare '" + p.string() + "'",
        "sweep '" + p.string() + "' --methods bullet --h 1e-2"}) {
    const auto r = lcsim(cmd);
    EXPECT_EQ(r.exit_code, 2) << cmd << "\n" << r.err;
    EXPECT_EQ(lcsim::cli_test::count_lines(r.err), 1) << cmd << "\n" << r.err;
    EXPECT_NE(r.err.find("M(1, 0) = 0.1"), std::string::npos) << cmd << "\n" << r.err;
  }
}

// Every shipped URDF scene runs beside Bullet: compare and sweep exit 0, compare
// names the
// scene Bullet built (the multibody, or rb6 for the hook scene) and warns
// about what it drops.
TEST(BulletCli, CompareRunsOnEveryShippedScene) {
  for (const char* scene : {"double_pendulum_scene", "arm_gripper_scene", "prismatic_chain_scene",
                            "two_carts_scene", "two_carts_hook_scene"}) {
    const auto r = lcsim("compare '" + kRobots + scene + ".yaml' --h 1e-2 --json");
    ASSERT_EQ(r.exit_code, 0) << scene << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    const std::string solver = j["bullet_solver"];
    const bool multibody = std::string(scene) != "two_carts_hook_scene";
    EXPECT_EQ(solver.rfind(multibody ? "btMultiBody from the URDF" : "btSequentialImpulse", 0), 0u)
        << scene << ": " << solver;
    // What Bullet does differently is said on stderr.
    if (std::string(scene) == "double_pendulum_scene") {
      EXPECT_NE(r.err.find("restitution is lost"), std::string::npos) << r.err;
    }
    if (!multibody) {
      EXPECT_NE(r.err.find("constraint 'hook'"), std::string::npos) << r.err;
    }
    const auto sw = lcsim("sweep '" + kRobots + scene + ".yaml' --methods bullet --h 1e-2 --json");
    ASSERT_EQ(sw.exit_code, 0) << scene << ": " << sw.err;
    const auto row = nlohmann::json::parse(sw.out)["rows"][0];
    EXPECT_EQ(row["method"], "bullet") << sw.out;
    EXPECT_EQ(row["status"], "completed") << sw.out;
  }
}

// A block on a rough floor: compare runs Bullet's box beside the exact run
// and prints the stick times and distances of the closed form, the exact
// run and Bullet (the figures are asserted in tests/bullet's
// CompareFrictionBoxBesideTheExactRun; here: what the command prints, and
// that Bullet sticks within a step h = 1e-2 of the exact t* = 0.5097 s). A
// frictional model that is not a block on a floor exits 2 with one line.
TEST(BulletCli, CompareShowsTheFrictionBox) {
  const auto r = lcsim("compare '" + kRobots + "block_on_floor_friction.yaml' --h 1e-2 --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["bullet_scene"], "friction box");
  const double t_exact = j["stop"]["exact run"]["time"], t_bullet = j["stop"]["bullet"]["time"];
  EXPECT_NEAR(t_exact, 2.0 / (0.4 * 9.81), 1e-12);
  EXPECT_GE(t_bullet, t_exact);
  EXPECT_LT(t_bullet, t_exact + 1e-2);
  const auto bad = lcsim("compare '" + kRobots + "incline_friction.yaml'");
  EXPECT_EQ(bad.exit_code, 2) << bad.err;
  EXPECT_EQ(lcsim::cli_test::count_lines(bad.err), 1) << bad.err;
  EXPECT_NE(bad.err.find("not a block on a floor"), std::string::npos) << bad.err;
}

// A massless simulated body (a universal joint's yoke without <inertial>):
// Bullet used to divide by its zero mass and fail with exit 3 ("non-finite
// state at t = 0.001"); now it runs (exit 0) with finite figures.
TEST(BulletCli, CompareRunsWithAMasslessBody) {
  const auto r = lcsim("compare '" + std::string(LCSIM_SOURCE_DIR) +
                       "/tests/bullet/data/massless_yoke_scene.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j["deviation_max"].is_number()) << r.out;
  EXPECT_TRUE(j["error_final"].is_number()) << r.out;
}

// An exact switch Bullet has not made by t_end: the panda's fingers touch the
// object at t = 0.14069 in the exact run, Bullet's a step or more later
// (0.143 at h = 1e-3), after t_end = 0.1412. The text says so instead of
// "t_bullet nan shift nan"; the JSON has null.
TEST(BulletCli, CompareSaysWhenAnExactSwitchHasNoBulletMatch) {
  const std::string scene = "'" + kRobots + "panda_gripper_scene.yaml' --t-end 0.1412";
  const auto r = lcsim("compare " + scene);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("object     activation t_exact 0.140693735    no Bullet switch"),
            std::string::npos)
      << r.out;
  EXPECT_EQ(r.out.find("nan"), std::string::npos) << r.out;
  const auto j = lcsim("compare " + scene + " --json");
  ASSERT_EQ(j.exit_code, 0) << j.err;
  EXPECT_TRUE(nlohmann::json::parse(j.out)["event_shifts"][0]["shift"].is_null()) << j.out;
}

// compare checks a scene's linear model at the exact run's states, as
// simulate does (scene::check_linearisation): the shipped double pendulum's
// exact run (inelastic reference law) swings to q = (-0.151, -0.368), where
// the linear model is off by 2.5 % (simulate's run, with restitution: 4.8 %),
// above the default 1 %; the prismatic chain's model is exact (constant M,
// gravity along fixed axes) and gets no warning.
TEST(BulletCli, CompareWarnsWhenTheLinearModelIsOff) {
  const std::string off = "the linear model is off by";
  const auto pendulum = lcsim("compare '" + kRobots + "double_pendulum_scene.yaml'");
  ASSERT_EQ(pendulum.exit_code, 0) << pendulum.err;
  EXPECT_NE(pendulum.err.find(off), std::string::npos) << pendulum.err;
  const auto simulate = lcsim("simulate '" + kRobots + "double_pendulum_scene.yaml'");
  ASSERT_EQ(simulate.exit_code, 0) << simulate.err;
  EXPECT_NE(simulate.err.find(off), std::string::npos) << simulate.err;
  const auto chain = lcsim("compare '" + kRobots + "prismatic_chain_scene.yaml'");
  ASSERT_EQ(chain.exit_code, 0) << chain.err;
  EXPECT_EQ(chain.err.find(off), std::string::npos) << chain.err;
}

}  // namespace
