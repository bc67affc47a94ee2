// The thesis §3.7 run (two carts and a stop, x0 = e^{-A}(0,-1,-1,0), T = 3)
// simulated by lcsim's exact event-driven integrator: CPU time of the
// simulation itself and the final-state error against the exact solution
// (counter "error_final"). bench/run_event_bench.sh runs it beside Siconos's
// event-driven simulation of the same run (bench/peer_siconos_two_carts).
#include <benchmark/benchmark.h>

#include <lcsim/sim/sim.hpp>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

namespace {

using Eigen::MatrixXd;
using Eigen::Vector4d;
using Eigen::VectorXd;

lcsim::mech::Model two_carts() { return lcsim::mech::two_carts_model(false); }

MatrixXd free_A() {
  MatrixXd A(4, 4);
  A << 0, 0, 1, 0, 0, 0, 0, 1, -2, 1, 0, 0, 1, -1, 0, 0;
  return A;
}

void BM_EventDrivenTwoCarts(benchmark::State& state) {
  const auto model = two_carts();
  const MatrixXd A = free_A();
  const VectorXd x0 = (-A).exp() * Vector4d(0, -1, -1, 0);
  const VectorXd exact = (A * (2.0 - std::numbers::pi / 2)).exp() * Vector4d(0, 0, 0, 1);
  lcsim::sim::Options opt;
  opt.t_end = 3.0;
  opt.record_samples = state.range(0) != 0;
  double err = 0.0;
  long events = 0;
  for (auto _ : state) {
    auto tr = lcsim::sim::simulate_event_driven(model, x0, opt);
    benchmark::DoNotOptimize(tr.final_state.data());
    err = (tr.final_state - exact).cwiseAbs().maxCoeff();
    events = static_cast<long>(tr.events.size());
  }
  state.counters["error_final"] = err;
  state.counters["events"] = static_cast<double>(events);
}
BENCHMARK(BM_EventDrivenTwoCarts)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
