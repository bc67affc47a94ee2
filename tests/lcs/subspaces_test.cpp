// V_I (3.4), T_I (3.7), P_I, F_I and regular states (3.40) against the
// thesis's exact values: the two-carts system (3.1), the hook system (3.74) of
// Example 3.8.3 and the triple integrator of Example 7.3.3.
//
// Tolerances: all data below are small integers, so every exact value is
// computed by a handful of SVD/QR steps with backward error ~1e-16 on O(1)
// numbers; 1e-12 leaves four orders of magnitude of room and is still far
// below any structural difference (which is O(1)).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <lcsim/lcs/lcs.hpp>
#include <stdexcept>

namespace lcsim::lcs {
namespace {

constexpr double kExact = 1e-12;

Lcs two_carts() {  // eq. (3.1)
  Lcs s;
  s.A.resize(4, 4);
  s.A << 0, 0, 1, 0,  //
      0, 0, 0, 1,     //
      -2, 1, 0, 0,    //
      1, -1, 0, 0;
  s.B = (MatrixXd(4, 1) << 0, 0, 1, 0).finished();
  s.C = (MatrixXd(1, 4) << 1, 0, 0, 0).finished();
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

Lcs hook() {  // eq. (3.74) as an LCS (3.65): x = (q, v), y = E q
  Lcs s = two_carts();
  s.B.resize(4, 2);
  s.B << 0, 0, 0, 0, 1, 1, 0, -1;  // [0; M^{-1} E'], E = [1 0; 1 -1]
  s.C.resize(2, 4);
  s.C << 1, 0, 0, 0, 1, -1, 0, 0;
  s.D = MatrixXd::Zero(2, 2);
  return s;
}

Lcs triple_integrator() {  // Example 7.3.3
  Lcs s;
  s.A = (MatrixXd(3, 3) << 0, 1, 0, 0, 0, 1, 0, 0, 0).finished();
  s.B = (MatrixXd(3, 1) << 0, 0, 1).finished();
  s.C = (MatrixXd(1, 3) << 1, 0, 0).finished();
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

MatrixXd orthogonal_projector(const MatrixXd& basis) {
  return basis * basis.transpose();  // basis is orthonormal
}

MatrixXd columns(std::initializer_list<int> unit_vectors, int n) {
  MatrixXd X = MatrixXd::Zero(n, static_cast<int>(unit_vectors.size()));
  int j = 0;
  for (int e : unit_vectors) X(e, j++) = 1.0;
  return X;
}

void expect_orthonormal(const MatrixXd& X) {
  MatrixXd G = X.transpose() * X;
  G.diagonal().array() -= 1.0;
  EXPECT_LT(G.norm(), kExact);
}

TEST(ConsistentSubspace, TwoCartsConstrainedModeIsE2E4) {
  // §3.7 step three: V_{1} = Im[e2 e4] (0-based {1, 3}); compare projectors,
  // since the basis is only unique up to rotation.
  const auto V = consistent_subspace(two_carts(), {0}).basis;
  ASSERT_EQ(V.rows(), 4);
  ASSERT_EQ(V.cols(), 2);
  expect_orthonormal(V);
  EXPECT_LT((orthogonal_projector(V) - orthogonal_projector(columns({1, 3}, 4))).norm(), kExact);
}

TEST(JumpSpace, TwoCartsConstrainedModeIsE1E3) {
  const auto T = jump_space(two_carts(), {0}).basis;
  ASSERT_EQ(T.cols(), 2);
  expect_orthonormal(T);
  EXPECT_LT((orthogonal_projector(T) - orthogonal_projector(columns({0, 2}, 4))).norm(), kExact);
}

TEST(Subspaces, UnconstrainedModeIsWholeSpaceAndNoJump) {
  const Lcs s = two_carts();
  EXPECT_EQ(consistent_subspace(s, {}).basis.cols(), 4);  // V_{} = R^4
  EXPECT_EQ(jump_space(s, {}).basis.cols(), 0);           // T_{} = {0}
  const auto P = projection(s, {});
  ASSERT_TRUE(P.ok()) << P.message;
  EXPECT_LT((P.P - MatrixXd::Identity(4, 4)).norm(), kExact);
}

TEST(Projection, TwoCartsExample345) {
  const auto P = projection(two_carts(), {0});
  ASSERT_TRUE(P.ok()) << P.message;
  // Example 3.4.5 / §3.7: the left cart's velocity is reset to zero.
  EXPECT_LT((P.P * Eigen::Vector4d(0, -1, -1, 0) - Eigen::Vector4d(0, -1, 0, 0)).norm(), kExact);
  EXPECT_LT((P.P * Eigen::Vector4d(0, 1, -1, 0) - Eigen::Vector4d(0, 1, 0, 0)).norm(), kExact);
  // A projection: P^2 = P.
  EXPECT_LT((P.P * P.P - P.P).norm(), kExact);
}

TEST(Projection, HookModeExample383) {
  // Example 3.8.3: the hook constraint (0-based index 1) re-initialises
  // (0,0,-1,2) to (0,0,1/2,1/2): equal velocities with momentum 1/2 + 1/2 = 1.
  const Lcs s = hook();
  const auto V = consistent_subspace(s, {1}).basis;
  const auto T = jump_space(s, {1}).basis;
  EXPECT_EQ(V.cols(), 2);
  EXPECT_EQ(T.cols(), 2);
  const auto P = projection(s, {1});
  ASSERT_TRUE(P.ok()) << P.message;
  EXPECT_LT((P.P * Eigen::Vector4d(0, 0, -1, 2) - Eigen::Vector4d(0, 0, 0.5, 0.5)).norm(), kExact);
  // Both constraints active: only rest at q = 0 is consistent.
  EXPECT_EQ(consistent_subspace(s, {0, 1}).basis.cols(), 0);
  const auto P01 = projection(s, {0, 1});
  ASSERT_TRUE(P01.ok()) << P01.message;
  EXPECT_LT(P01.P.norm(), kExact);
}

TEST(Projection, TripleIntegratorModeHasNoConsistentState) {
  // Example 7.3.3 in mode {0}: y = x1 = 0 with all derivatives forces x = 0,
  // so V = {0}, T = R^3 and P x = 0 for every x.
  const Lcs s = triple_integrator();
  EXPECT_EQ(consistent_subspace(s, {0}).basis.cols(), 0);
  EXPECT_EQ(jump_space(s, {0}).basis.cols(), 3);
  const auto P = projection(s, {0});
  ASSERT_TRUE(P.ok()) << P.message;
  EXPECT_LT((P.P * Eigen::Vector3d(1, -2, 3)).norm(), kExact);
  EXPECT_LT(P.P.norm(), kExact);
}

TEST(Projection, InvertibleFeedthroughMode) {
  // D_II = 2 (rho = 0): u = -C x / 2 is algebraic, so there are no
  // constraints on x: V = R^n, T = {0}, P = I.
  Lcs s = two_carts();
  s.D(0, 0) = 2.0;
  EXPECT_EQ(consistent_subspace(s, {0}).basis.cols(), 4);
  EXPECT_EQ(jump_space(s, {0}).basis.cols(), 0);
  const auto P = projection(s, {0});
  ASSERT_TRUE(P.ok()) << P.message;
  EXPECT_LT((P.P - MatrixXd::Identity(4, 4)).norm(), kExact);
  const auto F = mode_feedback(s, {0});
  ASSERT_TRUE(F.ok()) << F.message;
  // F = -D^{-1} C = (-1/2, 0, 0, 0).
  EXPECT_LT((F.F - (MatrixXd(1, 4) << -0.5, 0, 0, 0).finished()).norm(), kExact);
}

TEST(Projection, NonAutonomousModeIsRefused) {
  // Input column zero: u has no effect, y = x1 must vanish with all its
  // derivatives and nothing can make it so (Lemma 3.3.3).
  Lcs s = two_carts();
  s.B.setZero();
  const auto P = projection(s, {0});
  EXPECT_FALSE(P.ok());
  EXPECT_NE(P.message.find("not autonomous"), std::string::npos) << P.message;
  const auto F = mode_feedback(s, {0});
  EXPECT_FALSE(F.ok());
  EXPECT_FALSE(F.message.empty());
}

TEST(Projection, DuplicateConstraintIsNotAutonomous) {
  // Two identical constraints (the same y, the same force direction): G_II is
  // singular, so the mode {0, 1} is not autonomous and script M_II singular.
  Lcs s = two_carts();
  s.B = (MatrixXd(4, 2) << 0, 0, 0, 0, 1, 1, 0, 0).finished();
  s.C = (MatrixXd(2, 4) << 1, 0, 0, 0, 1, 0, 0, 0).finished();
  s.D = MatrixXd::Zero(2, 2);
  const auto P = projection(s, {0, 1});
  EXPECT_FALSE(P.ok());
  EXPECT_NE(P.message.find("Ker [B_.I; D_II]"), std::string::npos) << P.message;
  const auto F = mode_feedback(s, {0, 1});
  EXPECT_FALSE(F.ok());
  EXPECT_NE(F.message.find("singular"), std::string::npos) << F.message;
}

TEST(Projection, RejectsBadIndexSets) {
  EXPECT_THROW(projection(two_carts(), {1}), std::invalid_argument);
  EXPECT_THROW(projection(hook(), {1, 0}), std::invalid_argument);
}

// F_I keeps V_I invariant under A + B_.I F_I and C_I x = 0 there (§3.4.1).
void expect_feedback_invariance(const Lcs& s, const IndexSet& I) {
  const auto F = mode_feedback(s, I);
  ASSERT_TRUE(F.ok()) << F.message;
  const MatrixXd V = consistent_subspace(s, I).basis;
  MatrixXd BI(s.n(), static_cast<int>(I.size())), CI(static_cast<int>(I.size()), s.n());
  for (std::size_t a = 0; a < I.size(); ++a) {
    BI.col(a) = s.B.col(I[a]);
    CI.row(a) = s.C.row(I[a]);
  }
  const MatrixXd Acl = s.A + BI * F.F;
  // (I - V V') Acl V = 0: the closed loop maps V_I into V_I. Rounding scales
  // with the terms summed in Acl = A + B_.I F_I (which cancel heavily for
  // stiff springs), so the bound is relative to ||A|| + ||B_.I|| ||F_I||.
  const double scale = s.A.norm() + BI.norm() * F.F.norm();
  EXPECT_LT(((MatrixXd::Identity(s.n(), s.n()) - V * V.transpose()) * Acl * V).norm(),
            kExact * std::max(1.0, scale));
  EXPECT_LT((CI * V).norm(), kExact * std::max(1.0, CI.norm()));
}

TEST(ModeFeedback, TwoCartsConstrainedMode) {
  const Lcs s = two_carts();
  const auto F = mode_feedback(s, {0});
  ASSERT_TRUE(F.ok()) << F.message;
  // §3.7 step four (with DESIGN.md's sign fix): y'' = -2x1 + x2 + u, so
  // F = -(C A^2) = (2, -1, 0, 0), and on V_{1} u = -x2.
  EXPECT_LT((F.F - (MatrixXd(1, 4) << 2, -1, 0, 0).finished()).norm(), kExact);
  expect_feedback_invariance(s, {0});
}

TEST(ModeFeedback, HookModesKeepTheirSubspacesInvariant) {
  const Lcs s = hook();
  expect_feedback_invariance(s, {0});
  expect_feedback_invariance(s, {1});
  expect_feedback_invariance(s, {0, 1});
  EXPECT_EQ(mode_feedback(s, {}).F.rows(), 0);
}

TEST(RegularState, TwoCartsCondition340) {
  const Lcs s = two_carts();
  // rho = 2: (x1, x3) must be lexicographically >= 0.
  EXPECT_TRUE(is_regular_state(s, Eigen::Vector4d(0, -1, 0, 0), 1e-9));
  EXPECT_FALSE(is_regular_state(s, Eigen::Vector4d(0, -1, -1, 0), 1e-9));
  EXPECT_TRUE(is_regular_state(s, Eigen::Vector4d(0, 1, 1, 0), 1e-9));
  EXPECT_TRUE(is_regular_state(s, Eigen::Vector4d(0.3, 0, -5, 0), 1e-9));
  EXPECT_FALSE(is_regular_state(s, Eigen::Vector4d(-1e-3, 0, 5, 0), 1e-9));
  // A rounding-level negative position is zero (relative tol 1e-9).
  EXPECT_TRUE(is_regular_state(s, Eigen::Vector4d(-1e-15, -1, 0, 0), 1e-9));
}

// Rank decisions must not change when A, B, C are scaled by 1e6 or 1e-6
// (time and unit changes): compare dimensions and the subspaces themselves.
class ScaleInvariance : public ::testing::TestWithParam<double> {};

TEST_P(ScaleInvariance, SameSubspacesAndProjection) {
  const double c = GetParam();
  for (const Lcs& base : {two_carts(), hook()}) {
    Lcs s = base;
    s.A *= c;
    s.B *= c;
    s.C *= c;
    for (const IndexSet& I : {IndexSet{}, IndexSet{0}, IndexSet{static_cast<int>(s.k()) - 1},
                              IndexSet{0, static_cast<int>(s.k()) - 1}}) {
      if (I.size() == 2 && I[0] == I[1]) continue;
      const auto V0 = consistent_subspace(base, I).basis;
      const auto T0 = jump_space(base, I).basis;
      const auto V = consistent_subspace(s, I).basis;
      const auto T = jump_space(s, I).basis;
      ASSERT_EQ(V.cols(), V0.cols());
      ASSERT_EQ(T.cols(), T0.cols());
      EXPECT_LT((orthogonal_projector(V) - orthogonal_projector(V0)).norm(), kExact);
      EXPECT_LT((orthogonal_projector(T) - orthogonal_projector(T0)).norm(), kExact);
      const auto P0 = projection(base, I), P = projection(s, I);
      ASSERT_EQ(P.ok(), P0.ok());
      if (P.ok()) {
        EXPECT_LT((P.P - P0.P).norm(), kExact);
      }
    }
  }
  Lcs t = triple_integrator();
  t.A *= c;
  t.B *= c;
  t.C *= c;
  EXPECT_EQ(consistent_subspace(t, {0}).basis.cols(), 0);
  EXPECT_EQ(jump_space(t, {0}).basis.cols(), 3);
  // Leading indices and the regularity test are unchanged as well.
  Lcs s = two_carts();
  s.A *= c;
  s.B *= c;
  s.C *= c;
  EXPECT_EQ(leading_row_indices(s), std::vector<int>{2});
  EXPECT_TRUE(is_regular_state(s, Eigen::Vector4d(0, -1, 0, 0), 1e-9));
  EXPECT_FALSE(is_regular_state(s, Eigen::Vector4d(0, -1, -1, 0), 1e-9));
}

INSTANTIATE_TEST_SUITE_P(Scales, ScaleInvariance, ::testing::Values(1e6, 1e-6));

}  // namespace
}  // namespace lcsim::lcs

namespace lcsim::lcs {
namespace {

// A mechanical LCS (3.65) with the gap carried by a constant state c:
// x = (q, v, c), A = [0 I 0; -M^{-1}K 0 0; 0 0 0], B = [0; M^{-1}E'; 0],
// C = [E 0 g], D = 0. For E_I of full row rank the recursions give exactly
// V_I = {E_I q + g_I c = 0, E_I v = 0} and T_I = Im blockdiag(M^{-1}E_I',
// M^{-1}E_I', 0) (§3.8), so P_I is Moreau's inelastic projection (3.69)-(3.70):
// v+ = v - M^{-1}E_I'(E_I M^{-1}E_I')^{-1} E_I v, and the same for q with the
// gap.
struct Mechanical {
  Lcs sys;
  MatrixXd M, E;
  VectorXd g;
};

Mechanical random_mechanical(int N, int k, double mass_ratio, unsigned seed) {
  std::srand(seed);
  Mechanical m;
  // Masses spread log-uniformly over [1, mass_ratio], coupled by springs.
  VectorXd masses(N);
  for (int i = 0; i < N; ++i) masses(i) = std::pow(mass_ratio, static_cast<double>(i) / (N - 1));
  const MatrixXd R = MatrixXd::Random(N, N);
  m.M = masses.asDiagonal();
  m.M += 0.1 * masses.minCoeff() * R * R.transpose() / N;  // SPD, not diagonal
  const MatrixXd S = MatrixXd::Random(N, N);
  const MatrixXd K = 1e3 * (S * S.transpose() + MatrixXd::Identity(N, N));
  m.E = MatrixXd::Random(k, N);
  m.g = VectorXd::Random(k);
  const int n = 2 * N + 1;
  const MatrixXd Minv = m.M.inverse();
  m.sys.A = MatrixXd::Zero(n, n);
  m.sys.A.block(0, N, N, N).setIdentity();
  m.sys.A.block(N, 0, N, N) = -Minv * K;
  m.sys.B = MatrixXd::Zero(n, k);
  m.sys.B.block(N, 0, N, k) = Minv * m.E.transpose();
  m.sys.C = MatrixXd::Zero(k, n);
  m.sys.C.leftCols(N) = m.E;
  m.sys.C.col(n - 1) = m.g;
  m.sys.D = MatrixXd::Zero(k, k);
  return m;
}

TEST(Projection, MechanicalModeIsMoreausProjection) {
  const int N = 4, k = 3;
  for (double ratio : {1.0, 1e3, 1e6}) {
    const Mechanical m = random_mechanical(N, k, ratio, 7u);
    for (const IndexSet& I : {IndexSet{0}, IndexSet{1, 2}, IndexSet{0, 1, 2}}) {
      const int a = static_cast<int>(I.size());
      MatrixXd EI(a, N);
      VectorXd gI(a);
      for (int i = 0; i < a; ++i) {
        EI.row(i) = m.E.row(I[i]);
        gI(i) = m.g(I[i]);
      }
      const MatrixXd MinvEt = m.M.ldlt().solve(EI.transpose());
      const MatrixXd W = EI * MinvEt;  // Delassus matrix of the mode
      const MatrixXd Pv = MatrixXd::Identity(N, N) - MinvEt * W.ldlt().solve(EI);
      const VectorXd x = VectorXd::Random(2 * N + 1);
      VectorXd expected(2 * N + 1);
      expected.head(N) = x.head(N) - MinvEt * W.ldlt().solve(EI * x.head(N) + gI * x(2 * N));
      expected.segment(N, N) = Pv * x.segment(N, N);
      expected(2 * N) = x(2 * N);

      EXPECT_EQ(consistent_subspace(m.sys, I).basis.cols(), 2 * N + 1 - 2 * a);
      EXPECT_EQ(jump_space(m.sys, I).basis.cols(), 2 * a);
      const auto P = projection(m.sys, I);
      ASSERT_TRUE(P.ok()) << P.message;
      // The closed form and P both lose ~cond(M) * eps relative accuracy
      // (mass ratio up to 1e6 -> ~1e-10); 1e-8 relative to |x| leaves a margin.
      EXPECT_LT((P.P * x - expected).norm(), 1e-8 * x.norm())
          << "mass ratio " << ratio << ", |I| = " << a;
      expect_feedback_invariance(m.sys, I);
    }
  }
}

}  // namespace
}  // namespace lcsim::lcs
