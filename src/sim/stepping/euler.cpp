// Backward Euler, Algorithm 7.3.1 of the thesis, on sys = model.as_lcs() (the
// augmented state (q, v, 1) of (3.65) for mechanical models): one LCP per
// step on the fixed grid of time_stepping.cpp's description.
//
// run_euler is the driver; its stages are the members of EulerRun: set_up
// (the LCS and the solver), refusal (the consistency guard of §7.3), factor
// (one factorisation per step size), record, step (steps 4 and 5 of the
// algorithm) and advance (the divergence guard, the sample). A mechanical
// model with friction is run by euler_friction.cpp instead.
#include <algorithm>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim/stepping/step_sensitivity.hpp"
#include "sim/stepping/time_stepping_detail.hpp"

namespace lcsim::sim::detail {

namespace {

using Eigen::MatrixXd;

// kOk when computed; the message says why not.
struct EulerFactors : OutcomeStartingAs<Status::kNumericalFailure> {
  MatrixXd Phi;   // (I - hA)^{-1}
  MatrixXd PhiB;  // h (I - hA)^{-1} B
  MatrixXd G;     // D + h C (I - hA)^{-1} B, the LCP matrix of step 4
  double h = 0.0;
};

EulerFactors euler_factors(const lcs::Lcs& sys, double h) {
  EulerFactors f;
  const int n = sys.n();
  const MatrixXd IhA = MatrixXd::Identity(n, n) - h * sys.A;
  // One factorisation per step size; Phi is formed from it once so that each
  // step is a matrix-vector product (n is small: the models are low-order).
  const Eigen::FullPivLU<MatrixXd> lu(IhA);
  if (!lu.isInvertible()) {
    f.message = "I - hA is singular at h = " + short_number(h) + " (1/h is an eigenvalue of A)";
    return f;
  }
  f.h = h;
  f.Phi = lu.inverse();
  f.PhiB = h * (f.Phi * sys.B);
  f.G = sys.D + sys.C * f.PhiB;
  f.status = (f.Phi.allFinite() && f.G.allFinite()) ? Status::kOk : Status::kNumericalFailure;
  if (!f.ok()) f.message = "I - hA is too ill-conditioned at h = " + short_number(h);
  return f;
}

// One backward Euler run: the trajectory it builds and what its steps share.
class EulerRun {
 public:
  EulerRun(const mech::Model& model, const Options& opt)
      : model_(model),
        opt_(opt),
        mech_(model.is_mechanical()),
        N_(mech_ ? model.mechanical->dofs() : 0) {
    tr_.method = "euler";
    tr_.t_end = *opt.t_end;
    // Backward Euler's step LCP acts on positions: every impact is inelastic.
    if (mech_) tr_.impact_law = "inelastic (restitution ignored)";
  }

  // The LCS and the solver; false ends the run (Trajectory returned by
  // set_up_failure).
  bool set_up() {
    try {  // set-up, before the loop: invalid names or data end the run cleanly
      sys_ = model_.as_lcs();
      if (mech_ && model_.mechanical->has_inputs()) set_up_inputs();
      solver_ = lcp::make_solver(opt_.lcp_solver);
    } catch (const std::exception& e) {
      tr_.status = RunStatus::kNumericalFailure;
      tr_.message = std::string("euler: ") + e.what();
      return false;
    }
    n_ = sys_.n();
    k_ = sys_.k();
    return true;
  }
  Trajectory set_up_failure(const VectorXd& x0_user) {
    tr_.final_state = x0_user;
    return std::move(tr_);
  }

  // The augmented start (q, v, 1) of a mechanical model, the state of an LCS.
  VectorXd start(const VectorXd& x0_user) {
    VectorXd x(n_);
    if (mech_)
      x << x0_user, 1.0;
    else
      x = x0_user;
    tr_.energy_initial = energy(x);
    return x;
  }

  // Consistency guard (§7.3, Example 7.3.3): with a leading row index
  // rho_i >= 3 backward Euler produces impulses of order h^{1-rho_i} and does
  // not converge. Refuse unless forced: the failure message, or "".
  std::string refusal() {
    const std::vector<int> rho = lcs::leading_row_indices(sys_);
    for (int i = 0; i < k_; ++i) {
      if (rho[i] >= 3) {
        const std::string msg = "leading row index rho_" + std::to_string(i + 1) + " = " +
                                std::to_string(rho[i]) +
                                " >= 3: backward Euler is not consistent here (thesis §7.3, "
                                "Example 7.3.3: the outputs blow up as h -> 0)";
        if (!opt_.force) return "euler: refused: " + msg + "; set Options::force to run anyway";
        tr_.warn("forced", 0.0, "forced despite " + msg);
        break;
      }
    }
    return "";
  }

  void warn_restitution() {
    if (mech_ && model_.mechanical->restitution.size() > 0 &&
        model_.mechanical->restitution.maxCoeff() > 0.0)
      tr_.warn("restitution-ignored", 0.0,
               "backward Euler ignores restitution: every impact is inelastic");
  }

  // The factors of the grid's step and of its shortened last step: the
  // failure message, or "".
  std::string factor(const StepGrid& grid) {
    F_ = euler_factors(sys_, grid.h);
    if (!F_.ok()) return "euler: " + F_.message;
    if (grid.h_last != grid.h) {
      F_last_ = euler_factors(sys_, grid.h_last);
      if (!F_last_.ok()) return "euler: last step: " + F_last_.message;
    }
    return "";
  }

  // The steps from the sample at t = 0 to t_end, or to the first failure.
  Trajectory march(const StepGrid& grid, const VectorXd& x0_user, VectorXd& x) {
    OutputSampler sampler(opt_.dt_out);
    DivergenceGuard guard(model_, x0_user, *opt_.t_end);
    u_ = VectorXd::Zero(k_);
    if (!opt_.sensitivity.empty())  // the discrete map's derivative (step_sensitivity.hpp)
      sens_ = std::make_unique<EulerStepSensitivity>(
          model_, parse_sensitivity(model_, opt_.sensitivity), sys_);
    record(0.0, x, u_);
    xb_.resize(n_);
    q_.resize(k_);
    x_next_.resize(n_);
    for (long j = 1; j <= grid.n; ++j) {
      const bool last = j == grid.n;
      if (opt_.progress && j % Options::kProgressSteps == 0) opt_.progress(j * grid.h);
      const EulerFactors& f = (last && grid.h_last != grid.h) ? F_last_ : F_;
      if (!step(f, x, (j - 1) * grid.h)) return fail(failure_, x);
      if (sens_)
        sens_->step((j - 1) * grid.h, last ? grid.h_last : grid.h, f.Phi, f.PhiB, f.G, x_next_, u_);
      if (std::string why = guard.check(last ? *opt_.t_end : j * grid.h, x_next_, last);
          !why.empty()) {
        tr_.t_end = (j - 1) * grid.h;  // the time reached: the last sane state's
        return fail("euler: " + why, x);
      }
      x = x_next_;
      ++tr_.steps;
      const double t = last ? *opt_.t_end : j * grid.h;
      sample(sampler.want(t, grid.h, last), t, x);
    }
    return finish(x);
  }

  Trajectory fail(const std::string& msg, const VectorXd& xa) {
    tr_.status = RunStatus::kNumericalFailure;
    tr_.message = msg;
    return finish(xa);
  }

 private:
  VectorXd user(const VectorXd& xa) const { return mech_ ? VectorXd(xa.head(2 * N_)) : xa; }
  double energy(const VectorXd& xa) const {
    return mech_ ? mech::total_energy(*model_.mechanical, xa.head(N_), xa.segment(N_, N_)) : 0.0;
  }
  Trajectory finish(const VectorXd& xa) {
    tr_.final_state = user(xa);
    tr_.energy_final = energy(xa);
    if (sens_) sens_->finish(tr_);
    return std::move(tr_);  // only ever returned from the run: no copy of the samples
  }

  // A model with inputs (docs/inputs.md): the LCS without their exosystems,
  // the force inputs evaluated per step instead (input_drive).
  void set_up_inputs() {
    mech::Model plain = model_;
    plain.mechanical->inputs.clear();
    plain.mechanical->force_inputs.clear();
    plain.mechanical->gap_inputs.clear();
    sys_ = plain.as_lcs();
    Minv_ = Eigen::LLT<MatrixXd>(model_.mechanical->M.toDense()).solve(MatrixXd::Identity(N_, N_));
    inputs_ = true;
  }
  // The inputs' part of x' at t: (0, M^{-1} (f(t) - f), 0).
  VectorXd input_drive(double t) const {
    VectorXd d = VectorXd::Zero(sys_.n());
    d.segment(N_, N_) = Minv_ * (mech::force_at(*model_.mechanical, t) - model_.mechanical->f);
    return d;
  }

  // Steps 4 and 5 of Algorithm 7.3.1 from x (the step starting at t0) into
  // x_next_; false (failure_ says why) when the LCP fails.
  bool step(const EulerFactors& f, const VectorXd& x, double t0) {
    if (inputs_)  // the inputs at the step's end, as backward Euler takes every term
      xb_.noalias() = f.Phi * (x + f.h * input_drive(t0 + f.h));
    else
      xb_.noalias() = f.Phi * x;  // free step (I - hA)^{-1} x_k
    if (k_ == 0) {
      x_next_ = xb_;
      return true;
    }
    q_.noalias() = sys_.C * xb_;  // step 4 of Algorithm 7.3.1
    int attempts = 0;             // dependent constraints: pivoting fails, Lemke does not
    // Scaled: G = h C (I - hA)^{-1} B is h^2 E M^{-1} E' for a gap, 1e-16 at
    // h = 1e-8, and an unscaled tolerance would accept any u within 1e4 of it.
    const lcp::Result r = lcp::solve_scaled(*solver_, f.G, q_, lopt_, &attempts);
    tr_.lcp_solves += attempts;
    if (!r.ok()) {
      failure_ = lcp_failure("euler", t0, r);
      return false;
    }
    u_ = r.z;
    x_next_.noalias() = xb_ + f.PhiB * u_;  // step 5
    return true;
  }

  // The sample at t when `wanted`; the worst gap in any case.
  void sample(bool wanted, double t, const VectorXd& x) {
    if (wanted) {
      record(t, x, u_);  // also updates max_violation
    } else if (k_ > 0) {
      const VectorXd y = sys_.C * x + sys_.D * u_;
      tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y.minCoeff()));
    }
  }

  void record(double t, const VectorXd& xa, const VectorXd& uu) {
    const VectorXd y = sys_.C * xa + sys_.D * uu;
    if (k_ > 0) tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y.minCoeff()));
    if (!opt_.record_samples) return;
    Sample s;
    s.t = t;
    s.x = user(xa);
    s.u = uu;
    s.y = y;
    for (int i = 0; i < k_; ++i)
      if (uu(i) > 0.0) s.mode.push_back(i);
    if (sens_) sens_->fill(s.dx, s.dx_exists);
    tr_.record_sample(std::move(s), opt_);
  }

  const mech::Model& model_;
  const Options& opt_;
  const bool mech_;
  const int N_;
  Trajectory tr_;
  lcs::Lcs sys_;
  std::unique_ptr<lcp::Solver> solver_;
  int n_ = 0, k_ = 0;
  EulerFactors F_, F_last_;
  lcp::Options lopt_;
  VectorXd u_, xb_, q_, x_next_;
  std::string failure_;                         // why step() failed
  std::unique_ptr<EulerStepSensitivity> sens_;  // Options::sensitivity asked, else null
  bool inputs_ = false;                         // force inputs evaluated per step (set_up_inputs)
  MatrixXd Minv_;
};

}  // namespace

Trajectory run_euler(const mech::Model& model, const VectorXd& x0_user, const Options& opt) {
  // Coulomb's law has no variables in the LCS (3.65): with friction the step
  // is the mechanical one of euler_friction.cpp.
  if (model.is_mechanical() && model.mechanical->has_friction())
    return run_euler_friction(model, x0_user, opt);
  EulerRun run(model, opt);
  if (!run.set_up()) return run.set_up_failure(x0_user);
  VectorXd x = run.start(x0_user);
  if (std::string why = run.refusal(); !why.empty()) return run.fail(why, x);
  run.warn_restitution();
  const StepGrid grid = StepGrid::of(*opt.t_end, opt.h);
  if (std::string why = run.factor(grid); !why.empty()) return run.fail(why, x);
  return run.march(grid, x0_user, x);
}

}  // namespace lcsim::sim::detail
