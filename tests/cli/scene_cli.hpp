// Shared by the scene tests of the command line (test_contacts_cli.cpp,
// test_bodies_cli.cpp): a fresh directory per test holding the URDFs a
// scene names and an empty out/, and the check that a scene is refused as
// bad input (exit 2, one line, nothing written).
#pragma once

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <string>

#include "support/run_lcsim.hpp"

namespace lcsim::cli_test {

inline std::string quote(const std::filesystem::path& p) { return "'" + p.string() + "'"; }

// <temp>/lcsim_<stem>_<test>_<pid>, emptied, with out/ and a copy of each of
// `urdfs` (file names in robots/).
inline std::filesystem::path fresh_scene_dir(const std::string& stem,
                                             std::initializer_list<const char*> urdfs) {
  namespace fs = std::filesystem;
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const fs::path d = fs::path(::testing::TempDir()) /
                     ("lcsim_" + stem + "_" + info->name() + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d / "out");
  for (const char* u : urdfs) fs::copy_file(fs::path(LCSIM_SOURCE_DIR) / "robots" / u, d / u);
  return d;
}

inline std::filesystem::path write_file(const std::filesystem::path& dir, const std::string& name,
                                        const std::string& text) {
  const std::filesystem::path p = dir / name;
  std::ofstream(p) << text;
  return p;
}

// `simulate` and `analyze` on `scene`: exit 2, one line "lcsim: error:
// <scene>: <what>", nothing in dir/out.
inline void expect_refused(const std::filesystem::path& dir, const std::filesystem::path& scene,
                           const std::string& what) {
  for (const char* c : {"simulate", "analyze"}) {
    std::string args = std::string(c) + " " + quote(scene);
    if (std::string(c) == "simulate") args += " --out " + quote(dir / "out" / "t.csv");
    const auto r = run_lcsim(args, dir / "stderr.txt");
    EXPECT_EQ(r.exit_code, 2) << c << ": " << r.err;
    EXPECT_EQ(count_lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("lcsim: error: " + scene.string() + ": " + what, 0), 0u) << r.err;
    EXPECT_TRUE(std::filesystem::is_empty(dir / "out")) << c;
  }
}

}  // namespace lcsim::cli_test
