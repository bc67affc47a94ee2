// Time-stepping integrators: backward Euler for general LCS (Algorithm 7.3.1)
// and the Moreau–Jean theta-method for mechanical models.
//
// Both march on a fixed grid t_j = j h (the last step is shortened to land on
// t_end exactly when h does not divide it), solve one LCP per step (Moreau–Jean:
// only when some constraint is predicted to close) and report the same
// Trajectory as the event-driven method. Nothing throws inside the step loop:
// an LCP failure or a non-finite state ends the run with status kFailed and a
// message; the last good state is reported.
//
// Samples: every step when Options::dt_out = 0, otherwise the first step time
// at or after each multiple of dt_out (equal to it when dt_out is a multiple of
// h), always the initial and the final state. For time-stepping, Sample::u is
// the LCP multiplier as a force: backward Euler's u_{k+1} of (7.4), and the
// Moreau–Jean impulse divided by the step (the mean force over the step).
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>
#include <utility>
#include <vector>

namespace lcsim::sim {

namespace {

using Eigen::MatrixXd;

// Messages print numbers as every integrator does.
std::string fmt(double x) { return short_number(x); }

// The message of a step whose LCP failed, for both schemes.
std::string lcp_failure(const char* method, double t, const lcp::Result& r) {
  return std::string(method) + ": LCP failed at t = " + fmt(t) + " (" +
         std::string(lcp::to_string(r.status, "solved")) + ")" +
         (r.message.empty() ? "" : ": " + r.message);
}

// ---------------------------------------------------------------------------
// Backward Euler, Algorithm 7.3.1, on sys = model.as_lcs() (the augmented
// state (q, v, 1) of (3.65) for mechanical models).

struct EulerFactors {
  MatrixXd Phi;   // (I - hA)^{-1}
  MatrixXd PhiB;  // h (I - hA)^{-1} B
  MatrixXd G;     // D + h C (I - hA)^{-1} B, the LCP matrix of step 4
  bool ok = false;
  std::string message;
};

EulerFactors euler_factors(const lcs::Lcs& sys, double h) {
  EulerFactors f;
  const int n = sys.n();
  const MatrixXd IhA = MatrixXd::Identity(n, n) - h * sys.A;
  // One factorisation per step size; Phi is formed from it once so that each
  // step is a matrix-vector product (n is small: the models are low-order).
  const Eigen::FullPivLU<MatrixXd> lu(IhA);
  if (!lu.isInvertible()) {
    f.message = "I - hA is singular at h = " + fmt(h) + " (1/h is an eigenvalue of A)";
    return f;
  }
  f.Phi = lu.inverse();
  f.PhiB = h * (f.Phi * sys.B);
  f.G = sys.D + sys.C * f.PhiB;
  f.ok = f.Phi.allFinite() && f.G.allFinite();
  if (!f.ok) f.message = "I - hA is too ill-conditioned at h = " + fmt(h);
  return f;
}

Trajectory run_euler(const mech::Model& model, const VectorXd& x0_user, const Options& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  Trajectory tr;
  tr.method = "euler";
  tr.t_end = *opt.t_end;
  // Backward Euler's step LCP acts on positions: every impact is inelastic.
  if (model.is_mechanical()) tr.impact_law = "moreau (e = 0: restitution ignored)";
  const bool mech = model.is_mechanical();
  const int N = mech ? model.mechanical->dofs() : 0;
  auto user = [&](const VectorXd& xa) -> VectorXd { return mech ? VectorXd(xa.head(2 * N)) : xa; };
  auto energy = [&](const VectorXd& xa) {
    return mech ? mech::total_energy(*model.mechanical, xa.head(N), xa.segment(N, N)) : 0.0;
  };
  auto finish = [&](const VectorXd& xa) {
    tr.final_state = user(xa);
    tr.energy_final = energy(xa);
    tr.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return std::move(tr);  // only ever returned from the run: no copy of the samples
  };
  auto fail = [&](const std::string& msg, const VectorXd& xa) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = msg;
    return finish(xa);
  };

  lcs::Lcs sys;
  std::unique_ptr<lcp::Solver> solver;
  try {  // set-up, before the loop: invalid names or data end the run cleanly
    sys = model.as_lcs();
    solver = lcp::make_solver(opt.lcp_solver);
  } catch (const std::exception& e) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = std::string("euler: ") + e.what();
    tr.final_state = x0_user;
    return tr;
  }
  const int n = sys.n(), k = sys.k();
  VectorXd x(n);
  if (x0_user.size() != model.state_size()) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = "euler: initial state has " + std::to_string(x0_user.size()) +
                 " entries, the model needs " + std::to_string(model.state_size());
    tr.final_state = x0_user;
    return tr;
  }
  if (const std::string bad = infeasible_start(model, x0_user); !bad.empty()) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = "euler: " + bad;
    tr.final_state = x0_user;
    return tr;
  }
  if (mech)
    x << x0_user, 1.0;
  else
    x = x0_user;
  tr.energy_initial = energy(x);
  if (const std::string err = check_step_options(opt, false); !err.empty())
    return fail("euler: " + err, x);

  // Consistency guard (§7.3, Example 7.3.3): with a leading row index
  // rho_i >= 3 backward Euler produces impulses of order h^{1-rho_i} and does
  // not converge. Refuse unless forced.
  {
    const std::vector<int> rho = lcs::leading_row_indices(sys);
    for (int i = 0; i < k; ++i) {
      if (rho[i] >= 3) {
        const std::string msg = "leading row index rho_" + std::to_string(i + 1) + " = " +
                                std::to_string(rho[i]) +
                                " >= 3: backward Euler is not consistent here (thesis §7.3, "
                                "Example 7.3.3: the outputs blow up as h -> 0)";
        if (!opt.force)
          return fail(
              "euler: refused: " + msg + "; set Options::force (lcsim --force) to run anyway", x);
        tr.add_warning("forced despite " + msg);
        break;
      }
    }
  }
  if (mech && model.mechanical->restitution.size() > 0 &&
      model.mechanical->restitution.maxCoeff() > 0.0)
    tr.add_warning("backward Euler ignores restitution: every impact is inelastic");

  const StepGrid grid = StepGrid::of(*opt.t_end, opt.h);
  EulerFactors F = euler_factors(sys, grid.h);
  if (!F.ok) return fail("euler: " + F.message, x);
  EulerFactors F_last;
  if (grid.h_last != grid.h) {
    F_last = euler_factors(sys, grid.h_last);
    if (!F_last.ok) return fail("euler: last step: " + F_last.message, x);
  }

  OutputSampler sampler(opt.dt_out);
  VectorXd u = VectorXd::Zero(k);
  auto record = [&](double t, const VectorXd& xa, const VectorXd& uu) {
    const VectorXd y = sys.C * xa + sys.D * uu;
    if (k > 0) tr.max_violation = std::min(tr.max_violation, std::min(0.0, y.minCoeff()));
    if (!opt.record_samples) return;
    Sample s;
    s.t = t;
    s.x = user(xa);
    s.u = uu;
    s.y = y;
    for (int i = 0; i < k; ++i)
      if (uu(i) > 0.0) s.mode.push_back(i);
    tr.record_sample(std::move(s), opt);
  };
  record(0.0, x, u);

  lcp::Options lopt;
  VectorXd xb(n), q(k), x_next(n);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    if (opt.progress && j % Options::kProgressSteps == 0) opt.progress(j * grid.h);
    const EulerFactors& f = (last && grid.h_last != grid.h) ? F_last : F;
    xb.noalias() = f.Phi * x;  // free step (I - hA)^{-1} x_k
    if (k > 0) {
      q.noalias() = sys.C * xb;  // step 4 of Algorithm 7.3.1
      int attempts = 0;          // dependent constraints: pivoting fails, Lemke does not
      // Scaled: G = h C (I - hA)^{-1} B is h^2 E M^{-1} E' for a gap, 1e-16 at
      // h = 1e-8, and an unscaled tolerance would accept any u within 1e4 of it.
      const lcp::Result r = lcp::solve_scaled(*solver, f.G, q, lopt, &attempts);
      tr.lcp_solves += attempts;
      if (!r.ok()) return fail(lcp_failure("euler", (j - 1) * grid.h, r), x);
      u = r.z;
      x_next.noalias() = xb + f.PhiB * u;  // step 5
    } else {
      x_next = xb;
    }
    if (!x_next.allFinite()) return fail("euler: non-finite state at t = " + fmt(j * grid.h), x);
    x = x_next;
    ++tr.steps;
    const double t = last ? *opt.t_end : j * grid.h;
    if (sampler.want(t, grid.h, last)) {
      record(t, x, u);  // also updates max_violation
    } else if (k > 0) {
      const VectorXd y = sys.C * x + sys.D * u;
      tr.max_violation = std::min(tr.max_violation, std::min(0.0, y.minCoeff()));
    }
  }
  return finish(x);
}

// ---------------------------------------------------------------------------
// Moreau–Jean theta-method (mechanical models). With v_t = theta v+ + (1-theta) v
// and q_t = theta q+ + (1-theta) q:
//   M (v+ - v) = h (f - D v_t - K q_t) + E_A' lambda,   q+ = q + h v_t,
// i.e. W (v+ - v) = h (f - D v - K q - h theta K v) + E_A' lambda with the
// iteration matrix W = M + h theta D + h^2 theta^2 K (factored once per run).
// Impact law at velocity level on the active set A:
//   0 <= E_A v+ + e_A . E_A v  ⟂  lambda >= 0.
// Activation rule: constraint i is in A when its predicted gap
//   E_i (q + h theta v) + g_i <= kActivationGap (= 0),
// i.e. the gap extrapolated with the velocity at the point where the scheme
// evaluates the position (Siconos uses gamma h with gamma = 1/2 by default;
// here gamma = theta). Closed constraints (y <= 0, not opening) are in A; so
// is every constraint that the prediction says closes within the step. A
// constraint left out of A can then penetrate by at most
// h (1 - theta) |E_i v| + O(h^2) in one step (tests/sim/test_scale.cpp checks
// this bound on the cart chain at every step).
//
// Energy balance per step (f included in the potential, derivation in
// tests/sim/test_time_stepping.cpp):
//   E+ - E = -h v_t' D v_t + lambda' E_A v_t - (theta - 1/2)(|v+ - v|_M^2 + h^2 |v_t|_K^2),
// and lambda_i E_i v_t = lambda_i E_i v ((1 - theta) - theta e_i) when lambda_i > 0.
//
// Scaling. Cost per step grows with the coordinates N and the constraints in
// play, not with the constraints declared, and never cubically in N where M, D,
// K, E are sparse; a step allocates nothing once the active set has been seen
// (on the 2 x 2 models of the thesis a step takes ~0.1 us, bench/
// bench_time_stepping.cpp):
// - One code path over MjOperators (products with D, K, E, which the model
//   holds sparse) and MjIteration (W^{-1} rhs and the columns W^{-1} E_i').
//   Models with more than Options::sparse_dofs_threshold coordinates factor W
//   by Eigen::SimplicialLDLT (AMD ordering); smaller ones factor a dense copy
//   by Eigen::LLT (faster below a few dozen coordinates). The step below is
//   written once.
// - The Delassus matrix is never formed for all k constraints. The column
//   W^{-1} E_i' is computed (one solve with the factor, O(nnz(L)) for sparse W)
//   the first time constraint i enters the active set, pruned of entries below
//   kPruneRelative times its largest entry (W^{-1} of a banded W decays
//   geometrically away from the band, so the pruned column is short), and kept
//   for the run. Each step assembles E_A W^{-1} E_A' over the active set only,
//   from those columns and the columns of E: dense when |A| <=
//   Options::pivot_max_active (and then kept while A stays), sparse above.
// - The LCP over A: |A| <= pivot_max_active (default 32) goes to the pivoting
//   solver Options::lcp_solver (exact, and what the small models always used).
//   With the default solver "pivot" the step first tries the previous step's
//   basis (WarmPivot: the solver's own computation on that basis, accepted by
//   its own test with a margin), which settles almost every step of a contact
//   phase without the solver's set-up and gives bitwise its result. Larger
//   sets go to projected Gauss–Seidel on the sparse Delassus matrix,
//   warm-started from the previous step's impulses (the sets change little
//   between steps, so a few sweeps suffice). lcp::solve_pgs works on dense
//   matrices only, hence the sparse sweep here. PGS that does not reach the
//   tolerance falls back to the pivoting solver when |A| <= kPivotFallbackMax,
//   else the step keeps the PGS iterate and a warning is counted.

constexpr double kActivationGap = 0.0;  // predicted gap (model units) at or below which i is active
constexpr double kPruneRelative = 1e-17;  // columns of W^{-1} E' keep |x| > this * max|x|
constexpr double kPgsTolerance = 1e-13;   // natural residual <= tol * (1 + ||b||_inf)
constexpr int kPgsMaxSweeps = 5000;
constexpr size_t kLocalColumnMax = 256;  // largest neighbourhood of a local column solve
constexpr int kPivotFallbackMax = 2000;

using SparseCol = Eigen::SparseMatrix<double, Eigen::ColMajor>;
using SparseRow = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// Sparse times dense on compressed matrices, by the loops of Eigen 3.4's
// sparse_time_dense_product_impl in the same order (so the same rounding: a
// row sum from 0 in storage order; a column sweep adding A_ij (alpha x_j)),
// without its per-call set-up (resize, zeroing, evaluators), which costs more
// than the arithmetic on the 2 x 2 models of the thesis.
// out = A x, A by rows.
void times(const SparseRow& A, const VectorXd& x, VectorXd& out) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  for (Eigen::Index i = 0; i < A.rows(); ++i) {
    double s = 0.0;
    for (int p = outer[i]; p < outer[i + 1]; ++p) s += val[p] * x[inner[p]];
    out[i] = s;
  }
}
// out += alpha A x, A by columns.
void add_times(const SparseCol& A, double alpha, const VectorXd& x, VectorXd& out) {
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* val = A.valuePtr();
  for (Eigen::Index j = 0; j < A.cols(); ++j) {
    const double xj = alpha * x[j];
    for (int p = outer[j]; p < outer[j + 1]; ++p) out[inner[p]] += val[p] * xj;
  }
}

// Products with the model's matrices (held sparse, mech::MechanicalModel).
// `sparse` chooses how W is factored, nothing else.
class MjOperators {
 public:
  MjOperators(const mech::MechanicalModel& m, bool sparse)
      : m_(m), sparse_(sparse), Ec_(m.E), Er_(m.E), K_(m.K), D_(m.D) {
    Ec_.makeCompressed();
    Er_.makeCompressed();
    K_.makeCompressed();
    D_.makeCompressed();
  }
  bool sparse() const { return sparse_; }
  int dofs() const { return m_.dofs(); }
  int constraints() const { return m_.num_constraints(); }
  const SparseCol& E_by_columns() const { return Ec_; }
  // f - D v - K (q + h theta v): the smooth force of the step. No allocation
  // after the first call (the scratch vector is kept).
  void step_force(const VectorXd& q, const VectorXd& v, double h, double theta,
                  VectorXd& out) const {
    qt_ = q + (h * theta) * v;
    out.setZero();
    add_times(K_, 1.0, qt_, out);  // = K qt
    out = m_.f - out;
    add_times(D_, -1.0, v, out);
  }
  // out = E x (out sized k).
  void E_times(const VectorXd& x, VectorXd& out) const { times(Er_, x, out); }
  // W = M + h theta D + h^2 theta^2 K.
  SparseCol W_sparse(double h, double theta) const {
    SparseCol W = m_.M + (h * theta) * m_.D + (h * h * theta * theta) * m_.K;
    W.makeCompressed();
    return W;
  }
  MatrixXd W_dense(double h, double theta) const { return W_sparse(h, theta).toDense(); }
  // T + V = ½ v'Mv + ½ q'Kq - f'q (J).
  double energy(const VectorXd& q, const VectorXd& v) const { return mech::total_energy(m_, q, v); }

 private:
  const mech::MechanicalModel& m_;
  bool sparse_;
  SparseCol Ec_;         // E by columns: assembles the active Delassus matrix
  SparseRow Er_;         // E by rows: the gap rates E v
  SparseCol K_, D_;      // compressed copies for add_times
  mutable VectorXd qt_;  // step_force scratch: q + h theta v
};

// The factored iteration matrix W for one step length, and the cached columns
// W^{-1} E_i' (computed on first use).
class MjIteration {
 public:
  bool factor(const MjOperators& ops, double h, double theta) {
    sparse_ = ops.sparse();
    if (sparse_) {
      W_ = ops.W_sparse(h, theta);
      stamp_.clear();
      local_.assign(W_.rows(), 0);
      ldlt_.compute(W_);
      ok_ = ldlt_.info() == Eigen::Success && (ldlt_.vectorD().array() > 0.0).all();
    } else {
      llt_.compute(ops.W_dense(h, theta));
      ok_ = llt_.info() == Eigen::Success;
    }
    if (!ok_) {
      message_ = "iteration matrix M + h theta D + h^2 theta^2 K is not positive definite at h = " +
                 fmt(h) + " (D or K indefinite?)";
      return false;
    }
    const SparseCol& E = ops.E_by_columns();
    Et_ = E.transpose();  // column i = E_i'
    cols_.assign(ops.constraints(), SparseCol());
    have_.assign(ops.constraints(), 0);
    return true;
  }
  bool ok() const { return ok_; }
  const std::string& message() const { return message_; }
  VectorXd solve(const VectorXd& rhs) const {
    if (sparse_) return ldlt_.solve(rhs);
    return llt_.solve(rhs);
  }
  // out = W^{-1} rhs into a vector of the right size (no allocation).
  void solve(const VectorXd& rhs, VectorXd& out) const {
    if (sparse_)
      out = ldlt_.solve(rhs);
    else
      out = llt_.solve(rhs);
  }
  // W^{-1} E_i' as an N x 1 sparse column; false if not finite.
  bool column(int i, const SparseCol*& out) {
    if (!have_[i]) {
      VectorXd c;
      std::vector<int> rows;
      if (!(sparse_ && local_column(i, rows, c))) {
        c = solve(VectorXd(Et_.col(i)));
        rows.resize(c.size());
        for (int r = 0; r < c.size(); ++r) rows[r] = r;
      }
      if (!c.allFinite()) return false;
      const double cut = kPruneRelative * c.cwiseAbs().maxCoeff();
      std::vector<std::pair<int, double>> kept;
      for (int a = 0; a < c.size(); ++a)
        if (std::abs(c(a)) > cut) kept.emplace_back(rows[a], c(a));
      std::sort(kept.begin(), kept.end());
      SparseCol s(Et_.rows(), 1);
      s.reserve(static_cast<Eigen::Index>(kept.size()));
      for (const auto& [r, x] : kept) s.insert(r, 0) = x;
      s.makeCompressed();
      cols_[i] = std::move(s);
      have_[i] = 1;
    }
    out = &cols_[i];
    return true;
  }

 private:
  // W^{-1} E_i' by a local solve: W restricted to the coordinates within r
  // hops (in the graph of W) of E_i's support, zero outside, r grown until the
  // outermost ring holds only entries below kPruneRelative of the largest.
  // Then the neglected coupling W_{out,S} x_S is below that level too, so the
  // column equals the full solve to the pruning level. Gives up (false) when
  // the neighbourhood exceeds kLocalColumnMax coordinates (slow decay: large
  // h or stiff K); the caller then does the full solve.
  bool local_column(int i, std::vector<int>& nodes, VectorXd& c) {
    if (stamp_.empty()) stamp_.assign(W_.rows(), -1);
    nodes.clear();
    for (SparseCol::InnerIterator it(Et_, i); it; ++it) {
      nodes.push_back(static_cast<int>(it.row()));
      stamp_[it.row()] = i;
    }
    size_t ring_begin = 0;
    for (int hops = 1;; ++hops) {
      const size_t ring_end = nodes.size();
      for (size_t a = ring_begin; a < ring_end; ++a)
        for (SparseCol::InnerIterator it(W_, nodes[a]); it; ++it)
          if (stamp_[it.row()] != i) {
            stamp_[it.row()] = i;
            nodes.push_back(static_cast<int>(it.row()));
          }
      ring_begin = ring_end;
      if (nodes.size() > kLocalColumnMax) break;
      if (hops < 2 && ring_begin < nodes.size()) continue;
      const int ns = static_cast<int>(nodes.size());
      MatrixXd Ws = MatrixXd::Zero(ns, ns);
      VectorXd rhs = VectorXd::Zero(ns);
      for (int b = 0; b < ns; ++b) local_[nodes[b]] = b;
      for (int b = 0; b < ns; ++b)
        for (SparseCol::InnerIterator it(W_, nodes[b]); it; ++it)
          if (stamp_[it.row()] == i) Ws(local_[it.row()], b) = it.value();
      for (SparseCol::InnerIterator it(Et_, i); it; ++it) rhs(local_[it.row()]) = it.value();
      const Eigen::LLT<MatrixXd> llt(Ws);
      if (llt.info() != Eigen::Success) break;
      c = llt.solve(rhs);
      const double top = c.cwiseAbs().maxCoeff();
      double ring = 0.0;
      for (int b = static_cast<int>(ring_begin); b < ns; ++b) ring = std::max(ring, std::abs(c(b)));
      if (ring <= kPruneRelative * top || ring_begin == nodes.size()) return true;
    }
    for (int r : nodes) stamp_[r] = -1;
    return false;
  }

 private:
  bool sparse_ = false, ok_ = false;
  std::string message_;
  Eigen::LLT<MatrixXd> llt_;
  Eigen::SimplicialLDLT<SparseCol> ldlt_;
  SparseCol Et_, W_;
  std::vector<SparseCol> cols_;
  std::vector<int> stamp_, local_;  // local_column: visit marks and local indices
  std::vector<char> have_;
};

// Projected Gauss–Seidel on a sparse symmetric LCP w = G z + b, 0 <= z ⟂ w >= 0,
// from z (warm start, projected onto z >= 0). Returns the natural residual.
double sparse_pgs(const SparseRow& G, const VectorXd& b, VectorXd& z, int& sweeps) {
  const int n = static_cast<int>(b.size());
  VectorXd diag(n);
  for (int a = 0; a < n; ++a) diag(a) = G.coeff(a, a);
  z = z.cwiseMax(0.0);
  const double tol = kPgsTolerance * (1.0 + b.lpNorm<Eigen::Infinity>());
  double res = 0.0;
  for (sweeps = 1; sweeps <= kPgsMaxSweeps; ++sweeps) {
    double change = 0.0;
    for (int a = 0; a < n; ++a) {
      double r = b(a);
      for (SparseRow::InnerIterator it(G, a); it; ++it) r += it.value() * z(it.col());
      const double za = std::max(0.0, z(a) - r / diag(a));
      change = std::max(change, std::abs(za - z(a)) * diag(a));
      z(a) = za;
    }
    if (change <= tol) {
      const VectorXd w = G * z + b;
      res = z.cwiseMin(w).cwiseAbs().maxCoeff();
      if (res <= tol) return res;
    }
  }
  const VectorXd w = G * z + b;
  return z.cwiseMin(w).cwiseAbs().maxCoeff();
}

// The step's LCP w = G z + b, 0 <= z ⟂ w >= 0, solved by the pivoting solver
// "pivot" (block principal pivoting: z_J = -G_JJ^{-1} b_J on a basis J, by LLT
// for symmetric G) warm-started at the previous step's basis: J = the
// constraints of A with a positive impulse last step. The candidate (z_J from
// the LLT of G_JJ, zero elsewhere) is accepted when it passes the solver's own
// acceptance test with a margin, z_J > m, (G z + b)_a > m off J and
// |(G z + b)_J| <= tol (1 + |b|), with m = kWarmMargin times the solver's
// pivot tolerance 0.25 tol (1 + |b|); otherwise the solver runs from scratch.
// With the margin, the solver from scratch ends on the same basis J for any
// reasonably conditioned G (the LCP solution moves by O(cond(G) tol) under
// the tolerance's perturbations, far less than m), and on the same basis it
// computes the same numbers: the same LLT of the same G_JJ and the same
// solve, so the accepted z is bitwise the solver's (final states bitwise
// unchanged on the thesis runs and on the 1000-cart chain with hooks). Steps near a change of
// basis (an impulse or a gap rate within m of zero) go to the solver. The
// factor of G_JJ is kept while G and J stay (G is kept while A stays).
constexpr double kWarmMargin = 1e3;

class WarmPivot {
 public:
  // z_prev: last step's impulses on A (the warm start); g_version changes
  // whenever G does. On success z holds the solution.
  bool solve(const MatrixXd& G, long g_version, const VectorXd& b, const VectorXd& z_prev,
             double tolerance, VectorXd& z) {
    const int na = static_cast<int>(b.size());
    J_.clear();
    for (int a = 0; a < na; ++a)
      if (z_prev(a) > 0.0) J_.push_back(a);
    const int nj = static_cast<int>(J_.size());
    if (nj > 0) {
      if (g_version != version_ || J_ != J_factored_) {
        Gjj_.resize(nj, nj);
        for (int c = 0; c < nj; ++c)
          for (int r = 0; r < nj; ++r) Gjj_(r, c) = G(J_[r], J_[c]);
        llt_.compute(Gjj_);
        version_ = g_version;
        J_factored_ = J_;
      }
      if (llt_.info() != Eigen::Success) return false;
      // zj = -G_JJ^{-1} b_J, as the solver computes it (-llt.solve(b_J)).
      zj_.resize(nj);
      for (int c = 0; c < nj; ++c) zj_(c) = b(J_[c]);
      llt_.solveInPlace(zj_);
      zj_ = -zj_;
    }
    // The acceptance test; w = G z + b with z zero off J.
    const double acc = tolerance * (1.0 + b.lpNorm<Eigen::Infinity>());
    const double margin = kWarmMargin * 0.25 * acc;
    for (int c = 0; c < nj; ++c)
      if (!(zj_(c) > margin)) return false;  // also refuses NaN
    int next = 0;                            // J_ is sorted
    for (int a = 0; a < na; ++a) {
      double w = b(a);
      for (int c = 0; c < nj; ++c) w += G(a, J_[c]) * zj_(c);
      if (next < nj && J_[next] == a) {
        ++next;
        if (!(std::abs(w) <= acc)) return false;
      } else if (!(w > margin)) {
        return false;
      }
    }
    z.setZero(na);
    for (int c = 0; c < nj; ++c) z(J_[c]) = zj_(c);
    return true;
  }

 private:
  IndexSet J_, J_factored_;
  long version_ = -1;
  MatrixXd Gjj_;
  Eigen::LLT<MatrixXd> llt_;
  VectorXd zj_;
};

// x.allFinite() without its two subtractions per entry.
bool all_finite(const VectorXd& x) {
  for (Eigen::Index i = 0; i < x.size(); ++i)
    if (!std::isfinite(x[i])) return false;
  return true;
}

Trajectory run_moreau_jean(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  Trajectory tr;
  tr.method = "moreau-jean";
  tr.t_end = *opt.t_end;
  tr.impact_law = "moreau-restitution";  // the law inside the velocity LCP
  if (!model.is_mechanical()) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = "moreau-jean: needs a mechanical model ('" + model.name +
                 "' is a general LCS; use euler or event)";
    tr.final_state = x0;
    return tr;
  }
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs(), k = m.num_constraints();
  if (x0.size() != 2 * N) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = "moreau-jean: initial state has " + std::to_string(x0.size()) +
                 " entries, the model needs " + std::to_string(2 * N);
    tr.final_state = x0;
    return tr;
  }
  const MjOperators ops(m, N > opt.sparse_dofs_threshold);
  VectorXd q = x0.head(N), v = x0.tail(N);
  tr.energy_initial = ops.energy(q, v);
  auto finish = [&]() {
    tr.final_state.resize(2 * N);
    tr.final_state << q, v;
    tr.energy_final = ops.energy(q, v);
    tr.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return std::move(tr);  // only ever returned from the run: no copy of the samples
  };
  auto fail = [&](const std::string& msg) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = msg;
    return finish();
  };
  if (const std::string err = check_step_options(opt, true); !err.empty())
    return fail("moreau-jean: " + err);
  if (const std::string bad = infeasible_start(model, x0); !bad.empty())
    return fail("moreau-jean: " + bad);
  std::unique_ptr<lcp::Solver> solver;
  try {
    solver = lcp::make_solver(opt.lcp_solver);
  } catch (const std::exception& e) {
    return fail(std::string("moreau-jean: ") + e.what());
  }
  const double theta = opt.theta;
  const StepGrid grid = StepGrid::of(*opt.t_end, opt.h);
  MjIteration F, F_last;
  if (!F.factor(ops, grid.h, theta)) return fail("moreau-jean: " + F.message());
  if (grid.h_last != grid.h && !F_last.factor(ops, grid.h_last, theta))
    return fail("moreau-jean: last step: " + F_last.message());
  const VectorXd e = m.restitution.size() == k ? m.restitution : VectorXd::Zero(k);

  OutputSampler sampler(opt.dt_out);
  auto record = [&](double t, const VectorXd& y, const VectorXd& uu, const IndexSet& mode) {
    if (!opt.record_samples) return;
    Sample s;
    s.t = t;
    s.x.resize(2 * N);
    s.x << q, v;
    s.u = uu;
    s.y = y;
    s.mode = mode;
    tr.record_sample(std::move(s), opt);
  };
  VectorXd y(k);
  ops.E_times(q, y);
  y += m.g;
  if (k > 0) tr.max_violation = std::min(0.0, y.minCoeff());
  VectorXd u = VectorXd::Zero(k);
  record(0.0, y, u, {});

  const SparseCol& Ec = ops.E_by_columns();
  lcp::Options lopt;
  // The warm start reproduces the "pivot" solver's own computation (WarmPivot);
  // other solvers are called on every step.
  const bool warm_pivot = opt.lcp_solver == "pivot";
  WarmPivot warm;
  IndexSet A, A_prev, mode, u_set;
  std::vector<int> pos(k, -1);               // position of constraint i in A, or -1
  VectorXd lambda_prev = VectorXd::Zero(k);  // last step's impulses (warm start)
  std::vector<const SparseCol*> cols;
  std::vector<Eigen::Triplet<double>> trip;
  // The dense Delassus matrix E_A W^{-1} E_A' of an active set of at most
  // pivot_max_active rows, kept while A and the iteration matrix stay.
  MatrixXd Gd;
  IndexSet Gd_A;
  const MjIteration* Gd_f = nullptr;
  long Gd_version = 0;
  // v_next holds the free velocity v + h W^{-1} rhs until the impulses are added.
  VectorXd rhs(N), dv(N), v_next(N), q_next(N), Ev(k), Evf(k), b, z;
  // The step's LCP G z + b by the configured solver and its fallbacks
  // (dependent constraints: pivoting fails, Lemke does not); false leaves the
  // result in `failed`.
  lcp::Result failed;
  auto solve_exact = [&](const MatrixXd& G) {
    int attempts = 0;
    lcp::Result r = lcp::solve_with_fallbacks(*solver, G, b, lopt, &attempts);
    tr.lcp_solves += attempts;
    if (!r.ok()) {
      failed = std::move(r);
      return false;
    }
    z = r.z;
    return true;
  };
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    if (opt.progress && j % Options::kProgressSteps == 0) opt.progress(j * grid.h);
    const double h = last ? grid.h_last : grid.h;
    MjIteration& f = (last && grid.h_last != grid.h) ? F_last : F;
    ops.step_force(q, v, h, theta, rhs);
    f.solve(rhs, dv);
    v_next = v + h * dv;  // v_free
    // Active set: predicted gap E_i (q + h theta v) + g_i <= kActivationGap.
    for (int i : A) pos[i] = -1;
    A.clear();
    if (k > 0) {
      ops.E_times(v, Ev);
      for (int i = 0; i < k; ++i)
        if (y(i) + h * theta * Ev(i) <= kActivationGap) {
          pos[i] = static_cast<int>(A.size());
          A.push_back(i);
        }
    }
    for (int i : u_set) u(i) = 0.0;
    u_set.clear();
    mode.clear();
    z.resize(static_cast<Eigen::Index>(A.size()));  // warm start: last step's impulses
    for (size_t a = 0; a < A.size(); ++a) z(static_cast<Eigen::Index>(a)) = lambda_prev(A[a]);
    for (int i : A_prev) lambda_prev(i) = 0.0;  // set again below for this step's A
    A_prev = A;
    if (!A.empty()) {
      const int na = static_cast<int>(A.size());
      cols.resize(na);
      for (int a = 0; a < na; ++a)
        if (!f.column(A[a], cols[a]))
          return fail("moreau-jean: iteration matrix too ill-conditioned at h = " + fmt(h));
      ops.E_times(v_next, Evf);  // v_next is still v_free here
      b.resize(na);
      for (int a = 0; a < na; ++a) b(a) = Evf(A[a]) + e(A[a]) * Ev(A[a]);
      // Delassus matrix E_A W^{-1} E_A' from the cached columns W^{-1} E_a':
      // entry (p, a) sums E_p,r (W^{-1} E_a')_r over the column's rows r in
      // this order, dense or sparse alike.
      auto for_each_entry = [&](auto&& add) {
        for (int a = 0; a < na; ++a)
          for (SparseCol::InnerIterator it(*cols[a], 0); it; ++it)
            for (SparseCol::InnerIterator e_it(Ec, static_cast<int>(it.row())); e_it; ++e_it) {
              const int p = pos[e_it.row()];
              if (p >= 0) add(p, a, e_it.value() * it.value());
            }
      };
      bool solved = false;
      if (na <= opt.pivot_max_active) {
        if (Gd_f != &f || Gd_A != A) {
          Gd.setZero(na, na);
          for_each_entry([&](int p, int a, double x) { Gd(p, a) += x; });
          Gd_A = A;
          Gd_f = &f;
          ++Gd_version;
        }
        if (warm_pivot && warm.solve(Gd, Gd_version, b, z, lopt.tolerance, z)) {
          ++tr.lcp_solves;
          solved = true;
        }
        if (!solved && !solve_exact(Gd))
          return fail(lcp_failure("moreau-jean", (j - 1) * grid.h, failed));
      } else {
        trip.clear();
        for_each_entry([&](int p, int a, double x) { trip.emplace_back(p, a, x); });
        SparseRow G(na, na);
        G.setFromTriplets(trip.begin(), trip.end());
        int sweeps = 0;
        const double res = sparse_pgs(G, b, z, sweeps);
        ++tr.lcp_solves;
        solved = res <= kPgsTolerance * (1.0 + b.lpNorm<Eigen::Infinity>()) && z.allFinite();
        if (!solved && na > kPivotFallbackMax) {
          tr.add_warning("moreau-jean: PGS stopped at residual " + fmt(res) + " after " +
                         std::to_string(sweeps) + " sweeps at t = " + fmt((j - 1) * grid.h));
          solved = z.allFinite();
        }
        if (!solved && !solve_exact(MatrixXd(G)))
          return fail(lcp_failure("moreau-jean", (j - 1) * grid.h, failed));
      }
      for (int a = 0; a < na; ++a) {
        lambda_prev(A[a]) = z(a);
        if (z(a) > 0.0) {
          for (SparseCol::InnerIterator it(*cols[a], 0); it; ++it)
            v_next(it.row()) += it.value() * z(a);
          mode.push_back(A[a]);
        }
        u(A[a]) = z(a) / h;  // mean force over the step
        u_set.push_back(A[a]);
      }
    }
    q_next = q + h * ((1.0 - theta) * v + theta * v_next);
    if (!all_finite(q_next) || !all_finite(v_next))
      return fail("moreau-jean: non-finite state at t = " + fmt(j * grid.h));
    q.swap(q_next);
    v.swap(v_next);
    ++tr.steps;
    if (k > 0) {
      ops.E_times(q, y);
      y += m.g;
      tr.max_violation = std::min(tr.max_violation, std::min(0.0, y.minCoeff()));
    }
    const double t = last ? *opt.t_end : j * grid.h;
    if (sampler.want(t, grid.h, last)) record(t, y, u, mode);
  }
  return finish();
}

class EulerIntegrator : public Integrator {
 public:
  std::string name() const override { return "euler"; }
  OptionsUsed options_used() const override {
    OptionsUsed u;  // every impact inelastic: Options::impact is not read
    u.h = u.lcp_solver = u.force = true;
    return u;
  }
  Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                       const Options& opt) const override {
    return run_euler(model, x0, opt);
  }
};

class MoreauJeanIntegrator : public Integrator {
 public:
  std::string name() const override { return "moreau-jean"; }
  OptionsUsed options_used() const override {
    OptionsUsed u;  // its impact law is restitution inside the step LCP
    u.h = u.theta = u.lcp_solver = u.linear_algebra = true;
    return u;
  }
  Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                       const Options& opt) const override {
    return run_moreau_jean(model, x0, opt);
  }
};

}  // namespace

std::unique_ptr<Integrator> make_euler_integrator() { return std::make_unique<EulerIntegrator>(); }
std::unique_ptr<Integrator> make_moreau_jean_integrator() {
  return std::make_unique<MoreauJeanIntegrator>();
}

}  // namespace lcsim::sim
