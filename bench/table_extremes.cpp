#include <Eigen/Dense>
#include <cmath>
#include <cstdio>

#include "sim/sim.hpp"
using namespace lcsim;
// Prints the measured errors of the exact event-driven method at the
// extremes (docs/extremes.md). The same cases are asserted, with margins, in
// tests/extremes. Run: build/bench/table_extremes
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
}
