// `lcsim compare --peer bullet|mujoco` on the contact scenes, run as a user
// would (the lcsim program links MuJoCo where this test is built).
// Tolerances as in test_mujoco_contacts.cpp (MuJoCo's resting sink bound
// 2.4e-5 m) and tests/bullet/test_contact_scenes.cpp (Bullet's speculative
// contacts at ERP 0: the rest is exact to the solver's residual, 1e-9).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

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

// `compare --peer-out PATH` writes the peer's samples as a trajectory CSV
// with the friction multipliers of each contact along its two tangents
// (ut_<contact>, ut2_<contact>): on the box sliding along t1 (the scene of
// tests/support/slide_scene.hpp, psi = 0), every row where the box slides
// and touches (v_box.y > 0.05 m/s, normal forces above 0.1 N) has the
// friction sum -mu times the normal sum, to the CSV's 17 digits and the
// solvers' rounding (1e-9 N, as tests/bullet/test_contact_friction.cpp),
// and nothing along t2.
TEST(PeersCli, ComparePeerOutWritesTheFrictionMultipliers) {
  const auto dir = std::filesystem::path(lcsim::cli_test::private_temp("lcsim_peers_out", ""));
  const std::string scene = lcsim::test_support::write_slide_scene(dir, 0.0, 0.3, 1.0, 0.6);
  for (const char* peer : {"bullet", "mujoco"}) {
    const std::string csv = (dir / (std::string(peer) + ".csv")).string();
    const auto r = lcsim("compare '" + scene + "' --peer " + peer + " --peer-out '" + csv + "'");
    ASSERT_EQ(r.exit_code, 0) << peer << ": " << r.err;
    std::ifstream in(csv);
    std::string line;
    ASSERT_TRUE(std::getline(in, line)) << peer;
    auto split = [](const std::string& text) {
      std::vector<std::string> out;
      std::stringstream ss(text);
      for (std::string cell; std::getline(ss, cell, ',');) out.push_back(cell);
      return out;
    };
    const std::vector<std::string> head = split(line);
    std::vector<std::size_t> u, ut, ut2;
    std::size_t vy = 0;
    for (std::size_t c = 0; c < head.size(); ++c) {
      if (head[c].rfind("u_box.", 0) == 0) u.push_back(c);
      if (head[c].rfind("ut_box.", 0) == 0) ut.push_back(c);
      if (head[c].rfind("ut2_box.", 0) == 0) ut2.push_back(c);
      if (head[c] == "v_box.y") vy = c;
    }
    ASSERT_EQ(ut.size(), 4u) << peer << ": " << line;
    ASSERT_EQ(ut2.size(), 4u) << peer;
    int checked = 0;
    while (std::getline(in, line)) {
      const std::vector<std::string> row = split(line);
      auto sum = [&](const std::vector<std::size_t>& cols) {
        double total = 0.0;
        for (std::size_t c : cols) total += row[c].empty() ? 0.0 : std::stod(row[c]);
        return total;
      };
      if (std::stod(row[vy]) < 0.05 || sum(u) < 0.1) continue;
      EXPECT_NEAR(sum(ut), -0.3 * sum(u), 1e-9) << peer << ": " << line;
      EXPECT_NEAR(sum(ut2), 0.0, 1e-9) << peer << ": " << line;
      ++checked;
    }
    // The comparison grid's rows while it slides and touches (MuJoCo's box
    // hops, docs/contacts.md, so fewer of them: 34 measured against
    // Bullet's 322).
    std::printf("[ peers    ] %s: %d rows checked\n", peer, checked);
    EXPECT_GT(checked, 20) << peer;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
