// Private to src/sim: Moreau–Jean's step problem with 3-D Coulomb friction
// on the polyhedral cone (mj_friction.hpp) on a sparse Delassus matrix, by
// block (contact-by-contact) Gauss–Seidel: the sparse counterpart of the
// dense Stewart–Trinkle LCP (impact::friction_cone_lcp), for steps whose LCP
// is above the dense limit (issue 27). Each contact's three unknowns are
// solved exactly together with the others fixed, as friction_gs.hpp does
// for the planar law (and Siconos's fc3d_nsgs for the circular cone).
//
// Problem. u = W lambda + b over G = [E_A; T_F; T2_F] (n_N + 2 n_F square,
// symmetric positive semi-definite), lambda = (lambda_N, p1, p2): normal
// impulses, friction impulses along t and t2. Normal row a of a frictional
// contact j has its rows t = n_N + j and t2 = n_N + n_F + j. The polygon
// P_d = conv{D_i}, D_i = (cos, sin)(pi i/d), i = 0 .. 2d-1 (the cone's
// section at unit normal impulse, inscribed in the unit disk):
//   0 <= u_N ⟂ lambda_N >= 0 at every normal row;
//   p = (p1, p2) in mu lambda_N P_d, and p minimises p'.u_T over that polygon
//   (maximal dissipation), u_T = (u_t, u_t2).
// These are the solutions of impact::friction_cone_lcp with the same W (its
// edge impulses beta_i >= 0 with p = sum beta_i D_i, its slack xi the sliding
// speed in the polygon's dual norm, max_i -D_i.u_T). A contact with d = 1 (a
// planar contact, or a 3-D one with d = 1) has no friction along t2 (p2 = 0)
// and is solved by friction_gs.hpp's planar local problem on (N, t).
//
// Local solve at contact j (d >= 2), the rest r fixed: r_N >= 0 gives zero;
// else stick (the 3 x 3 solve of u = 0) when its force lies in the polygon;
// else slip on a facet: on vertex i (p = mu lambda_N D_i, u_N = 0, -u_T in
// the normal cone of the polygon at D_i) or along face i (between D_i and
// D_i+1, u_T = -sigma n_i with n_i the face's outward normal, sigma >= 0),
// each a linear system of at most 3 unknowns, tried from the contact's last
// facet outwards. The first that holds (to 1e-12 relative) is taken; when
// none holds by rounding, the one that violates least; a contact where no
// facet can be solved (a non-positive pivot: Painlevé-type) ends the solve
// kNumericalFailure.
//
// Stopping (the convergence criterion): after a sweep whose largest change
// |W_ii dlambda_i| is at most acceptance = tolerance (1 + ||b||_inf) (the
// planar rule), the natural residual ||min(z, w)||_inf of the Stewart–Trinkle
// LCP is computed at z = (lambda_N, beta, xi), beta the decomposition of p on
// the two edges that bracket it (the least sum: its gauge) and xi =
// max(0, max_i -D_i.u_T) (cone_residual()); kSolved when it is at most
// acceptance too. kIterationLimit after max_sweeps: the caller reports it as
// numerical trouble.
#pragma once

#include <lcsim/lcp/lcp.hpp>
#include <vector>

#include "sim/stepping/step_kernels.hpp"

namespace lcsim::sim::detail {

struct ConeGsProblem {
  const SparseRow* W = nullptr;  // compressed, symmetric, n_N + 2 n_F square
  const VectorXd* b = nullptr;
  const std::vector<int>* tangent_of = nullptr;  // per normal row: n_N + j, or -1
  const VectorXd* mu = nullptr;                  // per frictional contact (n_F)
  const std::vector<int>* d = nullptr;           // per frictional contact (n_F), >= 1
  int n_normal = 0;
  int n_friction = 0;
};

// kSolved, kIterationLimit, or kNumericalFailure (message says why).
struct ConeGsResult : OutcomeStartingAs<lcp::Status::kNumericalFailure> {
  int sweeps = 0;
  double residual = 0.0;  // natural residual of the Stewart–Trinkle LCP
};

// lambda: the warm start on entry (n_N + 2 n_F; the first sweep projects
// it), the last iterate on return. facet: per frictional contact, the last
// facet found (2i vertex i, 2i + 1 face i, -1 none): a hint on entry, kept
// across steps by the caller. u: scratch, W lambda + b at the last residual
// check on return.
ConeGsResult solve_cone_gs(const ConeGsProblem& p, double tolerance, int max_sweeps,
                           VectorXd& lambda, std::vector<int>& facet, VectorXd& u);

// The natural residual of the Stewart–Trinkle LCP at lambda (above), with
// u = W lambda + b given.
double cone_residual(const ConeGsProblem& p, const VectorXd& lambda, const VectorXd& u);

}  // namespace lcsim::sim::detail
