#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/sim/sim.hpp>
#include <stdexcept>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
using namespace lcsim;
// Prints the measured errors of the exact event-driven method and of the
// time-stepping methods and Bullet at the extremes (docs/extremes.md). The
// same cases are asserted, with margins, in tests/extremes. Run:
// build/bench/table_extremes
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

mech::Model wrap(mech::MechanicalModel m) { return mech::model_of(std::move(m), "extreme"); }

mech::Model spring_stop(double k, double s, double e = 0.0) {
  return mech::spring_stop_model(k, s, e);
}

mech::Model ball(double e) { return mech::ball_model(e); }

// The time-stepping methods of the table: Moreau–Jean at theta 1/2 and 1,
// backward Euler, Bullet.
const char* const kMethods[] = {"mj0.5", "mj1", "euler", "bullet"};

sim::Trajectory step_run(const std::string& method, const mech::Model& model, const VectorXd& x0,
                         double T, double h, bool samples = false) {
  sim::Options o;
  o.t_end = T;
  o.h = h;
  o.record_samples = samples;
  if (method == "bullet") {
    try {
      return bullet::simulate_bullet(model, x0, o);
    } catch (const std::invalid_argument& e) {  // a model Bullet cannot express
      sim::Trajectory tr;
      tr.status = sim::RunStatus::kNumericalFailure;
      tr.message = e.what();
      tr.final_state = x0;
      return tr;
    }
  }
  o.theta = method == "mj1" ? 1.0 : 0.5;
  return sim::make_integrator(method == "euler" ? "euler" : "moreau-jean")->run(model, x0, o);
}

// "failed: <message>" or "", and the warnings, for a row.
std::string diag(const sim::Trajectory& tr) {
  std::string s;
  if (tr.status != sim::RunStatus::kCompleted) s += " FAILED: " + tr.message;
  for (const auto& w : tr.warnings)
    s += " [warn x" + std::to_string(w.count) + ": " + w.message + "]";
  return s;
}

double maxabs(const VectorXd& x) { return x.size() ? x.cwiseAbs().maxCoeff() : 0.0; }

// Highest point after the first impact (e^2 of the drop height, exactly).
double rebound_height(const sim::Trajectory& tr, double t1) {
  double top = 0.0;
  for (const auto& s : tr.samples)
    if (s.t > t1 + 1e-2 && s.t < t1 * (1 + 2 * 0.99)) top = std::max(top, s.x(0));
  return top;
}

void time_stepping_table() {
  printf("\n== time-stepping methods and Bullet ==\n");
  // Stiff springs, resolved: h = period / 1000.
  for (double k : {1e-6, 1e-2, 1.0, 1e3, 1e6, 1e9}) {
    const double w = sqrt(k), P = 2 * M_PI / w, t1 = P / 3, T = t1 + 2.3 * P;
    const auto model = spring_stop(k, 0.5);
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, model, Eigen::Vector2d(1, 0), T, P / 1000);
      const double tau = w * (T - t1);
      printf("spring k=%g h=P/1000 %s: q_err=%.1e v_relerr=%.1e viol=%.1e%s\n", k, meth,
             std::abs(tr.final_state(0) + 0.5 * cos(tau)),
             std::abs(tr.final_state(1) / w - 0.5 * sin(tau)), tr.max_violation, diag(tr).c_str());
    }
  }
  // Stiff spring, unresolved: k = 1e9, h = 1e-3 (omega h = 32), 1000 steps.
  for (const char* meth : kMethods) {
    const auto model = spring_stop(1e9, 0.5);
    const auto tr = step_run(meth, model, Eigen::Vector2d(1, 0), 1.0, 1e-3);
    printf("spring k=1e9 h=1e-3 %s: |q|_T=%.2e E_T/E_0=%.2e viol=%.1e%s\n", meth,
           std::abs(tr.final_state(0)), tr.energy_final / tr.energy_initial, tr.max_violation,
           diag(tr).c_str());
  }
  // Stiffness ratio 1e12: k = 1e-3 (stop at -10) and 1e9 (stop at -1/2).
  {
    mech::MechanicalModel m;
    m.M = MatrixXd::Identity(2, 2).sparseView();
    m.K = Eigen::Vector2d(1e-3, 1e9).asDiagonal().toDenseMatrix().sparseView();
    m.E = MatrixXd::Identity(2, 2).sparseView();
    m.g = Eigen::Vector2d(10.0, 0.5);
    const auto model = wrap(m);
    const double ws = sqrt(1e-3), wf = sqrt(1e9), t1 = 2 * M_PI / (3 * wf);
    for (auto [h, T] : {std::pair{1e-7, 1e-3}, std::pair{1e-2, 10.0}})
      for (const char* meth : kMethods) {
        const auto tr = step_run(meth, model, Eigen::Vector4d(1, 1, 0, 0), T, h);
        printf("ratio 1e12 h=%g T=%g %s: slow_err=%.1e fast_err=%.1e |fast|=%.1e viol=%.1e%s\n", h,
               T, meth, std::abs(tr.final_state(0) - cos(ws * T)),
               std::abs(tr.final_state(1) + 0.5 * cos(wf * (T - t1))), std::abs(tr.final_state(1)),
               tr.max_violation, diag(tr).c_str());
      }
  }
  // Mass ratio 1e8 through a hook: common velocity after the plastic impact.
  for (auto [m1, m2] : {std::pair{1e-4, 1e4}, std::pair{1e4, 1e-4}}) {
    mech::MechanicalModel m;
    m.M = Eigen::Vector2d(m1, m2).asDiagonal().toDenseMatrix().sparseView();
    m.E = Eigen::RowVector2d(1, -1).sparseView();
    const auto model = wrap(m);
    const double vc = (-m1 + 2 * m2) / (m1 + m2);
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, model, Eigen::Vector4d(0, 0, -1, 2), 1.0, 1e-3);
      const VectorXd ex = Eigen::Vector4d(vc, vc, vc, vc);
      printf("mass ratio m1=%g m2=%g %s: state_err=%.1e viol=%.1e%s\n", m1, m2, meth,
             maxabs(tr.final_state - ex), tr.max_violation, diag(tr).c_str());
    }
  }
  // Step sizes 1e-8 .. 1 on the k = 1 spring with a stop at -1/2; below
  // h = 1e-3 the run starts 5000 steps before the impact and lasts 10^4 steps.
  for (double h : {1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8}) {
    const auto model = spring_stop(1.0, 0.5);
    const double t1 = 2 * M_PI / 3;
    const double t0 = h >= 1e-3 ? 0.0 : t1 - 5000 * h, T = h >= 1e-3 ? 10.0 : 1e4 * h;
    auto exact = [&](double t) -> Eigen::Vector2d {
      if (t < t1) return {cos(t), -sin(t)};
      return {-0.5 * cos(t - t1), 0.5 * sin(t - t1)};
    };
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, model, exact(t0), T, h);
      printf("step h=%g %s: err=%.1e viol=%.1e E_T-E_exact=%.1e%s\n", h, meth,
             maxabs(tr.final_state - exact(t0 + T)), tr.max_violation,
             tr.energy_final - (t0 + T < t1 ? 0.5 : 0.125), diag(tr).c_str());
    }
  }
  // 10^6 steps: elastic stop (e = 1), k = 1, h = 1e-3, T = 1000.
  for (const char* meth : kMethods) {
    const auto model = spring_stop(1.0, 0.5, 1.0);
    const auto tr = step_run(meth, model, Eigen::Vector2d(1, 0), 1000.0, 1e-3);
    printf("1e6 steps e=1 %s: E_T/E_0-1=%.1e viol=%.1e steps=%ld wall=%.2fs%s\n", meth,
           tr.energy_final / tr.energy_initial - 1, tr.max_violation, tr.steps, tr.wall_time_s,
           diag(tr).c_str());
  }
  // Grazing at the start: resting ball (u = g), spring released from its stop.
  for (const char* meth : kMethods) {
    const auto tr = step_run(meth, ball(0.0), Eigen::Vector2d(0, 0), 1.0, 1e-3, true);
    const auto tr2 = step_run(meth, spring_stop(1.0, 1.0), Eigen::Vector2d(-1, 0), 1.0, 1e-3);
    printf("graze start %s: ball |x_T|=%.1e u_err=%.1e; released spring err=%.1e%s%s\n", meth,
           maxabs(tr.final_state), std::abs(tr.samples.back().u(0) - 9.81),
           maxabs(tr2.final_state - Eigen::Vector2d(-cos(1.0), sin(1.0))), diag(tr).c_str(),
           diag(tr2).c_str());
  }
  // Simultaneous impacts: N carts hit N stops at t = 1.
  for (int N : {10, 100, 1000}) {
    const mech::Model model = wrap(*mech::chain_model({N, true, false, false}).mechanical);
    VectorXd x0(2 * N), rest(2 * N);
    x0 << VectorXd::Zero(N), -VectorXd::Ones(N);
    rest << -VectorXd::Ones(N), VectorXd::Zero(N);
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, model, x0, 2.0, 1e-3);
      printf("chain N=%d h=1e-3 %s: err=%.1e viol=%.1e lcp=%ld wall=%.3gs%s\n", N, meth,
             maxabs(tr.final_state - rest), tr.max_violation, tr.lcp_solves, tr.wall_time_s,
             diag(tr).c_str());
    }
  }
  // Accumulating impacts: rebound height e^2, rest after t* = t1 (1+e)/(1-e).
  for (double e : {0.5, 0.9}) {
    const double t1 = sqrt(2 / 9.81), ts = t1 * (1 + e) / (1 - e);
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, ball(e), Eigen::Vector2d(1, 0), ts + 1, 1e-3, true);
      printf("ball e=%g h=1e-3 %s: rebound_err=%.1e final=%.1e viol=%.1e%s\n", e, meth,
             std::abs(rebound_height(tr, t1) - e * e), maxabs(tr.final_state), tr.max_violation,
             diag(tr).c_str());
    }
  }
  // Dependent constraints: the §3.7 stop twice (c = 1) or as x1 >= 0, 2 x1 >= 0.
  {
    MatrixXd A(4, 4);
    A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
    const VectorXd xT = (A * (2.0 - M_PI / 2)).exp() * Eigen::Vector4d(0, 0, 0, 1);
    for (double c : {0.0, 1.0, 2.0}) {
      const auto model = mech::two_carts_model(c == 0 ? MatrixXd(Eigen::RowVector2d(1, 0))
                                                      : MatrixXd{{1, 0}, {c, 0}});
      for (const char* meth : kMethods) {
        const auto tr = step_run(meth, model, Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
        printf("dependent c=%g %s: err=%.1e final=(%.17g %.17g %.17g %.17g)%s\n", c, meth,
               maxabs(tr.final_state - xT), tr.final_state(0), tr.final_state(1), tr.final_state(2),
               tr.final_state(3), diag(tr).c_str());
      }
    }
  }
  // Nearly dependent constraints: x1 >= 0 and x1 + d (x2 + 1) >= 0, closed
  // at the §3.7 impact; the exact solution is the single-stop motion.
  {
    MatrixXd A(4, 4);
    A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
    const VectorXd xT = (A * (2.0 - M_PI / 2)).exp() * Eigen::Vector4d(0, 0, 0, 1);
    for (double d : {1e-2, 1e-4, 1e-6, 3e-8, 1e-8, 3e-9, 1e-11, 1e-14}) {
      const auto model =
          mech::two_carts_model(Eigen::Matrix2d{{1, 0}, {1, d}}, Eigen::Vector2d(0, d));
      sim::Options o;
      o.t_end = 2.0;
      const auto ev = sim::simulate_event_driven(model, Eigen::Vector4d(0, -1, -1, 0), o);
      printf("nearly dependent d=%g event: err=%.1e release_t_err=%.1e viol=%.1e lcp=%ld%s\n", d,
             maxabs(ev.final_state - xT),
             ev.events.empty() ? NAN : std::abs(ev.events.back().t - M_PI / 2), ev.max_violation,
             ev.lcp_solves, diag(ev).c_str());
      for (const char* meth : kMethods) {
        const auto tr = step_run(meth, model, Eigen::Vector4d(0, -1, -1, 0), 2.0, 1e-3);
        printf("nearly dependent d=%g %s: err=%.1e viol=%.1e lcp=%ld%s\n", d, meth,
               maxabs(tr.final_state - xT), tr.max_violation, tr.lcp_solves, diag(tr).c_str());
      }
    }
  }
  // Nearly singular M (cond 2e8): velocity after the impact vs Moreau's rule.
  {
    const double d = 1e-8;
    mech::MechanicalModel m;
    m.M = Eigen::Matrix2d{{1, 1 - d}, {1 - d, 1}}.sparseView();
    m.E = Eigen::RowVector2d(1, 0).sparseView();
    m.g = VectorXd::Constant(1, 1.0);
    const auto model = wrap(m);
    const MatrixXd Mi = m.M.toDense().inverse(), E = m.E.toDense();
    const Eigen::Vector2d v(-1, 0.5);
    const VectorXd vp = v - Mi * E.transpose() * (E * Mi * E.transpose()).inverse() * (E * v);
    for (const char* meth : kMethods) {
      const auto tr = step_run(meth, model, Eigen::Vector4d(0, 0, v(0), v(1)), 2.0, 1e-3);
      printf("nearly singular M %s: v_err=%.1e%s\n", meth,
             tr.final_state.size() == 4 ? maxabs(tr.final_state.tail(2) - vp) : NAN,
             diag(tr).c_str());
    }
  }
  // Infeasible start: ball 0.1 below the ground, at rest.
  for (const char* meth : kMethods) {
    const auto tr = step_run(meth, ball(0.0), Eigen::Vector2d(-0.1, 0), 1.0, 1e-3);
    printf("infeasible start %s: status=%s q_T=%.3g viol=%.3g%s\n", meth,
           tr.status == sim::RunStatus::kCompleted ? "completed" : "failed", tr.final_state(0),
           tr.max_violation, diag(tr).c_str());
  }
}

}  // namespace

int main() {
  for (double k : {1e-6, 1e-2, 1.0, 1e3, 1e6, 1e9}) {
    double a = 1, w = sqrt(k);
    mech::MechanicalModel m;
    m.M = Eigen::MatrixXd::Identity(1, 1).sparseView();
    m.K = Eigen::MatrixXd::Constant(1, 1, k).sparseView();
    m.E = Eigen::MatrixXd::Identity(1, 1).sparseView();
    m.g = Eigen::VectorXd::Constant(1, a / 2);
    mech::fill_defaults(m);
    mech::Model model;
    model.mechanical = m;
    sim::Options o;
    double t1 = 2 * M_PI / (3 * w);
    double T = t1 + 2.3 * 2 * M_PI / w;
    o.t_end = T;
    auto tr = sim::simulate_event_driven(model, Eigen::Vector2d(a, 0), o);
    double tau = w * (T - t1);
    double et = std::abs(tr.events[0].t / t1 - 1),
           eq = std::abs(tr.final_state(0) + 0.5 * cos(tau)),
           ev = std::abs(tr.final_state(1) / (a * w) - 0.5 * sin(tau));
    printf("k=%g events=%zu t1_relerr=%.1e q_err=%.1e v_relerr=%.1e viol=%.1e lcp=%ld wall=%.2gs\n",
           k, tr.events.size(), et, eq, ev, tr.max_violation, tr.lcp_solves, tr.wall_time_s);
  }
  for (int N : {10, 100}) {
    const mech::MechanicalModel m = *mech::chain_model({N, true, false, false}).mechanical;
    mech::Model model;
    model.mechanical = m;
    sim::Options o;
    o.t_end = 2;
    Eigen::VectorXd x0(2 * N);
    x0 << Eigen::VectorXd::Zero(N), -Eigen::VectorXd::Ones(N);
    auto tr = sim::simulate_event_driven(model, x0, o);
    Eigen::VectorXd rest(2 * N);
    rest << -Eigen::VectorXd::Ones(N), Eigen::VectorXd::Zero(N);
    printf("chain N=%d events=%zu t_err=%.1e final_err=%.1e wall=%.3gs\n", N, tr.events.size(),
           std::abs(tr.events[0].t - 1), (tr.final_state - rest).cwiseAbs().maxCoeff(),
           tr.wall_time_s);
  }
  for (double e : {0.5, 0.9}) {
    double g = 9.81, t1 = sqrt(2 / g);
    mech::MechanicalModel b;
    b.M = Eigen::MatrixXd::Identity(1, 1).sparseView();
    b.E = Eigen::MatrixXd::Identity(1, 1).sparseView();
    b.f = Eigen::VectorXd::Constant(1, -g);
    b.restitution = Eigen::VectorXd::Constant(1, e);
    mech::fill_defaults(b);
    mech::Model model;
    model.mechanical = b;
    sim::Options o;
    o.t_end = 12;
    auto tr = sim::simulate_event_driven(model, Eigen::Vector2d(1, 0), o);
    printf("ball e=%g impacts=%zu t*_err=%.1e final=%.1e\n", e, tr.events.size(),
           std::abs(tr.events.back().t - t1 * (1 + e) / (1 - e)),
           tr.final_state.cwiseAbs().maxCoeff());
  }
  time_stepping_table();
}
