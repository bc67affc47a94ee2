// Sets of constraints that can be active together, and Theorem 3.6.3 on them
// (src/mech/coactive.cpp). Every expected set is found by hand from the rows.
#include <gtest/gtest.h>

#include <lcsim/mech/mech.hpp>

namespace lcsim::mech {
namespace {

using Sets = std::vector<std::vector<int>>;

// One coordinate with both limits: q >= -1 (row 0) and q <= 2 (row 1). Both
// closed would need q = -1 and q = 2 at once: never; each alone is reachable.
TEST(Coactive, TheTwoLimitsOfOneJointAreNeverActiveTogether) {
  Eigen::MatrixXd E(2, 1);
  E << 1, -1;
  Eigen::VectorXd g(2);
  g << 1, 2;
  MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(1, 1).sparseView();
  m.E = E.sparseView();
  m.g = g;
  fill_defaults(m);
  EXPECT_TRUE(can_be_active_together(m, {0}));
  EXPECT_TRUE(can_be_active_together(m, {1}));
  EXPECT_FALSE(can_be_active_together(m, {0, 1}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0}, {1}}));
  ASSERT_EQ(s.exclusive_pairs.size(), 1u);
  EXPECT_EQ(s.exclusive_pairs[0], std::make_pair(0, 1));
  EXPECT_TRUE(s.never_active.empty());
  EXPECT_TRUE(s.complete);
  // E has rank 1 < 2, yet no set has dependent rows; each 1x1 Delassus
  // matrix is [1] > 0, so Theorem 3.6.3 applies on every set.
  const CoactiveWellPosedness w = coactive_well_posedness(m, s);
  EXPECT_FALSE(w.dependent);
  EXPECT_TRUE(w.all_delassus_p);
  EXPECT_TRUE(w.locally_well_posed);
}

// The same stop twice (x1 >= 0 in rows 0 and 1): active together at x1 = 0,
// E_J = [1 0; 1 0] of rank 1: truly dependent; Delassus [1 1; 1 1] is
// singular, not a P-matrix, and so is the leading coefficient matrix.
TEST(Coactive, ARepeatedStopIsDependentAndActiveTogether) {
  Eigen::MatrixXd E(2, 2);
  E << 1, 0, 1, 0;
  const Model model = two_carts_model(E);
  const MechanicalModel& m = *model.mechanical;
  EXPECT_TRUE(can_be_active_together(m, {0, 1}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0, 1}}));
  EXPECT_TRUE(s.exclusive_pairs.empty());
  const CoactiveWellPosedness w = coactive_well_posedness(m, s);
  ASSERT_EQ(w.sets.size(), 1u);
  EXPECT_EQ(w.sets[0].rank, 1);
  EXPECT_TRUE(w.dependent);
  EXPECT_FALSE(w.all_delassus_p);
  EXPECT_FALSE(w.locally_well_posed);
}

// Rows q1 >= 0, q2 >= 0, q1 + q2 <= 1: every pair closes at a corner of the
// triangle ((0,0), (0,1), (1,0)), all three never (q = 0 leaves gap 1). The
// pairwise graph is a triangle, its one clique {0,1,2} fails as a whole and
// splits into the three pairs.
TEST(Coactive, PairwiseButNotJointlyClosableRowsSplitIntoPairs) {
  Eigen::MatrixXd E(3, 2);
  E << 1, 0, 0, 1, -1, -1;
  Eigen::VectorXd g(3);
  g << 0, 0, 1;
  const Model model = two_carts_model(E, g);
  const MechanicalModel& m = *model.mechanical;
  EXPECT_FALSE(can_be_active_together(m, {0, 1, 2}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0, 1}, {0, 2}, {1, 2}}));
  EXPECT_TRUE(s.exclusive_pairs.empty());
  // Each pair of rows is independent: E_J M^-1 E_J' (M = I) is [1 0; 0 1],
  // [1 -1; -1 2] or [1 -1; -1 2]: positive definite, so P-matrices.
  const CoactiveWellPosedness w = coactive_well_posedness(m, s);
  EXPECT_FALSE(w.dependent);
  EXPECT_TRUE(w.all_delassus_p);
  EXPECT_TRUE(w.locally_well_posed);
}

// Rows x1 >= 0 and x1 <= -1 (-x1 - 1 >= 0): no q satisfies both, so no q is
// admissible and no row can ever close: no sets at all.
TEST(Coactive, InfeasibleRowsAreNeverActive) {
  Eigen::MatrixXd E(2, 2);
  E << 1, 0, -1, 0;
  Eigen::VectorXd g(2);
  g << 0, -1;
  const Model model = two_carts_model(E, g);
  const CoactiveSets s = coactive_sets(*model.mechanical);
  EXPECT_EQ(s.never_active, (std::vector<int>{0, 1}));
  EXPECT_TRUE(s.maximal.empty());
}

// The cart chain with stops (q_i >= -1) and hooks (q_{i+1} - q_i <= 0.5).
// By hand: closed hooks split the carts into runs moved rigidly 0.5 m apart;
// in a run only its leftmost cart's stop can close (closing cart j's stop puts
// the carts to its left below -1), and an open hook cannot close without
// joining two runs whose two closed stops then contradict. So each of the
// 2^(n-1) hook patterns gives exactly one maximal set: 2048 for n = 12, each
// a forest of rows (independent), so no set is dependent. For n = 20, 2^19
// sets exceed the cap: the enumeration says it is incomplete.
TEST(Coactive, CartChainHasOneMaximalSetPerHookPattern) {
  ChainSpec spec;
  spec.n = 12;
  spec.hooks = true;
  const Model chain = chain_model(spec);
  const CoactiveSets s = coactive_sets(*chain.mechanical);
  EXPECT_TRUE(s.complete);
  EXPECT_EQ(s.maximal.size(), 2048u);
  EXPECT_FALSE(coactive_well_posedness(*chain.mechanical, s).dependent);
  spec.n = 20;
  EXPECT_FALSE(coactive_sets(*chain_model(spec).mechanical).complete);
}

// A flat 2-D box on a floor, coordinates (z, theta): bottom corners
// z -/+ a theta - d >= 0 (rows 0, 1) and the top corners straight above them,
// with the same rows of E and gaps h larger (rows 2, 3). By hand: rows 0 and
// 1 close together at q = (d, 0), where the top gaps are h > 0; a top gap is
// its bottom gap + h, so closing it needs the bottom gap at -h: rows 2 and 3
// are never active. With row 0 closed, row 2 is constant (h) on the solution
// set: its projected row is rounding, not zero, and once broke the LCP (for
// a = 0.1 Eigen's SVD leaves 1.4e-17 there; for some widths, 0.15 among them,
// it happens to be exactly 0). With row 0 closed alone, the least-norm q_p
// tilts the box and opens row 1 below the floor (-2 a^2 d / (1 + a^2)), so
// the LCP is reached.
TEST(Coactive, CornersAboveOneAnotherWithEqualRowsFindTheBottomPair) {
  const double a = 0.1, d = 0.05, h = 0.1;  // half-width, rest height, box height (m)
  Eigen::MatrixXd E(4, 2);
  E << 1, -a, 1, a, 1, -a, 1, a;
  Eigen::VectorXd g(4);
  g << -d, -d, h - d, h - d;
  const Model model = two_carts_model(E, g);
  const MechanicalModel& m = *model.mechanical;
  EXPECT_TRUE(can_be_active_together(m, {0}));
  EXPECT_TRUE(can_be_active_together(m, {0, 1}));
  EXPECT_FALSE(can_be_active_together(m, {2}));
  EXPECT_FALSE(can_be_active_together(m, {0, 2}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0, 1}}));
  EXPECT_EQ(s.never_active, (std::vector<int>{2, 3}));
  EXPECT_TRUE(s.exclusive_pairs.empty());
  EXPECT_TRUE(s.complete);
}

// Three bottom corners of that box (left, right, middle: z - a theta,
// z + a theta, z, each - d) and the top corner above the left one (row 3,
// the same row of E as row 0, gap h larger). By hand: the three bottom rows
// close together at (d, 0) with rank 2 (the middle row is the mean of the
// others): a dependent set that can be active together, found so; row 3 is
// never active. With row 0 closed alone, q_p = d (1, -a) / (1 + a^2) opens
// rows 1 and 2 below the floor (-2 a^2 d / (1 + a^2), -a^2 d / (1 + a^2)):
// two tied rows in Lemke's ratio test next to row 3's rounding (1.4e-17 for
// a = 0.1), which is what stopped it on a wrong basis before (row 0 read as
// never active).
TEST(Coactive, ADependentSetOfBottomCornersIsActiveTogether) {
  const double a = 0.1, d = 0.05, h = 0.1;
  Eigen::MatrixXd E(4, 2);
  E << 1, -a, 1, a, 1, 0, 1, -a;
  Eigen::VectorXd g(4);
  g << -d, -d, -d, h - d;
  const Model model = two_carts_model(E, g);
  const MechanicalModel& m = *model.mechanical;
  EXPECT_TRUE(can_be_active_together(m, {0}));
  EXPECT_FALSE(can_be_active_together(m, {0, 3}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0, 1, 2}}));
  EXPECT_EQ(s.never_active, (std::vector<int>{3}));
  EXPECT_TRUE(s.complete);
  const CoactiveWellPosedness w = coactive_well_posedness(m, s);
  ASSERT_EQ(w.sets.size(), 1u);
  EXPECT_EQ(w.sets[0].rank, 2);
  EXPECT_TRUE(w.dependent);
}

// The box of robots/box_drop_scene.yaml as a matrix model, coordinates
// (z, rx, ry), M = I: a corner at (x, y) on the floor has gap
// z + y rx - x ry - d (the normal motion of a point of a rotated body is
// independent of its height), so the top corner above each bottom one has the
// same row of E and a gap h larger. By hand: the four bottom rows (0..3)
// close together at (d, 0, 0), with rank 3 (a plane through 4 points:
// dependent, §4.6.1), where every top gap is h; a top gap is its bottom gap +
// h, so no top row (4..7) can ever close. With one bottom row closed, the row
// above it is constant on the solution set; its projected row was the SVD's
// rounding, which Lemke's row scaling blew up: every corner read "never
// active" before.
TEST(Coactive, TheBoxsFourBottomCornersCloseTogetherAndTheTopOnesNever) {
  const double a = 0.15, b = 0.1, d = 0.05, h = 0.1;  // half-sizes, rest height, height (m)
  const double xs[4] = {a, -a, a, -a}, ys[4] = {b, b, -b, -b};
  Eigen::MatrixXd E(8, 3);
  Eigen::VectorXd g(8);
  for (int i = 0; i < 8; ++i) {
    E.row(i) << 1, ys[i % 4], -xs[i % 4];
    g(i) = i < 4 ? -d : h - d;
  }
  MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(3, 3).sparseView();
  m.E = E.sparseView();
  m.g = g;
  fill_defaults(m);
  EXPECT_TRUE(can_be_active_together(m, {0}));
  EXPECT_TRUE(can_be_active_together(m, {0, 1, 2, 3}));
  EXPECT_FALSE(can_be_active_together(m, {4}));
  const CoactiveSets s = coactive_sets(m);
  EXPECT_EQ(s.maximal, (Sets{{0, 1, 2, 3}}));
  EXPECT_EQ(s.never_active, (std::vector<int>{4, 5, 6, 7}));
  EXPECT_TRUE(s.complete);
  const CoactiveWellPosedness w = coactive_well_posedness(m, s);
  ASSERT_EQ(w.sets.size(), 1u);
  EXPECT_EQ(w.sets[0].rank, 3);
  EXPECT_TRUE(w.dependent);
}

}  // namespace
}  // namespace lcsim::mech
