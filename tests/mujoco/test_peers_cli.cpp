// `lcsim compare --peer bullet|mujoco` on the contact scenes, run as a user
// would (the lcsim program links MuJoCo where this test is built).
// Tolerances as in test_mujoco_contacts.cpp (MuJoCo's resting sink bound
// 2.4e-5 m) and tests/bullet/test_contact_scenes.cpp (Bullet's speculative
// contacts at ERP 0: the rest is exact to the solver's residual, 1e-9).
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>

#include "support/run_lcsim.hpp"
#include "support/slide_scene.hpp"

namespace {

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

lcsim::cli_test::CliRun lcsim(const std::string& args) {
  return lcsim::cli_test::run_lcsim(args,
                                    lcsim::cli_test::private_temp("lcsim_peers_stderr", ".txt"));
}

TEST(PeersCli, CompareBothPeersOnTheDroppedBox) {
  for (const char* peer : {"bullet", "mujoco"}) {
    const auto r = lcsim("compare '" + kRobots + "box_drop_scene.yaml' --peer " + peer + " --json");
    ASSERT_EQ(r.exit_code, 0) << peer << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["peer"], peer);
    const double bound = std::string(peer) == "bullet" ? 1e-9 : 2.4e-5;
    EXPECT_LE(j["error_final"].get<double>(), bound) << peer;
    EXPECT_NE(j["bullet_solver"].get<std::string>().find(
                  std::string(peer) == "bullet" ? "btStaticPlaneShape" : "solref"),
              std::string::npos)
        << j["bullet_solver"];
  }
}

TEST(PeersCli, BulletRunsTheQuadrupedDrop) {
  const auto r = lcsim("compare '" + kRobots + "quadruped_drop_scene.yaml' --json");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LE(nlohmann::json::parse(r.out)["error_final"].get<double>(), 1e-9);
}

TEST(PeersCli, UnknownPeerAndInexpressibleSceneExitTwoWithOneLine) {
  const auto bad = lcsim("compare '" + kRobots + "box_drop_scene.yaml' --peer drake");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("unknown peer 'drake'"), std::string::npos) << bad.err;
  const auto carts = lcsim("compare '" + kRobots + "two_carts_scene.yaml' --peer mujoco");
  EXPECT_EQ(carts.exit_code, 2);
  EXPECT_NE(carts.err.find("not a contact"), std::string::npos) << carts.err;
  EXPECT_EQ(carts.err.find('\n'), carts.err.size() - 1) << carts.err;  // one line
}

// A scene of several bodies (the gripper closing on the box): `compare`
// reports each peer beside the exact run, its settings among them. Bounds:
// Bullet at rest exact to its solver's residual (1e-9), MuJoCo's soft
// contacts' sinks (2.7e-5 m, tests/mujoco/test_mujoco_bodies.cpp).
TEST(PeersCli, CompareBothPeersOnTheGripperClosingOnTheBox) {
  for (const char* peer : {"bullet", "mujoco"}) {
    const auto r =
        lcsim("compare '" + kRobots + "gripper_box_scene.yaml' --peer " + peer + " --json");
    ASSERT_EQ(r.exit_code, 0) << peer << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_EQ(j["peer"], peer);
    EXPECT_LE(j["error_final"].get<double>(), std::string(peer) == "bullet" ? 1e-9 : 2.7e-5)
        << peer;
    EXPECT_NE(j["bullet_solver"].get<std::string>().find(
                  std::string(peer) == "bullet" ? "one btMultiBody per body" : "solref"),
              std::string::npos)
        << j["bullet_solver"];
    EXPECT_EQ(j["event_shifts"].size(), 2u) << peer;  // both tips close, once
  }
}

// A contact scene with friction (the box of tests/support/slide_scene.hpp at
// rest on the floor, mu = 0.3: the exact method runs it, sticking): each
// peer's friction settings are in compare's report, the chosen cone among
// them; the same bounds as the dropped box above (Bullet at rest exact to
// its solver's residual, MuJoCo's resting sink 2.4e-5 m). A bad name is one
// line, exit 2, before anything runs.
TEST(PeersCli, CompareReportsEachPeersFrictionSettings) {
  const auto dir = std::filesystem::path(lcsim::cli_test::private_temp("lcsim_peers_friction", ""));
  const std::string scene = lcsim::test_support::write_slide_scene(dir, 0.0, 0.3, 0.0, 0.2);
  struct Case {
    std::string flags, setting;
    double bound;
  };
  for (const Case& c :
       {Case{"--peer bullet --bullet-friction box", "SOLVER_DISABLE_IMPLICIT_CONE_FRICTION", 1e-9},
        Case{"--peer bullet", "with implicit cone friction", 1e-9},
        Case{"--peer mujoco", "condim 3", 2.4e-5},
        Case{"--peer mujoco --mujoco-cone elliptic", "elliptic cone", 2.4e-5}}) {
    const auto r = lcsim("compare '" + scene + "' " + c.flags + " --json");
    ASSERT_EQ(r.exit_code, 0) << c.flags << ": " << r.err;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NE(j["bullet_solver"].get<std::string>().find(c.setting), std::string::npos)
        << c.flags << ": " << j["bullet_solver"];
    EXPECT_LE(j["error_final"].get<double>(), c.bound) << c.flags;
  }
  const auto bad = lcsim("compare '" + scene + "' --peer mujoco --mujoco-cone circular");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_EQ(bad.err,
            "lcsim: error: mujoco: unknown friction cone 'circular' (pyramidal, elliptic)\n");
  const auto bad2 = lcsim("compare '" + scene + "' --bullet-friction pyramid");
  EXPECT_EQ(bad2.exit_code, 2);
  EXPECT_EQ(bad2.err,
            "lcsim: error: bullet: unknown friction model 'pyramid' (cone, box, one-direction)\n");
  std::filesystem::remove_all(dir);
}

}  // namespace
