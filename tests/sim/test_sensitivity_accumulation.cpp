// Forward sensitivities through an accumulation of impacts
// (docs/sensitivities.md, src/sim/exact/sensitivity_accumulation.cpp): the
// derivative of the limit as the run takes it, the M-orthogonal projection
// onto the closed contacts, against closed forms of the exact limit.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/model_file.hpp>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

sim::Trajectory run(const mech::Model& m, const VectorXd& x0, double T,
                    std::vector<std::string> sens) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, x0, opt, "event");
}

bool has_accumulation(const sim::Trajectory& tr) {
  for (const auto& e : tr.events)
    if (e.type == sim::EventType::kAccumulation) return true;
  return false;
}

// The ball (e = 0.5) from z0 = 1 m at 0.5 m/s accumulates at t = t1 + 2 e w
// / (g (1 - e)) = 1.414 s (w = sqrt(v0^2 + 2 g z0), t1 = (v0 + w) / g) and
// rests on the ground: its limit state (0, 0) does not depend on x0, e or
// f, so every derivative at T = 2 is zero (the projection onto z = 0, v = 0
// makes it exactly zero), and exists; before the limit (T = 1.2 s) it is
// not zero.
TEST(SensitivityAccumulation, BallAtRestHasZeroDerivative) {
  const mech::Model m = mech::ball_model(0.5);
  const Eigen::Vector2d x0(1.0, 0.5);
  const sim::Trajectory tr = run(m, x0, 2.0, {"x0", "e[0]", "f[0]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_TRUE(has_accumulation(tr));
  EXPECT_TRUE(tr.sensitivity_losses.empty()) << tr.sensitivity_losses.front().reason;
  for (char e : tr.dx_final_exists) EXPECT_TRUE(e);
  EXPECT_EQ(tr.dx_final.cwiseAbs().maxCoeff(), 0.0);
  const sim::Trajectory before = run(m, x0, 1.2, {"x0", "e[0]", "f[0]"});
  ASSERT_TRUE(before.ok()) << before.message;
  EXPECT_GT(before.dx_final.cwiseAbs().maxCoeff(), 0.1);
}

// A body whose vertical coordinate z bounces on the ground (e = 0.5) while
// coupled by its mass matrix M = [[2, m01], [m01, 1]] (m01 = 0.5) to a
// horizontal coordinate x pushed by f0 = 0.3 (f1 = -9.81). The impulses act
// on z's row only, so (M v)_x = p0 + f0 t at all times, and after the
// accumulation (t = 0.8926 s from x0 = (0, 0.5), v0 = (0.2, 0)) z = 0, vz =
// 0: vx(T) = (p0 + f0 T) / 2 and x(T) = x0 + (p0 T + f0 T^2 / 2) / 2 -
// (m01 / 2) (0 - z0). Derivatives at T = 2.5 (closed form; the same numbers
// as central differences of the piecewise solution through the geometric
// sequence of bounces, t_inf = t1 + 2 e w / (|a_z| (1 - e))): dx/dx0 = 1, dx/dz0 = m01 / 2 =
// 0.25, dx/dvx0 = T, dvx/dvx0 = 1, dx/dvz0 = m01 T / 2 = 0.625, dvx/dvz0 =
// m01 / 2, dx/df0 = T^2 / 4, dvx/df0 = T / 2, and zero for f1 and e (the
// limit does not depend on them), dx/dM01 = z0 / 2 = 0.25. The run
// takes the limit at its last resolved impact, the remaining geometric tail
// below accumulation_tail = 1e-6 s; the tail changes the run's derivative by
// at most its length times the rates' derivative (O(1) here): tolerance
// 1e-5, ten times that bound.
TEST(SensitivityAccumulation, CoupledBodyAgainstItsClosedForm) {
  const mech::Model m = io::parse_matrix_model(
      "name: coupled_bounce\nmechanical:\n  M: [[2, 0.5], [0.5, 1]]\n  E: [[0, 1]]\n"
      "  f: [0.3, -9.81]\n  restitution: [0.5]\n  coordinates: [x, z]\n"
      "  constraints: [ground]\ninitial: [0, 0.5, 0.2, 0]\nt_end: 2.5\n",
      "coupled_bounce.yaml");
  const double T = 2.5, m01 = 0.5, z0 = 0.5, f0 = 0.3;
  const sim::Trajectory tr = run(m, m.initial, T, {"x0", "f[0]", "f[1]", "e[ground]", "M[0][1]"});
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_TRUE(has_accumulation(tr));
  ASSERT_TRUE(tr.sensitivity_losses.empty()) << tr.sensitivity_losses.front().reason;
  const double p0 = 2 * 0.2;  // (M v0)_x
  EXPECT_NEAR(tr.final_state(0), (p0 * T + f0 * T * T / 2) / 2 + m01 / 2 * z0, 1e-6);
  EXPECT_NEAR(tr.final_state(2), (p0 + f0 * T) / 2, 1e-6);
  // Columns: x0 (x, z, vx, vz), f0, f1, e, M01; rows x, z, vx, vz.
  const MatrixXd& d = tr.dx_final;
  const double tol = 1e-5;
  const std::vector<std::pair<int, double>> dx = {{0, 1.0},         {1, m01 / 2},   {2, T},
                                                  {3, m01 * T / 2}, {4, T * T / 4}, {5, 0.0},
                                                  {6, 0.0},         {7, z0 / 2}};
  const std::vector<std::pair<int, double>> dvx = {{0, 0.0},   {1, 0.0}, {2, 1.0}, {3, m01 / 2},
                                                   {4, T / 2}, {5, 0.0}, {6, 0.0}, {7, 0.0}};
  for (const auto& [c, v] : dx) EXPECT_NEAR(d(0, c), v, tol) << tr.sensitivity_columns[c];
  for (const auto& [c, v] : dvx) EXPECT_NEAR(d(2, c), v, tol) << tr.sensitivity_columns[c];
  for (int c = 0; c < 8; ++c) {
    EXPECT_EQ(d(1, c), 0.0) << tr.sensitivity_columns[c];  // z held at 0
    EXPECT_EQ(d(3, c), 0.0) << tr.sensitivity_columns[c];
  }
}

}  // namespace
}  // namespace lcsim
