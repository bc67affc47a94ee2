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
//
// run_moreau_jean is the driver and MjRun::step the step, in the stages named
// for what they do: free_velocity, select_active, clear_step_outputs,
// active_columns, then friction_step or contact_step (the velocity LCP,
// solve_dense or solve_sparse, keep_impulses), and advance (the positions,
// the divergence guard, the sample). The run's state lives in MjRun, so no
// stage allocates once the active set has been seen.
#include <algorithm>
#include <cmath>
#include <lcsim/lcp/sparse.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim/stepping/friction_labels.hpp"
#include "sim/stepping/mj_friction.hpp"
#include "sim/stepping/step_kernels.hpp"
#include "sim/stepping/step_sensitivity.hpp"
#include "sim/stepping/time_stepping_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// A constraint is active when its predicted gap is at or below rounding:
// kActivationRounding times the magnitude of the terms it is formed from,
// |E| (|q| + h theta |v|) + |g|. Compared with exactly zero, a box resting on
// four corners dropped two of them for a step whenever rounding left their
// predicted gap at +1e-21 m, pivoted on the other two and sank 0.0143 h.
// 64 eps covers the rounding of a sparse row's sum (as the exact method's
// monitors' noise band does) and is far below any gap a model means.
constexpr double kActivationRounding = 64 * std::numeric_limits<double>::epsilon();
constexpr double kPgsTolerance = 1e-13;  // natural residual <= tol * (1 + ||b||_inf)
constexpr int kPgsMaxSweeps = 5000;
constexpr int kPivotFallbackMax = 2000;

// One Moreau–Jean run: the trajectory it builds, the state (q, v) and what
// the steps keep from one to the next (active set, impulses, the Delassus
// matrix, scratch vectors).
class MjRun {
 public:
  MjRun(const mech::Model& model, const VectorXd& x0, const Options& opt)
      : model_(model),
        opt_(opt),
        m_(*model.mechanical),
        N_(m_.dofs()),
        k_(m_.num_constraints()),
        ops_(m_, N_ > opt.sparse_dofs_threshold),
        Ec_(ops_.E_by_columns()),
        theta_(opt.theta),
        warm_pivot_(opt.lcp_solver == "pivot"),
        grid_(StepGrid::of(*opt.t_end, opt.h)),
        sampler_(opt.dt_out),
        guard_(model, x0, *opt.t_end) {
    tr_.method = "moreau-jean";
    tr_.t_end = *opt.t_end;
    tr_.impact_law = "moreau-restitution";  // the law inside the velocity LCP
    q_ = x0.head(N_);
    v_ = x0.tail(N_);
    tr_.energy_initial = ops_.energy(q_, v_);
  }

  // The solver and the iteration matrices; false: failure_ says why.
  bool set_up() {
    try {
      solver_ = lcp::make_solver(opt_.lcp_solver);
    } catch (const std::exception& e) {
      failure_ = std::string("moreau-jean: ") + e.what();
      return false;
    }
    if (!F_.factor(ops_, grid_.h, theta_)) {
      failure_ = "moreau-jean: " + F_.message();
      return false;
    }
    if (grid_.h_last != grid_.h && !F_last_.factor(ops_, grid_.h_last, theta_)) {
      failure_ = "moreau-jean: last step: " + F_last_.message();
      return false;
    }
    return true;
  }

  // What the loop keeps, and the sample at t = 0.
  void begin() {
    e_ = m_.restitution.size() == k_ ? m_.restitution : VectorXd::Zero(k_);
    // Friction (issue 17): steps whose active set holds a frictional contact
    // solve the friction LCP (mj_friction.hpp); the others are the
    // frictionless step, unchanged.
    if (m_.has_friction()) friction_ = std::make_unique<MjFriction>(m_, ops_);
    lambda_T_ = VectorXd::Zero(m_.has_friction() ? k_ : 0);
    u_t_ = VectorXd::Zero(static_cast<Eigen::Index>(m_.friction.size()));
    fmode_.assign(m_.friction.size(), FrictionMode::kOpen);
    if (m_.has_friction_3d()) {
      u_t2_ = VectorXd::Zero(static_cast<Eigen::Index>(m_.friction.size()));
      facet_.assign(m_.friction.size(), impact::ConeFacet{});
    }
    y_.resize(k_);
    ops_.E_times(q_, y_);
    y_ += m_.g;
    if (k_ > 0) tr_.max_violation = std::min(0.0, y_.minCoeff());
    u_ = VectorXd::Zero(k_);
    if (!opt_.sensitivity.empty())  // the discrete map's derivative (step_sensitivity.hpp)
      sens_ = std::make_unique<MjStepSensitivity>(
          model_, parse_sensitivity(model_, opt_.sensitivity), theta_);
    record(0.0);
    pgs_opt_.tolerance = kPgsTolerance;
    pgs_opt_.max_iterations = kPgsMaxSweeps;
    pos_.assign(k_, -1);
    lambda_prev_ = VectorXd::Zero(k_);
    rhs_.resize(N_);
    dv_.resize(N_);
    v_next_.resize(N_);
    q_next_.resize(N_);
    Ev_.resize(k_);
    gap_scale_.resize(k_);
    Evf_.resize(k_);
  }

  // Every step of the grid, or up to the first failure.
  Trajectory march() {
    for (long j = 1; j <= grid_.n; ++j) {
      if (opt_.progress && j % Options::kProgressSteps == 0) opt_.progress(j * grid_.h);
      if (!step(j)) return fail(failure_);
    }
    return finish();
  }

  Trajectory fail(const std::string& msg) {
    tr_.status = RunStatus::kNumericalFailure;
    tr_.message = msg;
    return finish();
  }
  const std::string& failure() const { return failure_; }

 private:
  Trajectory finish() {
    tr_.final_state.resize(2 * N_);
    tr_.final_state << q_, v_;
    tr_.energy_final = ops_.energy(q_, v_);
    if (sens_) sens_->finish(tr_);
    return std::move(tr_);  // only ever returned from the run: no copy of the samples
  }

  // Step j of the grid; false: failure_ says why.
  bool step(long j) {
    const bool last = j == grid_.n;
    const double h = last ? grid_.h_last : grid_.h;
    MjIteration& f = (last && grid_.h_last != grid_.h) ? F_last_ : F_;
    const double t0 = (j - 1) * grid_.h;  // the step's start, for messages
    ops_.set_step(t0, h, theta_);         // a model's inputs (docs/inputs.md)
    free_velocity(f, h);
    select_active(h);
    clear_step_outputs();
    if (!active_columns(f, h)) return false;
    if (friction_ && friction_->any_in(A_)) {
      if (!friction_step(f, h, t0)) return false;
    } else if (!A_.empty()) {
      if (!contact_step(f, h, t0)) return false;
    }
    if (sens_) sensitivity_step(t0, h);
    return advance(j, last, h);
  }

  // The last friction step's velocity scale (m/s), max(|v_free|, |v_end|)
  // with v_end its end velocity: the stick band's scale for the labels
  // (label_modes) and for the derivative's stick / slip pieces alike.
  double velocity_scale(const VectorXd& v_end) const {
    return std::max(v_free_size_, v_end.size() > 0 ? v_end.lpNorm<Eigen::Infinity>() : 0.0);
  }

  // The step map's derivative (step_sensitivity.hpp), with the step's
  // friction impulses and velocity scale (label_modes') where there are any.
  void sensitivity_step(double t0, double h) {
    MjStepSensitivity::Friction fr;
    if (friction_) {
      fr.t = &lambda_T_;
      fr.t2 = u_t2_.size() > 0 ? &friction_->lambda_T2() : nullptr;
      fr.V = velocity_scale(v_next_);
    }
    sens_->step(t0, h, q_, v_, v_next_, A_, z_, friction_ ? &fr : nullptr);
  }

  // v_next_ = v + h W^{-1} (f - D v - K (q + h theta v)): the free velocity.
  void free_velocity(const MjIteration& f, double h) {
    ops_.step_force(q_, v_, h, theta_, rhs_);
    f.solve(rhs_, dv_);
    v_next_ = v_ + h * dv_;  // v_free
  }

  // Active set: predicted gap E_i (q + h theta v) + g_i at or below its
  // rounding (kActivationRounding).
  void select_active(double h) {
    for (int i : A_) pos_[i] = -1;
    A_.clear();
    if (k_ > 0) {
      ops_.E_times(v_, Ev_);
      qv_abs_ = q_.cwiseAbs() + (h * theta_) * v_.cwiseAbs();
      ops_.abs_E_times(qv_abs_, gap_scale_);
      for (int i = 0; i < k_; ++i)
        if (y_(i) + h * theta_ * Ev_(i) <= kActivationRounding * gap_scale_(i)) {
          pos_[i] = static_cast<int>(A_.size());
          A_.push_back(i);
        }
    }
  }

  // The last step's forces and modes cleared; z_ the warm start (the last
  // step's impulses on this step's active set).
  void clear_step_outputs() {
    for (int i : u_set_) u_(i) = 0.0;
    if (friction_) {
      lambda_T_.setZero();
      u_t_.setZero();
      std::fill(fmode_.begin(), fmode_.end(), FrictionMode::kOpen);
      u_t2_.setZero();
    }
    u_set_.clear();
    mode_.clear();
    z_.resize(static_cast<Eigen::Index>(A_.size()));  // warm start: last step's impulses
    for (size_t a = 0; a < A_.size(); ++a) z_(static_cast<Eigen::Index>(a)) = lambda_prev_(A_[a]);
    for (int i : A_prev_) lambda_prev_(i) = 0.0;  // set again below for this step's A
    A_prev_ = A_;
  }

  // The columns W^{-1} E_a' of the active set, for either LCP.
  bool active_columns(MjIteration& f, double h) {
    const int na = static_cast<int>(A_.size());
    cols_.resize(na);
    for (int a = 0; a < na; ++a)
      if (!f.column(A_[a], cols_[a])) {
        failure_ = "moreau-jean: iteration matrix too ill-conditioned at h = " + short_number(h);
        return false;
      }
    return true;
  }

  // The friction LCP over [E_A; T_F] (mj_friction.hpp); v_next_ becomes the
  // post-step velocity.
  bool friction_step(MjIteration& f, double h, double t0) {
    v_free_size_ = v_next_.size() > 0 ? v_next_.lpNorm<Eigen::Infinity>() : 0.0;  // v_free
    if (!friction_->step(f, A_, cols_, Ev_, e_, *solver_, opt_.pivot_max_active, v_next_, z_,
                         lambda_T_, tr_.lcp_solves, failed_, friction_warning_)) {
      failure_ = lcp_failure("moreau-jean", t0, failed_);
      return false;
    }
    if (!friction_warning_.empty()) {
      tr_.warn("pgs-not-converged", t0, friction_warning_ + " at t = " + short_number(t0));
      friction_warning_.clear();
    }
    for (size_t fi = 0; fi < m_.friction.size(); ++fi) {
      const mech::FrictionalContact& fc = m_.friction[fi];
      u_t_(static_cast<Eigen::Index>(fi)) = lambda_T_(fc.contact) / h;
      // Closed; stick or slip is decided where a sample is kept (label_modes).
      if (const int p = pos_[static_cast<size_t>(fc.contact)]; p >= 0 && z_(p) > 0.0)
        fmode_[fi] = FrictionMode::kStick;
      if (u_t2_.size() == 0) continue;  // planar model
      u_t2_(static_cast<Eigen::Index>(fi)) = friction_->lambda_T2()(fc.contact) / h;
    }
    keep_impulses(h, false);
    return true;
  }

  // The frictionless velocity LCP over the active set; its impulses added to
  // v_next_.
  bool contact_step(const MjIteration& f, double h, double t0) {
    const int na = static_cast<int>(A_.size());
    ops_.E_times(v_next_, Evf_);  // v_next is still v_free here
    b_.resize(na);
    for (int a = 0; a < na; ++a) b_(a) = Evf_(A_[a]) + e_(A_[a]) * Ev_(A_[a]);
    const bool solved = na <= opt_.pivot_max_active ? solve_dense(f, na) : solve_sparse(na, t0);
    if (!solved) {
      failure_ = lcp_failure("moreau-jean", t0, failed_);
      return false;
    }
    keep_impulses(h, true);
    return true;
  }

  // Delassus matrix E_A W^{-1} E_A' from the cached columns W^{-1} E_a':
  // entry (p, a) sums E_p,r (W^{-1} E_a')_r over the column's rows r in
  // this order, dense or sparse alike.
  template <class Add>
  void for_each_delassus_entry(int na, Add&& add) const {
    for (int a = 0; a < na; ++a)
      for (SparseCol::InnerIterator it(*cols_[a], 0); it; ++it)
        for (SparseCol::InnerIterator e_it(Ec_, static_cast<int>(it.row())); e_it; ++e_it) {
          const int p = pos_[e_it.row()];
          if (p >= 0) add(p, a, e_it.value() * it.value());
        }
  }

  // Up to pivot_max_active rows: the dense Delassus matrix, kept while A and
  // the iteration matrix stay, by the warm pivot, else the solver.
  bool solve_dense(const MjIteration& f, int na) {
    if (Gd_f_ != &f || Gd_A_ != A_) {
      Gd_.setZero(na, na);
      for_each_delassus_entry(na, [&](int p, int a, double x) { Gd_(p, a) += x; });
      Gd_A_ = A_;
      Gd_f_ = &f;
      ++Gd_version_;
    }
    if (warm_pivot_) {
      const lcp::Result& r = warm_.solve(Gd_, Gd_version_, b_, z_, lopt_);
      if (r.ok()) {
        z_ = r.z;
        ++tr_.lcp_solves;
        return true;
      }
    }
    return solve_exact(Gd_);
  }

  // Above pivot_max_active rows: projected Gauss–Seidel on the sparse
  // Delassus matrix, warm-started; the pivoting solver when it does not
  // converge (up to kPivotFallbackMax rows; above, the iterate and a warning).
  bool solve_sparse(int na, double t0) {
    trip_.clear();
    for_each_delassus_entry(na, [&](int p, int a, double x) { trip_.emplace_back(p, a, x); });
    SparseRow G(na, na);
    G.setFromTriplets(trip_.begin(), trip_.end());
    pgs_opt_.warm_start = &z_;
    lcp::Result r = lcp::solve_sparse_pgs(G, b_, pgs_opt_);
    ++tr_.lcp_solves;
    bool solved = r.ok() && all_finite(r.z);
    if (!solved && na > kPivotFallbackMax && r.status == lcp::Status::kIterationLimit &&
        all_finite(r.z)) {
      tr_.warn("pgs-not-converged", t0,
               "moreau-jean: PGS stopped at residual " + short_number(r.residual) + " after " +
                   std::to_string(r.iterations) + " sweeps at t = " + short_number(t0));
      solved = true;
    }
    if (solved) z_.swap(r.z);
    return solved || solve_exact(MatrixXd(G));
  }

  // The step's LCP G z + b by the configured solver and its fallbacks
  // (dependent constraints: pivoting fails, Lemke does not); false leaves the
  // result in failed_.
  bool solve_exact(const MatrixXd& G) {
    int attempts = 0;
    lcp::Result r = lcp::solve_with_fallbacks(*solver_, G, b_, lopt_, &attempts);
    tr_.lcp_solves += attempts;
    if (!r.ok()) {
      failed_ = std::move(r);
      return false;
    }
    z_ = r.z;
    return true;
  }

  // The impulses z_ of the active set: the next step's warm start, the mode,
  // the mean forces over the step; added to v_next_ when `apply` (the
  // friction step has applied them itself).
  void keep_impulses(double h, bool apply) {
    const int na = static_cast<int>(A_.size());
    for (int a = 0; a < na; ++a) {
      lambda_prev_(A_[a]) = z_(a);
      if (z_(a) > 0.0) {
        if (apply)
          for (SparseCol::InnerIterator it(*cols_[a], 0); it; ++it)
            v_next_(it.row()) += it.value() * z_(a);
        mode_.push_back(A_[a]);
      }
      u_(A_[a]) = z_(a) / h;  // mean force over the step
      u_set_.push_back(A_[a]);
    }
  }

  // q+ = q + h v_theta, the divergence guard, the state taken, the gaps and
  // the sample.
  bool advance(long j, bool last, double h) {
    q_next_ = q_ + h * ((1.0 - theta_) * v_ + theta_ * v_next_);
    if (std::string why = guard_.check(last ? *opt_.t_end : j * grid_.h, q_next_, v_next_, last);
        !why.empty()) {
      tr_.t_end = (j - 1) * grid_.h;  // the time reached: the last sane state's
      failure_ = "moreau-jean: " + why;
      return false;
    }
    q_.swap(q_next_);
    v_.swap(v_next_);
    ++tr_.steps;
    if (k_ > 0) {
      ops_.E_times(q_, y_);
      y_ += m_.g;
      tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y_.minCoeff()));
    }
    const double t = last ? *opt_.t_end : j * grid_.h;
    if (sampler_.want(t, grid_.h, last)) record(t);
    return true;
  }

  void record(double t) {
    if (!opt_.record_samples) return;
    Sample s;
    s.t = t;
    s.x.resize(2 * N_);
    s.x << q_, v_;
    s.u = u_;
    s.y = y_;
    s.mode = mode_;
    if (friction_) {
      s.u_t = u_t_;
      label_modes();
      s.friction_mode = fmode_;
      s.u_t2 = u_t2_;
      // The facets only where a sample is kept (a run that records none, or
      // few, skips the 2d edges' trigonometry per sliding contact and step:
      // a third of a 3-D friction step at 10^4 contacts, bench/README.md).
      slip_facets(m_, fmode_, v_, facet_);
      s.friction_facet = facet_;
    }
    if (sens_) sens_->fill(s.dx, s.dx_exists);
    tr_.record_sample(std::move(s), opt_);
  }

  // The last step's closed contacts (fmode_ kStick) labelled stick or slip
  // by Coulomb's law (friction_mode_after_step), only where a sample is kept
  // (as the facets: the cone's gauge costs trigonometry per contact). Called
  // between the step and the next one: z_, pos_, lambda_T_ and the second
  // tangents' impulses are the step's, v_ its end velocity.
  void label_modes() {
    label_closed_contacts(
        m_, [this](int c) { return z_(pos_[static_cast<size_t>(c)]); }, lambda_T_,
        u_t2_.size() > 0 ? &friction_->lambda_T2() : nullptr, v_, velocity_scale(v_), fmode_);
  }

  const mech::Model& model_;
  const Options& opt_;
  const mech::MechanicalModel& m_;
  const int N_, k_;
  const MjOperators ops_;
  const SparseCol& Ec_;
  const double theta_;
  // The warm start reproduces the "pivot" solver's own computation
  // (WarmPivot); other solvers are called on every step.
  const bool warm_pivot_;
  const StepGrid grid_;
  OutputSampler sampler_;
  DivergenceGuard guard_;
  Trajectory tr_;
  VectorXd q_, v_;
  std::unique_ptr<lcp::Solver> solver_;
  MjIteration F_, F_last_;
  VectorXd e_;  // restitution per constraint
  std::unique_ptr<MjFriction> friction_;
  std::string friction_warning_;
  VectorXd lambda_T_;
  // Mean friction force over the step (N), per entry of m.friction: the
  // samples' u_t.
  VectorXd u_t_;
  // Their modes over the step (the samples' friction_mode): open unless the
  // normal impulse is positive; then Coulomb's law (label_modes): stick when
  // the friction impulse is strictly inside the cone or the sliding velocity
  // at the step's end is zero to the step's rounding band, else slip.
  std::vector<FrictionMode> fmode_;
  double v_free_size_ = 0.0;  // |v_free|_inf of the last friction step (m/s): label_modes' scale
  // Models with 3-D friction (empty otherwise): the mean force along each
  // entry's second tangent (N) and the facet of each sliding entry.
  VectorXd u_t2_;
  std::vector<impact::ConeFacet> facet_;
  VectorXd y_;  // gaps E q + g
  VectorXd u_;  // mean contact forces over the step
  lcp::Options lopt_;
  lcp::Options pgs_opt_;  // the sparse sweep for active sets above pivot_max_active
  lcp::WarmPivot warm_;
  IndexSet A_, A_prev_, mode_, u_set_;
  std::vector<int> pos_;  // position of constraint i in A, or -1
  VectorXd lambda_prev_;  // last step's impulses (warm start)
  std::vector<const SparseCol*> cols_;
  std::vector<Eigen::Triplet<double>> trip_;
  // The dense Delassus matrix E_A W^{-1} E_A' of an active set of at most
  // pivot_max_active rows, kept while A and the iteration matrix stay.
  MatrixXd Gd_;
  IndexSet Gd_A_;
  const MjIteration* Gd_f_ = nullptr;
  long Gd_version_ = 0;
  // v_next_ holds the free velocity v + h W^{-1} rhs until the impulses are added.
  VectorXd rhs_, dv_, v_next_, q_next_, Ev_, Evf_, b_, z_;
  VectorXd qv_abs_, gap_scale_;  // select_active: |q| + h theta |v|, and the gaps' scales
  lcp::Result failed_;           // the failed LCP
  std::string failure_;          // why the run ends
  std::unique_ptr<MjStepSensitivity> sens_;  // Options::sensitivity asked, else null
};

}  // namespace

Trajectory run_moreau_jean(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  MjRun run(model, x0, opt);
  if (!run.set_up()) return run.fail(run.failure());
  run.begin();
  return run.march();
}

}  // namespace lcsim::sim::detail
