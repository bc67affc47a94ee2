// Scenes a robotics user writes on day one from public robot descriptions
// (bullet3's data/: cube_small.urdf, r2d2.urdf, humanoid/nao.urdf), reproduced
// by small URDFs written here: what failed on them, checked against closed
// forms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

#include "scene/scene_files.hpp"

namespace lcsim {
namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81;

class PublicRobots : public test_support::SceneFiles {};

// A cube of bullet3's cube_small.urdf (edge 0.05 m, 0.1 kg) with inertia
// `inertia` about every axis (cube_small.urdf gives 1 kg m^2; a solid cube
// has m a^2 / 6 = 4.1667e-5).
std::string small_cube(double inertia) {
  const std::string i = std::to_string(inertia);
  return "<robot name='cube'><link name='baseLink'><inertial><mass value='0.1'/><inertia ixx='" +
         i + "' ixy='0' ixz='0' iyy='" + i + "' iyz='0' izz='" + i +
         "'/></inertial><collision><geometry><box size='0.05 0.05 0.05'/></geometry></collision>"
         "</link></robot>";
}

// The cube dropped flat from h = 0.025 m above its rest: its four bottom
// corners close together at t = sqrt(2 h / g) in one inelastic impact, which
// takes exactly the kinetic energy m v^2 / 2 (v = g t), and it then rests on
// them. Before, the exact method stopped right after the landing for both
// inertias ("mode feedback F_I unavailable: mode {0,1,2,3}: ... script M_II
// is singular"): the resting LCP's solution loaded all four dependent corners
// (it works for inertias 1e-3 to 0.1, as for robots/box.urdf, by the luck of
// rounding). The event time is a root found to rounding (1e-12 s); energies
// are O(0.05) J from O(1) numbers (1e-12 J).
TEST_F(PublicRobots, SmallCubeDroppedFlatLandsOnFourCornersAndRests) {
  for (const double inertia : {1.0, 0.1 * 0.05 * 0.05 / 6.0}) {
    write("cube.urdf", small_cube(inertia));
    const mech::Model model = scene::load_model(write("drop.yaml", R"(urdf: cube.urdf
base: {type: floating, pose: {xyz: [0, 0, 0.025]}}
planes: [{name: floor, normal: [0, 0, 1]}]
contacts: [{link: baseLink, plane: floor}]
initial: {q: {cube.z: 0.05}}
t_end: 0.5
)"));
    const mech::MechanicalModel& m = *model.mechanical;
    sim::Options opt;
    opt.t_end = model.t_end;
    const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << inertia << ": " << tr.message;
    ASSERT_GE(tr.events.size(), 1u);
    const sim::Event& e = tr.events[0];
    const double t_hit = std::sqrt(2 * 0.025 / kG), v = kG * t_hit;
    EXPECT_NEAR(e.t, t_hit, 1e-12) << inertia;
    const VectorXd gap = m.E * e.state_before.head(6) + m.g;
    const VectorXd rate = m.E * e.state_after.tail(6);
    for (const char* c :
         {"baseLink.corner0", "baseLink.corner1", "baseLink.corner2", "baseLink.corner3"}) {
      const auto r = std::find(m.constraints.begin(), m.constraints.end(), c);
      ASSERT_NE(r, m.constraints.end()) << c;
      const auto i = r - m.constraints.begin();
      EXPECT_NEAR(gap(i), 0.0, 1e-12) << inertia << " " << c;
      EXPECT_NEAR(rate(i), 0.0, 1e-12) << inertia << " " << c;
    }
    EXPECT_LE(e.state_after.tail(6).cwiseAbs().maxCoeff(), 1e-12) << inertia;
    EXPECT_NEAR(tr.energy_initial - tr.energy_final, 0.5 * 0.1 * v * v, 1e-12) << inertia;
    EXPECT_NEAR(tr.final_state(2), 0.025, 1e-12) << inertia;
    EXPECT_LE(tr.final_state.tail(6).cwiseAbs().maxCoeff(), 1e-12) << inertia;
  }
}

}  // namespace
}  // namespace lcsim
