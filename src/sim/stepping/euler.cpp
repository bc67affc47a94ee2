// Backward Euler, Algorithm 7.3.1 of the thesis, on sys = model.as_lcs() (the
// augmented state (q, v, 1) of (3.65) for mechanical models): one LCP per
// step on the fixed grid of time_stepping.cpp's description.
#include <algorithm>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "sim/stepping/time_stepping_detail.hpp"

namespace lcsim::sim::detail {

namespace {

using Eigen::MatrixXd;

struct EulerFactors {
  MatrixXd Phi;                               // (I - hA)^{-1}
  MatrixXd PhiB;                              // h (I - hA)^{-1} B
  MatrixXd G;                                 // D + h C (I - hA)^{-1} B, the LCP matrix of step 4
  Status status = Status::kNumericalFailure;  // kOk when computed; message says why not
  bool ok() const { return status == Status::kOk; }
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
    f.message = "I - hA is singular at h = " + short_number(h) + " (1/h is an eigenvalue of A)";
    return f;
  }
  f.Phi = lu.inverse();
  f.PhiB = h * (f.Phi * sys.B);
  f.G = sys.D + sys.C * f.PhiB;
  f.status = (f.Phi.allFinite() && f.G.allFinite()) ? Status::kOk : Status::kNumericalFailure;
  if (!f.ok()) f.message = "I - hA is too ill-conditioned at h = " + short_number(h);
  return f;
}

}  // namespace

Trajectory run_euler(const mech::Model& model, const VectorXd& x0_user, const Options& opt) {
  Trajectory tr;
  tr.method = "euler";
  tr.t_end = *opt.t_end;
  // Backward Euler's step LCP acts on positions: every impact is inelastic.
  if (model.is_mechanical()) tr.impact_law = "inelastic (restitution ignored)";
  const bool mech = model.is_mechanical();
  const int N = mech ? model.mechanical->dofs() : 0;
  auto user = [&](const VectorXd& xa) -> VectorXd { return mech ? VectorXd(xa.head(2 * N)) : xa; };
  auto energy = [&](const VectorXd& xa) {
    return mech ? mech::total_energy(*model.mechanical, xa.head(N), xa.segment(N, N)) : 0.0;
  };
  auto finish = [&](const VectorXd& xa) {
    tr.final_state = user(xa);
    tr.energy_final = energy(xa);
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
  if (mech)
    x << x0_user, 1.0;
  else
    x = x0_user;
  tr.energy_initial = energy(x);

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
          return fail("euler: refused: " + msg + "; set Options::force to run anyway", x);
        tr.warn("forced", 0.0, "forced despite " + msg);
        break;
      }
    }
  }
  if (mech && model.mechanical->restitution.size() > 0 &&
      model.mechanical->restitution.maxCoeff() > 0.0)
    tr.warn("restitution-ignored", 0.0,
            "backward Euler ignores restitution: every impact is inelastic");

  const StepGrid grid = StepGrid::of(*opt.t_end, opt.h);
  EulerFactors F = euler_factors(sys, grid.h);
  if (!F.ok()) return fail("euler: " + F.message, x);
  EulerFactors F_last;
  if (grid.h_last != grid.h) {
    F_last = euler_factors(sys, grid.h_last);
    if (!F_last.ok()) return fail("euler: last step: " + F_last.message, x);
  }

  OutputSampler sampler(opt.dt_out);
  DivergenceGuard guard(model, x0_user, *opt.t_end);
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
    if (std::string why = guard.check(last ? *opt.t_end : j * grid.h, x_next, last); !why.empty()) {
      tr.t_end = (j - 1) * grid.h;  // the time reached: the last sane state's
      return fail("euler: " + why, x);
    }
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

}  // namespace lcsim::sim::detail
