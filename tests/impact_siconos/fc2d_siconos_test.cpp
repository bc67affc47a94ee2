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

TEST(FrictionVsSiconos, RandomImpactsAgreeWithFc2dLemkeAndEnum) {
  std::mt19937_64 rng(2017);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  int compared = 0, several = 0, painleve = 0, siconos_wrong[2] = {0, 0};
  for (int trial = 0; trial < 200; ++trial) {
    const double e = u01(rng) < 0.5 ? 0.0 : u01(rng);
    const testing::RandomFriction p = testing::random_friction(rng, e, /*all_frictional=*/true);
    const mech::MechanicalModel& m = p.model;
    const int k = m.num_constraints(), N = m.dofs();
    ImpactInput in = testing::input(m, p.v, p.closed, m.restitution);
    const ImpactResult r = moreau_friction(in, *lcp::make_solver("pivot"));
    if (r.painleve) {
      ++painleve;
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
    if (impulses.size() != 1) {
      ++several;
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
  // The seed is fixed (measured: 99 of 200 compared, 38 Painlevé-type, 7 with
  // several solutions, Siconos without a solution on about 60 of the rest):
  // the test must keep comparing a good share.
  EXPECT_GE(compared, 90);
}

}  // namespace
}  // namespace lcsim::impact
