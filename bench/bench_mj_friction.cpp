// Moreau–Jean with friction against the frictionless step, side by side in
// one process (issue 17's target: at most 3x at N = 10^4).
//
// The planar cart chain: cart i has coordinates (x_i, y_i) (interleaved,
// unit masses), springs of stiffness 1 between neighbours in x (the 1-D
// chain of `lcsim generate chain`, without its wall spring), a floor y_i >= 0
// per cart, gravity 9.81 m/s^2 in -y, and per cart the frictional contact
// {floor_i, tangent e_{x_i}, mu = 0.3}. Start: resting on the floor
// (y = v_y = 0), x_i = 0.1 (i mod 3) (springs stretched), and v_x = 1 m/s
// (second argument 1: every cart slides through the window, friction
// taking mu g t = 0.6 m/s off) or v_x = 0 (argument 0: every cart sticks,
// the springs' forces, at most 0.4 N, are inside the cone mu g = 2.9 N). Both models
// have the same floor contacts, so the same active sets (every cart on the
// floor); only `friction` differs.
//
// Per step, as bench_chain.cpp: each iteration runs S = 200 steps and 1 step
// from the same state, both models in turn, and reports (T_S - T_1) / (S - 1)
// (set-up, the factorisation of W, not counted). h = 1e-3, theta = 0.5.
// The manual time is the friction step; counters: the frictionless step
// (`plain_s`), the ratio, LCP solves per step of each, the LCP sizes of a
// step when every cart is on the floor (|A| = n unknowns frictionless,
// |A| + 2 |F| = 3 n with friction) and the peak resident memory of a
// process that builds one of the models and runs it (KiB; peak_kib below;
// sliding runs only).
// Times: process CPU time (cpu_seconds), the fastest of the iterations (manual time: each
// iteration's friction step).
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81, kMu = 0.3, kH = 1e-3;
constexpr long kSteps = 200;

lcsim::mech::Model planar_chain(int n, bool friction, double vx) {
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
    model.initial(N + 2 * i) = vx;
  }
  return model;
}

// The process's CPU time (s), not the wall clock: at load 7-9 the
// wall-clock difference T_S - T_1 carried other processes' time slices
// (a 10^4 row read plain_us = 0), as in bench_mj_friction3d.cpp.
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

// Seconds per step (set-up removed) and the S-step run.
double per_step(const lcsim::mech::Model& model, Timed& full) {
  double t1 = run(model, 1).seconds;
  for (int r = 0; r < 2; ++r) t1 = std::min(t1, run(model, 1).seconds);
  full = run(model, kSteps);
  return std::max(0.0, full.seconds - t1) / static_cast<double>(kSteps - 1);
}

// The peak resident memory (KiB) of a fresh process that builds one model
// and runs it kSteps steps: this program re-executed with `--peak-child n
// friction` (main below), which prints its own VmHWM (/proc/self/status;
// ru_maxrss of a child would include this process's peak, inherited through
// fork). Counts the model itself (with friction n sparse tangent rows of one
// entry each, mech::FrictionalContact::tangent).
double peak_kib(int n, bool friction) {
  char exe[4096] = {};
  if (readlink("/proc/self/exe", exe, sizeof exe - 1) <= 0) return -1.0;
  const std::string cmd =
      std::string("'") + exe + "' --peak-child " + std::to_string(n) + (friction ? " 1" : " 0");
  FILE* p = popen(cmd.c_str(), "r");
  if (!p) return -1.0;
  double kib = -1.0;
  if (std::fscanf(p, "%lf", &kib) != 1) kib = -1.0;
  return pclose(p) == 0 ? kib : -1.0;
}

// VmHWM of this process (KiB).
double own_peak_kib() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6));
  return -1.0;
}

void BM_MoreauJeanFrictionVsPlain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const double vx = static_cast<double>(state.range(1));
  const auto plain = planar_chain(n, false, vx), fric = planar_chain(n, true, vx);
  Timed p, f;
  // The fastest of the iterations for each: the machine is shared, and the
  // slower samples are other processes' time.
  double plain_s = 1e300, fric_s = 1e300;
  for (auto _ : state) {
    plain_s = std::min(plain_s, per_step(plain, p));
    const double fs = per_step(fric, f);
    fric_s = std::min(fric_s, fs);
    state.SetIterationTime(fs);
  }
  const double mem_plain = vx > 0 ? peak_kib(n, false) : 0.0;
  const double mem_fric = vx > 0 ? peak_kib(n, true) : 0.0;
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
  state.counters["peak_plain_KiB"] = mem_plain;
  state.counters["peak_friction_KiB"] = mem_fric;
  state.counters["warnings"] = static_cast<double>(f.tr.warnings.size());
  state.SetLabel(ok ? (vx > 0 ? "friction step, sliding" : "friction step, sticking")
                    : p.tr.message + " | " + f.tr.message);
}

}  // namespace

BENCHMARK(BM_MoreauJeanFrictionVsPlain)
    ->Args({100, 1})
    ->Args({1000, 1})
    ->Args({10000, 1})
    ->Args({100, 0})
    ->Args({1000, 0})
    ->Args({10000, 0})
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond)
    ->Iterations(5);

int main(int argc, char** argv) {
  if (argc == 4 && std::string(argv[1]) == "--peak-child") {
    const auto model = planar_chain(std::stoi(argv[2]), std::string(argv[3]) == "1", 1.0);
    if (run(model, kSteps).tr.status != lcsim::sim::RunStatus::kCompleted) return 1;
    std::printf("%.0f\n", own_peak_kib());
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
