// The exact method's exponential of a nilpotent phase (a body without
// springs: x' = v, v' = const) by its finite series (Phase::expm,
// Phase::expv, nilpotency_index in src/sim/exact/phase.cpp), against closed
// forms and, independently, Eigen's Padé exponential.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <unsupported/Eigen/MatrixFunctions>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;
using sim::detail::nilpotency_index;
using sim::detail::no_path_of;
using sim::detail::Phase;

// A phase holding only a balanced matrix (D = 1), as build_phase sets it.
Phase phase_of(const MatrixXd& Ab) {
  Phase ph;
  ph.Ab = Ab;
  ph.D = VectorXd::Ones(Ab.rows());
  ph.Ab_norm1 = Ab.cwiseAbs().colwise().sum().maxCoeff();
  ph.nil = nilpotency_index(Ab);
  return ph;
}

// A strictly upper triangular n x n matrix with a full superdiagonal: its
// longest path has n - 1 edges, so its index is n. Entries (i, j) fall as
// 1/(j - i)^2, so ||A||_inf < 1.7 scale.
MatrixXd strictly_upper(Eigen::Index n, double scale) {
  MatrixXd A = MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = i + 1; j < n; ++j)
      A(i, j) = scale * std::sin(static_cast<double>(3 * i + 7 * j) + 1.0) /
                static_cast<double>((j - i) * (j - i));
  return A;
}

TEST(NilpotentExp, IndexIsTheLongestPathPlusOne) {
  EXPECT_EQ(nilpotency_index(MatrixXd::Zero(4, 4)), 1);  // A = 0
  EXPECT_EQ(nilpotency_index(strictly_upper(5, 1.0)), 5);
  // The large-state branch (over 64 rows, without bit masks).
  EXPECT_EQ(nilpotency_index(strictly_upper(70, 1.0)), 70);
  MatrixXd cycle = strictly_upper(70, 1.0);
  cycle(69, 0) = 1.0;
  EXPECT_EQ(nilpotency_index(cycle), 0);
  MatrixXd loop = MatrixXd::Zero(3, 3);
  loop(1, 1) = -0.5;  // damping: a self-loop, never nilpotent
  EXPECT_EQ(nilpotency_index(loop), 0);
  // A NaN entry is an edge (it is no zero).
  MatrixXd nan = MatrixXd::Zero(2, 2);
  nan(0, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(nilpotency_index(nan), 2);
  nan(1, 0) = nan(0, 1);
  EXPECT_EQ(nilpotency_index(nan), 0);
  // no_path_of(A, len) is index <= len.
  EXPECT_FALSE(no_path_of(strictly_upper(5, 1.0), 4));
  EXPECT_TRUE(no_path_of(strictly_upper(5, 1.0), 5));
  EXPECT_FALSE(no_path_of(cycle, 200));
}

// x = (q, v, 1): q' = v, v' = g. e^{A t} x0 = (q0 + v0 t + g t^2 / 2,
// v0 + g t, 1). Every number here is a short dyadic fraction, so the series'
// three terms, their products and sums are exact in double: equality, where
// Padé's scaling and squaring would round.
TEST(NilpotentExp, FreeFlightIsItsClosedFormExactly) {
  MatrixXd A = MatrixXd::Zero(3, 3);
  A(0, 1) = 1.0;
  A(1, 2) = -8.0;
  const Phase ph = phase_of(A);
  ASSERT_EQ(ph.nil, 3);
  const double t = 0.5;
  MatrixXd closed(3, 3);
  closed << 1.0, t, -8.0 * t * t / 2.0, 0.0, 1.0, -8.0 * t, 0.0, 0.0, 1.0;
  EXPECT_EQ(ph.expm(t), closed);
  const VectorXd x0 = (VectorXd(3) << 1.0, 2.0, 1.0).finished();
  const VectorXd x = ph.expv(t, x0);
  EXPECT_EQ(x(0), 1.0);  // 1 + 2 * 0.5 - 4 * 0.25
  EXPECT_EQ(x(1), -2.0);
  EXPECT_EQ(x(2), 1.0);
}

// Dense (11 states, q' = v, v' = const: index 3) and large (70 states,
// index 70, the action path) nilpotent matrices, ||A tau|| up to ~30 and
// ~1.5: the series against Padé. Both are backward stable at these norms,
// so they agree to a few hundred ulps of the result's size; 1e-12 relative
// leaves room. The 11-state series one term short (missing (A tau)^2/2,
// 4e-4 of the result or more for tau >= 0.01) fails it; at 70 states the
// last terms are below rounding, so there it checks the action path.
TEST(NilpotentExp, SeriesAgreesWithPade) {
  MatrixXd box = MatrixXd::Zero(11, 11);
  for (int i = 0; i < 5; ++i) box(i, 5 + i) = 1.0;            // q' = v
  for (int i = 5; i < 10; ++i) box(i, 10) = -9.81 + 0.3 * i;  // v' = const
  for (const MatrixXd& A : {box, strictly_upper(70, 0.3)}) {
    const Phase ph = phase_of(A);
    ASSERT_GT(ph.nil, 0);
    for (double tau : {1e-6, 0.01, 0.7, 3.0}) {
      const MatrixXd pade = (A * tau).exp();
      const double size = pade.cwiseAbs().maxCoeff();
      EXPECT_LE((ph.expm(tau) - pade).cwiseAbs().maxCoeff(), 1e-12 * size) << tau;
      const VectorXd z = VectorXd::LinSpaced(A.rows(), -1.0, 2.0);
      const VectorXd ref = pade * z;
      EXPECT_LE((ph.expv(tau, z) - ref).cwiseAbs().maxCoeff(), 1e-12 * size * 2.0 * A.rows())
          << tau;
    }
  }
}

}  // namespace
}  // namespace lcsim
