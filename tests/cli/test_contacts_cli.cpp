// Scenes with floating bases and contacts through the command line (issue
// 26): bad input exits 2 with one line naming the file, key and value and
// leaves no output behind; the contacts' names are the CSV's columns.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "cli/scene_cli.hpp"
#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

using lcsim::cli_test::expect_refused;
using lcsim::cli_test::quote;
using lcsim::cli_test::write_file;

fs::path fresh_dir() { return lcsim::cli_test::fresh_scene_dir("contacts", {"box.urdf"}); }

const std::string kHead = "urdf: box.urdf\nbase: {type: floating, pose: {xyz: [0, 0, 0.05]}}\n";
const std::string kFloor = "planes: [{name: floor, normal: [0, 0, 1]}]\n";

TEST(ContactsCli, BadInputExitsTwoWithOneLine) {
  const fs::path d = fresh_dir();
  expect_refused(
      d, write_file(d, "link.yaml", kHead + kFloor + "contacts: [{link: lid, plane: floor}]\n"),
      "contacts[0].link: no link 'lid' in ");
  expect_refused(
      d, write_file(d, "normal.yaml", kHead + "planes: [{name: floor, normal: [0, 0, 0]}]\n"),
      "planes[0].normal: must be non-zero (got 0, 0, 0)");
  expect_refused(d,
                 write_file(d, "deep.yaml",
                            "urdf: box.urdf\nbase: {type: floating, pose: {xyz: [0, 0, 0.04]}}\n" +
                                kFloor + "contacts: [{link: box, plane: floor}]\n"),
                 "contacts[0]: contact 'box.corner0' penetrates plane 'floor' by 0.01");
  expect_refused(
      d, write_file(d, "pose.yaml", "urdf: box.urdf\nbase: {type: fixed, pose: {xyz: [0, 1]}}\n"),
      "base.pose.xyz: expected 3 entries (x, y, z in m) (got 2)");
}

// The mesh's message names the URDF's link and element (the URDF's path
// comes first, not the scene's).
TEST(ContactsCli, MeshNamesTheLinkAndElement) {
  const fs::path d = fresh_dir();
  write_file(d, "mesh.urdf",
             "<robot name='m'><link name='m'><inertial><mass value='1'/><inertia ixx='1' "
             "ixy='0' ixz='0' iyy='1' iyz='0' izz='1'/></inertial><collision><geometry><mesh "
             "filename='m.stl'/></geometry></collision></link></robot>");
  const fs::path s = write_file(
      d, "mesh.yaml",
      "urdf: mesh.urdf\nbase: floating\n" + kFloor + "contacts: [{link: m, plane: floor}]\n");
  const auto r = lcsim::cli_test::run_lcsim("analyze " + quote(s), d / "stderr.txt");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_EQ(lcsim::cli_test::count_lines(r.err), 1) << r.err;
  EXPECT_NE(r.err.find((d / "mesh.urdf").string() + ": link 'm': <collision> 0: <mesh>: lcsim "
                                                    "has no contact points for it"),
            std::string::npos)
      << r.err;
}

// The CSV names every contact in its columns; the dropped box runs.
TEST(ContactsCli, CsvColumnsNameTheContacts) {
  const fs::path d = fresh_dir();
  const fs::path csv = d / "out" / "t.csv";
  const auto r = lcsim::cli_test::run_lcsim(
      "simulate " + quote(kRobots + "box_drop_scene.yaml") + " --out " + quote(csv),
      d / "stderr.txt");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream in(csv);
  std::string header;
  std::getline(in, header);
  for (const char* c : {"box.z", "box.rx", "box.corner0", "box.corner7"})
    EXPECT_NE(header.find(c), std::string::npos) << c << " in " << header;
}

}  // namespace
