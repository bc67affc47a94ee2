// `lcsim simulate` and `lcsim analyze` on netlists: the CSV columns in the
// circuit's language, a refused netlist exits 2 with one line and writes
// nothing.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "support/run_lcsim.hpp"

namespace lcsim {
namespace {

using cli_test::private_temp;
using cli_test::run_lcsim;
using cli_test::slurp;

const std::string kCircuits = std::string(LCSIM_SOURCE_DIR) + "/circuits/";

TEST(CliCircuits, SimulateWritesVoltagesAndCurrentsByName) {
  const auto csv = private_temp("rect", ".csv"), err = private_temp("rect", ".err");
  const auto r = run_lcsim("simulate " + kCircuits +
                               "half_wave_rectifier.cir --dt-out 1e-3 --out '" + csv.string() + "'",
                           err);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = slurp(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')),
            "t,C1.v,1,V1.sin,V1.cos,u_D1,y_D1,V(in),V(out),I(V1),I(D1),I(R1),I(C1),mode");
  // The report names the diode at each event.
  EXPECT_NE(r.out.find("mode {0 D1}"), std::string::npos) << r.out;
  std::filesystem::remove(csv);
}

TEST(CliCircuits, RefusedNetlistExitsTwoAndWritesNothing) {
  const auto cir = private_temp("bad", ".cir"), csv = private_temp("bad", ".csv"),
             err = private_temp("bad", ".err");
  { std::ofstream(cir) << "title\nV1 a 0 1\nR1 a 0 1k\nC1 a b x10\nR2 b 0 1k\n"; }
  const auto r = run_lcsim("simulate '" + cir.string() + "' --out '" + csv.string() + "'", err);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "lcsim: error: " + cir.string() + ":4: C1: non-numeric value 'x10'\n");
  EXPECT_FALSE(std::filesystem::exists(csv));
  std::filesystem::remove(cir);
}

// Sources with breakpoints: a PULSE with a negative width is refused (exit 2,
// one line, nothing written); a PWL circuit runs with the exact method (its
// breakpoints as `schedule` events, the PWL's states as CSV columns) and is
// refused by backward Euler (exit 2, nothing written).
TEST(CliCircuits, SourcesWithBreakpoints) {
  const auto cir = private_temp("src", ".cir"), csv = private_temp("src", ".csv"),
             err = private_temp("src", ".err");
  { std::ofstream(cir) << "t\nV1 a 0 PULSE(0 1 0 1u 1u -1m 2m)\nR1 a 0 1k\n.tran 1u 1m\n"; }
  auto r = run_lcsim("simulate '" + cir.string() + "' --out '" + csv.string() + "'", err);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "lcsim: error: " + cir.string() + ":2: V1: PULSE PW must be >= 0 (got -0.001 s)\n");
  EXPECT_FALSE(std::filesystem::exists(csv));
  { std::ofstream(cir) << "t\nV1 a 0 PWL(0 0 1m 1)\nR1 a b 1k\nC1 b 0 1u\n.tran 1u 2m uic\n"; }
  r = run_lcsim("simulate '" + cir.string() + "' --dt-out 1e-4 --out '" + csv.string() + "'", err);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string text = slurp(csv);
  EXPECT_EQ(text.substr(0, text.find('\n')), "t,C1.v,1,V1.p,V1.r,V(a),V(b),I(V1),I(R1),I(C1),mode");
  EXPECT_NE(r.out.find("schedule"), std::string::npos) << r.out;
  std::filesystem::remove(csv);
  r = run_lcsim("simulate '" + cir.string() + "' --method euler --out '" + csv.string() + "'", err);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("does not simulate inputs with breakpoints"), std::string::npos) << r.err;
  EXPECT_FALSE(std::filesystem::exists(csv));
  std::filesystem::remove(cir);
}

// Switches: a control that depends on the circuit's state is refused (exit
// 2, one line naming the switch, nothing written); the buck converter runs
// with the exact method and is refused by backward Euler (exit 2, nothing
// written); its switch times are `schedule` events named by the switch.
TEST(CliCircuits, Switches) {
  const auto cir = private_temp("sw", ".cir"), csv = private_temp("sw", ".csv"),
             err = private_temp("sw", ".err");
  {
    std::ofstream(cir) << "t\nV1 in 0 10\nR1 in b 1k\nC1 b 0 1u\nS1 in a b 0 sw\nR2 a 0 1k\n"
                          ".model sw SW\n.tran 1u 2m\n";
  }
  auto r = run_lcsim("simulate '" + cir.string() + "' --out '" + csv.string() + "'", err);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err, "lcsim: error: " + cir.string() +
                       ":5: S1: its control v(b, 0) depends on the circuit's state C1: lcsim "
                       "schedules a switch whose control sources alone fix (a DC, PULSE or PWL "
                       "voltage source across nc+ nc-)\n");
  EXPECT_FALSE(std::filesystem::exists(csv));
  const std::string buck = kCircuits + "buck_converter.cir";
  r = run_lcsim("simulate " + buck + " --method euler --h 1e-8 --out '" + csv.string() + "'", err);
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.err,
            "lcsim: error: method 'euler' does not simulate switched circuits (model "
            "'buck_converter' has ideal switches); method 'event' does\n");
  EXPECT_FALSE(std::filesystem::exists(csv));
  r = run_lcsim("simulate " + buck + " --t-end 2e-5 --out '" + csv.string() + "'", err);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("switch: S1 on"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("switch: S1 off"), std::string::npos) << r.out;
  std::filesystem::remove(csv);
  std::filesystem::remove(cir);
}

TEST(CliCircuits, AnalyzeSaysPassiveAndWellPosed) {
  const auto err = private_temp("an", ".err");
  const auto r = run_lcsim("analyze " + kCircuits + "half_wave_rectifier.cir --json", err);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("\"passive\": \"yes\""), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("\"globally_well_posed\": true"), std::string::npos);
}

}  // namespace
}  // namespace lcsim
