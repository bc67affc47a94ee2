// Forward sensitivities of the exact method on the shipped model files
// (robots/*.yaml; issue 28: every shipped model and robot scene), each to a
// short horizon: dx(T)/dx0 and one parameter f[0] against central
// differences of the exact method where the run says they exist, and where
// the run says they do not (a zero gap at the start, coinciding events, a
// general LCS started on a switching surface), the loss names a contact or
// says why and the columns carry no number. The planar friction files too.
// Tolerance as tests/sim/test_sensitivity.cpp's: 4 |D(d) - D(d/2)|
// (Richardson's estimate of D(d/2)'s truncation, margin 12) plus
// 64e-13 max(1, |x|) / d (the run's rounding, ~1e-13 of the state, over the
// step d, margin 32), the step d = 1e-4 max(1, |theta|) per entry; every
// perturbed run must have the run's events (else the difference would
// straddle one).
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim {
namespace {

using Eigen::VectorXd;

mech::Model load_file(const std::string& name) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
}

sim::Trajectory exact(const mech::Model& m, const VectorXd& x0, double T,
                      std::vector<std::string> sens = {}) {
  sim::Options opt;
  opt.t_end = T;
  opt.sensitivity = std::move(sens);
  return sim::simulate(m, x0, opt, "event");
}

// Column c of the run: x0[i] (c < n) or f[0]; theta += d.
void perturb(mech::Model& m, VectorXd& x, int c, double d) {
  if (c < x.size())
    x(c) += d;
  else
    m.mechanical->f(0) += d;
}

// Returns the number of columns compared against differences.
int check_file(const std::string& name, double T) {
  const mech::Model m = load_file(name);
  const VectorXd x0 = m.initial;
  const bool mech = m.is_mechanical();
  std::vector<std::string> cols = {"x0"};
  if (mech) cols.push_back("f[0]");
  const sim::Trajectory tr = exact(m, x0, T, cols);
  EXPECT_TRUE(tr.ok()) << name << ": " << tr.message;
  if (!tr.ok()) return 0;
  for (const sim::SensitivityLoss& l : tr.sensitivity_losses) {
    EXPECT_FALSE(l.reason.empty()) << name;
    if (l.reason.find("general LCS") == std::string::npos) {
      EXPECT_FALSE(l.contact.empty()) << name << ": " << l.reason;
    }
  }
  const double xs = std::max(1.0, tr.final_state.cwiseAbs().maxCoeff());
  int compared = 0;
  for (int c = 0; c < static_cast<int>(tr.sensitivity_columns.size()); ++c) {
    if (!tr.dx_final_exists[static_cast<size_t>(c)]) {  // absent: no number
      EXPECT_EQ(tr.dx_final.col(c).cwiseAbs().maxCoeff(), 0.0) << name << " column " << c;
      EXPECT_FALSE(tr.sensitivity_losses.empty()) << name;
      continue;
    }
    const double theta = c < x0.size() ? x0(c) : m.mechanical->f(0);
    const double d0 = 1e-4 * std::max(1.0, std::abs(theta));
    auto fd = [&](double d) {
      VectorXd out[2];
      for (int s = 0; s < 2; ++s) {
        mech::Model mm = m;
        VectorXd xx = x0;
        perturb(mm, xx, c, s == 0 ? d : -d);
        const sim::Trajectory t2 = exact(mm, xx, T);
        EXPECT_TRUE(t2.ok()) << name << ": " << t2.message;
        EXPECT_EQ(t2.events.size(), tr.events.size()) << name << " column " << c;
        out[s] = t2.final_state;
      }
      return VectorXd((out[0] - out[1]) / (2 * d));
    };
    const VectorXd d1 = fd(d0), d2 = fd(d0 / 2);
    for (int i = 0; i < d2.size(); ++i) {
      const double tol = 4 * std::abs(d1(i) - d2(i)) + 64e-13 * xs / d0;
      EXPECT_NEAR(tr.dx_final(i, c), d2(i), tol)
          << name << " dx[" << i << "]/d" << tr.sensitivity_columns[static_cast<size_t>(c)];
    }
    ++compared;
  }
  return compared;
}

// Horizons: short (seconds of test time), each past the file's first event
// where one comes early, else the free motion; the counts of columns
// compared are asserted so that a file whose every column went absent does
// not pass silently (0 where the run says none exists: a zero gap at the
// start and a coinciding event soon after).
TEST(SensitivityFiles, EveryShippedModelAgainstCentralDifferences) {
  struct File {
    const char* name;
    double T;
    int compared;  // columns with a derivative (x0 entries + f[0])
  };
  for (const File& f :
       {File{"ball.yaml", 1.1, 3}, File{"two_carts.yaml", 3.0, 5},
        File{"two_carts_scene.yaml", 3.0, 5}, File{"double_pendulum_scene.yaml", 0.5, 5},
        File{"prismatic_chain_scene.yaml", 0.5, 7}, File{"box_drop_scene.yaml", 0.2, 13},
        File{"arm_gripper_scene.yaml", 0.2, 5}, File{"kuka_iiwa_scene.yaml", 0.2, 5},
        File{"nao_legs_scene.yaml", 0.2, 11}, File{"panda_gripper_scene.yaml", 0.2, 1},
        File{"quadruped_drop_scene.yaml", 0.05, 29}, File{"box_tip_scene.yaml", 0.2, 0},
        File{"two_carts_hook_scene.yaml", 0.5, 0}, File{"triple_integrator.yaml", 0.5, 0}}) {
    const int n = check_file(f.name, f.T);
    if (f.compared >= 0) {
      EXPECT_EQ(n, f.compared) << f.name;
    }
    std::cout << f.name << " T = " << f.T << ": " << n << " columns against differences\n";
  }
}

// Files with friction (planar stick / slip and impacts, issue 28's "every
// shipped model"): x0 and f[0] as above, to their t_end (the spinning disk,
// which bounces with e = 0.5 from its start, to 0.5 s: three impacts before
// its accumulation at 0.61 s, whose limit's derivative is that of the limit
// as the run takes it). Each starts on its floor: the x0 entries that move
// the gap or its rate (y, vy; the disk's too) are absent, and the spring's
// vx (it starts at rest and slips: one-sided), the others and f[0] compared
// (columns: 3, 3, 3, 2, 5). M[i][j] and e[c] on them: test_sensitivity_friction_params.cpp.
TEST(SensitivityFiles, FrictionFilesAgainstCentralDifferences) {
  struct File {
    const char* name;
    double T;
    int compared;
  };
  for (const File& f :
       {File{"belt_friction.yaml", 3.0, 3}, File{"block_on_floor_friction.yaml", 1.0, 3},
        File{"incline_friction.yaml", 2.0, 3}, File{"mass_spring_friction.yaml", 5.0, 2},
        File{"spinning_disk_friction.yaml", 0.5, 5}}) {
    const int n = check_file(f.name, f.T);
    EXPECT_EQ(n, f.compared) << f.name;
    std::cout << f.name << " T = " << f.T << ": " << n << " columns against differences\n";
  }
}

// A scene contact's reference gap (issue 28: "the reference configuration's
// gap of a scene contact"): the scene's contact rows are constraints of the
// linearised model whose offset g_c is that contact's gap at the reference
// configuration q0 (robots/box_drop_scene.yaml: -0.05 m for the bottom
// corners, the box's pose 0.05 m above the floor and its half-size 0.1 m), so
// g[<contact name>] is that parameter: no second name (phi[...]) is added.
// Checked on the box dropped with a tilt (angular velocity (0.3, 0.2) rad/s
// about x and y) to T = 0.2 s, after its first corner's impact at 0.196 s
// and before the next at 0.203 s, against central differences of g_c (step
// 1e-4 m, tolerance as above).
TEST(SensitivityFiles, SceneContactReferenceGapIsG) {
  const mech::Model m = load_file("box_drop_scene.yaml");
  VectorXd x0 = m.initial;
  x0(9) = 0.3;
  x0(10) = 0.2;
  const double T = 0.2;
  std::vector<std::string> cols;
  for (const std::string& c : m.mechanical->constraints) cols.push_back("g[" + c + "]");
  const sim::Trajectory tr = exact(m, x0, T, cols);
  ASSERT_TRUE(tr.ok()) << tr.message;
  ASSERT_TRUE(tr.sensitivity_losses.empty()) << tr.sensitivity_losses.front().reason;
  ASSERT_EQ(tr.events.size(), 1u);  // the first corner's impact
  const double xs = std::max(1.0, tr.final_state.cwiseAbs().maxCoeff());
  double largest = 0.0;
  for (int c = 0; c < static_cast<int>(cols.size()); ++c) {
    auto fd = [&](double d) {
      VectorXd out[2];
      for (int s = 0; s < 2; ++s) {
        mech::Model mm = m;
        mm.mechanical->g(c) += s == 0 ? d : -d;
        const sim::Trajectory t2 = exact(mm, x0, T);
        EXPECT_TRUE(t2.ok()) << t2.message;
        EXPECT_EQ(t2.events.size(), tr.events.size()) << cols[static_cast<size_t>(c)];
        out[s] = t2.final_state;
      }
      return VectorXd((out[0] - out[1]) / (2 * d));
    };
    const double d0 = 1e-4;
    const VectorXd d1 = fd(d0), d2 = fd(d0 / 2);
    for (int i = 0; i < d2.size(); ++i) {
      const double tol = 4 * std::abs(d1(i) - d2(i)) + 64e-13 * xs / d0;
      EXPECT_NEAR(tr.dx_final(i, c), d2(i), tol)
          << "dx[" << i << "]/d" << cols[static_cast<size_t>(c)];
    }
    largest = std::max(largest, tr.dx_final.col(c).cwiseAbs().maxCoeff());
  }
  EXPECT_GT(largest, 1.0);  // the impacting corner's gap moves the state: not all zero
}

}  // namespace
}  // namespace lcsim
