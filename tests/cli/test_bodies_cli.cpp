// Scenes of several bodies through the command line (issue 26 part A): bad
// input exits 2 with one line naming the file, key and value and leaves no
// output behind.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cli/scene_cli.hpp"
#include "support/run_lcsim.hpp"

namespace {

namespace fs = std::filesystem;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

using lcsim::cli_test::expect_refused;
using lcsim::cli_test::quote;
using lcsim::cli_test::write_file;

fs::path fresh_dir() {
  return lcsim::cli_test::fresh_scene_dir("bodies", {"box.urdf", "two_finger_gripper.urdf"});
}

// The gripper (fingers open at 0.15 m) and the box on the floor, as the
// shipped scene has them, then `tail`.
std::string bodies(const std::string& box_z, const std::string& box_name, const std::string& tail) {
  return "bodies:\n"
         "  - {name: gripper, urdf: two_finger_gripper.urdf, base: {type: fixed, pose: {xyz: "
         "[0, 0, 0.05]}}, joints: [{name: left, stops: []}, {name: right, stops: []}], q0: "
         "{left: 0.15, right: 0.15}}\n"
         "  - {name: " +
         box_name + ", urdf: box.urdf, base: {type: floating, pose: {xyz: [0, 0, " + box_z +
         "]}}}\n" + "planes: [{name: floor, normal: [0, 0, 1]}]\n" + tail;
}

TEST(BodiesCli, BadInputExitsTwoWithOneLine) {
  const fs::path d = fresh_dir();
  expect_refused(d,
                 write_file(d, "unknown.yaml",
                            bodies("0.05", "box", "contacts: [{link: lid/box, plane: floor}]\n")),
                 "contacts[0].link: no body 'lid' (the bodies are gripper, box)");
  expect_refused(d,
                 write_file(d, "link.yaml",
                            bodies("0.05", "box", "contacts: [{link: box/lid, plane: floor}]\n")),
                 "contacts[0].link: no link 'lid' in body 'box' (");
  expect_refused(d, write_file(d, "duplicate.yaml", bodies("0.05", "gripper", "")),
                 "bodies[1].name: duplicate body 'gripper'");
  expect_refused(d,
                 write_file(d, "self.yaml",
                            bodies("0.05", "box",
                                   "contacts: [{link: gripper/finger_left, against: "
                                   "gripper/finger_right}]\n")),
                 "contacts[0].against: 'gripper/finger_left' and 'gripper/finger_right' are "
                 "links of one body");
  // The box raised 0.1 m and widened by nothing: the left tip (0.15 m out,
  // radius 0.01) clears it; moved to y = 0.1 its face is at 0.2, 0.05 past
  // the tip's centre: the tip's sphere is 0.06 m inside.
  expect_refused(d,
                 write_file(d, "deep.yaml",
                            "bodies:\n"
                            "  - {name: gripper, urdf: two_finger_gripper.urdf, base: {type: "
                            "fixed, pose: {xyz: [0, 0, 0.05]}}, joints: [{name: left, stops: "
                            "[]}], q0: {left: 0.15}}\n"
                            "  - {name: box, urdf: box.urdf, base: {type: floating, pose: {xyz: "
                            "[0, 0.1, 0.05]}}}\n"
                            "contacts: [{link: gripper/finger_left, against: box/box}]\n"),
                 "contacts[0]: contact 'gripper.finger_left.sphere0' penetrates 'box/box' by "
                 "0.06");
}

}  // namespace
