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

// One coordinate x (mass m, force f) held by six unilateral rows a_i x >= 0
// of both signs, every gap zero at rest: the rows are dependent (rank 1), so
// the LCP of the mode selection has many solutions. Pivoting ended on one
// that loads several rows in one direction: script M_II was singular and
// the exact method stopped ("leading row coefficient block of the active set
// is singular"), as a cube of bullet3's cube_small.urdf dropped flat on its
// four corners did. These numbers are one of 4 random draws in 54 that
// failed so. Now the multipliers are moved along the null space of B's
// columns to a vertex: the mode's rows are independent and its feedback
// holds x at rest (x'' = 0, to a few ulps of the O(10) terms: 1e-12).
TEST(Ldcp, DependentRowsOfBothSignsGiveAnIndependentMode) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Constant(1, 1, 2.3996686914048175).sparseView();
  m.K = MatrixXd::Zero(1, 1).sparseView();
  m.f = VectorXd::Constant(1, 9.310632356874635);
  VectorXd a(6);
  a << 1.596612827147528, -1.4186477981120906, 1.2912343448531378, -0.5334624922662704,
      2.4017950605003935, -1.3004111999435164;
  m.E = MatrixXd(a).sparseView();
  m.g = VectorXd::Zero(6);
  mech::fill_defaults(m);
  const Lcs sys = mech::to_lcs(m);
  const Eigen::Vector3d x0(0, 0, 1);
  LdcpOptions o;
  o.regular_only = true;  // as the exact method selects a resting state's mode
  const auto sel = select_mode(sys, x0, o);
  ASSERT_TRUE(sel.ok()) << sel.message;
  ASSERT_FALSE(sel.mode.empty());
  MatrixXd BI(3, static_cast<Eigen::Index>(sel.mode.size()));
  for (size_t i = 0; i < sel.mode.size(); ++i)
    BI.col(static_cast<Eigen::Index>(i)) = sys.B.col(sel.mode[i]);
  EXPECT_EQ(numerical_rank(BI), static_cast<int>(sel.mode.size()));
  const auto fb = mode_feedback(sys, sel.mode);
  ASSERT_TRUE(fb.ok()) << fb.message;
  const VectorXd xdot = (sys.A + BI * fb.F) * x0;
  EXPECT_NEAR(xdot(0), 0.0, 1e-12);
  EXPECT_NEAR(xdot(1), 0.0, 1e-12);
}

}  // namespace
}  // namespace lcsim::lcs
