// Private to src/sim: the planar Coulomb step problem of Moreau–Jean with
// friction (mj_friction.hpp) on a sparse Delassus matrix, by block
// (contact-by-contact) Gauss–Seidel: the sparse counterpart of
// impact::friction_lcp for active sets too large for a dense LCP, as
// lcp::solve_sparse_pgs is for the frictionless step. The friction LCP's
// matrix has a zero diagonal in its reserve rows (2 mu lambda_N - lambda_R ⟂
// xi), so PGS on it does not apply; each contact's two unknowns are instead
// solved exactly together, as Siconos's fc2d_nsgs and Bullet's sequential
// impulses do.
//
// Problem. u = W lambda + b with lambda = (lambda_N (n_N), lambda_T (n_F)),
// W symmetric positive semi-definite (n_N + n_F square, normal rows first),
// tangent_of[a] the position of normal a's tangent row (n_N + f) or -1:
//   0 <= u_N ⟂ lambda_N >= 0 at every normal row;
//   |lambda_T| <= mu lambda_N, lambda_T = -mu lambda_N sign(u_T) where u_T != 0
// at every frictional contact: the solutions of impact::friction_lcp, whose
// z = (lambda_N, lambda_T + mu lambda_N, max(0, -u_T)).
//
// Local solve at contact a, with the others fixed (r = the rest of u): r_N >= 0
// gives lambda = 0; else stick (the 2 x 2 solve of u_N = u_T = 0) if it lies in
// the cone; else slip with lambda_T = -s mu lambda_N, s = +-1, where
// u_N = 0 and s u_T >= 0. A contact where none holds (W_NN - s mu W_NT <= 0:
// Painlevé-type) ends the solve kNumericalFailure.
//
// Stopping: after a sweep whose largest change |W_aa dlambda_a| is at most
// acceptance = tolerance (1 + ||b||_inf) (lcp::solve_sparse_pgs's rule), the
// natural residual of the friction LCP at z above (residual()) is computed and
// the solve ends kSolved when it is at most acceptance too.
#pragma once

#include <lcsim/lcp/lcp.hpp>
#include <vector>

#include "sim/stepping/step_kernels.hpp"

namespace lcsim::sim::detail {

struct FrictionGsProblem {
  const SparseRow* W = nullptr;  // compressed, symmetric
  const VectorXd* b = nullptr;
  const std::vector<int>* tangent_of = nullptr;  // per normal row
  const VectorXd* mu = nullptr;                  // per tangent row (n_F)
  int n_normal = 0;
};

// kSolved or kIterationLimit when the sweeps ran; the message says why not.
struct FrictionGsResult : OutcomeStartingAs<lcp::Status::kNumericalFailure> {
  int sweeps = 0;
  double residual = 0.0;  // natural residual of the friction LCP
};

// lambda: the warm start on entry (n_N + n_F, projected onto the cone by the
// first sweep), the last iterate on return; u: scratch, W lambda + b of the
// last residual check on return.
FrictionGsResult solve_friction_gs(const FrictionGsProblem& p, double tolerance, int max_sweeps,
                                   VectorXd& lambda, VectorXd& u);

// The 2 x 2 local problem of one frictional contact (above): u_N = Wnn ln +
// Wnt lt + rn, u_T = Wnt ln + Wtt lt + rt. False when no mode holds
// (Painlevé-type). Also cone_gs.hpp's local solve at a contact with d = 1.
bool local_coulomb(double Wnn, double Wnt, double Wtt, double rn, double rt, double mu, double& ln,
                   double& lt);

// ||min(z, w)||_inf of impact::friction_lcp at z = (lambda_N, lambda_T + mu
// lambda_N, max(0, -u_T)), with u = W lambda + b given.
double friction_residual(const FrictionGsProblem& p, const VectorXd& lambda, const VectorXd& u);

}  // namespace lcsim::sim::detail
