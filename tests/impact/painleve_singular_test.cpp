// Issue 27 with planar friction: a Painlevé-type impact whose modes'
// systems are singular (dependent rows) is decided by velocity uniqueness
// (detail::solve_mode_system, shared with the cone's enumeration), not
// refused at the first singular system. Closed forms on small models
// (M = I); the shared function on hand-made systems.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/impact/impact.hpp>

#include "impact/detail.hpp"
#include "impact_test_util.hpp"

namespace lcsim::impact {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using testing::vec;

// Velocities and impulses of order 1 from a 2 x 2 or 3 x 3 LCP solved by
// pivoting and a diagonal M: a few ulps; 1e-12 leaves room for the LCP
// layer's scaling (as friction_test.cpp's kTol).
constexpr double kTol = 1e-12;

ImpactResult hit(const mech::MechanicalModel& m, const VectorXd& v) {
  const ImpactInput in = testing::input(m, v, {0, 1}, m.restitution);
  return make_impact_law("moreau")->apply(in, *lcp::make_solver("lemke"));
}

// Two copies of friction_test.cpp's skew contact (n = (1, 0), t = (0.5, 1),
// mu = 2.5: W_NN - mu |W_NT| = -0.25, Painlevé-type alone) at v- = (-1, 3),
// where one copy has one motion: it sticks, v+ = 0, with P_N = 2.5 and P_T
// = -3 (friction_test.cpp's PainleveCaseIsDiagnosedByName). The copies'
// rows are equal, so the modes (stick, stick) and others have singular
// systems: the copies share the impulse in a continuum of ways, all with
// the same velocity. This was refused ("is singular (it may hold a
// continuum of motions)"); it is one motion: v+ = 0, the impulses' sums
// P_N = 2.5 and P_T = -3, each copy inside its cone.
TEST(PlanarPainleveSingular, CopiesOfOneContactAreOneMotion) {
  mech::MechanicalModel m =
      testing::make_model(Eigen::Matrix2d::Identity(), (MatrixXd(2, 2) << 1, 0, 1, 0).finished());
  m.restitution = vec({0, 0});
  m.friction.push_back({0, vec({0.5, 1}), 2.5});
  m.friction.push_back({1, vec({0.5, 1}), 2.5});
  const ImpactResult r = hit(m, vec({-1, 3}));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.painleve);
  EXPECT_LE(r.v_after.cwiseAbs().maxCoeff(), kTol);
  EXPECT_NEAR(r.impulse.sum(), 2.5, kTol);
  EXPECT_NEAR(r.friction_impulse.sum(), -3.0, kTol);
  for (int i = 0; i < 2; ++i) {
    EXPECT_GE(r.impulse(i), -kTol) << i;
    EXPECT_LE(std::abs(r.friction_impulse(i)), 2.5 * r.impulse(i) + kTol) << i;
  }
}

// A singular system with no solution is no motion, and the enumeration goes
// on. M = I (3 coordinates), c1: n1 = e1, t1 = (0.5, 1, 0), mu 2 (W_NN - mu
// |W_NT| = 1 - 2 * 0.5 = 0: Painlevé-type alone, so the modes are
// enumerated); c2: n2 = (0, 1, 1), t2 = e3, mu 1. Slipping along +t, c1's
// impulse is n1 - 2 t1 = (0, -2, 0) and c2's n2 - t2 = (0, 1, 0), parallel:
// the mode (slip+, slip+) has the system [n1; n2] (0, -2, 0)' l1 + [n1;
// n2] (0, 1, 0)' l2 = -[n1; n2] v-, i.e. [0 0; -2 1] l = (1, -3) at v- =
// (-1, 3, 0): singular and inconsistent (0 = 1). Before, the enumeration
// refused the impact at the first singular system; now that one is
// skipped, and the impact is one motion: c1 sticks as the skew contact
// alone (P_N1 = 2.5, P_T1 = -3: v+ = v- + 2.5 n1 - 3 t1 = 0) and c2, shut
// at u_N2 = 0, takes no impulse.
TEST(PlanarPainleveSingular, InconsistentSingularModeIsSkipped) {
  mech::MechanicalModel m = testing::make_model(Eigen::Matrix3d::Identity(),
                                                (MatrixXd(2, 3) << 1, 0, 0, 0, 1, 1).finished());
  m.restitution = vec({0, 0});
  m.friction.push_back({0, vec({0.5, 1, 0}), 2.0});
  m.friction.push_back({1, vec({0, 0, 1}), 1.0});
  const ImpactResult r = hit(m, vec({-1, 3, 0}));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_FALSE(r.painleve);
  EXPECT_LE(r.v_after.cwiseAbs().maxCoeff(), kTol);
  testing::expect_near(r.impulse, vec({2.5, 0}), kTol);
  testing::expect_near(r.friction_impulse, vec({-3, 0}), kTol);

  // The mode (slip+, slip+) itself, through the shared analysis: Wg = G G'
  // over (n1, n2, t1, t2), lambda = P (l1, l2), the equations u_N = 0.
  const MatrixXd G =
      (MatrixXd(4, 3) << 1, 0, 0, 0, 1, 1, 0.5, 1, 0, 0, 0, 1).finished();  // n1 n2 t1 t2
  const MatrixXd Wg = G * G.transpose();
  const VectorXd b = G * vec({-1, 3, 0});
  const MatrixXd P = (MatrixXd(4, 2) << 1, 0, 0, 1, -2, 0, 0, -1).finished();
  const MatrixXd WP = Wg * P;
  const MatrixXd A = WP.topRows(2);
  const VectorXd rhs = -b.head(2);
  const auto rows = [&](const VectorXd& bb) {
    detail::ModeInequalities q{MatrixXd(0, 2), VectorXd(0), {}};
    const MatrixXd zero = MatrixXd::Zero(1, 4);
    for (int j = 0; j < 2; ++j) {
      MatrixXd a = zero;
      a(0, j) = 1.0;
      q.add(zero, a, P, WP, bb, false);  // lambda_N >= 0
      a.setZero();
      a(0, 2 + j) = 1.0;
      q.add(a, zero, P, WP, bb, true);  // u_T >= 0
    }
    return q;
  };
  const VectorXd law = vec({2.5, 0, -3, 0});
  EXPECT_EQ(detail::solve_mode_system(Wg, b, P, A, rhs, rows(b), law).kind,
            detail::ModeOutcome::kNone);
  // The same system made consistent, at v- = (0, 3, 0): v+ = (0, 3 - 2 l1
  // + l2, 0), so n1 v+ = 0 always and n2 v+ = 0 on the line l2 = 2 l1 - 3,
  // where v+ = 0: one velocity over the kernel (1, 2). Given a law's impulse
  // of another velocity (zero: v+ = v-), the set is searched: l1 >= 0 and
  // l2 >= 0 leave the ray l1 >= 1.5 (u_T1 = u_T2 = 0 on it), whose vertex
  // l1 = 1.5 is a motion, v+ = 0 (G v+ = Wg lambda + b = 0).
  const VectorXd b0 = G * vec({0, 3, 0});
  const detail::ModeOutcome one =
      detail::solve_mode_system(Wg, b0, P, A, -b0.head(2), rows(b0), VectorXd::Zero(4));
  EXPECT_EQ(one.kind, detail::ModeOutcome::kMotion);
  EXPECT_LE((Wg * one.lambda + b0).cwiseAbs().maxCoeff(), kTol);
  // The vertex of the set widened by the modes' tolerance (1e-9 of the
  // terms, 4e-9 here: the impulse rows hold to -tol_l): within 1e-8.
  EXPECT_NEAR(one.lambda(0), 1.5, 1e-8);
  EXPECT_NEAR(one.lambda(1), 0.0, 1e-8);
}

// A singular system the shared analysis cannot decide is refused by name.
// Five copies of one frictionless row (M = 1, G = ones(5, 1)) at v- = -1,
// all closed: the system ones(5, 5) lambda = 1 has a kernel of dimension
// 4, every impulse in it the same velocity (0). Given the law's impulse
// (1, 0, 0, 0, 0) (velocity 0) that is the law's motion; given one of
// another velocity (0: v+ = -1) the set must be searched for another
// motion, and a kernel above 3 is not searched: kUndecided, which the
// tally turns into the refusal naming the modes.
TEST(PlanarPainleveSingular, KernelAboveThreeIsNotDecidedAndSaysSo) {
  const MatrixXd Wg = MatrixXd::Ones(5, 5), P = MatrixXd::Identity(5, 5);
  const VectorXd b = -VectorXd::Ones(5);
  detail::ModeInequalities q{MatrixXd(0, 5), VectorXd(0), {}};
  for (int j = 0; j < 5; ++j) {
    MatrixXd a = MatrixXd::Zero(1, 5);
    a(0, j) = 1.0;
    q.add(MatrixXd::Zero(1, 5), a, P, Wg, b, false);  // lambda_j >= 0
  }
  const VectorXd law = (VectorXd(5) << 1, 0, 0, 0, 0).finished();
  const detail::ModeOutcome same = detail::solve_mode_system(Wg, b, P, Wg, -b, q, law);
  EXPECT_EQ(same.kind, detail::ModeOutcome::kMotion);
  EXPECT_LE((Wg * same.lambda + b).cwiseAbs().maxCoeff(), kTol);
  const detail::ModeOutcome other =
      detail::solve_mode_system(Wg, b, P, Wg, -b, q, VectorXd::Zero(5));
  EXPECT_EQ(other.kind, detail::ModeOutcome::kUndecided);
  detail::MotionTally tally{Wg, b, {}, {}};
  detail::PainleveVerdict verdict;
  EXPECT_FALSE(tally.add(
      other, [] { return std::string("0 ('a') (closed)"); }, verdict));
  EXPECT_EQ(verdict.message,
            "the system of the modes 0 ('a') (closed) is singular and whether its impulses hold "
            "a motion other than the LCP's is not decided");
}

}  // namespace
}  // namespace lcsim::impact
