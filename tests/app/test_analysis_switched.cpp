// `lcsim analyze` on a switched circuit (issue 29): thesis Ch. 5's verdict
// for every configuration its switches' schedule visits, named by the
// switches' states, each checked here by hand.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <lcsim/app/analysis.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace lcsim::app {
namespace {

using nlohmann::json;

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// The buck converter: S1 off at t = 0 (its gate Vg = 0 < VT = 0.5 V), on
// where the 1 ns rise of Vg crosses 0.5 V (t = 0.5 ns). Both configurations
// are passive: every resistor (RON 10 mOhm or ROFF 1 MOhm, R1 6 Ohm) is
// positive, so the stored energy L i^2 / 2 + C v^2 / 2 is a storage
// function, which the test checks on each configuration's LCS with its own
// K = diag(L1, C1) from the netlist's values.
TEST(AnalysisSwitched, BuckConverterJudgesBothConfigurations) {
  const scene::LoadedModel loaded =
      scene::load_model_and_scene(std::string(LCSIM_SOURCE_DIR) + "/circuits/buck_converter.cir");
  const AnalysisReport r = analysis_report(loaded);
  const json& conf = r.json["circuit"]["configurations"];
  ASSERT_EQ(conf.size(), 2u) << r.text;
  EXPECT_EQ(conf[0]["switches"]["S1"], "off");
  EXPECT_EQ(conf[0]["first_holds_at"], 0.0);
  EXPECT_EQ(conf[1]["switches"]["S1"], "on");
  EXPECT_NEAR(conf[1]["first_holds_at"].get<double>(), 0.5e-9, 1e-24);  // one division
  const mech::Model& m = loaded.model;
  const int nc = loaded.circuit->circuit_states;
  ASSERT_EQ(nc, 2);
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(nc, nc);
  for (int i = 0; i < nc; ++i)
    K(i, i) = m.state_names[static_cast<size_t>(i)] == "L1.i" ? 200e-6 : 5e-6;
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(conf[k]["passive"], "yes");
    const lcs::Lcs& s = m.configurations[k].lcs;
    const lcs::Lcs part{s.A.topLeftCorner(nc, nc), s.B.topRows(nc), s.C.leftCols(nc), s.D};
    EXPECT_TRUE(lcs::verify_passivity_certificate(part, K).ok()) << k;
  }
  EXPECT_TRUE(contains(r.text, "configurations: 2 visited by the switches' schedule")) << r.text;
  EXPECT_TRUE(contains(r.text, "  S1 off (from t = 0 s): passive yes; ")) << r.text;
  EXPECT_TRUE(contains(r.text, "  S1 on (from t = 5e-10 s): passive yes; ")) << r.text;
}

// A negative resistor Rn = -2 Ohm across C1 = 1 uF, with a switch (RON =
// 1 Ohm, ROFF = 1e12 Ohm) in parallel: C v' = -v (1/Rn + 1/R_S). Off, the
// net conductance -0.5 + 1e-12 S is negative: A = +5e5 1/s, an eigenvalue in
// the right half plane, not passive. On, it is +0.5 S: passive. The schedule
// (Vg's rise at 1 ms) visits both; the verdicts must differ.
TEST(AnalysisSwitched, ANegativeResistorIsPassiveOnlyWhileTheSwitchConducts) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "lcsim_test_analysis_switched";
  std::filesystem::create_directories(dir);
  const std::filesystem::path file = dir / "negative.cir";
  std::ofstream(file) << "negative resistor, switched\n"
                         "C1 a 0 1u IC=1\n"
                         "Rn a 0 -2\n"
                         "S1 a 0 g 0 sw\n"
                         "D1 0 a ideal\n"
                         "Vg g 0 PULSE(0 1 1m 1u 1u 1m 2m)\n"
                         ".model sw SW(VT=0.5 RON=1 ROFF=1e12)\n"
                         ".model ideal D\n"
                         ".tran 1u 3m uic\n"
                         ".end\n";
  const AnalysisReport r = analysis_report(scene::load_model_and_scene(file));
  const json& conf = r.json["circuit"]["configurations"];
  ASSERT_EQ(conf.size(), 2u) << r.text;
  EXPECT_EQ(conf[0]["switches"]["S1"], "off");
  EXPECT_EQ(conf[0]["passive"], "no") << conf[0]["passive_reason"];
  EXPECT_TRUE(contains(conf[0]["passive_reason"].get<std::string>(), "right half plane"));
  EXPECT_EQ(conf[1]["switches"]["S1"], "on");
  EXPECT_EQ(conf[1]["passive"], "yes") << conf[1]["passive_reason"];
  EXPECT_NEAR(conf[1]["first_holds_at"].get<double>(), 1e-3 + 0.5e-6, 1e-15);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace lcsim::app
