// Dependent contacts in the exact method's mode selection (src/lcs/ldcp.cpp,
// mark_dependent): a row whose [C_r D_r] is a combination of the active
// rows' is undetermined from the level it is found, not carried on as
// undecided to meet rounding at later levels.
#include <gtest/gtest.h>

#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim {
namespace {

// The KUKA pressing a box resting on four coplanar corners (the linear
// model of docs/contacts.md's scene, tests/sim/data: corner0 = corner1 +
// corner2 - corner3). The exact run refused at t = 0.6219 s (events that
// changed nothing at corner0, classified inactive on a q of 3.5e-10 at the
// LDCP's second level, until the livelock guard); it now completes to t = 1
// with the tip's impact as its one event, and its final state is the static
// equilibrium that backward Euler (h = 1e-4) reaches too: the arm's springs
// against the box, everything at rest. Tolerance 1e-9: both runs end at
// rest (velocities below 1e-11) on the same equilibrium, which neither
// method's error reaches at rest (measured 5.4e-13).
TEST(DependentContacts, KukaPressingABoxOnFourCoplanarCornersCompletes) {
  const mech::Model m = scene::load_model(std::string(LCSIM_SOURCE_DIR) +
                                          "/tests/sim/data/kuka_press_box_linear.yaml");
  sim::Options opt;
  opt.t_end = 1.0;
  const sim::Trajectory ev = sim::simulate(m, m.initial, opt, "event");
  ASSERT_TRUE(ev.ok()) << ev.message;
  ASSERT_EQ(ev.events.size(), 1u);
  EXPECT_EQ(ev.events[0].type, sim::EventType::kImpact);
  sim::Options eo;
  eo.t_end = 1.0;
  eo.h = 1e-4;
  const sim::Trajectory eu = sim::simulate(m, m.initial, eo, "euler");
  ASSERT_TRUE(eu.ok()) << eu.message;
  EXPECT_LT(ev.final_state.tail(9).cwiseAbs().maxCoeff(), 1e-11);
  EXPECT_LT((ev.final_state - eu.final_state).cwiseAbs().maxCoeff(), 1e-9);
}

}  // namespace
}  // namespace lcsim
