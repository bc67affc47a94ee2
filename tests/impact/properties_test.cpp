// Invariants of the impact rules over thousands of random models (fixed
// seeds): SPD mass matrices with masses over two decades, E of full row rank
// and rank deficient (§4.6.1), random closed sets, velocities and restitution.
//
//  - energy never rises: "moreau" (e = 0), "moreau-qp", "moreau-restitution"
//    with one e in [0, 1] for all contacts, "sequential" with e_i in [0, 1];
//  - E_J v+ >= 0 after every admissible result, complementarity;
//  - "moreau" and "moreau-qp" agree; with dependent constraints the impulse
//    is not unique but E'·impulse is (Theorem 4.6.5, Lemma 4.6.1).
//
// Tolerances are relative to the scale of the quantity: rates to
// |E_i|(|v| + |v+|), energies to T(v), velocities to |v| in the M-norm. The
// pivoting solvers solve one linear system of size <= 8 per impact; the
// largest errors seen over these seeds are printed by each test (about 1e-15
// to 1e-13 relative), so the stated bounds keep a margin of 10-100 while
// still catching any error of the rules themselves (which are O(1)).
#include <gtest/gtest.h>

#include <cstdio>
#include <lcsim/impact/impact.hpp>
#include <lcsim/ipopt/moreau_qp.hpp>
#include <random>

#include "impact_test_util.hpp"

namespace lcsim::impact {
namespace {

using testing::RandomImpact;

const lcp::Solver& solver(const char* name) {
  static const auto pivot = lcp::make_solver("pivot");
  static const auto lemke = lcp::make_solver("lemke");
  return std::string(name) == "lemke" ? *lemke : *pivot;
}

double m_norm(const Eigen::MatrixXd& M, const Eigen::VectorXd& x) {
  return std::sqrt(x.dot(M * x));
}

// Worst of E_i v+ / scale_i over the closed set (negative = violation). The
// scale is the size of the terms of E_i v+ = E_i v + E_i M^{-1}E' lambda:
// |E_i|(|v| + |v+| + |M^{-1}E'||lambda|), what rounding is relative to.
double worst_relative_rate(const ImpactInput& in, const ImpactResult& r) {
  const Eigen::MatrixXd& E = in.model->E;
  const Eigen::MatrixXd MinvEt = in.model->M.toDense().llt().solve(E.transpose());
  const Eigen::VectorXd scale = testing::rate_scale(E, in.v, r.v_after) +
                                E.cwiseAbs() * (MinvEt.cwiseAbs() * r.impulse.cwiseAbs());
  double worst = 0.0;
  for (int i : in.closed) worst = std::min(worst, E.row(i).dot(r.v_after) / (scale(i) + 1e-300));
  return worst;
}

struct Worst {
  double energy_rise = 0.0;  // max (T+ - T-) / T-
  double violation = 0.0;    // max -E_i v+ / scale_i
  double complementarity = 0.0;
  void energy(const ImpactResult& r) {
    if (r.energy_before > 0.0)
      energy_rise = std::max(energy_rise, (r.energy_after - r.energy_before) / r.energy_before);
  }
};

constexpr int kCases = 3000;

// Energy and feasibility for the dissipative rules; feasibility for all.
TEST(ImpactProperties, EnergyNeverRisesAndContactsNeverApproach) {
  std::mt19937_64 rng(20261121);
  std::uniform_real_distribution<double> u01(0.0, 1.0);
  Worst moreau, mj, seq, all;
  int flagged = 0, seq_capped = 0;
  double violation[7] = {};
  const char* names[7] = {"moreau",     "moreau-restitution", "newton (uniform e)",
                          "sequential", "newton (e_i)",       "moreau-restitution (e_i)",
                          "flip"};
  for (int c = 0; c < kCases; ++c) {
    const RandomImpact ri = testing::random_impact(rng, c % 3 == 0);
    const int k = ri.model.num_constraints();
    ImpactInput in = testing::input(ri.model, ri.v, ri.closed);
    const Eigen::VectorXd e_uniform = Eigen::VectorXd::Constant(k, u01(rng));
    Eigen::VectorXd e_each(k);
    for (int i = 0; i < k; ++i) e_each(i) = u01(rng);
    SCOPED_TRACE("case " + std::to_string(c));

    in.restitution = Eigen::VectorXd::Zero(k);
    const ImpactResult rm = moreau_newton(in, solver("pivot"));
    ASSERT_TRUE(rm.ok()) << rm.message;
    moreau.energy(rm);
    in.restitution = e_uniform;
    const ImpactResult rmj = moreau_restitution(in, solver("pivot"));
    ASSERT_TRUE(rmj.ok()) << rmj.message;
    mj.energy(rmj);
    const ImpactResult rmu = moreau_newton(in, solver("pivot"));  // uniform e: the same map
    ASSERT_TRUE(rmu.ok()) << rmu.message;
    mj.energy(rmu);
    // Two LCPs with the same solution in exact arithmetic, each accepted at
    // 1e-12..1e-10 on its scaled problem; cond(W) up to ~1e3 here: 1e-7.
    EXPECT_LE(m_norm(ri.model.M, rmu.v_after - rmj.v_after), 1e-7 * m_norm(ri.model.M, ri.v));
    in.restitution = e_each;
    const ImpactResult rs = sequential(in);
    if (rs.ok())
      seq.energy(rs);
    else
      ++seq_capped;
    // Feasibility after every admissible result, per-contact e included.
    const ImpactResult rn = moreau_newton(in, solver("pivot"));
    const ImpactResult rmje = moreau_restitution(in, solver("lemke"));
    in.restitution = Eigen::VectorXd::Zero(k);
    const ImpactResult rf = flip_rule(in);
    const std::pair<int, const ImpactResult*> checked[] = {
        {0, &rm}, {1, &rmj}, {2, &rmu}, {3, &rs}, {4, &rn}, {5, &rmje}, {6, &rf}};
    for (const auto& [which, r] : checked) {
      if (!r->ok() || !r->admissible) {
        ++flagged;
        continue;
      }
      violation[which] = std::max(violation[which], -worst_relative_rate(in, *r));
      all.violation = std::max(all.violation, violation[which]);
    }
    // Complementarity of Moreau's rule: lambda_i (E_i v+) = 0.
    const Eigen::MatrixXd MinvEt =
        ri.model.M.toDense().llt().solve(ri.model.E.transpose().toDense());
    const Eigen::VectorXd scale =
        testing::rate_scale(ri.model.E, ri.v, rm.v_after) +
        ri.model.E.cwiseAbs() * (MinvEt.cwiseAbs() * rm.impulse.cwiseAbs());
    const double lmax = rm.impulse.cwiseAbs().maxCoeff();
    for (int i : ri.closed)
      if (lmax > 0.0)
        moreau.complementarity = std::max(
            moreau.complementarity,
            std::abs(rm.impulse(i) * ri.model.E.row(i).dot(rm.v_after)) / (lmax * scale(i)));
  }
  std::printf("worst relative energy rise: moreau %.2e, moreau-restitution %.2e, sequential %.2e\n",
              moreau.energy_rise, mj.energy_rise, seq.energy_rise);
  std::printf(
      "worst relative violation %.2e, complementarity %.2e; %d results flagged, "
      "sequential capped %d of %d\n",
      all.violation, moreau.complementarity, flagged, seq_capped, kCases);
  for (int i = 0; i < 7; ++i) std::printf("  worst violation %-26s %.2e\n", names[i], violation[i]);
  // A rise by rounding: T is computed as ½ v'Mv from v+ that carries a
  // relative error ~ cond(W) eps; 1e-10 keeps a wide margin over what is seen.
  EXPECT_LE(moreau.energy_rise, 1e-10);
  EXPECT_LE(mj.energy_rise, 1e-10);
  EXPECT_LE(seq.energy_rise, 1e-10);
  EXPECT_LE(all.violation, 1e-12);
  EXPECT_LE(moreau.complementarity, 1e-12);
  // The sequential rule converges on most of these; the rest are reported.
  EXPECT_LE(seq_capped, kCases / 20);
}

// moreau-qp (Ipopt) against moreau (pivoting) on a few hundred cases.
TEST(ImpactProperties, MinimisationAgreesWithTheLcp) {
  std::mt19937_64 rng(7);
  double worst_v = 0.0, worst_rate = 0.0, worst_energy = 0.0, worst_lambda = 0.0;
  for (int c = 0; c < 300; ++c) {
    const RandomImpact ri = testing::random_impact(rng, c % 3 == 0);
    const ImpactInput in = testing::input(ri.model, ri.v, ri.closed);
    SCOPED_TRACE("case " + std::to_string(c));
    const ImpactResult lcp = moreau_newton(in, solver("pivot"));
    const ImpactResult qp = moreau_qp(in);
    ASSERT_TRUE(lcp.ok()) << lcp.message;
    ASSERT_TRUE(qp.ok()) << qp.message;
    const double vn = m_norm(ri.model.M, ri.v);
    if (vn == 0.0) continue;
    // Same post-impact velocity, i.e. the same E'·impulse = M (v+ - v).
    worst_v = std::max(worst_v, m_norm(ri.model.M, qp.v_after - lcp.v_after) / vn);
    worst_rate = std::max(worst_rate, -worst_relative_rate(in, qp));
    if (qp.energy_before > 0.0)
      worst_energy =
          std::max(worst_energy, (qp.energy_after - qp.energy_before) / qp.energy_before);
    // Independent rows: the impulse itself is unique (compared when nonzero;
    // a zero impulse is covered by the velocity check).
    const double ln = lcp.impulse.cwiseAbs().maxCoeff();
    if (!ri.dependent && ln > 0.0)
      worst_lambda = std::max(worst_lambda, (qp.impulse - lcp.impulse).cwiseAbs().maxCoeff() / ln);
  }
  std::printf(
      "moreau-qp vs moreau: velocity %.2e, impulse %.2e, violation %.2e, energy rise %.2e\n",
      worst_v, worst_lambda, worst_rate, worst_energy);
  // Ipopt stops at tol 1e-12 on the scaled problem; the interior point leaves
  // errors ~ sqrt(mu) in the active set's neighbourhood, far below 1e-7.
  EXPECT_LE(worst_v, 1e-7);
  EXPECT_LE(worst_lambda, 1e-6);  // impulses can lose a factor cond(W) more
  EXPECT_LE(worst_rate, 1e-9);    // Ipopt's constr_viol_tol 1e-12, scaled
  EXPECT_LE(worst_energy, 1e-9);
}

// Theorem 4.6.5 (Lemma 4.6.1): with dependent constraints the impact LCP may
// have several solutions lambda, but all give the same E_J' lambda, hence the
// same jump. Enumerate every solution and compare.
TEST(ImpactProperties, DependentConstraintsShareTheJump) {
  std::mt19937_64 rng(4651);
  int multiple = 0, checked = 0;
  for (int c = 0; c < 1000; ++c) {
    const RandomImpact ri = testing::random_impact(rng, true);
    if (ri.closed.size() < 2 || ri.closed.size() > 8) continue;
    Eigen::MatrixXd EJ(ri.closed.size(), ri.model.dofs());
    for (size_t i = 0; i < ri.closed.size(); ++i) EJ.row(i) = ri.model.E.row(ri.closed[i]);
    const Eigen::MatrixXd W = EJ * ri.model.M.toDense().llt().solve(EJ.transpose());
    const lcp::EnumerationResult all = lcp::enumerate_solutions(W, EJ * ri.v);
    if (all.solutions.empty()) continue;  // enumeration misses singular-only bases
    ++checked;
    const ImpactResult r =
        moreau_newton(testing::input(ri.model, ri.v, ri.closed), solver("pivot"));
    ASSERT_TRUE(r.ok()) << r.message;
    const Eigen::VectorXd jump = r.v_after - ri.v;
    const double scale = std::max(m_norm(ri.model.M, ri.v), 1e-300);
    if (all.solutions.size() > 1) ++multiple;
    for (const Eigen::VectorXd& z : all.solutions) {
      const Eigen::VectorXd jz = ri.model.M.toDense().llt().solve(EJ.transpose() * z);
      // Enumeration solves singular subsystems by least squares: 1e-8
      // relative. Relative to the larger of |v| and the jump's own terms
      // M^{-1} |E_J'| |z|: the LCP layer accepts a z row by row against
      // |q_i| + sum_j |W_ij| |z_j| (lcp::scaled_residual), so on a nearly
      // singular W a solution whose large entries cancel is exact only to
      // that scale (case 938: error 3.6e-8 against the former bound 4.2e-9).
      const Eigen::VectorXd terms =
          ri.model.M.toDense().llt().solve(EJ.cwiseAbs().transpose() * z.cwiseAbs());
      EXPECT_LE(m_norm(ri.model.M, jz - jump), 1e-8 * std::max(scale, m_norm(ri.model.M, terms)))
          << "case " << c;
    }
  }
  std::printf("dependent constraints: %d cases checked, %d with several impulses\n", checked,
              multiple);
  EXPECT_GT(checked, 300);
  EXPECT_GT(multiple, 10);  // the theorem is not vacuous here
}

}  // namespace
}  // namespace lcsim::impact
