// Impact rules besides Moreau's LCP: the Moreau–Jean law with restitution in
// the LCP, sequential pairwise impacts (Example 1.4.1) and the mode rule of
// ref. [177] that Example 3.8.3 refutes ("flip").
#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <sstream>

#include "impact/detail.hpp"

namespace lcsim::impact {

ImpactResult moreau_restitution(const ImpactInput& in, const lcp::Solver& solver) {
  ImpactResult out;
  const auto s = detail::prepare(in, out);
  if (!s) return out;
  // 0 <= E_J v+ + e∘E_J v ⟂ lambda >= 0 with E_J v+ = a + W lambda:
  // the LCP w = W lambda + (1 + e)∘a.
  const VectorXd q = (1.0 + s->e_J.array()).matrix().cwiseProduct(s->a);
  const auto z = detail::solve_impact_lcp(s->W, q, solver, out);
  if (!z) return out;
  // Rates E_J v+ + e∘a >= 0: refined on E where that still solves the LCP.
  if (const auto ref = detail::refine_on_active_set(*s, in.v, s->e_J, *z))
    detail::finish(in, *s, ref->impulse_J, ref->v_after, 0.0, out);
  else
    detail::finish(in, *s, *z, in.v + s->MinvEt * *z, 0.0, out);
  out.status = Status::kOk;
  return out;
}

ImpactResult sequential(const ImpactInput& in) {
  ImpactResult out;
  const auto s = detail::prepare(in, out);
  if (!s) return out;
  const int nj = static_cast<int>(in.closed.size());
  const int cap = in.max_iterations > 0 ? in.max_iterations : 100000;
  // "Approaching": E_i v < -1e-12 |E_i||v-|, relative to the pre-impact
  // velocity and fixed for the whole sequence, so the test does not tighten
  // as energy drains (no absolute floor: it would dominate at small |v|).
  const VectorXd scale = s->EJ.cwiseAbs() * in.v.cwiseAbs();
  VectorXd v = in.v;
  VectorXd impulse_J = VectorXd::Zero(nj);
  if (in.record_iterates) out.iterates.push_back(v);
  int impacts = 0, sweeps = 0;
  bool converged = false;
  while (!converged && impacts < cap) {
    ++sweeps;
    converged = true;
    for (int i = 0; i < nj && impacts < cap; ++i) {
      const double rate = s->EJ.row(i).dot(v);
      if (rate >= -kRelTol * scale(i)) continue;
      if (!(s->W(i, i) > 0.0)) {
        out.message = "sequential: constraint " + std::to_string(in.closed[i]) +
                      " has a zero row E_i, it cannot be resolved";
        return out;
      }
      // Contact i alone: E_i v+ = -e_i E_i v, v+ = v + M^{-1} E_i' lambda_i.
      const double lambda = -(1.0 + s->e_J(i)) * rate / s->W(i, i);
      v += s->MinvEt.col(i) * lambda;
      impulse_J(i) += lambda;
      ++impacts;
      converged = false;
      if (in.record_iterates) out.iterates.push_back(v);
    }
  }
  out.iterations = impacts;
  // After the cap, one more check: the last impact may have settled it.
  if (!converged) {
    converged = true;
    for (int i = 0; i < nj; ++i)
      if (s->EJ.row(i).dot(v) < -kRelTol * scale(i)) converged = false;
  }
  detail::finish(in, *s, impulse_J, v, 0.0, out);
  std::ostringstream msg;
  if (converged) {
    msg << "converged after " << impacts << " pairwise impacts (" << sweeps << " sweeps)";
    out.status = Status::kOk;
  } else {
    msg << "sequential: not converged after " << impacts
        << " pairwise impacts (cap); closed contacts still approach";
    out.admissible = false;
  }
  out.message = msg.str();
  return out;
}

ImpactResult flip_rule(const ImpactInput& in) {
  ImpactResult out;
  const auto s = detail::prepare(in, out);
  if (!s) return out;
  const int nj = static_cast<int>(in.closed.size());
  const VectorXd scale = s->EJ.cwiseAbs() * in.v.cwiseAbs();
  // Mode of [177] from the unconstrained mode: Gamma_1 = the closed
  // constraints whose inequality continuation would violate, E_i v < 0.
  std::vector<int> sel;
  for (int i = 0; i < nj; ++i)
    if (s->a(i) < -(kRelTol * scale(i) + kAbsTol)) sel.push_back(i);
  VectorXd impulse_J = VectorXd::Zero(nj);
  if (!sel.empty()) {
    const int ni = static_cast<int>(sel.size());
    MatrixXd WII(ni, ni);
    VectorXd aI(ni);
    for (int r = 0; r < ni; ++r) {
      aI(r) = s->a(sel[r]);
      for (int c = 0; c < ni; ++c) WII(r, c) = s->W(sel[r], sel[c]);
    }
    // E_I v+ = 0: W_II lambda_I = -E_I v. Consistent even for dependent rows
    // (E_I v is in Im E_I = Im W_II, Lemma 4.6.2); the minimal-norm solution
    // is then one of many with the same E_I' lambda_I.
    const VectorXd lambdaI = WII.completeOrthogonalDecomposition().solve(-aI);
    for (int r = 0; r < ni; ++r) impulse_J(sel[r]) = (1.0 + s->e_J(sel[r])) * lambdaI(r);
  }
  detail::finish(in, *s, impulse_J, in.v + s->MinvEt * impulse_J, 0.0, out);
  // The selected mode is I itself, whatever the signs of the impulse.
  out.mode.clear();
  for (int i : sel) out.mode.push_back(in.closed[i]);
  out.status = Status::kOk;
  if (!out.admissible) {
    std::ostringstream msg;
    msg << "not an admissible solution:";
    bool negative = false;
    for (int i : sel) {
      if (impulse_J(i) >= 0.0) continue;
      const int c = in.closed[i];
      const std::string name = c < static_cast<int>(in.model->constraints.size())
                                   ? in.model->constraints[c]
                                   : std::to_string(c);
      msg << " impulse " << impulse_J(i) << " < 0 on constraint '" << name << "';";
      negative = true;
    }
    if (!negative) msg << " E_J v+ = " << out.worst_rate << " < 0;";
    out.message = msg.str();
    out.message.pop_back();
    out.message += " (rule [177], Example 3.8.3)";
  }
  return out;
}

}  // namespace lcsim::impact
