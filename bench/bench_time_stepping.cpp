// Where a Moreau–Jean step's time goes on the small runs of issue 5 (thesis
// §3.7 two carts, robots/two_carts.yaml; the hook of Example 3.8.3 from
// (0,0,-1,2)), and the cost of each piece the step calls, timed alone.
//
// Per step: each iteration runs from x0 to the window's end and to its start
// (one step for windows starting at 0); the counter ns_per_step is the
// difference of the times over the difference of the steps, so set-up (model
// checks, factoring W) is excluded. Iterations are fixed so that
// one repetition takes about 0.3 s (3e-6 / h runs of 1 us per step); run with
// --benchmark_repetitions=N and read the median. The argument is -log10(h).
//   TwoCarts         T = 3 from the model's x0 (about half the steps in contact)
//   TwoCartsSamples  the same, recording a sample at every step (dt_out = 0)
//   TwoCartsFree     t in [0, 0.9]: no constraint active, no LCP
//   TwoCartsContact  t in [1.1, 2.5]: one active constraint, one 1 x 1 LCP
//                    per step
//   Hook             the hook run, x0 = (0,0,-1,2), T = 3
//   Euler            backward Euler on the two carts, T = 3 (for comparison)
// Pieces (ns per call): the pivoting LCP solver on a 1 x 1 and a 2 x 2 LCP,
// lcp::Solver::solve through the interface, and the set-up alone (one step).
//
// bench/run_work_precision.sh measures the same runs next to Siconos; this
// program is for finding where the time goes.
#include <benchmark/benchmark.h>

#include <chrono>
#include <cmath>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// robots/two_carts.yaml's initial state, e^{-A} (0,-1,-1,0) (§3.7).
VectorXd two_carts_x0() {
  VectorXd x(4);
  x << 0.32024033250148565, -0.43350467028455375, 0.37155103230826902, -1.0914506084129831;
  return x;
}

double run_seconds(const std::string& method, const lcsim::mech::Model& model, const VectorXd& x0,
                   double t_end, double h, bool samples, lcsim::sim::Trajectory* out = nullptr) {
  lcsim::sim::Options opt;
  opt.t_end = t_end;
  opt.h = h;
  opt.theta = 0.5;
  opt.record_samples = samples;
  opt.dt_out = 0.0;
  const auto integ = lcsim::sim::make_integrator(method);
  const auto t0 = std::chrono::steady_clock::now();
  lcsim::sim::Trajectory tr = integ->run(model, x0, opt);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (out) *out = std::move(tr);
  return s;
}

void per_step(benchmark::State& state, const std::string& method, bool hook, double t_from,
              double t_to, bool samples, int log_h) {
  const double h = std::pow(10.0, -static_cast<double>(log_h));
  const lcsim::mech::Model model = lcsim::mech::two_carts_model(hook);
  VectorXd x0 = hook ? VectorXd(VectorXd::Zero(4)) : two_carts_x0();
  if (hook) x0 << 0, 0, -1, 2;
  // Both runs start at x0 (a time-stepping state inside a contact phase
  // penetrates by O(h) and is refused as a start): the window's steps are
  // those of the run to t_to less those of the run to t_from (or one step).
  const double t_a = std::max(t_from, h);
  lcsim::sim::Trajectory ta, tb;
  double per_step_sum = 0.0;
  for (auto _ : state) {
    const double sa = run_seconds(method, model, x0, t_a, h, samples, &ta);
    const double sb = run_seconds(method, model, x0, t_to, h, samples, &tb);
    per_step_sum += std::max(0.0, sb - sa) / static_cast<double>(tb.steps - ta.steps);
  }
  state.counters["ns_per_step"] =
      benchmark::Counter(1e9 * per_step_sum, benchmark::Counter::kAvgIterations);
  state.counters["steps"] = static_cast<double>(tb.steps - ta.steps);
  state.counters["lcp_solves"] = static_cast<double>(tb.lcp_solves - ta.lcp_solves);
  state.SetLabel(tb.status == lcsim::sim::RunStatus::kCompleted ? "" : tb.message);
}

void register_per_step() {
  struct Case {
    const char* name;
    const char* method;
    bool hook;
    double t_from, t_to;
    bool samples;
    std::vector<int> log_h;
  };
  const std::vector<Case> cases = {
      {"TwoCarts", "moreau-jean", false, 0.0, 3.0, false, {2, 3, 4, 5}},
      {"TwoCartsSamples", "moreau-jean", false, 0.0, 3.0, true, {4}},
      {"TwoCartsFree", "moreau-jean", false, 0.0, 0.9, false, {4}},
      {"TwoCartsContact", "moreau-jean", false, 1.1, 2.5, false, {4}},
      {"Hook", "moreau-jean", true, 0.0, 3.0, false, {3, 5}},
      {"Euler", "euler", false, 0.0, 3.0, false, {4}},
  };
  for (const Case& c : cases)
    for (int lh : c.log_h) {
      const double h = std::pow(10.0, -lh);
      // about 0.3 s per repetition at ~1 us per step
      const long iters = std::max(1L, std::lround(3e5 * h / c.t_to));
      benchmark::RegisterBenchmark((std::string(c.name) + "/h=1e-" + std::to_string(lh)).c_str(),
                                   [c, lh](benchmark::State& s) {
                                     per_step(s, c.method, c.hook, c.t_from, c.t_to, c.samples, lh);
                                   })
          ->Iterations(iters)
          ->Unit(benchmark::kMillisecond);
    }
}

// The set-up of a Moreau–Jean run alone (a one-step run).
void BM_SetupOneStep(benchmark::State& state) {
  const lcsim::mech::Model model = lcsim::mech::two_carts_model(false);
  const VectorXd x0 = two_carts_x0();
  for (auto _ : state)
    benchmark::DoNotOptimize(run_seconds("moreau-jean", model, x0, 1e-3, 1e-3, false));
}
BENCHMARK(BM_SetupOneStep)->Unit(benchmark::kNanosecond);

// The step's LCP through the solver interface: G = E W^{-1} E' of the two
// carts at h = 1e-4 (1 x 1) and of the hook (2 x 2).
void lcp_solve(benchmark::State& state, const std::string& name, int k) {
  const auto solver = lcsim::lcp::make_solver(name);
  MatrixXd G(k, k);
  VectorXd b(k);
  if (k == 1) {
    G << 0.9999999975;
    b << -1.0;
  } else {
    G << 1.0, 1.0, 1.0, 2.0;
    b << -1.0, -3.0;
  }
  const lcsim::lcp::Options opt;
  for (auto _ : state) {
    lcsim::lcp::Result r = solver->solve(G, b, opt);
    benchmark::DoNotOptimize(r.z.data());
  }
}
void BM_LcpPivot1(benchmark::State& s) { lcp_solve(s, "pivot", 1); }
void BM_LcpPivot2(benchmark::State& s) { lcp_solve(s, "pivot", 2); }
void BM_LcpLemke1(benchmark::State& s) { lcp_solve(s, "lemke", 1); }
BENCHMARK(BM_LcpPivot1)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_LcpPivot2)->Unit(benchmark::kNanosecond);
BENCHMARK(BM_LcpLemke1)->Unit(benchmark::kNanosecond);

}  // namespace

int main(int argc, char** argv) {
  register_per_step();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
