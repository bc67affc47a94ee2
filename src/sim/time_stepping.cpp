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
#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "sim/sim.hpp"

namespace lcsim::sim {

namespace {

using Eigen::MatrixXd;

// The step grid: n steps, all of length h except possibly the last.
struct Grid {
  long n = 0;
  double h = 0.0;
  double h_last = 0.0;
  double time(long j) const {  // t_j, with t_n = t_end exactly
    return j * h;
  }
};

Grid make_grid(double t_end, double h) {
  Grid g;
  g.h = h;
  const double r = t_end / h;
  const double rn = std::round(r);
  // h "divides" t_end when t_end / h is an integer up to rounding of the quotient.
  if (rn >= 1.0 && std::abs(r - rn) <= 1e-9 * rn) {
    g.n = static_cast<long>(rn);
    g.h_last = h;
  } else {
    const double nf = std::floor(r);
    g.n = static_cast<long>(nf) + 1;
    g.h_last = t_end - nf * h;
  }
  return g;
}

// Output sampling shared by both schemes.
class Sampler {
 public:
  explicit Sampler(double dt_out) : dt_out_(dt_out) {}
  // True if the state at step time t (with step h) should be recorded.
  bool want(double t, double h, bool last) {
    if (last || dt_out_ <= 0.0) return true;
    if (t < next_ - 1e-9 * h) return false;
    while (next_ <= t + 1e-9 * h) next_ += dt_out_;
    return true;
  }
  void start() { next_ = dt_out_; }

 private:
  double dt_out_;
  double next_ = 0.0;
};

void warn(Trajectory& tr, const std::string& w) {
  ++tr.warnings;
  if (tr.warning_messages.size() < 10) tr.warning_messages.push_back(w);
}

std::string fmt(double x) {
  std::ostringstream s;
  s.precision(6);
  s << x;
  return s.str();
}

// Checks common to both schemes; "" when the options are usable.
std::string check_options(const Options& opt, bool theta_used) {
  if (!(opt.t_end > 0.0) || !std::isfinite(opt.t_end))
    return "t_end must be a finite number > 0 (got " + fmt(opt.t_end) + ")";
  if (!(opt.h > 0.0) || !std::isfinite(opt.h))
    return "step h must be a finite number > 0 (got " + fmt(opt.h) + ")";
  if (opt.t_end / opt.h > 1e9)
    return "t_end / h = " + fmt(opt.t_end / opt.h) + " steps is more than 1e9";
  if (theta_used && !(opt.theta >= 0.0 && opt.theta <= 1.0))
    return "theta must lie in [0, 1] (got " + fmt(opt.theta) + ")";
  return "";
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
  tr.t_end = opt.t_end;
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
    return tr;
  };
  auto fail = [&](const std::string& msg, const VectorXd& xa) {
    tr.status = RunStatus::kFailed;
    tr.message = msg;
    return finish(xa);
  };

  lcs::Lcs sys;
  std::unique_ptr<lcp::Solver> solver;
  try {  // set-up, before the loop: invalid names or data end the run cleanly
    sys = model.as_lcs();
    solver = lcp::make_solver(opt.lcp_solver);
  } catch (const std::exception& e) {
    tr.status = RunStatus::kFailed;
    tr.message = std::string("euler: ") + e.what();
    tr.final_state = x0_user;
    return tr;
  }
  const int n = sys.n(), k = sys.k();
  VectorXd x(n);
  if (x0_user.size() != model.state_size()) {
    tr.status = RunStatus::kFailed;
    tr.message = "euler: initial state has " + std::to_string(x0_user.size()) +
                 " entries, the model needs " + std::to_string(model.state_size());
    tr.final_state = x0_user;
    return tr;
  }
  if (mech)
    x << x0_user, 1.0;
  else
    x = x0_user;
  tr.energy_initial = energy(x);
  if (const std::string err = check_options(opt, false); !err.empty())
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
        warn(tr, "forced despite " + msg);
        break;
      }
    }
  }
  if (mech && model.mechanical->restitution.size() > 0 &&
      model.mechanical->restitution.maxCoeff() > 0.0)
    warn(tr, "backward Euler ignores restitution: every impact is inelastic");

  const Grid grid = make_grid(opt.t_end, opt.h);
  EulerFactors F = euler_factors(sys, grid.h);
  if (!F.ok) return fail("euler: " + F.message, x);
  EulerFactors F_last;
  if (grid.h_last != grid.h) {
    F_last = euler_factors(sys, grid.h_last);
    if (!F_last.ok) return fail("euler: last step: " + F_last.message, x);
  }

  Sampler sampler(opt.dt_out);
  sampler.start();
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
    tr.samples.push_back(std::move(s));
  };
  record(0.0, x, u);

  lcp::Options lopt;
  VectorXd xb(n), q(k), x_next(n);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    const EulerFactors& f = (last && grid.h_last != grid.h) ? F_last : F;
    xb.noalias() = f.Phi * x;  // free step (I - hA)^{-1} x_k
    if (k > 0) {
      q.noalias() = sys.C * xb;  // step 4 of Algorithm 7.3.1
      const lcp::Result r = solver->solve(f.G, q, lopt);
      ++tr.lcp_solves;
      if (!r.ok())
        return fail("euler: LCP failed at t = " + fmt((j - 1) * grid.h) + " (" +
                        std::string(lcp::to_string(r.status)) + ")" +
                        (r.message.empty() ? "" : ": " + r.message),
                    x);
      u = r.z;
      x_next.noalias() = xb + f.PhiB * u;  // step 5
    } else {
      x_next = xb;
    }
    if (!x_next.allFinite()) return fail("euler: non-finite state at t = " + fmt(j * grid.h), x);
    x = x_next;
    ++tr.steps;
    const double t = last ? opt.t_end : grid.time(j);
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
//   M (v+ - v) = h (f - D v_t - K q_t) + E_J' lambda,   q+ = q + h v_t,
// i.e. W (v+ - v) = h (f - D v - K q - h theta K v) + E_J' lambda with the
// iteration matrix W = M + h theta D + h^2 theta^2 K (factored once, LLT).
// Impact law at velocity level on the predicted-active set J:
//   0 <= E_J v+ + e_J . E_J v  ⟂  lambda >= 0.
// Activation rule: constraint i is in J when its predicted gap
//   E_i (q + h theta v) + g_i <= 0,
// i.e. the gap extrapolated with the velocity at the point where the scheme
// evaluates the position (Siconos uses gamma h with gamma = 1/2 by default;
// here gamma = theta). A constraint left out of J can then penetrate by at
// most h (1 - theta) |E_i v| + O(h^2) in one step.
//
// Energy balance per step (f included in the potential, derivation in
// tests/sim/test_time_stepping.cpp):
//   E+ - E = -h v_t' D v_t + lambda' E_J v_t - (theta - 1/2)(|v+ - v|_M^2 + h^2 |v_t|_K^2),
// and lambda_i E_i v_t = lambda_i E_i v ((1 - theta) - theta e_i) when lambda_i > 0.

struct MoreauJeanFactors {
  Eigen::LLT<MatrixXd> llt;  // W = M + h theta D + h^2 theta^2 K
  MatrixXd WinvEt;           // W^{-1} E'  (N x k)
  MatrixXd delassus;         // E W^{-1} E' (k x k)
  bool ok = false;
  std::string message;
};

MoreauJeanFactors mj_factors(const mech::MechanicalModel& m, double h, double theta) {
  MoreauJeanFactors f;
  const MatrixXd W = m.M + h * theta * m.D + h * h * theta * theta * m.K;
  f.llt.compute(W);
  if (f.llt.info() != Eigen::Success) {
    f.message =
        "iteration matrix M + h theta D + h^2 theta^2 K is not positive definite at h = " + fmt(h) +
        " (D or K indefinite?)";
    return f;
  }
  f.WinvEt = f.llt.solve(m.E.transpose());
  f.delassus = m.E * f.WinvEt;
  f.ok = f.WinvEt.allFinite();
  if (!f.ok) f.message = "iteration matrix too ill-conditioned at h = " + fmt(h);
  return f;
}

Trajectory run_moreau_jean(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  Trajectory tr;
  tr.method = "moreau-jean";
  tr.t_end = opt.t_end;
  if (!model.is_mechanical()) {
    tr.status = RunStatus::kFailed;
    tr.message = "moreau-jean: needs a mechanical model ('" + model.name +
                 "' is a general LCS; use euler or event)";
    tr.final_state = x0;
    return tr;
  }
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs(), k = m.num_constraints();
  if (x0.size() != 2 * N) {
    tr.status = RunStatus::kFailed;
    tr.message = "moreau-jean: initial state has " + std::to_string(x0.size()) +
                 " entries, the model needs " + std::to_string(2 * N);
    tr.final_state = x0;
    return tr;
  }
  VectorXd q = x0.head(N), v = x0.tail(N);
  tr.energy_initial = mech::total_energy(m, q, v);
  auto finish = [&]() {
    tr.final_state.resize(2 * N);
    tr.final_state << q, v;
    tr.energy_final = mech::total_energy(m, q, v);
    tr.wall_time_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
    return tr;
  };
  auto fail = [&](const std::string& msg) {
    tr.status = RunStatus::kFailed;
    tr.message = msg;
    return finish();
  };
  if (const std::string err = check_options(opt, true); !err.empty())
    return fail("moreau-jean: " + err);
  std::unique_ptr<lcp::Solver> solver;
  try {
    solver = lcp::make_solver(opt.lcp_solver);
  } catch (const std::exception& e) {
    return fail(std::string("moreau-jean: ") + e.what());
  }
  const double theta = opt.theta;
  const Grid grid = make_grid(opt.t_end, opt.h);
  MoreauJeanFactors F = mj_factors(m, grid.h, theta), F_last;
  if (!F.ok) return fail("moreau-jean: " + F.message);
  if (grid.h_last != grid.h) {
    F_last = mj_factors(m, grid.h_last, theta);
    if (!F_last.ok) return fail("moreau-jean: last step: " + F_last.message);
  }
  const VectorXd e = m.restitution.size() == k ? m.restitution : VectorXd::Zero(k);

  Sampler sampler(opt.dt_out);
  sampler.start();
  auto record = [&](double t, const VectorXd& y, const VectorXd& uu, const IndexSet& mode) {
    if (!opt.record_samples) return;
    Sample s;
    s.t = t;
    s.x.resize(2 * N);
    s.x << q, v;
    s.u = uu;
    s.y = y;
    s.mode = mode;
    tr.samples.push_back(std::move(s));
  };
  VectorXd y = m.E * q + m.g;
  if (k > 0) tr.max_violation = std::min(0.0, y.minCoeff());
  VectorXd u = VectorXd::Zero(k);
  record(0.0, y, u, {});

  lcp::Options lopt;
  IndexSet J, mode;
  VectorXd rhs(N), v_free(N), Ev(k);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    const double h = last ? grid.h_last : grid.h;
    const MoreauJeanFactors& f = (last && grid.h_last != grid.h) ? F_last : F;
    rhs = m.f - m.D * v - m.K * (q + h * theta * v);
    v_free = v + h * f.llt.solve(rhs);
    // Activation: predicted gap E_i (q + h theta v) + g_i <= 0.
    J.clear();
    if (k > 0) {
      const VectorXd yp = y + h * theta * (m.E * v);
      for (int i = 0; i < k; ++i)
        if (yp(i) <= 0.0) J.push_back(i);
    }
    u.setZero();
    mode.clear();
    VectorXd v_next = v_free;
    if (!J.empty()) {
      const int nj = static_cast<int>(J.size());
      MatrixXd W(nj, nj);
      VectorXd b(nj);
      for (int a = 0; a < nj; ++a) {
        const double Ev_a = m.E.row(J[a]).dot(v);
        b(a) = m.E.row(J[a]).dot(v_free) + e(J[a]) * Ev_a;
        for (int c = 0; c < nj; ++c) W(a, c) = f.delassus(J[a], J[c]);
      }
      const lcp::Result r = solver->solve(W, b, lopt);
      ++tr.lcp_solves;
      if (!r.ok())
        return fail("moreau-jean: LCP failed at t = " + fmt((j - 1) * grid.h) + " (" +
                    std::string(lcp::to_string(r.status)) + ")" +
                    (r.message.empty() ? "" : ": " + r.message));
      for (int a = 0; a < nj; ++a) {
        if (r.z(a) > 0.0) {
          v_next += f.WinvEt.col(J[a]) * r.z(a);
          mode.push_back(J[a]);
        }
        u(J[a]) = r.z(a) / h;  // mean force over the step
      }
    }
    const VectorXd q_next = q + h * ((1.0 - theta) * v + theta * v_next);
    if (!q_next.allFinite() || !v_next.allFinite())
      return fail("moreau-jean: non-finite state at t = " + fmt(j * grid.h));
    q = q_next;
    v = v_next;
    ++tr.steps;
    y = m.E * q + m.g;
    if (k > 0) tr.max_violation = std::min(tr.max_violation, std::min(0.0, y.minCoeff()));
    const double t = last ? opt.t_end : grid.time(j);
    if (sampler.want(t, grid.h, last)) record(t, y, u, mode);
  }
  return finish();
}

class EulerIntegrator : public Integrator {
 public:
  std::string name() const override { return "euler"; }
  Trajectory run(const mech::Model& model, const VectorXd& x0, const Options& opt) const override {
    return run_euler(model, x0, opt);
  }
};

class MoreauJeanIntegrator : public Integrator {
 public:
  std::string name() const override { return "moreau-jean"; }
  Trajectory run(const mech::Model& model, const VectorXd& x0, const Options& opt) const override {
    return run_moreau_jean(model, x0, opt);
  }
};

}  // namespace

std::unique_ptr<Integrator> make_euler_integrator() { return std::make_unique<EulerIntegrator>(); }
std::unique_ptr<Integrator> make_moreau_jean_integrator() {
  return std::make_unique<MoreauJeanIntegrator>();
}

}  // namespace lcsim::sim
