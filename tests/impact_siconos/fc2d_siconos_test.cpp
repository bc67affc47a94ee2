// Differential test of the friction impact LCP (impact::moreau_friction)
// against Siconos's 2-D friction solvers (libsiconos-numerics, Debian 4.4:
// fc2d_driver with SICONOS_FRICTION_2D_LEMKE and SICONOS_FRICTION_2D_ENUM)
// on seeded random problems. Siconos gets the same local problem
// u = W r + q (W = G M^{-1} G', G = [E_J; T], q = (u_N- with restitution,
// u_T-)) and solves it with its own algorithms; problems with several
// solutions (checked by enumerating our LCP) are not compared, and neither
// are Siconos answers that fail an independent check of the Coulomb law
// (Debian's Siconos 4.4 fc2d Lemke returns info 0 with a negative normal
// rate on some multi-contact problems here); every answer of ours is checked.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <lcsim/impact/impact.hpp>
#include <random>
#include <vector>

#include "impact/friction_test_util.hpp"

extern "C" {
#include <FrictionContactProblem.h>
#include <Friction_cst.h>
#include <NonSmoothDrivers.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
}

namespace lcsim::impact {
namespace {

// Siconos's reactions (r_N, r_T per contact), or empty if it failed.
Eigen::VectorXd siconos_fc2d(const Eigen::MatrixXd& W, const Eigen::VectorXd& q,
                             const Eigen::VectorXd& mu, int solver_id) {
  const int nc = static_cast<int>(mu.size()), n = 2 * nc;
  NumericsMatrix* M = NM_create(NM_DENSE, n, n);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) M->matrix0[i + j * n] = W(i, j);
  auto* qq = static_cast<double*>(std::malloc(sizeof(double) * n));
  auto* mm = static_cast<double*>(std::malloc(sizeof(double) * nc));
  for (int i = 0; i < n; ++i) qq[i] = q(i);
  for (int i = 0; i < nc; ++i) mm[i] = mu(i);
  FrictionContactProblem* p = frictionContactProblem_new_with_data(2, nc, M, qq, mm);
  SolverOptions* opt = solver_options_create(solver_id);
  opt->dparam[SICONOS_DPARAM_TOL] = 1e-10;
  std::vector<double> r(n, 0.0), u(n, 0.0);
  const int info = fc2d_driver(p, r.data(), u.data(), opt);
  solver_options_delete(opt);
  frictionContactProblem_free(p);  // frees M, q and mu
  if (info != 0) return {};
  return Eigen::Map<Eigen::VectorXd>(r.data(), n);
}

// How far r = (r_N, r_T per contact) is from solving the 2-D Coulomb
// problem u = W r + q: 0 <= u_N ⟂ r_N >= 0, |r_T| <= mu r_N, u_T = 0 inside
// the cone and r_T = -sign(u_T) mu r_N when sliding; relative to |q| + |W||r|.
double coulomb_error(const Eigen::MatrixXd& W, const Eigen::VectorXd& q, const Eigen::VectorXd& mu,
                     const Eigen::VectorXd& r) {
  const Eigen::VectorXd u = W * r + q;
  const Eigen::VectorXd s = q.cwiseAbs() + W.cwiseAbs() * r.cwiseAbs();
  double err = 0.0;
  for (Eigen::Index c = 0; c < mu.size(); ++c) {
    const double rn = r(2 * c), rt = r(2 * c + 1), un = u(2 * c), ut = u(2 * c + 1);
    const double rs = 1.0 + std::abs(rn) + std::abs(rt);
    err = std::max({err, -rn / rs, -un / (1 + s(2 * c)), std::min(rn / rs, un / (1 + s(2 * c))),
                    (std::abs(rt) - mu(c) * rn) / rs,
                    std::min(std::abs(ut) / (1 + s(2 * c + 1)),
                             std::abs(rt + std::copysign(mu(c) * rn, ut)) / rs)});
  }
  return err;
}

// Every solution of the planar Coulomb impact problem u = Wg lambda + b
// (Wg over the closed normals, then the tangents; contact j's tangent is
// row nj + j here, every contact frictional), found by enumerating the
// contacts' modes, independently of the LCP: per contact open (lambda = 0,
// u_N >= 0), stick (u_N = 0, u_T = 0, |lambda_T| <= mu lambda_N), or slip
// with sign s (u_N = 0, lambda_T = -s mu lambda_N, s u_T >= 0). Each mode is
// a square linear system; a solution is kept when it satisfies the mode's
// inequalities to 1e-9 of its terms. Unlike the enumeration of the LCP's
// complementary bases, a degenerate solution (a contact with no normal
// impulse that slides, a stick on the cone's edge) is found in the mode it
// satisfies. `singular`: the modes whose system is singular (not solved: a
// continuum there is not seen).
std::vector<Eigen::VectorXd> coulomb_solutions(const Eigen::MatrixXd& Wg, const Eigen::VectorXd& b,
                                               const Eigen::VectorXd& mu, int& singular) {
  const int k = static_cast<int>(mu.size()), n = 2 * k;
  std::vector<Eigen::VectorXd> out;
  singular = 0;
  int total = 1;
  for (int j = 0; j < k; ++j) total *= 4;
  for (int code = 0; code < total; ++code) {
    std::vector<int> mode(static_cast<size_t>(k));  // 0 open, 1 stick, 2 slip +, 3 slip -
    for (int j = 0, c = code; j < k; ++j, c /= 4) mode[static_cast<size_t>(j)] = c % 4;
    Eigen::MatrixXd P = Eigen::MatrixXd::Zero(n, n);  // lambda = P x
    std::vector<int> rows;                            // the equations u_row = 0
    for (int j = 0; j < k; ++j) {
      const int mj = mode[static_cast<size_t>(j)];
      if (mj == 0) continue;
      const auto x = static_cast<Eigen::Index>(rows.size());
      P(j, x) = 1.0;
      if (mj >= 2) P(k + j, x) = -(mj == 2 ? 1.0 : -1.0) * mu(j);
      rows.push_back(j);
    }
    for (int j = 0; j < k; ++j) {
      if (mode[static_cast<size_t>(j)] != 1) continue;
      P(k + j, static_cast<Eigen::Index>(rows.size())) = 1.0;
      rows.push_back(k + j);
    }
    const auto nx = static_cast<Eigen::Index>(rows.size());
    const Eigen::MatrixXd WP = Wg * P.leftCols(nx);
    Eigen::MatrixXd A(nx, nx);
    Eigen::VectorXd rhs(nx);
    for (Eigen::Index i = 0; i < nx; ++i) {
      A.row(i) = WP.row(rows[static_cast<size_t>(i)]);
      rhs(i) = -b(rows[static_cast<size_t>(i)]);
    }
    Eigen::VectorXd x = Eigen::VectorXd::Zero(nx);
    if (nx > 0) {
      const Eigen::FullPivLU<Eigen::MatrixXd> lu(A);
      if (!lu.isInvertible()) {
        ++singular;
        continue;
      }
      x = lu.solve(rhs);
    }
    const Eigen::VectorXd lambda = P.leftCols(nx) * x, u = Wg * lambda + b;
    const double tol_u =
        1e-9 * (1.0 + b.cwiseAbs().maxCoeff() + (Wg.cwiseAbs() * lambda.cwiseAbs()).maxCoeff());
    const double tol_l = 1e-9 * (1.0 + lambda.cwiseAbs().maxCoeff());
    bool ok = true;
    for (int j = 0; j < k && ok; ++j) {
      const int mj = mode[static_cast<size_t>(j)];
      if (mj == 0) {
        ok = u(j) >= -tol_u;
      } else if (mj == 1) {
        ok = lambda(j) >= -tol_l && std::abs(lambda(k + j)) <= mu(j) * lambda(j) + tol_l;
      } else {
        ok = lambda(j) >= -tol_l && (mj == 2 ? 1.0 : -1.0) * u(k + j) >= -tol_u;
      }
    }
    if (ok) out.push_back(lambda);
  }
  return out;
}

// The distinct motions among `solutions`: Wg lambda differing by more than
// 1e-8 of its terms (the comparison's tolerance on the impulses). Equal Wg
// lambda is equal G' lambda (Wg = G M^-1 G' is PSD), so the same velocity.
int distinct_motions(const Eigen::MatrixXd& Wg, const Eigen::VectorXd& b,
                     const std::vector<Eigen::VectorXd>& solutions) {
  std::vector<Eigen::VectorXd> seen;
  for (const Eigen::VectorXd& l : solutions) {
    bool same = false;
    for (const Eigen::VectorXd& o : seen)
      same |= (Wg * (l - o)).cwiseAbs().maxCoeff() <=
              1e-8 * (1.0 + b.cwiseAbs().maxCoeff() +
                      (Wg.cwiseAbs() * (l.cwiseAbs() + o.cwiseAbs())).maxCoeff());
    if (!same) seen.push_back(l);
  }
  return static_cast<int>(seen.size());
}

// The distinct motions of a draw's Coulomb problem (every constraint closed
// and frictional, Newton's restitution e on the normal rates), by the modes'
// enumeration.
int painleve_motions(const mech::MechanicalModel& m, const Eigen::VectorXd& v, double e) {
  const int k = m.num_constraints(), N = m.dofs();
  Eigen::MatrixXd G(2 * k, N);  // normals first, then tangents
  Eigen::VectorXd mu(k);
  for (int c = 0; c < k; ++c) {
    G.row(c) = m.E.row(c);
    G.row(k + c) = m.friction[static_cast<size_t>(c)].tangent.transpose();
    mu(c) = m.friction[static_cast<size_t>(c)].mu;
  }
  const Eigen::MatrixXd Wg = G * Eigen::MatrixXd(m.M).llt().solve(G.transpose());
  Eigen::VectorXd b = G * v;
  for (int c = 0; c < k; ++c) b(c) += e * std::min(b(c), 0.0);
  int singular = 0;
  return distinct_motions(Wg, b, coulomb_solutions(Wg, b, mu, singular));
}

TEST(FrictionVsSiconos, RandomImpactsAgreeWithFc2dLemkeAndEnum) {
  std::mt19937_64 rng(2017);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int compared = 0, several = 0, painleve = 0, siconos_wrong[2] = {0, 0};
  // Issue 27: the draws the LCP enumeration counts as "several" (it finds no
  // solution, or more than one), and the refused draws whose Coulomb
  // problem has one motion by the mode enumeration.
  int lcp_enum_none = 0, lcp_enum_more = 0, refused_unique = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const double e = u01(rng) < 0.5 ? 0.0 : u01(rng);
    const testing::RandomFriction p = testing::random_friction(rng, e, /*all_frictional=*/true);
    const mech::MechanicalModel& m = p.model;
    const int k = m.num_constraints(), N = m.dofs();
    ImpactInput in = testing::input(m, p.v, p.closed, m.restitution);
    const ImpactResult r = moreau_friction(in, *lcp::make_solver("pivot"));
    if (r.painleve) {
      ++painleve;
      refused_unique += painleve_motions(m, p.v, e) == 1;
      // Issue 27: the laws decide a Painlevé-type impact by the contacts'
      // modes, so only a draw with several motions is refused, and the
      // message names the contacts and the modes of two motions.
      EXPECT_GE(painleve_motions(m, p.v, e), 2) << "trial " << trial << ": " << r.message;
      EXPECT_NE(r.message.find("motions: the modes 0 ('c1') ("), std::string::npos) << r.message;
      std::printf("refused trial %d: %s\n", trial, r.message.c_str());
      continue;
    }
    ASSERT_TRUE(r.ok()) << "trial " << trial << ": " << r.message;
    // The local problem, interleaved (normal, tangent) per contact.
    Eigen::MatrixXd G(2 * k, N);
    Eigen::VectorXd mu(k), q(2 * k);
    for (int c = 0; c < k; ++c) {
      G.row(2 * c) = m.E.row(c);
      G.row(2 * c + 1) = m.friction[static_cast<size_t>(c)].tangent.transpose();
      mu(c) = m.friction[static_cast<size_t>(c)].mu;
    }
    const Eigen::MatrixXd W = G * Eigen::MatrixXd(m.M).llt().solve(G.transpose());
    const Eigen::VectorXd a = G * p.v;
    for (int c = 0; c < k; ++c) {
      q(2 * c) = a(2 * c) + e * std::min(a(2 * c), 0.0);
      q(2 * c + 1) = a(2 * c + 1);
    }
    // Unique? Enumerate our LCP (size 3k <= 12) and compare the impulses.
    std::vector<int> normal_of(static_cast<size_t>(k));
    for (int c = 0; c < k; ++c) normal_of[static_cast<size_t>(c)] = c;
    Eigen::MatrixXd Wg(2 * k, 2 * k);  // normals first, then tangents
    std::vector<int> perm;
    for (int c = 0; c < k; ++c) perm.push_back(2 * c);
    for (int c = 0; c < k; ++c) perm.push_back(2 * c + 1);
    for (int i = 0; i < 2 * k; ++i)
      for (int j = 0; j < 2 * k; ++j) Wg(i, j) = W(perm[i], perm[j]);
    Eigen::VectorXd qN(k), qT(k);
    for (int c = 0; c < k; ++c) qN(c) = q(2 * c), qT(c) = q(2 * c + 1);
    const FrictionLcp lcp = friction_lcp(Wg, qN, qT, normal_of, mu);
    lcp::Options eo;
    eo.tolerance = 1e-10;
    const auto sols = lcp::enumerate_solutions(lcp.M, lcp.q, eo);
    std::vector<Eigen::VectorXd> impulses;
    for (const Eigen::VectorXd& z : sols.solutions) {
      Eigen::VectorXd lN, lT;
      friction_impulses(z, k, normal_of, mu, lN, lT);
      Eigen::VectorXd im(2 * k);
      im << lN, lT;
      bool seen = false;
      for (const auto& o : impulses)
        seen |= (o - im).cwiseAbs().maxCoeff() <= 1e-8 * (1 + im.cwiseAbs().maxCoeff());
      if (!seen) impulses.push_back(im);
    }
    // Every accepted draw has one motion: the mode enumeration finds
    // exactly one Coulomb solution's motion, and ours is it (issue 27: 11
    // draws read "several" here; the LCP enumeration found none in each, its
    // complementary bases missing their degenerate solution, never two).
    {
      int singular = 0;
      const Eigen::VectorXd b = (Eigen::VectorXd(2 * k) << qN, qT).finished();
      const std::vector<Eigen::VectorXd> sols_c = coulomb_solutions(Wg, b, mu, singular);
      Eigen::VectorXd lambda(2 * k);
      lambda << r.impulse, r.friction_impulse;
      std::vector<Eigen::VectorXd> with_ours = sols_c;
      with_ours.push_back(lambda);
      EXPECT_EQ(distinct_motions(Wg, b, sols_c), 1) << "trial " << trial;
      EXPECT_EQ(distinct_motions(Wg, b, with_ours), 1) << "trial " << trial;
      EXPECT_EQ(singular, 0) << "trial " << trial;  // every mode was solved
    }
    if (impulses.size() != 1) {
      ++several;
      ++(impulses.empty() ? lcp_enum_none : lcp_enum_more);
      continue;
    }
    Eigen::VectorXd ours(2 * k);
    for (int c = 0; c < k; ++c) ours(2 * c) = r.impulse(c), ours(2 * c + 1) = r.friction_impulse(c);
    // Ours solves the Coulomb problem, checked independently of the LCP
    // (1e-9: the impact's acceptance of rates and impulses).
    EXPECT_LE(coulomb_error(W, q, mu, ours), 1e-9) << "trial " << trial;
    bool agreed = false;
    for (const int solver_id : {SICONOS_FRICTION_2D_LEMKE, SICONOS_FRICTION_2D_ENUM}) {
      const Eigen::VectorXd rs = siconos_fc2d(W, q, mu, solver_id);
      // Siconos 4.4 may report success (info 0) with a non-solution (a
      // negative normal rate): its answer counts only when it passes the
      // same check; the others are counted and reported.
      if (rs.size() != 2 * k || coulomb_error(W, q, mu, rs) > 1e-8) {
        ++siconos_wrong[solver_id == SICONOS_FRICTION_2D_LEMKE ? 0 : 1];
        continue;
      }
      // One solution: both are it. The impulses agree to the accuracy of
      // the solves (entries of W and q O(10)), 1e-8 relative to the largest
      // (Siconos's own tolerance is 1e-10 on its error measure).
      const double scale = 1.0 + rs.cwiseAbs().maxCoeff();
      EXPECT_LE((ours - rs).cwiseAbs().maxCoeff(), 1e-8 * scale)
          << "trial " << trial << " solver " << solver_id;
      agreed = true;
    }
    if (!agreed) continue;
    ++compared;
  }
  std::printf(
      "compared %d, several solutions %d, Painlevé %d; Siconos without a solution: "
      "lemke %d, enum %d\n",
      compared, several, painleve, siconos_wrong[0], siconos_wrong[1]);
  std::printf(
      "of the 'several': the LCP enumeration found none %d, more than one %d; refused as "
      "Painlevé with one motion by the modes' enumeration: %d\n",
      lcp_enum_none, lcp_enum_more, refused_unique);
  EXPECT_EQ(lcp_enum_more, 0);  // no accepted draw has two solutions
  // Issue 27: of the 17 draws refused by the sufficient conditions (a
  // contact alone with W_NN - mu |W_NT| <= 0, or a normal matrix that is
  // not a P-matrix in the solved modes), the 16 with one motion are now
  // accepted (each checked above as every accepted draw: its motion the
  // enumeration's one, and Siconos's where Siconos solves it); trial 84,
  // with three motions, is the one refused.
  EXPECT_EQ(painleve, 1);
  EXPECT_EQ(refused_unique, 0);
  // The seed is fixed (measured: 99 of 200 compared, 38 Painlevé-type, 7 with
  // several solutions, Siconos without a solution on about 60 of the rest;
  // with issue 27's modes: 113 compared, 1 Painlevé-type, 13 "several"):
  // the test must keep comparing a good share.
  EXPECT_GE(compared, 90);
}

}  // namespace
}  // namespace lcsim::impact
