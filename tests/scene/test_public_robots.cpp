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

// Two legs (hip, knee, ankle pitch each, PD springs) with four contact
// points on each sole, as the NAO of bullet3's humanoid/nao.urdf is given
// them (its feet are meshes), dropped 5.8 cm: 5 of 40 random poses of this
// robot stopped in the exact method ("mode selection at t = ...: leading row
// coefficient block of the active set is singular" or "mode feedback F_I
// unavailable"); this is one of them. The pose puts the soles on the floor
// to the rounding of its forward kinematics: the eight gaps at q0 are 0,
// 5.6e-17 and 1.1e-16 m (each the height of a point reached through three
// rotations and lengths below 0.5 m: a dozen roundings of ~0.5 eps m, so
// 1e-15 bounds them), far inside the default penetration tolerance (1e-6
// m), which the scene keeps. Checked: it completes; the robot is
// symmetric about its x-z plane, so each left joint equals its right one
// and the base neither drifts sideways nor rolls nor yaws (1e-9: rounding of
// the symmetric sums); no sample penetrates (1e-12 m); and the final
// positions agree with the time-stepping methods at h = 2e-4 and 1e-4, to
// first order (e(h): the largest difference over the 12 coordinates, in
// each case the base pitch):
// - backward Euler: e = 7.271e-5 and 3.609e-5 rad, e / h = 0.3635 and
//   0.3609 rad/s: e(h) <= C h with C = 0.4 rad/s (10 % over the measured
//   constant); its Richardson extrapolant 2 x(h) - x(2h) meets the event
//   run to 5.3e-7 (second order: a quarter of that, 1.4e-7, from h = 1e-4
//   and 5e-5), and 2e-6 bounds it with a margin of about 4;
// - Moreau-Jean: e = 1.010e-3 and 5.370e-4 rad (e(h) / e(2h) = 0.53), e / h
//   = 5.05 and 5.37 rad/s: e(h) <= C h with C = 5.9 rad/s (10 % over the
//   measured constant at h = 1e-4), and e(h) <= 0.6 e(2h). Its error is
//   first order plus a part that does not vanish with h, 6.4e-5 rad (its
//   Richardson extrapolant's distance, 6.2e-5 and 7.0e-5 from h = 1e-4 down
//   to 2.5e-5), which appears at the heels' second landing (t = 0.2515 s)
//   and which backward Euler does not show: the event run is the limit
//   that backward Euler converges to.
TEST_F(PublicRobots, TwoLegsOnFourPointSolesLandAndSettle) {
  write("legs.urdf", R"(<robot name='b'>
 <link name='torso'><inertial><origin xyz='0 0 0.1'/><mass value='5'/><inertia ixx='0.05' ixy='0' ixz='0' iyy='0.04' iyz='0' izz='0.03'/></inertial></link>
 <link name='lthigh'><inertial><origin xyz='0 0 -0.1'/><mass value='0.5'/><inertia ixx='0.002' ixy='0' ixz='0' iyy='0.002' iyz='0' izz='0.0005'/></inertial></link>
 <link name='lshin'><inertial><origin xyz='0 0 -0.1'/><mass value='0.4'/><inertia ixx='0.002' ixy='0' ixz='0' iyy='0.002' iyz='0' izz='0.0005'/></inertial></link>
 <link name='lfoot'><inertial><origin xyz='0.02 0 -0.02'/><mass value='0.2'/><inertia ixx='0.0002' ixy='0' ixz='0' iyy='0.0003' iyz='0' izz='0.0004'/></inertial></link>
 <link name='rthigh'><inertial><origin xyz='0 0 -0.1'/><mass value='0.5'/><inertia ixx='0.002' ixy='0' ixz='0' iyy='0.002' iyz='0' izz='0.0005'/></inertial></link>
 <link name='rshin'><inertial><origin xyz='0 0 -0.1'/><mass value='0.4'/><inertia ixx='0.002' ixy='0' ixz='0' iyy='0.002' iyz='0' izz='0.0005'/></inertial></link>
 <link name='rfoot'><inertial><origin xyz='0.02 0 -0.02'/><mass value='0.2'/><inertia ixx='0.0002' ixy='0' ixz='0' iyy='0.0003' iyz='0' izz='0.0004'/></inertial></link>
 <joint name='lhip' type='revolute'><parent link='torso'/><child link='lthigh'/><origin xyz='0 0.05 -0.05'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
 <joint name='lknee' type='revolute'><parent link='lthigh'/><child link='lshin'/><origin xyz='0 0 -0.2'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
 <joint name='lankle' type='revolute'><parent link='lshin'/><child link='lfoot'/><origin xyz='0 0 -0.2'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
 <joint name='rhip' type='revolute'><parent link='torso'/><child link='rthigh'/><origin xyz='0 -0.05 -0.05'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
 <joint name='rknee' type='revolute'><parent link='rthigh'/><child link='rshin'/><origin xyz='0 0 -0.2'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
 <joint name='rankle' type='revolute'><parent link='rshin'/><child link='rfoot'/><origin xyz='0 0 -0.2'/><axis xyz='0 1 0'/><limit lower='-1' upper='1' effort='1' velocity='1'/></joint>
</robot>)");
  const mech::Model model = scene::load_model(write("legs.yaml", R"(urdf: legs.urdf
base: {type: floating, pose: {xyz: [0, 0, 0.4800553567802965]}}
joints: [{name: lhip, stops: []}, {name: lknee, stops: []}, {name: lankle, stops: []}, {name: rhip, stops: []}, {name: rknee, stops: []}, {name: rankle, stops: []}]
q0: {lhip: 0.3013820626487555, lknee: -0.3978597731826419, lankle: 0.09647771053388637, rhip: 0.3013820626487555, rknee: -0.3978597731826419, rankle: 0.09647771053388637}
planes: [{name: floor, normal: [0, 0, 1]}]
contacts:
  - {link: lfoot, plane: floor, points: [[0.07523479922561183, 0.03707322510422971, -0.04], [0.07523479922561183, -0.03707322510422971, -0.04], [-0.03, 0.03707322510422971, -0.04], [-0.03, -0.03707322510422971, -0.04]]}
  - {link: rfoot, plane: floor, points: [[0.07523479922561183, 0.03707322510422971, -0.04], [0.07523479922561183, -0.03707322510422971, -0.04], [-0.03, 0.03707322510422971, -0.04], [-0.03, -0.03707322510422971, -0.04]]}
springs:
  - {name: k_lhip, joint: lhip, stiffness: 100, damping: 2, rest: 0.3013820626487555}
  - {name: k_lknee, joint: lknee, stiffness: 100, damping: 2, rest: -0.3978597731826419}
  - {name: k_lankle, joint: lankle, stiffness: 100, damping: 2, rest: 0.09647771053388637}
  - {name: k_rhip, joint: rhip, stiffness: 100, damping: 2, rest: 0.3013820626487555}
  - {name: k_rknee, joint: rknee, stiffness: 100, damping: 2, rest: -0.3978597731826419}
  - {name: k_rankle, joint: rankle, stiffness: 100, damping: 2, rest: 0.09647771053388637}
initial: {q: {b.z: 0.5381101688822949}}
t_end: 0.5
)"));
  const mech::MechanicalModel& m = *model.mechanical;
  sim::Options opt;
  opt.t_end = model.t_end;
  opt.dt_out = 0.01;
  const sim::Trajectory tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  const Eigen::Index n = static_cast<Eigen::Index>(m.coordinates.size());
  ASSERT_EQ(n, 12);
  for (const sim::Sample& x : tr.samples) {
    EXPECT_GE((m.E * x.x.head(n) + m.g).minCoeff(), -1e-12) << x.t;
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(x.x(6 + j), x.x(9 + j), 1e-9) << x.t;
    for (const int c : {1, 3, 5}) EXPECT_NEAR(x.x(c), 0.0, 1e-9) << x.t;
  }
  VectorXd q0 = model.initial.head(n);  // the reference pose: the initial one but its height
  q0(2) = 0.4800553567802965;
  const VectorXd gap0 = m.E * q0 + m.g;
  for (const std::string foot : {"lfoot", "rfoot"})
    for (int k = 0; k < 4; ++k) {
      const std::string c = foot + ".point" + std::to_string(k);
      const auto r = std::find(m.constraints.begin(), m.constraints.end(), c);
      ASSERT_NE(r, m.constraints.end()) << c;
      EXPECT_NEAR(gap0(r - m.constraints.begin()), 0.0, 1e-15) << c;
    }
  const auto final_positions = [&](const char* method, double h) {
    opt.h = h;
    const sim::Trajectory run = sim::simulate(model, model.initial, opt, method);
    EXPECT_EQ(run.status, sim::RunStatus::kCompleted) << method << " " << h << ": " << run.message;
    return VectorXd(run.final_state.head(n));
  };
  const VectorXd x = tr.final_state.head(n);
  const double h = 1e-4;
  const VectorXd be2 = final_positions("euler", 2 * h), be1 = final_positions("euler", h);
  EXPECT_LE((be1 - x).cwiseAbs().maxCoeff(), 0.4 * h);
  EXPECT_LE((2 * be1 - be2 - x).cwiseAbs().maxCoeff(), 2e-6);
  const VectorXd mj2 = final_positions("moreau-jean", 2 * h),
                 mj1 = final_positions("moreau-jean", h);
  const double e2 = (mj2 - x).cwiseAbs().maxCoeff(), e1 = (mj1 - x).cwiseAbs().maxCoeff();
  EXPECT_LE(e1, 5.9 * h);
  EXPECT_LE(e1, 0.6 * e2);
  EXPECT_LT(tr.energy_final, tr.energy_initial);
}

}  // namespace
}  // namespace lcsim
