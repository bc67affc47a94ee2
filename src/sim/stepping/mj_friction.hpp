// Moreau–Jean's step LCP with planar Coulomb friction (issue 17): the
// frictionless step's active set A and free velocity, the friction LCP of
// impact::friction_lcp over A and the frictional contacts F in A (the same
// three unknowns per contact as the impact law), restitution inside the LCP
// as in the frictionless step. The frictionless path never comes here.
//
// Sparse and active-set as the frictionless step (moreau_jean.cpp):
// - The columns W^{-1} t_f' are MjIteration's (column k + f), computed on
//   first use and pruned like W^{-1} E_i'.
// - The Delassus matrix G W^{-1} G' over G = [E_A; T_F] is assembled from
//   those columns and the columns of G (an entry where a cached column meets
//   a row of G, nothing else), kept while A and the iteration matrix stay.
// - |A| + |F| <= Options::pivot_max_active: the dense friction LCP
//   (impact::friction_lcp), first on the previous step's basis when A is
//   unchanged (MjFriction::warm: one solve with a kept LU factor, accepted
//   when it is a solution), else solved by impact::solve_friction_lcp with
//   the configured solver and its fallbacks. Larger: block Gauss–Seidel on the
//   sparse Delassus matrix (friction_gs.hpp), warm-started from the previous
//   step's impulses; where it does not converge, the dense friction LCP when
//   it is at most kDenseFallbackMax unknowns, else the iterate is kept and
//   the caller warns (as the frictionless step's PGS).
// - Scratch is kept across steps: a step with an unchanged active set
//   allocates nothing on the sparse path.
//
// 3-D friction (issue 27; models with mech::MechanicalModel::has_friction_3d,
// planar models never take this path): G = [E_A; T_F; T2_F] (T2 the second
// tangents, MjIteration's columns k + n_F + f; a planar contact of such a
// model has an empty one) assembled as above, then Wb = P Wg P' over the
// cone's edges D_i = cos(pi i/d) t + sin(pi i/d) t2 (P maps the tangent
// rows to the 2d edge rows of each contact) and the step LCP in Stewart and
// Trinkle's form (impact::friction_cone_lcp: lambda_N, 2d edge impulses, the
// slack xi, the sliding speed in the polygon's dual norm), solved dense: on
// the previous step's basis when A is unchanged (warm()), else by
// impact::solve_friction_cone_lcp. A step whose LCP has more than
// kDenseFallbackMax unknowns is solved by block Gauss–Seidel over the
// contacts on the sparse Wg (cone_gs.hpp), warm-started from the previous
// step's impulses and facets, stopped on the cone LCP's natural residual;
// where it does not converge in kGsMaxSweeps sweeps the step fails
// (numerical trouble, never a kept iterate). The sweeps also take a step
// whose dense LCP found no solution (dependent rows: four corners of one
// face); where the dense path solves, its numbers stand.
#pragma once

#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <string>
#include <vector>

#include "sim/stepping/step_kernels.hpp"

namespace lcsim::sim::detail {

class MjFriction {
 public:
  static constexpr double kGsTolerance = 1e-13;  // as the frictionless PGS (moreau_jean.cpp)
  static constexpr int kGsMaxSweeps = 5000;
  static constexpr int kDenseFallbackMax = 600;   // friction LCP unknowns (n_N + 2 n_F)
  static constexpr double kWarmResidual = 1e-12;  // as impact::solve_friction_lcp's acceptance

  MjFriction(const mech::MechanicalModel& m, const MjOperators& ops);
  // Whether A holds a frictional contact.
  bool any_in(const IndexSet& A) const;
  // Solves the step: v_next holds v_free on entry (rates from it), the
  // post-step velocity on return; lambda_N (|A|) holds the previous step's
  // normal impulses on entry (warm start) and this step's on return;
  // lambda_T (k, zero on entry) gets the tangential impulses (N s) of A's
  // frictional contacts. cols: W^{-1} E_a' for a in A. Ev = E v at the
  // step's start (restitution e_i E_i v on the normal rows). False on an LCP
  // failure (`failed` holds it); `warning` non-empty when the iterate of a
  // non-converged sweep was kept.
  // 3-D friction: the impulses (N s) along the second tangents of the last
  // step, per constraint (k; zero without 3-D friction).
  const VectorXd& lambda_T2() const { return lamT2_; }
  bool step(MjIteration& f, const IndexSet& A, const std::vector<const SparseCol*>& cols,
            const VectorXd& Ev, const VectorXd& e, const lcp::Solver& solver, int pivot_max_active,
            VectorXd& v_next, VectorXd& lambda_N, VectorXd& lambda_T, long& solves,
            lcp::Result& failed, std::string& warning);

 private:
  bool assemble(MjIteration& f, const IndexSet& A, const std::vector<const SparseCol*>& cols);
  void pack_columns();
  bool solve_dense(const MatrixXd& Wg, const lcp::Solver& solver, long& solves,
                   lcp::Result& failed);
  bool solve_kept(bool cone, const lcp::Solver& solver, long& solves, lcp::Result& failed);
  bool warm();
  void assemble_cone();
  bool solve_cone(const lcp::Solver& solver, long& solves, lcp::Result& failed);
  bool solve_cone_sparse(long& solves, lcp::Result& failed);
  bool solve_sparse(const lcp::Solver& solver, long& solves, lcp::Result& failed,
                    std::string& warning);

  const mech::MechanicalModel& m_;
  const SparseCol& Gt_;          // [E; T]' (MjOperators::rows_transposed)
  SparseCol Gc_;                 // [E; T] by columns: the rows of G touching a coordinate
  std::vector<int> of_contact_;  // index into m.friction per constraint, -1 if none
  std::vector<int> gpos_;        // position of row i of [E; T] in this step's G, or -1
  // The active set of the assembled Delassus matrix, and its iteration matrix.
  IndexSet A_;
  const MjIteration* f_ = nullptr;
  long na_ = 0, nf_ = 0;
  std::vector<int> fric_;                // F: index into m.friction
  std::vector<int> contact_;             // F: its constraint (m.friction[fric_[j]].contact)
  std::vector<int> normal_of_;           // F: position of the normal row in A
  std::vector<int> tangent_of_;          // A: position of the tangent row in G, or -1
  std::vector<const SparseCol*> gcols_;  // W^{-1} G_g' per row g of G
  SparseCol gpacked_;                    // the same columns in one matrix (the impulses' update)
  VectorXd mu_, belt_;
  SparseRow Wg_;  // G W^{-1} G'
  MatrixXd Wd_;   // the same, dense, for |G| <= pivot_max_active
  std::vector<Eigen::Triplet<double>> trip_;
  VectorXd b_, lam_, u_, lamT_prev_;  // rates, impulses (N, T), scratch, last lambda_T per row
  // Dense path: the friction LCP (M kept while A stays: version_), the last
  // solution z and the warm start's basis, factor and scratch.
  long version_ = 0, p_version_ = -1, zprev_version_ = -1, lu_version_ = -1;
  impact::FrictionLcp p_;
  VectorXd zprev_, qj_, zj_, zw_, ww_;
  std::vector<int> J_, J_factored_;
  MatrixXd Mjj_;
  Eigen::PartialPivLU<MatrixXd> lu_;
  // 3-D friction: whether the model has it, the columns' offset k + n_F of
  // the second tangents, an empty column (a planar contact's second
  // tangent), per F: edge pairs d and first edge row; the edges' Delassus
  // matrix Wb, their rates and the impulses along t2 per constraint.
  bool cone_ = false;
  int t2_col_ = 0;
  SparseCol empty_;
  long ne_ = 0;
  std::vector<int> d_, first_;
  MatrixXd Wb_;
  VectorXd rate_D_, lamT2_;
  // The sparse cone path: per constraint, the facet of the last step (the
  // search's start, cone_gs.hpp), and per F this step's.
  std::vector<int> facet_prev_, facet_;
};

}  // namespace lcsim::sim::detail
