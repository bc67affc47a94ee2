// Mode selection by the LDCP (§3.5.2) against the thesis's worked examples,
// and the jump it computes against the projection P_I of §3.4.2.
//
// Tolerances: the LDCP here involves a handful of products of O(1) matrices
// and LCPs of size <= 2 solved by pivoting, so its numbers are exact to a few
// ulps; 1e-12 leaves a margin of ~1e3 while any wrong mode or impulse is off
// by O(1).
#include <gtest/gtest.h>

#include <lcsim/lcs/lcs.hpp>

namespace lcsim::lcs {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector4d;
using Eigen::VectorXd;

Lcs two_carts() {  // eq. (3.1)
  Lcs s;
  s.A.resize(4, 4);
  s.A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  s.B = MatrixXd::Zero(4, 1);
  s.B(2, 0) = 1;
  s.C = MatrixXd::Zero(1, 4);
  s.C(0, 0) = 1;
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

Lcs hook() {  // Example 3.8.3
  Lcs s;
  s.A.resize(4, 4);
  s.A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  s.B.resize(4, 2);
  s.B << 0, 0, 0, 0, 1, 1, 0, -1;
  s.C.resize(2, 4);
  s.C << 1, 0, 0, 0, 1, -1, 0, 0;
  s.D = MatrixXd::Zero(2, 2);
  return s;
}

// §3.7 step one at (0,-1,-1,0): u(s) = 1 + s/(s^2+1), so u^0 = 1 (a Dirac of
// weight 1), the constrained mode, and the jump to (0,-1,0,0).
TEST(Ldcp, TwoCartsImpact) {
  const auto sel = select_mode(two_carts(), Vector4d(0, -1, -1, 0));
  ASSERT_TRUE(sel.ok()) << sel.message;
  EXPECT_EQ(sel.mode, (IndexSet{0}));
  EXPECT_NEAR(sel.impulse[0](0), 1.0, 1e-12);
  for (size_t j = 1; j < sel.impulse.size(); ++j) EXPECT_EQ(sel.impulse[j](0), 0.0);
  EXPECT_LE((sel.x_plus - Vector4d(0, -1, 0, 0)).norm(), 1e-12);
}

// §3.7 at (0,0,0,1): LDCP_4 selects the unconstrained mode (y^4 = 1 > 0).
TEST(Ldcp, TwoCartsReleaseSelectsUnconstrained) {
  const auto sel = select_mode(two_carts(), Vector4d(0, 0, 0, 1));
  ASSERT_TRUE(sel.ok()) << sel.message;
  EXPECT_TRUE(sel.mode.empty());
  EXPECT_TRUE(sel.undetermined.empty());
  EXPECT_LE((sel.x_plus - Vector4d(0, 0, 0, 1)).norm(), 0.0);
}

// Example 3.4.4: (0,-1,0,0) is regular and continues constrained (u = cos t).
TEST(Ldcp, RegularConstrainedState) {
  LdcpOptions o;
  o.regular_only = true;
  const auto sel = select_mode(two_carts(), Vector4d(0, -1, 0, 0), o);
  ASSERT_TRUE(sel.ok()) << sel.message;
  EXPECT_EQ(sel.mode, (IndexSet{0}));
  // regular_only refuses the irregular (0,-1,-1,0) with a message, no guess.
  const auto bad = select_mode(two_carts(), Vector4d(0, -1, -1, 0), o);
  EXPECT_FALSE(bad.ok());
  EXPECT_NE(bad.message.find("not regular"), std::string::npos);
}

// Example 3.8.3 at (0,0,-1,2): the hook alone, jump to (0,0,½,½).
TEST(Ldcp, HookOnlyMode) {
  const auto sel = select_mode(hook(), Vector4d(0, 0, -1, 2));
  ASSERT_TRUE(sel.ok()) << sel.message;
  EXPECT_EQ(sel.mode, (IndexSet{1}));
  EXPECT_LE((sel.x_plus - Vector4d(0, 0, 0.5, 0.5)).norm(), 1e-12);
  // The same jump as the projection onto V_{hook} along T_{hook} (§3.4.2).
  const auto P = projection(hook(), IndexSet{1});
  ASSERT_TRUE(P.ok()) << P.message;
  EXPECT_LE((P.P * Vector4d(0, 0, -1, 2) - sel.x_plus).norm(), 1e-12);
}

// Example 7.3.3: the triple integrator from (0,-1,0) needs u = delta'
// (impulse[1] = 1): the jump goes to V = {0}.
TEST(Ldcp, TripleIntegratorDeltaPrime) {
  Lcs s;
  s.A = MatrixXd::Zero(3, 3);
  s.A(0, 1) = 1;
  s.A(1, 2) = 1;
  s.B = MatrixXd::Zero(3, 1);
  s.B(2, 0) = 1;
  s.C = MatrixXd::Zero(1, 3);
  s.C(0, 0) = 1;
  s.D = MatrixXd::Zero(1, 1);
  const auto sel = select_mode(s, Eigen::Vector3d(0, -1, 0));
  ASSERT_TRUE(sel.ok()) << sel.message;
  EXPECT_EQ(sel.mode, (IndexSet{0}));
  EXPECT_NEAR(sel.impulse[1](0), 1.0, 1e-12);  // coefficient of delta'
  EXPECT_NEAR(sel.impulse[0](0), 0.0, 1e-12);
  EXPECT_LE(sel.x_plus.norm(), 1e-12);
}

// An ideal full-wave diode bridge (Siconos's DiodeBridge) in units where the
// tank's C and L and the load's R are 1: x = (v, i), the tank voltage and
// inductor current; diode 1 (a -> p) in voltage form (u1 = its reverse
// voltage, y1 = its current), diodes 2..4 in current form. By hand from
// Kirchhoff's laws: C v' = -i + u2 - u4, L i' = v, y1 = -u2 + u3 + u4,
// y2 = v + u1, y3 = -u1 + R (u3 + u4), y4 = -v - u1 + R (u3 + u4). D has a
// zero diagonal in rows 1 and 2 (the skew coupling of the two forms) and
// equal rows 3 and 4: D + D' >= 0 (passive) but D is no P-matrix.
Lcs diode_bridge() {
  Lcs s;
  s.A.resize(2, 2);
  s.A << 0, -1, 1, 0;
  s.B.resize(2, 4);
  s.B << 0, 1, 0, -1, 0, 0, 0, 0;
  s.C.resize(4, 2);
  s.C << 0, 0, 1, 0, 0, 0, -1, 0;
  s.D.resize(4, 4);
  s.D << 0, -1, 1, 1, 1, 0, 0, 0, -1, 0, 1, 1, -1, 0, 1, 1;
  return s;
}

// At a zero of v the bridge's four diodes switch at once. With i = 1 the tank
// voltage falls (v' = -1): diodes 2 and 3 conduct and 1 blocks, mode {0, 1, 2};
// the level-2 LCP (y^2 = C A x0 + D u^2) has the unique solution
// u^2 = (1, 1, 1, 0), y^2 = (0, 0, 0, 1) (by hand). With i = -1 it rises: 1
// and 4 conduct, mode {3}, u^2 = (0, 0, 0, 1). Before the fix the zero
// diagonal of D made u1 and u2 "rounding" (tol / 1e-300) and the mode {2}.
TEST(Ldcp, DiodeBridgeZeroDiagonalSkewCoupling) {
  const Lcs s = diode_bridge();
  for (const bool regular : {false, true}) {
    LdcpOptions o;
    o.regular_only = regular;
    const auto falling = select_mode(s, Eigen::Vector2d(0, 1), o);
    ASSERT_TRUE(falling.ok()) << falling.message;
    EXPECT_EQ(falling.mode, (IndexSet{0, 1, 2}));
    EXPECT_TRUE(falling.undetermined.empty());
    const auto rising = select_mode(s, Eigen::Vector2d(0, -1), o);
    ASSERT_TRUE(rising.ok()) << rising.message;
    EXPECT_EQ(rising.mode, (IndexSet{3}));
    EXPECT_TRUE(rising.undetermined.empty());
    // Away from a zero the sign of v alone decides (level 1).
    EXPECT_EQ(select_mode(s, Eigen::Vector2d(1, 0), o).mode, (IndexSet{3}));
    EXPECT_EQ(select_mode(s, Eigen::Vector2d(-1, 0), o).mode, (IndexSet{0, 1, 2}));
    // No jump: the state is regular (exactly: no impulse is computed at all).
    EXPECT_EQ(falling.x_plus, Eigen::Vector2d(0, 1));
  }
}

}  // namespace
}  // namespace lcsim::lcs

namespace lcsim::lcs {
namespace {

// A unit point mass in the plane, x0 = (x, z, vx, vz, 1), under gravity g
// (9.81 or 0), resting on two copies of the floor row z >= 0 (dependent
// constraints, as a box's coplanar corners give); `spring` pulls x towards
// 0 with stiffness 1, which the floor rows do not see.
Lcs twin_floor(bool spring, double g = 9.81) {
  Lcs s;
  s.A = MatrixXd::Zero(5, 5);
  s.A(0, 2) = s.A(1, 3) = 1.0;
  s.A(3, 4) = -g;
  if (spring) s.A(2, 0) = -1.0;
  s.B = MatrixXd::Zero(5, 2);
  s.B(3, 0) = s.B(3, 1) = 1.0;
  s.C = MatrixXd::Zero(2, 5);
  s.C(0, 1) = s.C(1, 1) = 1.0;
  s.D = MatrixXd::Zero(2, 2);
  return s;
}

// Under gravity one row of the pair carries the weight (9.81) from level 1
// on, and the other, whose row [C D] is the active one's, is undetermined
// from there (mark_dependent: u and y identically zero, Remark 3.4.8), so
// the LDCP stops after level 1 with the spring or without it: the same mode
// and undetermined row, no jump.
TEST(Ldcp, DependentRowIsUndeterminedFromTheLevelItIsFound) {
  LdcpOptions o;
  o.regular_only = true;
  VectorXd x0(5);
  x0 << 1.0, 0.0, 0.0, 0.0, 1.0;  // on the floor, at rest, 1 m from the spring's rest
  const ModeSelection stop = select_mode(twin_floor(false), x0, o);
  const ModeSelection all = select_mode(twin_floor(true), x0, o);
  ASSERT_TRUE(stop.ok()) << stop.message;
  ASSERT_TRUE(all.ok()) << all.message;
  // Level 1's singular 2 x 2 LCP takes two attempts (principal pivoting,
  // then Lemke), and no level follows.
  EXPECT_EQ(stop.lcp_solves, 2);
  EXPECT_EQ(all.lcp_solves, 2);
  EXPECT_EQ(stop.mode, all.mode);
  EXPECT_EQ(stop.undetermined, all.undetermined);
  ASSERT_EQ(stop.mode.size(), 1u);
  ASSERT_EQ(stop.undetermined.size(), 1u);
  EXPECT_NE(stop.mode[0], stop.undetermined[0]);
  EXPECT_EQ(stop.x_plus, x0);  // regular: no jump
}

// Without gravity no row is active (nothing presses the floor), so no row
// is dependent on an active one and both stay undecided (u and y
// identically zero). Without the spring every level after the first
// repeats it exactly (its known part is zero: A^2 x0 = 0 and C A B u = 0)
// and the LDCP stops there (later_levels_repeat), not at n = 5; with the
// spring the free response never vanishes and every level 1..5 is solved.
// The z rows are the same, so the mode (empty), the undetermined rows (both)
// and the (absent) jump are too.
TEST(Ldcp, StopsAtRepeatingLevelsWithTheSameMode) {
  LdcpOptions o;
  o.regular_only = true;
  VectorXd x0(5);
  x0 << 1.0, 0.0, 0.0, 0.0, 1.0;
  const ModeSelection stop = select_mode(twin_floor(false, 0.0), x0, o);
  const ModeSelection all = select_mode(twin_floor(true, 0.0), x0, o);
  ASSERT_TRUE(stop.ok()) << stop.message;
  ASSERT_TRUE(all.ok()) << all.message;
  // One attempt per level (q = 0: the pivoting solver's first basis
  // solves it): level 1 with the stop, levels 1..5 without.
  EXPECT_EQ(stop.lcp_solves, 1);
  EXPECT_EQ(all.lcp_solves, 5);
  EXPECT_TRUE(stop.mode.empty());
  EXPECT_EQ(stop.mode, all.mode);
  EXPECT_EQ(stop.undetermined, (IndexSet{0, 1}));
  EXPECT_EQ(stop.undetermined, all.undetermined);
  EXPECT_EQ(stop.x_plus, x0);
}

}  // namespace
}  // namespace lcsim::lcs

namespace lcsim::lcs {
namespace {

// The two carts of eq. (3.1) in a time 2^k times faster, t' = t / 2^k:
// (A, B) 2^k (A, B). The same motion, so the same mode selection: the mode,
// the undetermined rows and x_plus of the original, and each impulse of
// delta^(j) 2^(-k (j + 1)) times the original's (delta^(j)(t) =
// 2^(k (j + 1)) delta^(j)(t')).
Lcs fast_carts(int k) {
  Lcs s;
  s.A.resize(4, 4);
  s.A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  s.B = MatrixXd::Zero(4, 1);
  s.B(2, 0) = 1;
  s.A *= std::ldexp(1.0, k);  // exact: a power of two
  s.B *= std::ldexp(1.0, k);
  s.C = MatrixXd::Zero(1, 4);
  s.C(0, 0) = 1;
  s.D = MatrixXd::Zero(1, 1);
  return s;
}

// Issue 27 (the 80-link chain's overflow): at (0, 0, 0, 1) the LDCP decides
// at level 2 on C A^3 x0 (y''' = 1 > 0: the unconstrained mode, as
// TwoCartsReleaseSelectsUnconstrained). With k = 400, A^3 x0 = 2^1200 (1,
// -1, 0, 0) is past the double range (~2^1024), computed with level 1's
// free response, before the level that decides: level 2's coefficient is
// inf with terms of size inf. The levels are solved again with time scaled
// back by the growth of |A|^m, and select the original's mode exactly
// (script M = C A B 2^(2k) = 2^800 stays finite, so the leading index is
// found as for k = 0). k = 0 and k = 300 (2^900: no overflow) take the
// direct path.
TEST(Ldcp, LevelsPastTheDoubleRangeAreSolvedInScaledTime) {
  for (const int k : {0, 300, 400}) {
    SCOPED_TRACE("k = " + std::to_string(k));
    const ModeSelection sel = select_mode(fast_carts(k), Vector4d(0, 0, 0, 1));
    ASSERT_TRUE(sel.ok()) << sel.message;
    EXPECT_TRUE(sel.mode.empty());
    EXPECT_TRUE(sel.undetermined.empty());
    EXPECT_EQ(sel.x_plus, Vector4d(0, 0, 0, 1));
    for (const VectorXd& u : sel.impulse) EXPECT_EQ(u(0), 0.0);
  }
}

// The impulses mapped back: from y = q1 = -1 (a state that is not
// consistent) the two carts, and the hook of Example 3.8.3 (the same A, its
// B and C scaled alike), jump with impulses (delta and delta'), and the
// levels after the jump overflow at k = 400 (without the scaled retry these
// selections fail). The same mode, undetermined rows and x_plus as at
// k = 0, and impulse[j] = the original's impulse[j] 2^(-400 (j + 1)). 1e-12:
// the scaled run's A is 2^-e' A (e' >= 1, the growth of |A|, not 1), so its
// products round differently from the original's; both are a few ulps of
// O(1) numbers (the file's tolerance).
TEST(Ldcp, ImpulsesOfTheScaledLevelsAreMappedBack) {
  for (const bool with_hook : {false, true}) {
    SCOPED_TRACE(with_hook ? "hook" : "two carts");
    const Lcs s0 = with_hook ? hook() : two_carts();
    Lcs s = s0;
    s.A *= std::ldexp(1.0, 400);
    s.B *= std::ldexp(1.0, 400);
    const Vector4d x0(-1, 0, 0, 0);
    const ModeSelection a = select_mode(s0, x0), b = select_mode(s, x0);
    ASSERT_TRUE(a.ok()) << a.message;
    ASSERT_TRUE(b.ok()) << b.message;
    EXPECT_EQ(a.mode, b.mode);
    EXPECT_EQ(a.undetermined, b.undetermined);
    EXPECT_LE((a.x_plus - b.x_plus).norm(), 1e-12);
    ASSERT_EQ(a.impulse.size(), b.impulse.size());
    bool impulsive = false;
    for (size_t j = 0; j < a.impulse.size(); ++j) {
      impulsive = impulsive || !a.impulse[j].isZero(0.0);
      // The original's impulse in the fast time (zero where it is zero;
      // 2^-1200 and below underflow to zero, as the library's mapping does).
      const VectorXd fast = a.impulse[j] * std::ldexp(1.0, -400 * static_cast<int>(j + 1));
      EXPECT_LE((b.impulse[j] - fast).norm(), 1e-12 * fast.norm()) << "j = " << j;
    }
    EXPECT_TRUE(impulsive);  // the mapping is exercised
  }
}

}  // namespace
}  // namespace lcsim::lcs
