// The mechanical LCS (3.65) through the LCS layer: Theorem 3.8.2 says the
// LDCP re-initialisation is Moreau's rule; §3.4.2 says it is P_I x0.
#include <gtest/gtest.h>

#include <lcsim/lcs/lcs.hpp>
#include <lcsim/mech/mech.hpp>
#include <random>

namespace lcsim::lcs {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// On random mechanical models (full-rank E, feasible gap-zero states), the
// LDCP jump equals P_I x0 for the mode it selects: two independent routes
// to the re-initialisation (Theorem 3.8.2 and §3.4.2). The tolerance 1e-9
// allows for the conditioning of random M (cond <= ~1e3 here).
TEST(Ldcp, JumpEqualsProjectionOnRandomMechanicalModels) {
  std::mt19937 gen(42);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  int checked = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const int N = 3, k = 2;
    MatrixXd R(N, N), S(N, N);
    for (int i = 0; i < N; ++i)
      for (int j = 0; j < N; ++j) {
        R(i, j) = U(gen);
        S(i, j) = U(gen);
      }
    mech::MechanicalModel m;
    m.M = (R * R.transpose() + 0.5 * MatrixXd::Identity(N, N)).sparseView();
    m.K = (S * S.transpose()).sparseView();
    m.E.resize(k, N);
    for (int i = 0; i < k; ++i)
      for (int j = 0; j < N; ++j) m.E.coeffRef(i, j) = U(gen);
    mech::fill_defaults(m);
    const Lcs sys = mech::to_lcs(m);
    // q = 0 puts both gaps at zero; a random velocity.
    VectorXd x = VectorXd::Zero(2 * N + 1);
    for (int i = 0; i < N; ++i) x(N + i) = U(gen);
    x(2 * N) = 1.0;
    const auto sel = select_mode(sys, x);
    ASSERT_TRUE(sel.ok()) << sel.message;
    if (sel.mode.empty()) continue;
    const auto P = projection(sys, sel.mode);
    ASSERT_TRUE(P.ok()) << P.message;
    EXPECT_LE((P.P * x - sel.x_plus).norm(), 1e-9 * (1.0 + x.norm())) << "trial " << trial;
    // Moreau: the post-jump rates of the active constraints vanish.
    const VectorXd rates = m.E * sel.x_plus.segment(N, N);
    for (int r : sel.mode) EXPECT_NEAR(rates(r), 0.0, 1e-10);
    ++checked;
  }
  EXPECT_GT(checked, 50);
}

}  // namespace
}  // namespace lcsim::lcs
