// Moreau–Jean's step with friction (see mj_friction.hpp).
#include "sim/stepping/mj_friction.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sim/stepping/cone_gs.hpp"
#include "sim/stepping/friction_gs.hpp"

namespace lcsim::sim::detail {

MjFriction::MjFriction(const mech::MechanicalModel& m, const MjOperators& ops)
    : m_(m),
      Gt_(ops.rows_transposed()),
      Gc_(ops.rows_transposed().transpose()),
      of_contact_(static_cast<size_t>(m.num_constraints()), -1),
      gpos_(static_cast<size_t>(ops.rows_transposed().cols()), -1),
      lamT_prev_(VectorXd::Zero(m.num_constraints())),
      cone_(m.has_friction_3d()),
      t2_col_(m.num_constraints() + static_cast<int>(m.friction.size())),
      empty_(m.dofs(), 1),
      lamT2_(VectorXd::Zero(m.has_friction_3d() ? m.num_constraints() : 0)),
      facet_prev_(static_cast<size_t>(m.num_constraints()), -1) {
  for (size_t f = 0; f < m.friction.size(); ++f)
    of_contact_[static_cast<size_t>(m.friction[f].contact)] = static_cast<int>(f);
  Gc_.makeCompressed();
}

bool MjFriction::any_in(const IndexSet& A) const {
  if (m_.friction.empty()) return false;
  for (int i : A)
    if (of_contact_[static_cast<size_t>(i)] >= 0) return true;
  return false;
}

// G = [E_A; T_F] and its Delassus matrix from the cached columns: entry
// (p, g) sums G_p,r (W^{-1} G_g')_r over the column's rows r, as the
// frictionless step's for_each_entry.
bool MjFriction::assemble(MjIteration& f, const IndexSet& A,
                          const std::vector<const SparseCol*>& cols) {
  const int k = m_.num_constraints();
  for (int i : A_) gpos_[static_cast<size_t>(i)] = -1;
  for (int j : fric_) {
    gpos_[static_cast<size_t>(k + j)] = -1;
    if (cone_) gpos_[static_cast<size_t>(t2_col_ + j)] = -1;
  }
  A_ = A;
  f_ = &f;
  ++version_;
  na_ = static_cast<long>(A.size());
  fric_.clear();
  contact_.clear();
  normal_of_.clear();
  tangent_of_.assign(A.size(), -1);
  for (long a = 0; a < na_; ++a)
    if (const int fi = of_contact_[static_cast<size_t>(A[a])]; fi >= 0) {
      tangent_of_[static_cast<size_t>(a)] = static_cast<int>(na_ + fric_.size());
      normal_of_.push_back(static_cast<int>(a));
      fric_.push_back(fi);
      contact_.push_back(A[a]);
    }
  nf_ = static_cast<long>(fric_.size());
  const long ng = na_ + (cone_ ? 2 : 1) * nf_;
  gcols_.assign(cols.begin(), cols.end());
  mu_.resize(nf_);
  belt_.resize(nf_);
  for (long a = 0; a < na_; ++a) gpos_[static_cast<size_t>(A[a])] = static_cast<int>(a);
  for (long j = 0; j < nf_; ++j) {
    const int fi = fric_[static_cast<size_t>(j)];
    gpos_[static_cast<size_t>(k + fi)] = static_cast<int>(na_ + j);
    const SparseCol* c = nullptr;
    if (!f.column(k + fi, c)) return false;
    gcols_.push_back(c);
    mu_(j) = m_.friction[static_cast<size_t>(fi)].mu;
    belt_(j) = m_.friction[static_cast<size_t>(fi)].velocity;
  }
  for (long j = 0; cone_ && j < nf_; ++j) {  // the second tangents
    const int fi = fric_[static_cast<size_t>(j)];
    gpos_[static_cast<size_t>(t2_col_ + fi)] = static_cast<int>(na_ + nf_ + j);
    const SparseCol* c = &empty_;
    if (m_.friction[static_cast<size_t>(fi)].is_3d() && !f.column(t2_col_ + fi, c)) return false;
    gcols_.push_back(c);
  }
  trip_.clear();
  for (long g = 0; g < ng; ++g)
    for (SparseCol::InnerIterator it(*gcols_[static_cast<size_t>(g)], 0); it; ++it)
      for (SparseCol::InnerIterator r(Gc_, static_cast<int>(it.row())); r; ++r)
        if (const int p = gpos_[static_cast<size_t>(r.row())]; p >= 0)
          trip_.emplace_back(p, static_cast<int>(g), r.value() * it.value());
  Wg_.resize(ng, ng);
  Wg_.setFromTriplets(trip_.begin(), trip_.end());  // sums the entries
  Wg_.makeCompressed();
  pack_columns();
  return true;
}

// gpacked_ = [W^{-1} G_0', W^{-1} G_1', ...]: the cached columns copied into
// one compressed matrix, so that the step's update of v walks three arrays
// rather than a heap object per column (a fifth of the sparse 3-D step, by
// perf, at 10^4 contacts). Same entries in the same order.
void MjFriction::pack_columns() {
  const Eigen::Index ng = static_cast<Eigen::Index>(gcols_.size());
  Eigen::Index nnz = 0;
  for (const SparseCol* c : gcols_) nnz += c->nonZeros();
  gpacked_.resize(m_.dofs(), ng);
  gpacked_.resizeNonZeros(nnz);
  int* outer = gpacked_.outerIndexPtr();
  int* inner = gpacked_.innerIndexPtr();
  double* value = gpacked_.valuePtr();
  int at = 0;
  for (Eigen::Index g = 0; g < ng; ++g) {
    outer[g] = at;
    for (SparseCol::InnerIterator it(*gcols_[static_cast<size_t>(g)], 0); it; ++it, ++at) {
      inner[at] = static_cast<int>(it.row());
      value[at] = it.value();
    }
  }
  outer[ng] = at;
}

// The dense friction LCP (the impact law's): first the previous step's basis
// when A is unchanged (warm()), else the configured solver and its fallbacks
// (impact::solve_friction_lcp). lam_ gets (lambda_N, lambda_T), zprev_ z.
bool MjFriction::solve_dense(const MatrixXd& Wg, const lcp::Solver& solver, long& solves,
                             lcp::Result& failed) {
  if (p_version_ != version_) {  // M depends on Wg and mu only: kept while A stays
    p_ = impact::friction_lcp(Wg, b_.head(na_), b_.tail(nf_), normal_of_, mu_);
    p_version_ = version_;
  } else {
    p_.q.head(na_) = b_.head(na_);
    p_.q.segment(na_, nf_) = b_.tail(nf_);
  }
  if (!solve_kept(false, solver, solves, failed)) return false;
  for (long a = 0; a < na_; ++a) lam_(a) = zprev_(a);
  for (long j = 0; j < nf_; ++j)
    lam_(na_ + j) = zprev_(na_ + j) - mu_(j) * zprev_(normal_of_[static_cast<size_t>(j)]);
  return true;
}

// p_ solved into zprev_: on the previous step's basis when A is unchanged
// (warm()), else by the planar or the cone's solver with its fallbacks.
bool MjFriction::solve_kept(bool cone, const lcp::Solver& solver, long& solves,
                            lcp::Result& failed) {
  if (zprev_version_ == version_ && warm()) {
    ++solves;
  } else {
    int attempts = 0;
    std::string tried;
    lcp::Result r = cone ? impact::solve_friction_cone_lcp(p_, solver, &attempts, &tried)
                         : impact::solve_friction_lcp(p_, solver, &attempts, nullptr);
    solves += attempts;
    if (!r.ok()) {
      if (cone)
        r.message =
            "friction cone LCP (" + tried + ")" + (r.message.empty() ? "" : ": ") + r.message;
      failed = std::move(r);
      return false;
    }
    zprev_ = r.z;
  }
  zprev_version_ = version_;
  return true;
}

// The edges' Delassus matrix Wb = P Wg P' (mj_friction.hpp), once per A.
void MjFriction::assemble_cone() {
  d_.resize(static_cast<size_t>(nf_));
  first_.resize(static_cast<size_t>(nf_));
  ne_ = 0;
  for (long j = 0; j < nf_; ++j) {
    d_[static_cast<size_t>(j)] =
        m_.edges_of(m_.friction[static_cast<size_t>(fric_[static_cast<size_t>(j)])]);
    first_[static_cast<size_t>(j)] = static_cast<int>(ne_);
    ne_ += 2 * d_[static_cast<size_t>(j)];
  }
  if (na_ + ne_ + nf_ > kDenseFallbackMax) return;  // refused by solve_cone
  MatrixXd P = MatrixXd::Zero(na_ + ne_, na_ + 2 * nf_);
  P.topLeftCorner(na_, na_).setIdentity();
  for (long j = 0; j < nf_; ++j)
    for (int i = 0; i < 2 * d_[static_cast<size_t>(j)]; ++i) {
      const auto [c, s] = impact::cone_edge(i, d_[static_cast<size_t>(j)]);
      P(na_ + first_[static_cast<size_t>(j)] + i, na_ + j) = c;
      P(na_ + first_[static_cast<size_t>(j)] + i, na_ + nf_ + j) = s;
    }
  Wb_.noalias() = P * (Wg_ * P.transpose());
}

namespace {

// Slack of edges_in_cone, relative to the step's largest normal or edge
// impulse: a solution on a slipping contact has mu lambda_N - sum beta = 0
// to the LCP's rounding (1e-12 of the problem; on an open contact beside
// others, edge impulses of 8e-15 with lambda_N = 0 where they reach 0.3:
// the DeepMimic humanoid's feet in euler).
constexpr double kConeSlack = 1e-9;

// Whether the cone LCP's z keeps each contact's edge impulses in its cone,
// sum_i beta_i <= mu lambda_N (to kConeSlack). On a 0.1 kg cube whose URDF
// gives it 1 kg m^2 (bullet3's cube_small.urdf: its four corners act almost
// as one point) landing at 0.44 m/s, the cold solve's last fallback once
// accepted lambda_N = 0 with sum beta = 0.28 N s (a residual relative to
// |z|_inf, inflated by xi = 5.7e11), and the step reversed the cube's 1 m/s
// slide, gaining energy. impact::solve_friction_cone_lcp now refuses such a
// z itself (its acceptance on the impulses and rates; the cube's test
// passes without this check); the check stays for the warm-started basis
// (warm(): |w_J| within 1e-12 of a scale that xi inflates alike), which
// does not go through it. Such a z is no solution: the sweeps decide.
bool edges_in_cone(const VectorXd& z, long na, const std::vector<int>& normal_of,
                   const std::vector<int>& first, const std::vector<int>& d, const VectorXd& mu) {
  if (mu.size() == 0) return true;
  long ne = 0;
  for (const int dj : d) ne += 2 * dj;
  const double slack = kConeSlack * z.head(na + ne).cwiseAbs().maxCoeff();  // xi left out
  for (Eigen::Index j = 0; j < mu.size(); ++j) {
    const std::size_t js = static_cast<std::size_t>(j);
    double sum = 0.0;
    for (int i = 0; i < 2 * d[js]; ++i) sum += z(na + first[js] + i);
    const double cap = mu(j) * z(normal_of[js]);
    if (!(sum - cap <= slack)) return false;
  }
  return true;
}

}  // namespace

// The step's cone LCP (mj_friction.hpp); lam_ gets (lambda_N, the impulses
// along t, along t2) from the edge impulses.
bool MjFriction::solve_cone(const lcp::Solver& solver, long& solves, lcp::Result& failed) {
  if (na_ + ne_ + nf_ > kDenseFallbackMax) return solve_cone_sparse(solves, failed);
  rate_D_.resize(ne_);
  for (long j = 0; j < nf_; ++j)
    for (int i = 0; i < 2 * d_[static_cast<size_t>(j)]; ++i) {
      const auto [c, s] = impact::cone_edge(i, d_[static_cast<size_t>(j)]);
      rate_D_(first_[static_cast<size_t>(j)] + i) = c * b_(na_ + j) + s * b_(na_ + nf_ + j);
    }
  if (p_version_ != version_) {
    p_ = impact::friction_cone_lcp(Wb_, b_.head(na_), rate_D_, normal_of_, first_, d_, mu_);
    p_version_ = version_;
  } else {
    p_.q.head(na_) = b_.head(na_);
    p_.q.segment(na_, ne_) = rate_D_;
  }
  // Where the dense LCP finds no solution (its pivots on a Delassus matrix
  // of dependent rows: four corners of one face), the sweeps, whose local
  // 3 x 3 blocks stay positive definite; wherever the dense path solves,
  // its numbers stand.
  bool dense_ok = solve_kept(true, solver, solves, failed);
  if (dense_ok && !edges_in_cone(zprev_, na_, normal_of_, first_, d_, mu_)) {
    dense_ok = false;
    zprev_version_ = -1;  // not a basis to start the next step from
    failed.status = lcp::Status::kNumericalFailure;
    failed.message = "friction cone LCP: its solution leaves the friction cone";
  }
  if (!dense_ok) {
    lcp::Result dense = failed;
    if (solve_cone_sparse(solves, failed)) return true;
    failed.message = dense.message + "; then " + failed.message;
    return false;
  }
  lam_.head(na_) = zprev_.head(na_);
  for (long j = 0; j < nf_; ++j) {
    double p1 = 0.0, p2 = 0.0;
    for (int i = 0; i < 2 * d_[static_cast<size_t>(j)]; ++i) {
      const auto [c, s] = impact::cone_edge(i, d_[static_cast<size_t>(j)]);
      const double beta = zprev_(na_ + first_[static_cast<size_t>(j)] + i);
      p1 += c * beta;
      p2 += s * beta;
    }
    lam_(na_ + j) = p1;
    lam_(na_ + nf_ + j) = p2;
  }
  return true;
}

// The LCP's solution on the basis J = {i : z_prev,i > 0} of the previous step
// (the same M: A unchanged): z_J = -M_JJ^{-1} q_J, zero off J, accepted when
// it is a solution, z_J > 0 and w = M z + q > 0 off J, with |w_J| within
// kWarmResidual of the terms forming it (the acceptance of
// solve_friction_lcp, 1e-12). A sticking or sliding phase keeps its basis, so
// a step is one solve with the kept LU factor of M_JJ. False: solve cold.
bool MjFriction::warm() {
  const Eigen::Index n = p_.q.size();
  J_.clear();
  for (Eigen::Index i = 0; i < n; ++i)
    if (zprev_(i) > 0.0) J_.push_back(static_cast<int>(i));
  const Eigen::Index nj = static_cast<Eigen::Index>(J_.size());
  if (J_ != J_factored_ || lu_version_ != version_) {
    Mjj_.resize(nj, nj);
    for (Eigen::Index r = 0; r < nj; ++r)
      for (Eigen::Index c = 0; c < nj; ++c) Mjj_(r, c) = p_.M(J_[r], J_[c]);
    lu_.compute(Mjj_);
    J_factored_ = J_;
    lu_version_ = version_;
  }
  qj_.resize(nj);
  for (Eigen::Index r = 0; r < nj; ++r) qj_(r) = -p_.q(J_[r]);
  zj_.resize(nj);
  zj_ = lu_.solve(qj_);
  zw_.setZero(n);
  for (Eigen::Index r = 0; r < nj; ++r) {
    if (!(zj_(r) > 0.0)) return false;
    zw_(J_[r]) = zj_(r);
  }
  ww_.resize(n);
  ww_.noalias() = p_.M * zw_;
  double scale = 1.0 + p_.q.cwiseAbs().maxCoeff();
  for (Eigen::Index i = 0; i < n; ++i) scale = std::max(scale, std::abs(ww_(i)));
  ww_ += p_.q;
  size_t r = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    if (r < J_.size() && J_[r] == i) {
      if (!(std::abs(ww_(i)) <= kWarmResidual * scale)) return false;
      ++r;
    } else if (!(ww_(i) > 0.0)) {
      return false;
    }
  }
  zprev_.swap(zw_);
  return true;
}

// The cone's step by block Gauss–Seidel (cone_gs.hpp) on Wg_ = G W^{-1} G',
// lam_ holding the previous step's impulses (the warm start, step()); a
// sweep limit is numerical trouble (the step fails with its residual).
bool MjFriction::solve_cone_sparse(long& solves, lcp::Result& failed) {
  const ConeGsProblem p{
      &Wg_, &b_, &tangent_of_, &mu_, &d_, static_cast<int>(na_), static_cast<int>(nf_)};
  facet_.resize(static_cast<size_t>(nf_));
  for (long j = 0; j < nf_; ++j)
    facet_[static_cast<size_t>(j)] =
        facet_prev_[static_cast<size_t>(contact_[static_cast<size_t>(j)])];
  const ConeGsResult r = solve_cone_gs(p, kGsTolerance, kGsMaxSweeps, lam_, facet_, u_);
  ++solves;
  if (r.status == lcp::Status::kSolved && all_finite(lam_)) {
    for (long j = 0; j < nf_; ++j)
      facet_prev_[static_cast<size_t>(contact_[static_cast<size_t>(j)])] =
          facet_[static_cast<size_t>(j)];
    return true;
  }
  failed.status = r.status == lcp::Status::kSolved ? lcp::Status::kNumericalFailure : r.status;
  failed.message = "friction cone Gauss-Seidel: " +
                   (r.message.empty() ? std::string("impulses not finite") : r.message);
  return false;
}

bool MjFriction::solve_sparse(const lcp::Solver& solver, long& solves, lcp::Result& failed,
                              std::string& warning) {
  const FrictionGsProblem p{&Wg_, &b_, &tangent_of_, &mu_, static_cast<int>(na_)};
  const FrictionGsResult r = solve_friction_gs(p, kGsTolerance, kGsMaxSweeps, lam_, u_);
  ++solves;
  if (r.status == lcp::Status::kSolved && all_finite(lam_)) return true;
  if (na_ + 2 * nf_ <= kDenseFallbackMax) return solve_dense(MatrixXd(Wg_), solver, solves, failed);
  if (r.status == lcp::Status::kIterationLimit && all_finite(lam_)) {
    warning = "moreau-jean: friction Gauss-Seidel stopped at residual " + short_number(r.residual) +
              " after " + std::to_string(r.sweeps) + " sweeps";
    return true;
  }
  failed.status = r.status;
  failed.message = "friction Gauss-Seidel: " + r.message;
  return false;
}

bool MjFriction::step(MjIteration& f, const IndexSet& A, const std::vector<const SparseCol*>& cols,
                      const VectorXd& Ev, const VectorXd& e, const lcp::Solver& solver,
                      int pivot_max_active, VectorXd& v_next, VectorXd& lambda_N,
                      VectorXd& lambda_T, long& solves, lcp::Result& failed, std::string& warning) {
  const int k = m_.num_constraints();
  if (&f != f_ || A != A_) {
    if (!assemble(f, A, cols)) {
      failed.status = lcp::Status::kNumericalFailure;
      failed.message = "a column W^{-1} t' is not finite";
      return false;
    }
    if (cone_)
      assemble_cone();
    else if (na_ + nf_ <= pivot_max_active)
      Wd_ = MatrixXd(Wg_);
  }
  const long ng = na_ + (cone_ ? 2 : 1) * nf_;
  // Rates G v_free, restitution on the normals, minus the surfaces' velocities.
  b_.resize(ng);
  auto row_times = [&](int i) {
    double s = 0.0;
    for (SparseCol::InnerIterator it(Gt_, i); it; ++it) s += it.value() * v_next(it.row());
    return s;
  };
  for (long a = 0; a < na_; ++a) {
    const int i = A[static_cast<size_t>(a)];
    b_(a) = row_times(i) + e(i) * Ev(i);
  }
  for (long j = 0; j < nf_; ++j)
    b_(na_ + j) = row_times(k + fric_[static_cast<size_t>(j)]) - belt_(j);
  for (long j = 0; cone_ && j < nf_; ++j)
    b_(na_ + nf_ + j) = row_times(t2_col_ + fric_[static_cast<size_t>(j)]);
  lam_.resize(ng);
  lam_.head(na_) = lambda_N;
  for (long j = 0; j < nf_; ++j) lam_(na_ + j) = lamT_prev_(contact_[static_cast<size_t>(j)]);
  for (long j = 0; cone_ && j < nf_; ++j)  // the sparse cone path's warm start
    lam_(na_ + nf_ + j) = lamT2_(contact_[static_cast<size_t>(j)]);
  const bool ok = cone_                    ? solve_cone(solver, solves, failed)
                  : ng <= pivot_max_active ? solve_dense(Wd_, solver, solves, failed)
                                           : solve_sparse(solver, solves, failed, warning);
  if (!ok) return false;
  const int* outer = gpacked_.outerIndexPtr();
  const int* inner = gpacked_.innerIndexPtr();
  const double* value = gpacked_.valuePtr();
  for (long g = 0; g < ng; ++g)
    if (const double x = lam_(g); x != 0.0)
      for (int at = outer[g]; at < outer[g + 1]; ++at) v_next(inner[at]) += value[at] * x;
  lambda_N = lam_.head(na_);
  lamT_prev_.setZero();
  for (long j = 0; j < nf_; ++j) {
    const int c = contact_[static_cast<size_t>(j)];
    lambda_T(c) = lamT_prev_(c) = lam_(na_ + j);
  }
  if (cone_) {
    lamT2_.setZero();
    for (long j = 0; j < nf_; ++j) lamT2_(contact_[static_cast<size_t>(j)]) = lam_(na_ + nf_ + j);
  }
  return true;
}

}  // namespace lcsim::sim::detail
