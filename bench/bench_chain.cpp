// The cart chain of `lcsim generate chain N --stops` (unit masses and springs,
// stops q_i + 1 >= 0, x_i = 0.1 (i mod 3), v_i = -1) timed per Moreau–Jean
// step for N = 10 ... 10000 (h = 1e-3, theta = 0.5), and per event-driven event
// for N = 10 ... 1000. bench/run_chain_bench.sh runs it beside Siconos and
// Bullet.
//
// Per step: each iteration runs S steps and 1 step from the same state and
// reports (T_S - T_1) / (S - 1) as the iteration's (manual) time, so set-up
// (model conversion, factorisation of W) is not counted. Two windows:
//   Free: t in [0, 0.2], no constraint active (S = 200);
//   Impacts: t in [0.7, 1.5], every cart hits its stop in it (S = 800);
//     the state at t = 0.7 is computed once before timing.
// Set-up alone (one step) is reported as BM_MoreauJeanSetup.
// Event-driven: time of a run to t = 1.5 divided by the number of events; the
// method is dense and refuses state sizes above 1001 (N > 500).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <lcsim/bullet/bullet.hpp>
#include <lcsim/sim/sim.hpp>

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

lcsim::mech::Model chain(int n) { return lcsim::mech::chain_model({n, true, false, true}); }

VectorXd start(int n) { return chain(n).initial; }

lcsim::sim::Options options(long steps) {
  lcsim::sim::Options opt;
  opt.h = 1e-3;
  opt.theta = 0.5;
  opt.t_end = steps * opt.h;
  opt.record_samples = false;
  return opt;
}

bool g_bullet = false;  // per_step runs Bullet's rb6 scene instead of Moreau–Jean

double seconds(const lcsim::mech::Model& model, const VectorXd& x0, long steps,
               lcsim::sim::Trajectory* out = nullptr) {
  const auto mj = lcsim::sim::make_integrator("moreau-jean");
  const auto t0 = std::chrono::steady_clock::now();
  lcsim::sim::Trajectory tr = g_bullet ? lcsim::bullet::simulate_bullet(model, x0, options(steps))
                                       : mj->run(model, x0, options(steps));
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (out) *out = std::move(tr);
  return s;
}

void per_step(benchmark::State& state, double t_from, long steps) {
  const int n = static_cast<int>(state.range(0));
  const auto model = chain(n);
  VectorXd x0 = start(n);
  if (t_from > 0.0) {
    lcsim::sim::Trajectory pre;
    seconds(model, x0, std::lround(t_from / 1e-3), &pre);
    x0 = pre.final_state;
  }
  lcsim::sim::Trajectory tr;
  for (auto _ : state) {
    // Set-up varies by more than 200 Bullet steps at N = 10 take (one
    // sample gave a negative difference): the fastest of three one-step runs.
    double t1 = seconds(model, x0, 1);
    for (int r = 0; r < 2; ++r) t1 = std::min(t1, seconds(model, x0, 1));
    const double ts = seconds(model, x0, steps, &tr);
    state.SetIterationTime(std::max(0.0, ts - t1) / static_cast<double>(steps - 1));
  }
  state.counters["N"] = n;
  state.counters["lcp_solves"] = static_cast<double>(tr.lcp_solves);
  state.counters["max_violation"] = tr.max_violation;
  state.SetLabel(tr.status == lcsim::sim::RunStatus::kCompleted ? "per step" : tr.message);
}

void BM_MoreauJeanStepFree(benchmark::State& state) { per_step(state, 0.0, 200); }
void BM_MoreauJeanStepImpacts(benchmark::State& state) { per_step(state, 0.7, 800); }

// Bullet, rb6 scene of src/bullet/world.cpp (one btRigidBody per cart, a 6DOF2
// limit per stop, springs as forces f - K q - D v applied before every step,
// with the model's sparse K: O(N) per step on lcsim's side).
void BM_BulletStepFree(benchmark::State& state) {
  g_bullet = true;
  per_step(state, 0.0, 200);
  g_bullet = false;
}
void BM_BulletStepImpacts(benchmark::State& state) {
  g_bullet = true;
  per_step(state, 0.7, 800);
  g_bullet = false;
}

void BM_MoreauJeanSetup(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto model = chain(n);
  const VectorXd x0 = start(n);
  for (auto _ : state) state.SetIterationTime(seconds(model, x0, 1));
  state.counters["N"] = n;
}

void BM_EventDrivenPerEvent(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto model = chain(n);
  const VectorXd x0 = start(n);
  lcsim::sim::Options opt;
  opt.t_end = 1.5;
  opt.record_samples = false;
  lcsim::sim::Trajectory tr;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    tr = lcsim::sim::simulate_event_driven(model, x0, opt);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    state.SetIterationTime(s / std::max<double>(1.0, static_cast<double>(tr.events.size())));
  }
  state.counters["N"] = n;
  state.counters["events"] = static_cast<double>(tr.events.size());
  state.SetLabel(tr.status == lcsim::sim::RunStatus::kCompleted ? "per event"
                                                                : "refused: " + tr.message);
}

}  // namespace

// The chain sizes of issue #9, timed by hand (manual time).
void chain_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {10, 100, 1000, 10000}) b->Arg(n);
  b->UseManualTime()->Unit(benchmark::kMicrosecond);
}
// The exact method: dense in the state, refused beyond N = 500.
void event_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {10, 100, 300, 500, 1000}) b->Arg(n);
  b->UseManualTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_MoreauJeanStepFree)->Apply(chain_sizes)->Iterations(3);
BENCHMARK(BM_MoreauJeanStepImpacts)->Apply(chain_sizes)->Iterations(3);
BENCHMARK(BM_BulletStepFree)->Apply(chain_sizes)->Iterations(1);
BENCHMARK(BM_BulletStepImpacts)->Apply(chain_sizes)->Iterations(1);
BENCHMARK(BM_MoreauJeanSetup)->Apply(chain_sizes)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_EventDrivenPerEvent)->Apply(event_sizes)->Iterations(1);

BENCHMARK_MAIN();
