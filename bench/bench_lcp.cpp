// LCP solvers side by side: lcsim (Lemke, block principal pivoting, PGS,
// enumeration) against Bullet's MLCP solvers (Dantzig, Lemke, PGS) and, when
// installed, Siconos numerics (lexicographic Lemke, PGS), on the same random
// problems: SPD (A A'/k + I/2) and nonsymmetric positive definite P-matrices
// (SPD + skew part), k = 4, 16, 64, 256, q standard normal, fixed seeds.
//
// Each benchmark reports the wall time per solve and counters:
//   residual  natural residual ||min(z, Mz + q)||_inf of the returned z,
//   ok        1 if the solver claimed success (lcsim: status kSolved),
//   pivots / iterations where the solver reports them.
// Peers are called through their plain LCP interfaces: Bullet
// btMLCPSolverInterface::solveMLCP with A = M, b = -q, lo = 0, hi = inf;
// Siconos lcp_lexicolemke / lcp_pgs on a dense NumericsMatrix.
#include <BulletDynamics/MLCPSolvers/btDantzigSolver.h>
#include <BulletDynamics/MLCPSolvers/btLemkeSolver.h>
#include <BulletDynamics/MLCPSolvers/btSolveProjectedGaussSeidel.h>
#include <benchmark/benchmark.h>

#include <functional>
#include <lcsim/lcp/lcp.hpp>
#include <map>
#include <random>
#include <string>
#include <vector>

// bench/CMakeLists.txt adds only <prefix>/siconos/numerics to the include path,
// but the numerics headers include "SiconosConfig.h" from <prefix>/siconos. Use
// Siconos only when that header is reachable (e.g. CPLUS_INCLUDE_PATH=
// /usr/include/siconos) so that the benchmark still builds without it.
#if defined(LCSIM_HAVE_SICONOS) && __has_include(<SiconosConfig.h>)
#define LCSIM_BENCH_SICONOS 1
#endif

#ifdef LCSIM_BENCH_SICONOS
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"  // third-party headers
#include <LCP_Solvers.h>
#include <LinearComplementarityProblem.h>
#include <NumericsMatrix.h>
#include <SolverOptions.h>
#include <lcp_cst.h>
#pragma GCC diagnostic pop
#endif

namespace {

using lcsim::lcp::MatrixXd;
using lcsim::lcp::VectorXd;

struct Problem {
  MatrixXd M;
  VectorXd q;
};

enum class Kind { kSpd, kNonsymmetricP };

const Problem& problem(Kind kind, int k) {
  static std::map<std::pair<int, int>, Problem> cache;
  auto key = std::make_pair(static_cast<int>(kind), k);
  auto it = cache.find(key);
  if (it != cache.end()) return it->second;
  std::mt19937 rng(1000 + k);
  std::normal_distribution<double> n(0.0, 1.0);
  auto gauss = [&](int r, int c) {
    MatrixXd A(r, c);
    for (int j = 0; j < c; ++j)
      for (int i = 0; i < r; ++i) A(i, j) = n(rng);
    return A;
  };
  Problem p;
  const MatrixXd A = gauss(k, k);
  p.M = A * A.transpose() / k + 0.5 * MatrixXd::Identity(k, k);
  if (kind == Kind::kNonsymmetricP) {
    const MatrixXd B = gauss(k, k) / std::sqrt(static_cast<double>(k));
    p.M += B - B.transpose();
  }
  p.q = gauss(k, 1);
  return cache.emplace(key, std::move(p)).first->second;
}

void report(benchmark::State& state, const Problem& p, const VectorXd& z, bool ok) {
  state.counters["residual"] = lcsim::lcp::natural_residual(p.M, p.q, z);
  state.counters["ok"] = ok ? 1.0 : 0.0;
}

// ---- lcsim -----------------------------------------------------------------

void run_lcsim(benchmark::State& state, const std::string& name, Kind kind, int k) {
  const Problem& p = problem(kind, k);
  const auto solver = lcsim::lcp::make_solver(name);
  lcsim::lcp::Options opt;
  lcsim::lcp::Result r;
  for (auto _ : state) {
    r = solver->solve(p.M, p.q, opt);
    benchmark::DoNotOptimize(r.z.data());
  }
  report(state, p, r.z, r.ok());
  state.counters["pivots"] = r.pivots;
  state.counters["iterations"] = r.iterations;
}

// ---- Bullet ----------------------------------------------------------------

struct BulletLcp {
  btMatrixXu A;
  btVectorXu b, lo, hi, x;
  btAlignedObjectArray<int> dependency;
  explicit BulletLcp(const Problem& p) {
    const int k = static_cast<int>(p.q.size());
    A.resize(k, k);
    b.resize(k);
    lo.resize(k);
    hi.resize(k);
    x.resize(k);
    dependency.resize(k, -1);
    for (int i = 0; i < k; ++i) {
      for (int j = 0; j < k; ++j) A.setElem(i, j, p.M(i, j));
      b[i] = -p.q(i);
      lo[i] = 0.0;
      hi[i] = BT_INFINITY;
    }
  }
  VectorXd z() const {
    VectorXd z(x.size());
    for (int i = 0; i < x.size(); ++i) z(i) = x[i];
    return z;
  }
};

void run_bullet(benchmark::State& state, btMLCPSolverInterface& solver, int iterations, Kind kind,
                int k) {
  const Problem& p = problem(kind, k);
  BulletLcp lcp(p);
  bool ok = false;
  for (auto _ : state) {
    for (int i = 0; i < k; ++i) lcp.x[i] = 0.0;
    ok = solver.solveMLCP(lcp.A, lcp.b, lcp.x, lcp.lo, lcp.hi, lcp.dependency, iterations, false);
    benchmark::DoNotOptimize(lcp.x[0]);
  }
  report(state, p, lcp.z(), ok);
}

// ---- Siconos ---------------------------------------------------------------

#ifdef LCSIM_BENCH_SICONOS
void run_siconos(benchmark::State& state, int solver_id, Kind kind, int k) {
  const Problem& p = problem(kind, k);
  NumericsMatrix* M = NM_create(NM_DENSE, k, k);
  std::copy(p.M.data(), p.M.data() + k * k, M->matrix0);  // both column-major
  VectorXd q = p.q;
  LinearComplementarityProblem lcp;
  lcp.size = k;
  lcp.M = M;
  lcp.q = q.data();
  SolverOptions* options = solver_options_create(solver_id);
  options->iparam[SICONOS_IPARAM_MAX_ITER] = solver_id == SICONOS_LCP_LEMKE ? 50 * k + 1000 : 10000;
  options->dparam[SICONOS_DPARAM_TOL] = 1e-12;
  VectorXd z(k), w(k);
  int info = -1;
  for (auto _ : state) {
    z.setZero();
    w.setZero();
    if (solver_id == SICONOS_LCP_LEMKE)
      lcp_lexicolemke(&lcp, z.data(), w.data(), &info, options);
    else
      lcp_pgs(&lcp, z.data(), w.data(), &info, options);
    benchmark::DoNotOptimize(z.data());
  }
  report(state, p, z, info == 0);
  state.counters["iterations"] = options->iparam[SICONOS_IPARAM_ITER_DONE];
  solver_options_delete(options);
  NM_free(M);
}
#endif

std::string kind_name(Kind kind) { return kind == Kind::kSpd ? "spd" : "nonsym_p"; }

}  // namespace

int main(int argc, char** argv) {
  static btDantzigSolver dantzig;
  static btLemkeSolver lemke_bounded;  // Bullet's default (m_useLoHighBounds = true)
  static btLemkeSolver lemke_unbounded;
  lemke_unbounded.m_useLoHighBounds = false;
  static btSolveProjectedGaussSeidel bullet_pgs;

  for (Kind kind : {Kind::kSpd, Kind::kNonsymmetricP}) {
    for (int k : {4, 16, 64, 256}) {
      const std::string suffix = "/" + kind_name(kind) + "/" + std::to_string(k);
      for (const std::string& name : lcsim::lcp::solver_names()) {
        if (name == "enum" && k > 16) continue;  // 2^k bases
        benchmark::RegisterBenchmark(("lcsim_" + name + suffix).c_str(), [name, kind,
                                                                          k](benchmark::State& s) {
          run_lcsim(s, name, kind, k);
        })->Unit(benchmark::kMicrosecond);
      }
      benchmark::RegisterBenchmark(("bullet_dantzig" + suffix).c_str(), [kind,
                                                                         k](benchmark::State& s) {
        run_bullet(s, dantzig, 0, kind, k);
      })->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("bullet_lemke" + suffix).c_str(), [kind,
                                                                       k](benchmark::State& s) {
        run_bullet(s, lemke_bounded, 0, kind, k);
      })->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(
          ("bullet_lemke_unbounded" + suffix).c_str(),
          [kind, k](benchmark::State& s) { run_bullet(s, lemke_unbounded, 0, kind, k); })
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("bullet_pgs1000" + suffix).c_str(), [kind,
                                                                         k](benchmark::State& s) {
        run_bullet(s, bullet_pgs, 1000, kind, k);
      })->Unit(benchmark::kMicrosecond);
#ifdef LCSIM_BENCH_SICONOS
      benchmark::RegisterBenchmark(
          ("siconos_lexicolemke" + suffix).c_str(),
          [kind, k](benchmark::State& s) { run_siconos(s, SICONOS_LCP_LEMKE, kind, k); })
          ->Unit(benchmark::kMicrosecond);
      benchmark::RegisterBenchmark(("siconos_pgs" + suffix).c_str(), [kind,
                                                                      k](benchmark::State& s) {
        run_siconos(s, SICONOS_LCP_PGS, kind, k);
      })->Unit(benchmark::kMicrosecond);
#endif
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
