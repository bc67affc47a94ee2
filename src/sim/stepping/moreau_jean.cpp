// The Moreau–Jean theta-method for mechanical models: one velocity LCP per
// step over the constraints predicted to close, on the fixed grid of
// time_stepping.cpp's description. Kernels in step_kernels.hpp; the step LCP
// goes to the LCP layer (the configured solver, lcp::WarmPivot,
// lcp::solve_sparse_pgs).
//
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
//   MjIteration::kPruneRelative times its largest entry (W^{-1} of a banded W decays
//   geometrically away from the band, so the pruned column is short), and kept
//   for the run. Each step assembles E_A W^{-1} E_A' over the active set only,
//   from those columns and the columns of E: dense when |A| <=
//   Options::pivot_max_active (and then kept while A stays), sparse above.
// - The LCP over A: |A| <= pivot_max_active (default 32) goes to the pivoting
//   solver Options::lcp_solver (exact, and what the small models always used).
//   With the default solver "pivot" the step first tries the previous step's
//   basis (lcp::WarmPivot: the solver's own computation on that basis,
//   accepted by its own test with a margin), which settles almost every step of a contact
//   phase without the solver's set-up and gives bitwise its result. Larger
//   sets go to projected Gauss–Seidel on the sparse Delassus matrix,
//   warm-started from the previous step's impulses (the sets change little
//   between steps, so a few sweeps suffice): lcp::solve_sparse_pgs. PGS that
//   does not reach the
//   tolerance falls back to the pivoting solver when |A| <= kPivotFallbackMax,
//   else the step keeps the PGS iterate and a warning is counted.
// - Friction (mj_friction.hpp) follows the same pattern: cached columns
//   W^{-1} t_f', the Delassus matrix over [E_A; T_F] assembled from them and
//   kept while A stays, the dense friction LCP (warm-started on the previous
//   basis) up to pivot_max_active rows, block Gauss–Seidel above.
#include <algorithm>
#include <lcsim/lcp/sparse.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim/stepping/mj_friction.hpp"
#include "sim/stepping/step_kernels.hpp"
#include "sim/stepping/time_stepping_detail.hpp"

namespace lcsim::sim::detail {

namespace {

constexpr double kActivationGap = 0.0;  // predicted gap (model units) at or below which i is active
constexpr double kPgsTolerance = 1e-13;  // natural residual <= tol * (1 + ||b||_inf)
constexpr int kPgsMaxSweeps = 5000;
constexpr int kPivotFallbackMax = 2000;

// A closed frictional contact's mode after a step with velocity v: stick
// when its sliding velocity is zero to rounding (a stuck velocity is a
// cancellation of terms of the size of |t| |v|, exact to a few hundred eps
// of it: 1e-12 of it), else slip along the sliding velocity's sign.
FrictionMode friction_mode_after_step(const mech::FrictionalContact& fc, const VectorXd& v) {
  const double s = fc.sliding(v);
  const double scale = fc.tangent.cwiseAbs().dot(v.cwiseAbs()) + std::abs(fc.velocity);
  if (std::abs(s) <= 1e-12 * scale + std::numeric_limits<double>::min())
    return FrictionMode::kStick;
  return s > 0.0 ? FrictionMode::kSlipPositive : FrictionMode::kSlipNegative;
}

}  // namespace

Trajectory run_moreau_jean(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  Trajectory tr;
  tr.method = "moreau-jean";
  tr.t_end = *opt.t_end;
  tr.impact_law = "moreau-restitution";  // the law inside the velocity LCP
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs(), k = m.num_constraints();
  const MjOperators ops(m, N > opt.sparse_dofs_threshold);
  VectorXd q = x0.head(N), v = x0.tail(N);
  tr.energy_initial = ops.energy(q, v);
  auto finish = [&]() {
    tr.final_state.resize(2 * N);
    tr.final_state << q, v;
    tr.energy_final = ops.energy(q, v);
    return std::move(tr);  // only ever returned from the run: no copy of the samples
  };
  auto fail = [&](const std::string& msg) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = msg;
    return finish();
  };
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

  // Friction (issue 17): steps whose active set holds a frictional contact
  // solve the friction LCP (mj_friction.hpp); the others are the
  // frictionless step below, unchanged.
  std::unique_ptr<MjFriction> friction;
  if (m.has_friction()) friction = std::make_unique<MjFriction>(m, ops);
  std::string friction_warning;
  VectorXd lambda_T = VectorXd::Zero(m.has_friction() ? k : 0);
  // Mean friction force over the step (N), per entry of m.friction: the
  // samples' u_t.
  VectorXd u_t = VectorXd::Zero(static_cast<Eigen::Index>(m.friction.size()));
  // Their modes over the step (the samples' friction_mode): open unless the
  // normal impulse is positive; then stick when the sliding velocity at the
  // step's end is zero to rounding, else slip along its sign.
  std::vector<FrictionMode> fmode(m.friction.size(), FrictionMode::kOpen);
  OutputSampler sampler(opt.dt_out);
  DivergenceGuard guard(model, x0, *opt.t_end);
  auto record = [&](double t, const VectorXd& y, const VectorXd& uu, const IndexSet& mode) {
    if (!opt.record_samples) return;
    Sample s;
    s.t = t;
    s.x.resize(2 * N);
    s.x << q, v;
    s.u = uu;
    s.y = y;
    s.mode = mode;
    if (friction) {
      s.u_t = u_t;
      s.friction_mode = fmode;
    }
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
  lcp::Options pgs_opt;  // the sparse sweep for active sets above pivot_max_active
  pgs_opt.tolerance = kPgsTolerance;
  pgs_opt.max_iterations = kPgsMaxSweeps;
  // The warm start reproduces the "pivot" solver's own computation (WarmPivot);
  // other solvers are called on every step.
  const bool warm_pivot = opt.lcp_solver == "pivot";
  lcp::WarmPivot warm;
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
    if (friction) {
      lambda_T.setZero();
      u_t.setZero();
      std::fill(fmode.begin(), fmode.end(), FrictionMode::kOpen);
    }
    u_set.clear();
    mode.clear();
    z.resize(static_cast<Eigen::Index>(A.size()));  // warm start: last step's impulses
    for (size_t a = 0; a < A.size(); ++a) z(static_cast<Eigen::Index>(a)) = lambda_prev(A[a]);
    for (int i : A_prev) lambda_prev(i) = 0.0;  // set again below for this step's A
    A_prev = A;
    // The columns W^{-1} E_a' of the active set, for either LCP below.
    const int na = static_cast<int>(A.size());
    cols.resize(na);
    for (int a = 0; a < na; ++a)
      if (!f.column(A[a], cols[a]))
        return fail("moreau-jean: iteration matrix too ill-conditioned at h = " + short_number(h));
    if (friction && friction->any_in(A)) {
      if (!friction->step(f, A, cols, Ev, e, *solver, opt.pivot_max_active, v_next, z, lambda_T,
                          tr.lcp_solves, failed, friction_warning))
        return fail(lcp_failure("moreau-jean", (j - 1) * grid.h, failed));
      if (!friction_warning.empty()) {
        tr.warn("pgs-not-converged", (j - 1) * grid.h,
                friction_warning + " at t = " + short_number((j - 1) * grid.h));
        friction_warning.clear();
      }
      for (size_t fi = 0; fi < m.friction.size(); ++fi) {
        const mech::FrictionalContact& fc = m.friction[fi];
        u_t(static_cast<Eigen::Index>(fi)) = lambda_T(fc.contact) / h;
        if (const int p = pos[static_cast<size_t>(fc.contact)]; p >= 0 && z(p) > 0.0)
          fmode[fi] = friction_mode_after_step(fc, v_next);
      }
      for (int a = 0; a < na; ++a) {
        lambda_prev(A[a]) = z(a);
        if (z(a) > 0.0) mode.push_back(A[a]);
        u(A[a]) = z(a) / h;
        u_set.push_back(A[a]);
      }
    } else if (!A.empty()) {
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
        if (warm_pivot) {
          const lcp::Result& r = warm.solve(Gd, Gd_version, b, z, lopt);
          if (r.ok()) {
            z = r.z;
            ++tr.lcp_solves;
            solved = true;
          }
        }
        if (!solved && !solve_exact(Gd))
          return fail(lcp_failure("moreau-jean", (j - 1) * grid.h, failed));
      } else {
        trip.clear();
        for_each_entry([&](int p, int a, double x) { trip.emplace_back(p, a, x); });
        SparseRow G(na, na);
        G.setFromTriplets(trip.begin(), trip.end());
        pgs_opt.warm_start = &z;
        lcp::Result r = lcp::solve_sparse_pgs(G, b, pgs_opt);
        ++tr.lcp_solves;
        solved = r.ok() && all_finite(r.z);
        if (!solved && na > kPivotFallbackMax && r.status == lcp::Status::kIterationLimit &&
            all_finite(r.z)) {
          tr.warn("pgs-not-converged", (j - 1) * grid.h,
                  "moreau-jean: PGS stopped at residual " + short_number(r.residual) + " after " +
                      std::to_string(r.iterations) +
                      " sweeps at t = " + short_number((j - 1) * grid.h));
          solved = true;
        }
        if (solved) z.swap(r.z);
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
    if (std::string why = guard.check(last ? *opt.t_end : j * grid.h, q_next, v_next, last);
        !why.empty()) {
      tr.t_end = (j - 1) * grid.h;  // the time reached: the last sane state's
      return fail("moreau-jean: " + why);
    }
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

}  // namespace lcsim::sim::detail
