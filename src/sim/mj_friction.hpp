// Moreau–Jean's step LCP with planar Coulomb friction (issue 17): the
// frictionless step's active set A and free velocity, the friction LCP of
// impact::friction_lcp over A and the frictional contacts in A (the same
// three unknowns per contact as the impact law), restitution inside the LCP
// as in the frictionless step. Dense: the friction path assembles
// G W^{-1} G' (G = [E_A; T_F]) for each step; the frictionless path never
// comes here.
#pragma once

#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <vector>

#include "sim/step_kernels.hpp"

namespace lcsim::sim::detail {

class MjFriction {
 public:
  explicit MjFriction(const mech::MechanicalModel& m);
  // The frictional contacts among A (positions in A), none if the model has
  // no friction.
  bool any_in(const IndexSet& A) const;
  // Solves the step: v_next holds v_free on entry (rates from it), the
  // post-step velocity on return; lambda_N (|A|) and, per constraint,
  // lambda_T (k, zero outside A's frictional contacts) the impulses (N s).
  // Ev = E v at the step's start (restitution e_i E_i v on the normal rows).
  // False on an LCP failure (`failed` holds it).
  bool step(MjIteration& f, const IndexSet& A, const std::vector<const SparseCol*>& cols,
            const VectorXd& Ev, const VectorXd& e, const lcp::Solver& solver, VectorXd& v_next,
            VectorXd& lambda_N, VectorXd& lambda_T, long& solves, lcp::Result& failed);

 private:
  const mech::MechanicalModel& m_;
  std::vector<int> of_contact_;  // index into m.friction per constraint, -1 if none
  SparseRow Er_;                 // E by rows
  // W^{-1} t_f' per iteration matrix (the run's two step lengths).
  std::vector<std::pair<const MjIteration*, std::vector<VectorXd>>> tcols_;
  const std::vector<VectorXd>& tangent_columns(const MjIteration& f);
};

}  // namespace lcsim::sim::detail
