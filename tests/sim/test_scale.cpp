// Moreau–Jean at scale (src/sim/stepping/time_stepping.cpp): the chain of N carts of
// `lcsim generate chain` (unit masses, unit springs between neighbours and from
// cart 0 to the wall, a stop q_i + 1 >= 0 per cart, optional hooks
// q_i - q_{i+1} + 0.5 >= 0), started at x_i = 0.1 (i mod 3), v_i = -1, so every
// cart hits its stop near t = 1 at a different time. The sparse path
// (SimplicialLDLT, cached pruned columns of W^{-1} E') must agree with the
// dense one (LLT) on the same model, and both must keep the invariants of the
// scheme. No timings here: bench/bench_chain.cpp measures them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/sim/sim.hpp>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

mech::Model chain(int n, bool hooks) { return mech::chain_model({n, true, hooks, true}); }

VectorXd chain_start(int n) { return chain(n, false).initial; }

sim::Trajectory run(const mech::Model& model, double t_end, double h, double theta,
                    int sparse_threshold, bool samples = true) {
  sim::Options opt;
  opt.t_end = t_end;
  opt.h = h;
  opt.theta = theta;
  opt.sparse_dofs_threshold = sparse_threshold;
  opt.record_samples = samples;
  return sim::make_integrator("moreau-jean")
      ->run(model, chain_start(model.mechanical->dofs()), opt);
}

constexpr int kForceSparse = 0;
constexpr int kForceDense = 1 << 30;

// Same algorithm, same active sets, same LCP solver on each step: the paths
// differ only in the rounding of the factorisations and products and in the
// pruning of W^{-1} E' below 1e-17 of its largest entry, so they agree far
// below 1e-10 over 3000 steps through all the impacts.
TEST(Scale, SparsePathAgreesWithDensePath) {
  for (const bool hooks : {false, true}) {
    for (const int n : {10, 40, 100}) {
      const mech::Model model = chain(n, hooks);
      const sim::Trajectory d = run(model, 3.0, 1e-3, 0.5, kForceDense);
      const sim::Trajectory s = run(model, 3.0, 1e-3, 0.5, kForceSparse);
      ASSERT_EQ(d.status, sim::RunStatus::kCompleted) << d.message;
      ASSERT_EQ(s.status, sim::RunStatus::kCompleted) << s.message;
      ASSERT_EQ(d.samples.size(), s.samples.size());
      double dev = 0.0;
      for (size_t j = 0; j < d.samples.size(); ++j)
        dev = std::max(dev, (d.samples[j].x - s.samples[j].x).cwiseAbs().maxCoeff());
      EXPECT_LE(dev, 1e-10) << "n = " << n << (hooks ? " with hooks" : "");
      EXPECT_NEAR(d.energy_final, s.energy_final, 1e-10);
      EXPECT_GT(d.lcp_solves, 0);
    }
  }
}

// theta = 1, e = 0, D = 0: E+ - E = lambda' E_A v+ - ½(|v+ - v|_M^2 + h^2 |v+|_K^2)
// and lambda' E_A v+ = lambda' w = 0 by complementarity, so the energy never
// rises; the PGS residual (<= 1e-13 (1 + |b|)) and rounding allow 1e-11 per step.
TEST(Scale, EnergyNeverRisesThetaOne) {
  for (const int threshold : {kForceSparse, kForceDense}) {
    const mech::Model model = chain(100, true);
    const mech::MechanicalModel& m = *model.mechanical;
    const sim::Trajectory tr = run(model, 3.0, 1e-3, 1.0, threshold);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    double prev = tr.energy_initial, worst_rise = -1.0;
    for (const sim::Sample& s : tr.samples) {
      const double en = mech::total_energy(m, s.x.head(100), s.x.tail(100));
      worst_rise = std::max(worst_rise, en - prev);
      prev = en;
    }
    EXPECT_LE(worst_rise, 1e-11);
    EXPECT_LT(tr.energy_final, tr.energy_initial);
  }
}

// Feasibility to O(h): an active constraint ends its step with
// y+ >= y + h (1 - theta) E_i v >= -h (1 - theta) |E_i v|, so the worst gap
// over the run is above -h (1 - theta) max|E v| - O(h^2), and it shrinks
// with h.
TEST(Scale, FeasibilityToOrderH) {
  const mech::Model model = chain(300, true);
  double prev = 0.0;
  for (const double h : {1e-3, 1e-4}) {
    const sim::Trajectory tr = run(model, 2.0, h, 0.5, 64, false);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    // |E_i v| <= 2 max|v| for hooks; the carts never exceed |v| = 1.5 here.
    EXPECT_GE(tr.max_violation, -h * 0.5 * 3.0 - 10 * h * h) << "h = " << h;
    EXPECT_LT(tr.max_violation, 0.0);
    if (prev < 0.0) {
      EXPECT_GT(tr.max_violation, 0.2 * prev);  // about 10x smaller
    }
    prev = tr.max_violation;
  }
}

// The active-set rule drops a constraint only when its predicted gap
// E_i (q + h theta v) + g_i is > 0. Such a constraint then ends the step at
// y+ = predicted + h (1 - theta) E_i v + h theta E_i (v+ - v) >=
// -h (1 - theta) |E_i v| - h theta |E_i (v+ - v)|, and v+ - v is O(h) for the
// carts a dropped constraint touches (smooth forces; impulses on neighbours
// reach them through W^{-1} only at O(h^2)). Checked at every step with the
// documented bound h (1 - theta) |E_i v| + 10 h^2.
TEST(Scale, ActiveSetNeverDropsAConstraintThatEndsViolated) {
  for (const double theta : {0.5, 1.0}) {
    const int n = 200;
    const double h = 1e-3;
    const mech::Model model = chain(n, true);
    const mech::MechanicalModel& m = *model.mechanical;
    const sim::Trajectory tr = run(model, 3.0, h, theta, kForceSparse);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    long dropped = 0;
    double worst_excess = -1.0;
    for (size_t j = 0; j + 1 < tr.samples.size(); ++j) {
      const VectorXd q = tr.samples[j].x.head(n), v = tr.samples[j].x.tail(n);
      const VectorXd Ev = m.E * v;
      const VectorXd yp = m.E * q + m.g + h * theta * Ev;
      const VectorXd y_next = tr.samples[j + 1].y;
      for (int i = 0; i < m.num_constraints(); ++i) {
        if (yp(i) <= 0.0) continue;  // in the active set
        ++dropped;
        const double tol = h * (1.0 - theta) * std::abs(Ev(i)) + 10 * h * h;
        worst_excess = std::max(worst_excess, -y_next(i) - tol);
      }
    }
    EXPECT_GT(dropped, 0);
    EXPECT_LE(worst_excess, 0.0) << "theta = " << theta;
  }
}

// A large chain takes the sparse path by default and runs through the impacts.
TEST(Scale, LargeChainRunsSparseByDefault) {
  const mech::Model model = chain(2000, false);
  const sim::Trajectory tr =
      run(model, 1.5, 1e-3, 0.5, sim::Options{}.sparse_dofs_threshold, false);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  EXPECT_EQ(tr.steps, 1500);
  EXPECT_GT(tr.lcp_solves, 0);
  EXPECT_GE(tr.max_violation, -1e-3 * 0.5 * 2.5 - 1e-5);  // |v| < 2.5 here
  EXPECT_LT(tr.energy_final, tr.energy_initial);
}

}  // namespace
}  // namespace lcsim
