// Moreau–Jean with 3-D friction (polyhedral cone, d = 4) against the
// frictionless step, side by side in one process (issue 27's target: at most
// 3x at N = 10^4 carts).
//
// The planar chain of docs/friction.md extended to three dimensions: cart i
// has coordinates (x_i, y_i, z_i) (interleaved, unit masses), springs of
// stiffness 1 between neighbours in x and in y, a floor z_i >= 0 per cart,
// gravity 9.81 m/s^2 in -z, and per cart the 3-D frictional contact
// {floor_i, tangents e_{x_i}, e_{y_i}, mu = 0.3, d = 4} (10 LCP unknowns per
// cart: lambda_N, 8 edge impulses, the slack). Start: resting on the floor,
// x_i = 0.1 (i mod 3), y_i = 0.05 (i mod 2) (springs stretched), and the
// velocity (1, 0.5) m/s in the plane (second argument 1: every cart slides
// through the window, along a heading between two edges) or 0 (argument 0:
// every cart sticks, the springs' forces inside the cone). Both models have
// the same floor contacts, so the same active sets; only `friction`
// differs. Above 600 unknowns (N > 60 carts) the step is solved by block
// Gauss–Seidel over the contacts (src/sim/stepping/cone_gs.cpp).
//
// Per step, as bench_mj_friction.cpp: each iteration runs S = 200 steps and
// 1 step from the same state, both models in turn, and reports (T_S - T_1) /
// (S - 1) (set-up not counted). h = 1e-3, theta = 0.5. The manual time is
// the friction step; counters: the frictionless step (`plain_us`), the
// ratio, LCP solves per step of each, the LCP sizes of a step with every
// cart on the floor (|A| = n frictionless, 10 n with friction).
// Times: process CPU time (cpu_seconds), the fastest of the iterations.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <ctime>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81, kMu = 0.3, kH = 1e-3;
constexpr int kD = 4;
constexpr long kSteps = 200;

lcsim::mech::Model chain3d(int n, bool friction, double v) {
  using T = Eigen::Triplet<double>;
  lcsim::mech::MechanicalModel m;
  const int N = 3 * n;
  m.M.resize(N, N);
  m.M.setIdentity();
  std::vector<T> k, e;
  for (int i = 0; i + 1 < n; ++i)  // summed by setFromTriplets
    for (int c = 0; c < 2; ++c) {
      const int a = 3 * i + c, b = 3 * i + 3 + c;
      k.emplace_back(a, a, 1.0);
      k.emplace_back(b, b, 1.0);
      k.emplace_back(a, b, -1.0);
      k.emplace_back(b, a, -1.0);
    }
  m.K.resize(N, N);
  m.K.setFromTriplets(k.begin(), k.end());
  for (int i = 0; i < n; ++i) {
    e.emplace_back(i, 3 * i + 2, 1.0);
    m.constraints.push_back("floor" + std::to_string(i));
  }
  m.E.resize(n, N);
  m.E.setFromTriplets(e.begin(), e.end());
  m.g = VectorXd::Zero(n);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < n; ++i) m.f(3 * i + 2) = -kG;
  lcsim::mech::fill_defaults(m);
  if (friction)
    for (int i = 0; i < n; ++i) {
      lcsim::mech::FrictionalContact c(i, VectorXd::Unit(N, 3 * i), kMu);
      c.tangent2 = VectorXd::Unit(N, 3 * i + 1).sparseView();
      c.edges = kD;
      m.friction.push_back(c);
    }
  lcsim::mech::Model model = lcsim::mech::model_of(m, "chain3d_" + std::to_string(n));
  model.initial = VectorXd::Zero(2 * N);
  for (int i = 0; i < n; ++i) {
    model.initial(3 * i) = 0.1 * (i % 3);
    model.initial(3 * i + 1) = 0.05 * (i % 2);
    model.initial(N + 3 * i) = v;
    model.initial(N + 3 * i + 1) = 0.5 * v;
  }
  return model;
}

// The process's CPU time (s), not the wall clock: on the shared machine
// (load 7-9) a wall-clock difference T_S - T_1 carried the other processes'
// time slices, seconds of it against the S steps' one or two (a row measured 0
// or 3x its rerun); the CPU time keeps only the cache's share of the load.
double cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

struct Timed {
  double seconds = 0.0;
  lcsim::sim::Trajectory tr;
};
Timed run(const lcsim::mech::Model& model, long steps) {
  lcsim::sim::Options opt;
  opt.h = kH;
  opt.theta = 0.5;
  opt.t_end = steps * kH;
  opt.record_samples = false;
  const auto mj = lcsim::sim::make_integrator("moreau-jean");
  Timed t;
  const double t0 = cpu_seconds();
  t.tr = mj->run(model, model.initial, opt);
  t.seconds = cpu_seconds() - t0;
  return t;
}

// Seconds per step (set-up removed) and the S-step run; t1 gets the
// fastest 1-step run (s): the run's set-up (input check, divergence guard,
// factorisation) and one step.
double per_step(const lcsim::mech::Model& model, Timed& full, double& t1) {
  t1 = run(model, 1).seconds;
  for (int r = 0; r < 2; ++r) t1 = std::min(t1, run(model, 1).seconds);
  full = run(model, kSteps);
  return std::max(0.0, full.seconds - t1) / static_cast<double>(kSteps - 1);
}

void BM_MoreauJeanFriction3dVsPlain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double v = static_cast<double>(state.range(1));
  const auto plain = chain3d(n, false, v), fric = chain3d(n, true, v);
  Timed p, f;
  // The fastest of the iterations for each: the machine is shared, and the
  // slower samples are other processes' time.
  double plain_s = 1e300, fric_s = 1e300, plain_t1 = 1e300, fric_t1 = 1e300, t1 = 0.0;
  for (auto _ : state) {
    plain_s = std::min(plain_s, per_step(plain, p, t1));
    plain_t1 = std::min(plain_t1, t1);
    const double fs = per_step(fric, f, t1);
    fric_t1 = std::min(fric_t1, t1);
    fric_s = std::min(fric_s, fs);
    state.SetIterationTime(fs);
  }
  const bool ok = p.tr.status == lcsim::sim::RunStatus::kCompleted &&
                  f.tr.status == lcsim::sim::RunStatus::kCompleted;
  state.counters["N_carts"] = n;
  state.counters["plain_us"] = plain_s * 1e6;
  state.counters["friction_us"] = fric_s * 1e6;
  state.counters["ratio"] = plain_s > 0.0 ? fric_s / plain_s : 0.0;
  // The 1-step runs (set-up and one step, ms): issue 27 measured ~3 s at
  // N = 10^4 from two O(N^2) loops of the input check and the divergence
  // guard, now O(nnz).
  state.counters["plain_1step_ms"] = plain_t1 * 1e3;
  state.counters["friction_1step_ms"] = fric_t1 * 1e3;
  state.counters["plain_solves_per_step"] = static_cast<double>(p.tr.lcp_solves) / kSteps;
  state.counters["friction_solves_per_step"] = static_cast<double>(f.tr.lcp_solves) / kSteps;
  state.counters["plain_lcp_size"] = n;                      // every cart on the floor
  state.counters["friction_lcp_size"] = (2.0 * kD + 2) * n;  // lambda_N, 2d edges, slack
  state.counters["warnings"] = static_cast<double>(f.tr.warnings.size());
  state.SetLabel(ok ? (v > 0 ? "3-D friction step, sliding" : "3-D friction step, sticking")
                    : p.tr.message + " | " + f.tr.message);
}

}  // namespace

BENCHMARK(BM_MoreauJeanFriction3dVsPlain)
    ->Args({100, 1})
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({100, 0})
    ->Args({1000, 0})
    ->Args({10000, 0})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(5);

BENCHMARK_MAIN();
