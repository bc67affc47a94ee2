// mode_feedback when script M_II is singular because the mode's rows are
// dependent (issue 29): a combination of the rows without feedthrough is
// differentiated (Silverman's structure algorithm), as where an ideal
// bridge's tank meets a loaded capacitor through two diodes (C1 || C2).
//
// Tolerances: the data are small integers, so every value below comes from a
// handful of SVD/QR steps on O(1) numbers (backward error ~1e-16); 1e-12
// leaves four orders of room and is far below any structural error (O(1)).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <lcsim/lcs/lcs.hpp>

namespace lcsim::lcs {
namespace {

constexpr double kExact = 1e-12;

// States (v, w): pair 1 a voltage-form diode (u1 moves no state: B's first
// column is zero), pair 2 a current u2 that discharges v (v' = -2 u2) and
// charges w (w' = u2 - w). y1 = v + u1, y2 = w - u1: both have leading index
// 0 and script M_II = [[1, 0], [-1, 0]] is singular; y1 + y2 = v + w has no
// feedthrough, and its derivative -w - u2 ... fixes u2. By hand on the
// consistent subspace v + w = 0: u1 = -v, and (v + w)' = -2 u2 + u2 - w = 0
// gives u2 = -w; the closed loop is v' = 2 w, w' = -2 w.
Lcs coupled_pair() {
  Lcs s;
  s.A = (MatrixXd(2, 2) << 0, 0, 0, -1).finished();
  s.B = (MatrixXd(2, 2) << 0, -2, 0, 1).finished();
  s.C = (MatrixXd(2, 2) << 1, 0, 0, 1).finished();
  s.D = (MatrixXd(2, 2) << 1, 0, -1, 0).finished();
  return s;
}

TEST(ModeFeedback, DependentRowsAreDifferentiated) {
  const Lcs s = coupled_pair();
  const ModeFeedback fb = mode_feedback(s, {0, 1});
  ASSERT_TRUE(fb.ok()) << fb.message;
  // On V_I = span{(1, -1)} the multipliers are unique: u = (-1, 1) at x = (1, -1).
  const Eigen::Vector2d x(1.0, -1.0);
  const Eigen::Vector2d u = fb.F * x;
  EXPECT_NEAR(u(0), -1.0, kExact);
  EXPECT_NEAR(u(1), 1.0, kExact);
  // y_I = C x + D u vanishes there, and the closed loop keeps v + w = 0.
  EXPECT_LT((s.C * x + s.D * u).norm(), kExact);
  const MatrixXd Acl = s.A + s.B * fb.F;
  EXPECT_LT((Eigen::RowVector2d(1.0, 1.0) * Acl).norm(), kExact);
  EXPECT_LT((Acl * x - Eigen::Vector2d(-2.0, 2.0)).norm(), kExact);  // v' = 2 w, w' = -2 w
}

// A combination of rows that vanishes in x too (two identical outputs with
// identical inputs) has no derivative to fix anything: still refused.
TEST(ModeFeedback, RedundantRowsStayRefused) {
  Lcs s = coupled_pair();
  s.B = (MatrixXd(2, 2) << 1, 1, 0, 0).finished();
  s.C = (MatrixXd(2, 2) << 1, 0, 1, 0).finished();
  s.D = MatrixXd::Zero(2, 2);
  s.D << 1, 1, 1, 1;
  const ModeFeedback fb = mode_feedback(s, {0, 1});
  EXPECT_FALSE(fb.ok());
  EXPECT_NE(fb.message.find("singular"), std::string::npos) << fb.message;
}

}  // namespace
}  // namespace lcsim::lcs
