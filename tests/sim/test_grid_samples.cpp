// The exact method's output grid (issue 24, item 2): samples at exactly
// k dt_out, each stepped from the one before by the mode's step exponential,
// checked on one long phase against the chain's modal solution (an
// eigendecomposition of K, independent of any matrix exponential).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <lcsim/sim/sim.hpp>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// 32 carts and springs without stops (65 states with the constant-force
// state, above the dense-exponential limit of 64: the action path, then the
// step exponential once the actions have cost as much), one 10 s phase,
// 10^4 samples.
TEST(GridSamples, StepFromSampleToSampleOnTheExactGrid) {
  const int n = 32;
  const mech::Model model = mech::chain_model({n, false, false, true});
  sim::Options opt;
  opt.t_end = 10.0;
  opt.dt_out = 1e-3;
  const auto tr = sim::simulate_event_driven(model, model.initial, opt);
  ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
  // t = 0, the grid 1e-3 ... 9.999 and t_end: a running sum of dt_out
  // reached 9.99999999999998 < t_end and added a sample an ulp before it.
  ASSERT_EQ(tr.samples.size(), 10001u);
  for (size_t i = 0; i < tr.samples.size(); ++i)
    ASSERT_EQ(tr.samples[i].t, static_cast<double>(i) * opt.dt_out) << "sample " << i;

  // Modal solution: M = I, K = V diag(w^2) V'.
  const MatrixXd K = MatrixXd(model.mechanical->K);
  const Eigen::SelfAdjointEigenSolver<MatrixXd> eig(K);
  const VectorXd w = eig.eigenvalues().cwiseSqrt();
  const MatrixXd& V = eig.eigenvectors();
  const VectorXd a = V.transpose() * model.initial.head(n);
  const VectorXd b = V.transpose() * model.initial.tail(n);
  double worst = 0.0, scale = 0.0;
  for (const auto& s : tr.samples) {
    const Eigen::ArrayXd c = (w * s.t).array().cos(), sn = (w * s.t).array().sin();
    const VectorXd q = V * (a.array() * c + b.array() / w.array() * sn).matrix();
    const VectorXd v = V * (-a.array() * w.array() * sn + b.array() * c).matrix();
    worst = std::max(worst, std::max((s.x.head(n) - q).cwiseAbs().maxCoeff(),
                                     (s.x.tail(n) - v).cwiseAbs().maxCoeff()));
    scale = std::max(scale, s.x.cwiseAbs().maxCoeff());
  }
  // Each step's product rounds by at most 65 eps of the state's size, and
  // the chain's motion (energy-conserving, balanced) does not amplify it:
  // 10^4 steps accumulate at most 1e4 * 65 eps * max|x| (1.4e-9 here, x ~ 10);
  // measured 6.3e-13 (8e-14 when every sample was evaluated from the start).
  // A sample a step off the grid would be off by dt |v| ~ 1e-3.
  EXPECT_LE(worst, 1e4 * 65 * 2.22e-16 * scale) << "max |x| " << scale;
}

}  // namespace
}  // namespace lcsim
