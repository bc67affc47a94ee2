// Passivity and well-posedness of circuits (thesis Ch. 5): the shipped
// circuits are passive, a negative resistor makes a circuit not passive.
#include <gtest/gtest.h>

#include <lcsim/circuit/circuit.hpp>
#include <string>

namespace lcsim {
namespace {

circuit::PassivityReport judge(const std::string& file) {
  return circuit::judge_passivity(
      circuit::load_circuit(std::string(LCSIM_SOURCE_DIR) + "/circuits/" + file));
}

TEST(Passivity, ShippedCircuitsArePassive) {
  for (const char* f :
       {"diode_bridge.cir", "half_wave_rectifier.cir", "diode_clamp.cir", "half_wave_rlc.cir"}) {
    const circuit::PassivityReport r = judge(f);
    EXPECT_EQ(r.passive, "yes") << f << ": " << r.passive_reason;
    EXPECT_TRUE(r.negative_elements.empty()) << f;
  }
  // The bridge has four diodes and two states: B cannot have full column
  // rank, so Theorems 5.5.2-5.5.3 do not apply as stated (Assumption 5.2.2).
  const circuit::PassivityReport bridge = judge("diode_bridge.cir");
  EXPECT_FALSE(bridge.full_column_rank_b);
  EXPECT_FALSE(bridge.globally_well_posed);
  // One diode, a minimal RC: the rectifier satisfies Assumption 5.2.2.
  const circuit::PassivityReport rect = judge("half_wave_rectifier.cir");
  EXPECT_TRUE(rect.full_column_rank_b && rect.controllable && rect.observable);
  EXPECT_TRUE(rect.globally_well_posed) << rect.verdict;
}

TEST(Passivity, NegativeResistorIsNotPassive) {
  // C1 in parallel with -2 kOhm and +4 kOhm: net conductance -1/4k, so the
  // capacitor voltage grows as exp(t / (4k * 1u)): A = +250 1/s.
  const char* text =
      "t\nV1 in 0 1\nD1 in a dm\nC1 a 0 1u\nR1 a 0 -2k\nR2 a 0 4k\n.model dm D\n.tran 1u 1m uic\n";
  const circuit::PassivityReport r =
      circuit::judge_passivity(circuit::parse_circuit(text, "neg.cir"));
  EXPECT_EQ(r.passive, "no") << r.passive_reason;
  EXPECT_NE(r.passive_reason.find("eigenvalue 250"), std::string::npos) << r.passive_reason;
  EXPECT_EQ(r.negative_elements, (std::vector<std::string>{"R1"}));
  EXPECT_FALSE(r.globally_well_posed);
}

}  // namespace
}  // namespace lcsim
