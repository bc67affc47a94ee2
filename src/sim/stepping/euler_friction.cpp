// Backward Euler on a mechanical model with Coulomb friction, planar or 3-D
// (issue 27): the step of Stewart and Trinkle (1996) at theta = 1.
//
// Backward Euler (Algorithm 7.3.1 on (3.65)) takes every term at the step's
// end: q+ = q + h v+, M (v+ - v) = h (f - D v+ - K q+) + lambda (lambda = h u,
// the impulses, N s), so with W = M + h D + h^2 K
//   W (v+ - v) = h (f - D v - K q - h K v) + E' lambda_N + T' lambda_T,
// the Moreau–Jean step at theta = 1 (step_kernels.hpp). The normal rows are
// backward Euler's, at the position level on every constraint:
//   0 <= E q+ + g = (E q + g) + h E v+   ⟂  lambda_N >= 0,
// i.e. 0 <= E v+ + (E q + g)/h ⟂ lambda_N; the frictional rows are Coulomb's
// law at the step's end velocity, as in Moreau–Jean's friction step. So the
// step is MjFriction::step (mj_friction.hpp: its assembly, its dense or
// sparse LCP, its cone in Stewart and Trinkle's form) with its normal rates
// E v_free + e .* Ev taken with Ev = E q + g and e = 1/h, on an active set
// grown until no other constraint's end gap is negative (contact_step):
// nothing of that step is written twice. On a
// model without friction euler.cpp's LCS step runs as before (this path is
// taken only where mech::MechanicalModel::has_friction).
//
// Samples as Moreau–Jean's with friction: u the mean normal force over the
// step (lambda_N / h, which is backward Euler's u_{k+1}), y the gaps at the
// step's end, u_t (u_t2) the mean friction forces, the contacts' modes open
// or, with a positive normal impulse, stick / slip by Coulomb's law on the
// step's impulses and end velocity (friction_labels.hpp), a sliding 3-D
// contact's facet that of maximal dissipation for its end velocity.
// Restitution is ignored (every impact inelastic), as on euler's LCS path.
#include <algorithm>
#include <lcsim/mech/mech.hpp>
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

constexpr double kTheta = 1.0;  // backward Euler: every term at the step's end
// A gap is at or below zero within kActivationRounding times the magnitude
// of the terms it is formed from, |E| (|q| + h |v_free|) + |g|: Moreau–Jean's
// activation rounding (moreau_jean.cpp says why 64 eps).
constexpr double kActivationRounding = 64 * std::numeric_limits<double>::epsilon();

// One backward Euler run with friction: the state (q, v), the step's
// impulses and what the steps keep (the factored W, MjFriction's Delassus
// matrix over every constraint).
class EulerFrictionRun {
 public:
  EulerFrictionRun(const mech::Model& model, const VectorXd& x0, const Options& opt)
      : opt_(opt),
        model_(model),
        m_(*model.mechanical),
        N_(m_.dofs()),
        k_(m_.num_constraints()),
        nf_(static_cast<Eigen::Index>(m_.friction.size())),
        ops_(m_, N_ > opt.sparse_dofs_threshold),
        grid_(StepGrid::of(*opt.t_end, opt.h)),
        sampler_(opt.dt_out),
        guard_(model, x0, *opt.t_end) {
    tr_.method = "euler";
    tr_.t_end = *opt.t_end;
    tr_.impact_law = "inelastic (restitution ignored)";  // as euler's LCS path
    q_ = x0.head(N_);
    v_ = x0.tail(N_);
    tr_.energy_initial = ops_.energy(q_, v_);
    if (m_.restitution.size() > 0 && m_.restitution.maxCoeff() > 0.0)
      tr_.warn("restitution-ignored", 0.0,
               "backward Euler ignores restitution: every impact is inelastic");
  }

  // The solver and W = M + h D + h^2 K (its Cholesky factor: D and K
  // symmetric, checked here since euler's LCS path takes asymmetric ones);
  // false: the trajectory's status and message say why.
  bool set_up(const std::string& model_name) {
    std::string why = mech::asymmetry(m_.D, "D");
    if (why.empty()) why = mech::asymmetry(m_.K, "K");
    if (!why.empty()) {
      tr_.status = RunStatus::kInvalidInput;
      tr_.message =
          "method 'euler' with friction factors M + h D + h^2 K by Cholesky and needs "
          "symmetric D and K; model '" +
          model_name + "' has " + why;
      return false;
    }
    try {
      solver_ = lcp::make_solver(opt_.lcp_solver);
    } catch (const std::exception& e) {
      return fail(std::string("euler: ") + e.what());
    }
    if (!F_.factor(ops_, grid_.h, kTheta)) return fail("euler: " + F_.message());
    if (grid_.h_last != grid_.h && !F_last_.factor(ops_, grid_.h_last, kTheta))
      return fail("euler: last step: " + F_last_.message());
    return true;
  }

  // What the loop keeps, and the sample at t = 0.
  void begin() {
    friction_ = std::make_unique<MjFriction>(m_, ops_);
    Ev_.resize(k_);
    band_.resize(k_);
    lambda_ = VectorXd::Zero(k_);
    lambda_T_ = VectorXd::Zero(k_);
    u_ = VectorXd::Zero(k_);
    u_t_ = VectorXd::Zero(nf_);
    fmode_.assign(m_.friction.size(), FrictionMode::kOpen);
    if (m_.has_friction_3d()) {
      u_t2_ = VectorXd::Zero(nf_);
      facet_.assign(m_.friction.size(), impact::ConeFacet{});
    }
    y_.resize(k_);
    gaps();
    rhs_.resize(N_);
    dv_.resize(N_);
    if (!opt_.sensitivity.empty())  // Moreau–Jean's at theta = 1 with the gap rows
      sens_ = std::make_unique<MjStepSensitivity>(
          model_, parse_sensitivity(model_, opt_.sensitivity), kTheta, true);
    record(0.0);
  }

  // Every step of the grid, or up to the first failure.
  Trajectory march() {
    for (long j = 1; j <= grid_.n; ++j) {
      if (opt_.progress && j % Options::kProgressSteps == 0) opt_.progress(j * grid_.h);
      if (!step(j)) return finish();  // the last sane state
    }
    return finish();
  }

  Trajectory finish() {
    tr_.final_state.resize(2 * N_);
    tr_.final_state << q_, v_;
    tr_.energy_final = ops_.energy(q_, v_);
    if (sens_) sens_->finish(tr_);
    return std::move(tr_);  // only ever returned from the run: no copy of the samples
  }

 private:
  bool fail(const std::string& msg) {
    tr_.status = RunStatus::kNumericalFailure;
    tr_.message = msg;
    return false;
  }

  // y_ = E q + g, and the run's worst gap.
  void gaps() {
    if (k_ == 0) return;
    ops_.E_times(q_, y_);
    y_ += m_.g;
    tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y_.minCoeff()));
  }

  // Step j of the grid; false: the trajectory says why.
  bool step(long j) {
    const bool last = j == grid_.n;
    const double h = last ? grid_.h_last : grid_.h;
    MjIteration& f = (last && grid_.h_last != grid_.h) ? F_last_ : F_;
    const double t0 = (j - 1) * grid_.h;  // the step's start, for messages
    ops_.set_step(t0, h, kTheta);         // force inputs at the step's end
    ops_.step_force(q_, v_, h, kTheta, rhs_);
    f.solve(rhs_, dv_);
    v_next_ = v_ + h * dv_;  // v_free
    v_free_size_ = v_next_.size() > 0 ? v_next_.lpNorm<Eigen::Infinity>() : 0.0;
    if (k_ > 0 && !contact_step(f, h, t0)) return false;
    if (sens_) sensitivity_step(t0, h);
    q_next_ = q_ + h * v_next_;  // q+ = q + h v+
    if (std::string why = guard_.check(last ? *opt_.t_end : j * grid_.h, q_next_, v_next_, last);
        !why.empty()) {
      tr_.t_end = t0;  // the time reached: the last sane state's
      return fail("euler: " + why);
    }
    q_.swap(q_next_);
    v_.swap(v_next_);
    ++tr_.steps;
    gaps();
    const double t = last ? *opt_.t_end : j * grid_.h;
    if (sampler_.want(t, grid_.h, last)) record(t);
    return true;
  }

  // The step map's derivative (step_sensitivity.hpp): the step's active
  // set, normal and friction impulses, and label_modes' velocity scale.
  void sensitivity_step(double t0, double h) {
    MjStepSensitivity::Friction fr;
    fr.t = &lambda_T_;
    fr.t2 = u_t2_.size() > 0 ? &friction_->lambda_T2() : nullptr;
    fr.V = std::max(v_free_size_, v_next_.size() > 0 ? v_next_.lpNorm<Eigen::Infinity>() : 0.0);
    static const IndexSet kNone;
    sens_->step(t0, h, q_, v_, v_next_, k_ > 0 ? A_ : kNone, lamA_, &fr);
  }

  // The step LCP (MjFriction::step with the normal rows at the position
  // level: Ev = E q + g, e = 1/h) over the active set; v_next_ becomes v+.
  // The LCP is backward Euler's over every constraint, solved on a growing
  // set: A starts with the constraints whose end gap predicted with v_free
  // is at or below its rounding, or that carried an impulse in the last
  // step; a constraint outside A whose end gap y_i + h E_i v+ is below minus
  // its rounding joins A and the step is solved again from v_free (A grows
  // each round: at most k rounds). What remains outside has no impulse and
  // an end gap >= 0 to rounding, so the result solves the LCP over all k
  // constraints, and a step costs what its closing contacts cost.
  bool contact_step(MjIteration& f, double h, double t0) {
    v_free_ = v_next_;
    ops_.E_times(v_free_, Ev_);
    qv_abs_ = q_.cwiseAbs() + h * v_free_.cwiseAbs();
    ops_.abs_E_times(qv_abs_, band_);
    band_ *= kActivationRounding;
    A_.clear();
    for (int i = 0; i < k_; ++i)
      if (y_(i) + h * Ev_(i) <= band_(i) || lambda_(i) > 0.0) A_.push_back(i);
    if (inv_h_.size() != k_ || inv_h_for_ != h) {
      inv_h_ = VectorXd::Constant(k_, 1.0 / h);
      inv_h_for_ = h;
    }
    lambda_T_.setZero();
    for (bool again = !A_.empty(); again;) {
      if (!solve_active(f, h, t0)) return false;
      ops_.E_times(v_next_, Ev_);
      in_A_.assign(static_cast<size_t>(k_), 0);
      for (int i : A_) in_A_[static_cast<size_t>(i)] = 1;
      again = false;
      for (int i = 0; i < k_; ++i)
        if (!in_A_[static_cast<size_t>(i)] && y_(i) + h * Ev_(i) < -band_(i)) {
          A_.push_back(i);
          again = true;
        }
      std::sort(A_.begin(), A_.end());
    }
    lambda_.setZero();
    for (size_t a = 0; a < A_.size(); ++a) lambda_(A_[a]) = lamA_(static_cast<Eigen::Index>(a));
    keep_forces(h);
    return true;
  }

  // One round of contact_step: the LCP over A_ from v_free, warm-started
  // from the last impulses; lamA_ the normal impulses on A_.
  bool solve_active(MjIteration& f, double h, double t0) {
    cols_.resize(A_.size());
    lamA_.resize(static_cast<Eigen::Index>(A_.size()));
    for (size_t a = 0; a < A_.size(); ++a) {
      if (!f.column(A_[a], cols_[a])) {
        fail("euler: iteration matrix too ill-conditioned at h = " + short_number(h));
        return false;
      }
      lamA_(static_cast<Eigen::Index>(a)) = lambda_(A_[a]);
    }
    v_next_ = v_free_;
    lambda_T_.setZero();
    if (!friction_->step(f, A_, cols_, y_, inv_h_, *solver_, opt_.pivot_max_active, v_next_, lamA_,
                         lambda_T_, tr_.lcp_solves, failed_, warning_)) {
      fail(lcp_failure("euler", t0, failed_));
      return false;
    }
    if (!warning_.empty()) {
      tr_.warn("pgs-not-converged", t0, warning_ + " at t = " + short_number(t0));
      warning_.clear();
    }
    return true;
  }

  // The mean forces over the step (N) and the modes: open, or closed
  // (kStick until label_modes judges it where a sample is kept).
  void keep_forces(double h) {
    mode_.clear();
    for (int i = 0; i < k_; ++i) {
      u_(i) = lambda_(i) / h;
      if (lambda_(i) > 0.0) mode_.push_back(i);
    }
    for (Eigen::Index fi = 0; fi < nf_; ++fi) {
      const mech::FrictionalContact& fc = m_.friction[static_cast<size_t>(fi)];
      u_t_(fi) = lambda_T_(fc.contact) / h;
      fmode_[static_cast<size_t>(fi)] =
          lambda_(fc.contact) > 0.0 ? FrictionMode::kStick : FrictionMode::kOpen;
      if (u_t2_.size() > 0) u_t2_(fi) = friction_->lambda_T2()(fc.contact) / h;
    }
  }

  // The closed contacts labelled stick or slip by Coulomb's law at the
  // step's impulses and end velocity v_ (friction_mode_after_step), the
  // band's scale max(|v_free|, |v+|) as Moreau–Jean's (moreau_jean.cpp's
  // velocity_scale), and a sliding 3-D contact's facet.
  void label_modes() {
    const double V = std::max(v_free_size_, v_.size() > 0 ? v_.lpNorm<Eigen::Infinity>() : 0.0);
    label_closed_contacts(
        m_, [this](int c) { return lambda_(c); }, lambda_T_,
        u_t2_.size() > 0 ? &friction_->lambda_T2() : nullptr, v_, V, fmode_);
    slip_facets(m_, fmode_, v_, facet_);
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
    s.u_t = u_t_;
    label_modes();  // at t = 0 every contact is open (no step yet)
    s.friction_mode = fmode_;
    s.u_t2 = u_t2_;
    s.friction_facet = facet_;
    if (sens_) sens_->fill(s.dx, s.dx_exists);
    tr_.record_sample(std::move(s), opt_);
  }

  const Options& opt_;
  const mech::Model& model_;
  const mech::MechanicalModel& m_;
  const int N_, k_;
  const Eigen::Index nf_;
  const MjOperators ops_;
  const StepGrid grid_;
  OutputSampler sampler_;
  DivergenceGuard guard_;
  Trajectory tr_;
  VectorXd q_, v_, q_next_, v_next_, rhs_, dv_;
  std::unique_ptr<lcp::Solver> solver_;
  MjIteration F_, F_last_;
  std::unique_ptr<MjFriction> friction_;
  IndexSet A_;                          // the step's active set (contact_step), ascending
  std::vector<char> in_A_;              // contact_step: whether constraint i is in A_
  std::vector<const SparseCol*> cols_;  // W^{-1} E_a' for a in A_
  VectorXd lamA_;                       // the normal impulses on A_ (N s)
  VectorXd v_free_, Ev_, qv_abs_,
      band_;                    // contact_step: v_free, E v, |q| + h |v|, the gaps' rounding
  VectorXd inv_h_;              // 1/h per constraint (the normal rows' e)
  double inv_h_for_ = 0.0;      // the h of inv_h_
  VectorXd y_;                  // gaps E q + g (m)
  VectorXd lambda_, lambda_T_;  // the step's normal and tangential impulses (N s)
  VectorXd u_, u_t_, u_t2_;     // mean forces over the step (N)
  IndexSet mode_;               // constraints with a positive impulse
  std::vector<FrictionMode> fmode_;
  std::vector<impact::ConeFacet> facet_;
  double v_free_size_ = 0.0;  // |v_free|_inf of the last step (m/s): label_modes' scale
  lcp::Result failed_;
  std::string warning_;
  std::unique_ptr<MjStepSensitivity> sens_;  // Options::sensitivity asked, else null
};

}  // namespace

Trajectory run_euler_friction(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  EulerFrictionRun run(model, x0, opt);
  if (!run.set_up(model.name)) return run.finish();
  run.begin();
  return run.march();
}

}  // namespace lcsim::sim::detail
