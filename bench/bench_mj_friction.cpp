// Moreau–Jean with friction against the frictionless step, side by side in
// one process (issue 17's target: at most 3x at N = 10^4).
//
// The planar cart chain: cart i has coordinates (x_i, y_i) (interleaved,
// unit masses), springs of stiffness 1 between neighbours in x (the 1-D
// chain of `lcsim generate chain`, without its wall spring), a floor y_i >= 0
// per cart, gravity 9.81 m/s^2 in -y, and per cart the frictional contact
// {floor_i, tangent e_{x_i}, mu = 0.3}. Start: resting on the floor
// (y = v_y = 0), x_i = 0.1 (i mod 3) (springs stretched), v_x = 1 m/s: the
// carts slide, the springs and friction bring some to a stick. Both models
// have the same floor contacts, so the same active sets (every cart on the
// floor); only `friction` differs.
//
// Per step, as bench_chain.cpp: each iteration runs S = 200 steps and 1 step
// from the same state, both models in turn, and reports (T_S - T_1) / (S - 1)
// (set-up, the factorisation of W, not counted). h = 1e-3, theta = 0.5.
// The manual time is the friction step; counters: the frictionless step
// (`plain_s`), the ratio, LCP solves per step of each, the LCP sizes of a
// step when every cart is on the floor (|A| = n unknowns frictionless,
// |A| + 2 |F| = 3 n with friction) and the peak resident memory of a run of
// each (KiB; peak_of below): `peak_*` the process's peak during the run,
// `run_*` the part the run added to what was resident before it (both
// models are held throughout: mech::FrictionalContact's tangent is a dense
// row of length 2 n, so the friction model alone holds n * 2n doubles).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <fstream>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81, kMu = 0.3, kH = 1e-3;
constexpr long kSteps = 200;

lcsim::mech::Model planar_chain(int n, bool friction) {
  using T = Eigen::Triplet<double>;
  lcsim::mech::MechanicalModel m;
  const int N = 2 * n;
  m.M.resize(N, N);
  m.M.setIdentity();
  std::vector<T> k, e;
  for (int i = 0; i + 1 < n; ++i) {  // summed by setFromTriplets
    k.emplace_back(2 * i, 2 * i, 1.0);
    k.emplace_back(2 * i + 2, 2 * i + 2, 1.0);
    k.emplace_back(2 * i, 2 * i + 2, -1.0);
    k.emplace_back(2 * i + 2, 2 * i, -1.0);
  }
  m.K.resize(N, N);
  m.K.setFromTriplets(k.begin(), k.end());
  for (int i = 0; i < n; ++i) {
    e.emplace_back(i, 2 * i + 1, 1.0);
    m.constraints.push_back("floor" + std::to_string(i));
  }
  m.E.resize(n, N);
  m.E.setFromTriplets(e.begin(), e.end());
  m.g = VectorXd::Zero(n);
  m.f = VectorXd::Zero(N);
  for (int i = 0; i < n; ++i) m.f(2 * i + 1) = -kG;
  lcsim::mech::fill_defaults(m);
  if (friction)
    for (int i = 0; i < n; ++i) m.friction.push_back({i, VectorXd::Unit(N, 2 * i), kMu});
  lcsim::mech::Model model = lcsim::mech::model_of(m, "planar_chain" + std::to_string(n));
  model.initial = VectorXd::Zero(2 * N);
  for (int i = 0; i < n; ++i) {
    model.initial(2 * i) = 0.1 * (i % 3);
    model.initial(N + 2 * i) = 1.0;
  }
  return model;
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
  const auto t0 = std::chrono::steady_clock::now();
  t.tr = mj->run(model, model.initial, opt);
  t.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return t;
}

// Seconds per step (set-up removed) and the S-step run.
double per_step(const lcsim::mech::Model& model, Timed& full) {
  double t1 = run(model, 1).seconds;
  for (int r = 0; r < 2; ++r) t1 = std::min(t1, run(model, 1).seconds);
  full = run(model, kSteps);
  return std::max(0.0, full.seconds - t1) / static_cast<double>(kSteps - 1);
}

// A line "<key>: <n> kB" of /proc/self/status, in KiB (0 if absent).
double status_kib(const std::string& key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind(key + ":", 0) == 0) return std::stod(line.substr(key.size() + 1));
  return 0.0;
}

// The peak resident memory of a call (KiB): VmHWM after resetting it to the
// current RSS (writing 5 to /proc/self/clear_refs, Linux >= 4.0), and the
// part of it above the RSS before the call (what the run itself allocated).
struct Peak {
  double peak = 0.0, added = 0.0;
};
template <class F>
Peak peak_of(F&& f) {
  const double before = status_kib("VmRSS");
  std::ofstream("/proc/self/clear_refs") << "5";
  f();
  const double hwm = status_kib("VmHWM");
  return {hwm, hwm - before};
}

void BM_MoreauJeanFrictionVsPlain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto plain = planar_chain(n, false), fric = planar_chain(n, true);
  Timed p, f;
  double plain_s = 0.0, fric_s = 0.0;
  Peak mem_plain, mem_fric;
  for (auto _ : state) {
    plain_s = per_step(plain, p);
    fric_s = per_step(fric, f);
    state.SetIterationTime(fric_s);
  }
  mem_plain = peak_of([&] { run(plain, kSteps); });
  mem_fric = peak_of([&] { run(fric, kSteps); });
  const bool ok = p.tr.status == lcsim::sim::RunStatus::kCompleted &&
                  f.tr.status == lcsim::sim::RunStatus::kCompleted;
  state.counters["N_carts"] = n;
  state.counters["plain_us"] = plain_s * 1e6;
  state.counters["friction_us"] = fric_s * 1e6;
  state.counters["ratio"] = plain_s > 0.0 ? fric_s / plain_s : 0.0;
  state.counters["plain_solves_per_step"] = static_cast<double>(p.tr.lcp_solves) / kSteps;
  state.counters["friction_solves_per_step"] = static_cast<double>(f.tr.lcp_solves) / kSteps;
  state.counters["plain_lcp_size"] = n;           // every cart on the floor: |A| = n
  state.counters["friction_lcp_size"] = 3.0 * n;  // |A| + 2 |F|
  state.counters["peak_plain_KiB"] = mem_plain.peak;
  state.counters["peak_friction_KiB"] = mem_fric.peak;
  state.counters["run_plain_KiB"] = mem_plain.added;
  state.counters["run_friction_KiB"] = mem_fric.added;
  state.counters["warnings"] = static_cast<double>(f.tr.warnings.size());
  state.SetLabel(ok ? "friction step" : p.tr.message + " | " + f.tr.message);
}

}  // namespace

BENCHMARK(BM_MoreauJeanFrictionVsPlain)
    ->Arg(100)
    ->Arg(1000)
    ->Arg(10000)
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(3);

BENCHMARK_MAIN();
