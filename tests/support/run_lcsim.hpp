// Running the lcsim executable (LCSIM_BINARY) from tests: stdout through a
// pipe, stderr through a file, the exit code. Shared by test_cli and
// test_extremes (Bullet runs through the executable).
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace lcsim::cli_test {

struct CliRun {
  int exit_code = -1;
  std::string out, err;
};

inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

inline int count_lines(const std::string& s) {
  int n = 0;
  for (char c : s) n += c == '\n';
  return n;
}

// A path in the test temp folder private to this test process: ctest runs
// every test as its own process, in parallel, so a fixed name races (a
// shared model file made BulletExtremes read another test's model in CI).
inline std::filesystem::path private_temp(const std::string& stem, const std::string& ext) {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  const std::string test = info ? std::string(info->test_suite_name()) + "." + info->name() : "";
  std::string name = stem + "_" + test + "_" + std::to_string(::getpid()) + ext;
  for (char& c : name)
    if (c == '/') c = '_';  // parameterised test names contain '/'
  return std::filesystem::path(::testing::TempDir()) / name;
}

// Runs `lcsim <args>` with stderr captured in `err_file`, which is removed
// afterwards. ctest runs tests as parallel processes: `err_file` must be
// private to the test.
inline CliRun run_lcsim(const std::string& args, const std::filesystem::path& err_file) {
  const std::string cmd =
      std::string("'") + LCSIM_BINARY + "' " + args + " 2> '" + err_file.string() + "'";
  CliRun r;
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) return r;
  char buf[4096];
  std::size_t n;
  while ((n = std::fread(buf, 1, sizeof buf, pipe)) > 0) r.out.append(buf, n);
  const int status = ::pclose(pipe);
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.err = slurp(err_file);
  std::filesystem::remove(err_file);
  return r;
}

}  // namespace lcsim::cli_test
