// Shared by the Siconos 4.4 peer programs (peer_siconos_two_carts.cpp,
// peer_siconos_wp.cpp): a linear Lagrangian model with unilateral constraints described
// by matrices and built in Siconos, Moreau–Jean time-stepping, the exact two-carts
// solution (thesis §3.7), CPU timing of the simulation loop, the output rows (text or
// JSON) and the capture of Siconos exceptions.
//
// Build note: Boost.uBLAS 1.74, used by the Siconos headers, calls
// std::allocator<T>::construct, which C++20 removed; compile as C++17.
#pragma once

#if __cplusplus > 201703L
#error \
    "Siconos 4.4 headers (Boost.uBLAS 1.74) need C++17: std::allocator::construct is gone in C++20"
#endif

#include <time.h>
#include <unistd.h>

#include <Eigen/Dense>
#include <SiconosKernel.hpp>
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <iostream>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace peer_siconos {

// ---------------------------------------------------------------------------------------
// Model description: M q'' + K q = f + E^T u, 0 <= y = E q ⟂ u >= 0, Newton impact law
// with restitution e_i per constraint; state x = (q, v).
struct MechSpec {
  std::string name;
  Eigen::MatrixXd M, K;
  Eigen::VectorXd f;  // constant external force (size n; empty: none)
  Eigen::MatrixXd E;  // one row per constraint
  Eigen::VectorXd e;  // restitution per constraint
  Eigen::VectorXd x0;
};

// The model built in Siconos: one LagrangianLinearTIDS, and one LagrangianLinearTIR +
// NewtonImpactNSL + Interaction per constraint row.
struct SiconosModel {
  SP::NonSmoothDynamicalSystem nsds;
  SP::LagrangianLinearTIDS ds;
  std::vector<SP::Interaction> constraints;
  SP::SiconosVector fext;  // kept alive with the model

  Eigen::VectorXd state() const {
    const SiconosVector& q = *ds->q();
    const SiconosVector& v = *ds->velocity();
    const int n = static_cast<int>(q.size());
    Eigen::VectorXd x(2 * n);
    for (int i = 0; i < n; ++i) {
      x(i) = q(i);
      x(n + i) = v(i);
    }
    return x;
  }
};

inline SP::SimpleMatrix to_siconos(const Eigen::MatrixXd& a) {
  SP::SimpleMatrix m(new SimpleMatrix(a.rows(), a.cols()));
  for (int i = 0; i < a.rows(); ++i)
    for (int j = 0; j < a.cols(); ++j) (*m)(i, j) = a(i, j);
  return m;
}

inline SP::SiconosVector to_siconos(const Eigen::VectorXd& a) {
  SP::SiconosVector v(new SiconosVector(a.size()));
  for (int i = 0; i < a.size(); ++i) (*v)(i) = a(i);
  return v;
}

inline SiconosModel build_model(const MechSpec& spec, double t_end) {
  const int n = static_cast<int>(spec.M.rows());
  SiconosModel m;
  SP::SimpleMatrix damping(new SimpleMatrix(n, n));
  damping->zero();
  m.ds.reset(new LagrangianLinearTIDS(to_siconos(Eigen::VectorXd(spec.x0.head(n))),
                                      to_siconos(Eigen::VectorXd(spec.x0.tail(n))),
                                      to_siconos(spec.M), to_siconos(spec.K), damping));
  if (spec.f.size() == n) {
    m.fext = to_siconos(spec.f);
    m.ds->setFExtPtr(m.fext);
  }
  m.nsds.reset(new NonSmoothDynamicalSystem(0.0, t_end));
  m.nsds->insertDynamicalSystem(m.ds);
  for (int i = 0; i < spec.E.rows(); ++i) {
    SP::NonSmoothLaw law(new NewtonImpactNSL(spec.e(i)));
    SP::Relation rel(new LagrangianLinearTIR(to_siconos(Eigen::MatrixXd(spec.E.row(i)))));
    SP::Interaction inter(new Interaction(law, rel));
    m.nsds->link(inter, m.ds);
    m.constraints.push_back(inter);
  }
  return m;
}

// ---------------------------------------------------------------------------------------
// The two carts of thesis §3.2 (run S1 of §3.7): masses 1, K = [[2,-1],[-1,1]], inelastic
// stop x1 >= 0, x0 = e^{-A} (0,-1,-1,0).
using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

// State matrix of eq. (3.1) in free motion, x = (x1, x2, x3, x4) = (q, v).
inline Mat4 two_carts_free_matrix() {
  Mat4 a;
  a << 0, 0, 1, 0,  //
      0, 0, 0, 1,   //
      -2, 1, 0, 0,  //
      1, -1, 0, 0;
  return a;
}

inline MechSpec two_carts_spec() {
  MechSpec s;
  s.name = "two_carts";
  s.M = Eigen::Matrix2d::Identity();
  s.K.resize(2, 2);
  s.K << 2, -1, -1, 1;
  s.E.resize(1, 2);
  s.E << 1, 0;
  s.e = Eigen::VectorXd::Zero(1);
  s.x0 = (Mat4(-two_carts_free_matrix())).exp() * Vec4(0, -1, -1, 0);
  return s;
}

// Exact solution of §3.7 at time t >= 0; right-continuous at the impact t = 1: free flight
// to (0,-1,-1,0) at t = 1, jump to (0,-1,0,0), constrained phase x2 = -cos(t-1), release at
// 1 + π/2 at (0,0,0,1), free flight afterwards.
inline Eigen::VectorXd two_carts_exact(double t) {
  const double release = 1.0 + M_PI / 2.0;
  const Mat4 a = two_carts_free_matrix();
  if (t < 1.0) return (Mat4(a * (t - 1.0))).exp() * Vec4(0, -1, -1, 0);
  if (t < release) return Vec4(0, -std::cos(t - 1.0), 0, std::sin(t - 1.0));
  return (Mat4(a * (t - release))).exp() * Vec4(0, 0, 0, 1);
}

// ---------------------------------------------------------------------------------------
// Timing and runs.
inline double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

inline double wall_seconds() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<double>(clock::now().time_since_epoch()).count();
}

// Result of one simulation: everything but the timing statistics.
struct Outcome {
  Eigen::VectorXd x;
  double t_final = NAN;
  long steps = 0;
  long events = 0;
  double cpu = NAN;   // CPU seconds of the loop
  double wall = NAN;  // wall seconds of the loop
};

// Moreau–Jean time-stepping (MoreauJeanOSI(theta), constant step h) with the given Siconos
// LCP solver (SICONOS_LCP_LEMKE, SICONOS_LCP_PGS, ...). Times the loop only.
inline Outcome run_moreau_jean(const MechSpec& spec, double t_end, double theta, double h,
                               int lcp_solver) {
  SiconosModel model = build_model(spec, t_end);
  SP::MoreauJeanOSI osi(new MoreauJeanOSI(theta));
  SP::TimeDiscretisation td(new TimeDiscretisation(0.0, h));
  SP::OneStepNSProblem lcp(new LCP(lcp_solver));
  SP::TimeStepping sim(new TimeStepping(model.nsds, td, osi, lcp));
  sim->initialize();

  Outcome out;
  const double w0 = wall_seconds();
  const double c0 = process_cpu_seconds();
  while (sim->hasNextEvent()) {
    sim->computeOneStep();
    sim->nextStep();
    ++out.steps;
  }
  out.cpu = process_cpu_seconds() - c0;
  out.wall = wall_seconds() - w0;
  out.t_final = sim->startingTime();
  out.x = model.state();
  return out;
}

// ---------------------------------------------------------------------------------------
// Output rows.
struct Row {
  std::string method;    // e.g. "ed_lsodar", "mj_theta0.5", "mj_theta1_pgs"
  std::string param;     // "tol=1e-08,hout=3" or "h=1e-03"
  double theta = NAN;    // Moreau–Jean theta (NaN: not time-stepping)
  std::string solver;    // Siconos LCP solver ("lemke", "pgs"; empty: n/a)
  double h = NAN;        // time step (NaN: not time-stepping)
  double error = NAN;    // max-abs error of (q, v) at the final time
  double cpu = NAN;      // CPU seconds of the simulation loop (median over repeats)
  double wall = NAN;     // wall seconds of the simulation loop (median over repeats)
  long steps = 0;        // Lsodar steps (event-driven) or time steps (Moreau–Jean)
  long events = 0;       // non-smooth events processed (event-driven); 0 for Moreau–Jean
  double t_final = NAN;  // time the simulation stopped at (should be T)
  int repeats = 0;
  std::string status = "ok";
  std::string message;
};

// The message of the exception being handled: for a Siconos exception, where it was thrown
// and its message (kept as boost::error_info, not in what()); else what().
inline std::string failure_message() {
  const std::string info = boost::current_exception_diagnostic_information(true);
  const std::string tag = "[Siconos::message*] = ";
  const std::size_t at = info.find(tag);
  if (at == std::string::npos) return info;
  std::string where = info.substr(0, info.find(':'));  // "file(line)"
  const std::size_t slash = where.rfind('/');
  if (slash != std::string::npos) where = where.substr(slash + 1);
  std::string what = info.substr(at + tag.size());
  while (!what.empty() && std::isspace(static_cast<unsigned char>(what.back()))) what.pop_back();
  return what + " (thrown at " + where + ")";
}

// Runs `once` (repeated while a run takes under 0.5 s CPU, `repeats` times in all) and
// turns it into a row: error of the first run's final state against exact(t_final), median
// CPU and wall times. A Siconos failure becomes a row with status "failed" and the
// exception's message; a run that stops before t_end gets status "short".
inline Row measure(Row row, int repeats, double t_end,
                   const std::function<Eigen::VectorXd(double)>& exact,
                   const std::function<Outcome()>& once) {
  try {
    std::vector<double> cpus, walls;
    Outcome first = once();
    cpus.push_back(first.cpu);
    walls.push_back(first.wall);
    if (first.cpu < 0.5)
      for (int i = 1; i < repeats; ++i) {
        const Outcome o = once();
        cpus.push_back(o.cpu);
        walls.push_back(o.wall);
      }
    std::sort(cpus.begin(), cpus.end());
    std::sort(walls.begin(), walls.end());
    row.cpu = cpus[cpus.size() / 2];
    row.wall = walls[walls.size() / 2];
    row.repeats = static_cast<int>(cpus.size());
    row.steps = first.steps;
    row.events = first.events;
    row.t_final = first.t_final;
    row.error = (first.x - exact(first.t_final)).cwiseAbs().maxCoeff();
    if (std::abs(first.t_final - t_end) > 1e-9) {
      row.status = "short";
      row.message = "stopped before T";
    }
  } catch (...) {
    row.status = "failed";
    row.message = failure_message();
  }
  return row;
}

inline std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\t', ' ');
  return s;
}

inline std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : one_line(s)) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

inline std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6e", x);
  return buf;
}

inline std::string format_param(const char* name, double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s=%.0e", name, value);
  return buf;
}

// Siconos prints diagnostics on stdout; while an object of this class lives, stdout goes to
// stderr, so that the real stdout holds only the rows (parseable with --json).
class StdoutToStderr {
 public:
  StdoutToStderr() {
    std::fflush(stdout);
    saved_ = dup(STDOUT_FILENO);
    dup2(STDERR_FILENO, STDOUT_FILENO);
  }
  ~StdoutToStderr() {
    std::cout.flush();
    std::fflush(stdout);
    dup2(saved_, STDOUT_FILENO);
    close(saved_);
  }
  StdoutToStderr(const StdoutToStderr&) = delete;
  StdoutToStderr& operator=(const StdoutToStderr&) = delete;

 private:
  int saved_ = -1;
};

// Prints the rows: as one JSON list of objects, or as text after two '#' header lines,
//   method param error_final cpu_seconds steps events t_final status
// with a '#   method: message' line after a row that has a message.
inline void print_rows(const std::vector<Row>& rows, bool json, const std::string& scene,
                       const std::string& title) {
  if (json) {
    std::printf("[\n");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::printf(
          "  {\"peer\": \"siconos\", \"scene\": \"%s\", \"method\": \"%s\", \"param\": \"%s\", "
          "\"theta\": %s, \"solver\": \"%s\", \"h\": %s, \"error_final\": %s, "
          "\"cpu_seconds\": %s, \"wall_seconds\": %s, \"cpu_per_step\": %s, \"steps\": %ld, "
          "\"events\": %ld, \"t_final\": %s, \"repeats\": %d, \"status\": \"%s\", "
          "\"message\": \"%s\"}%s\n",
          scene.c_str(), r.method.c_str(), r.param.c_str(), json_number(r.theta).c_str(),
          r.solver.c_str(), json_number(r.h).c_str(), json_number(r.error).c_str(),
          json_number(r.cpu).c_str(), json_number(r.wall).c_str(),
          json_number(r.steps > 0 ? r.cpu / static_cast<double>(r.steps) : NAN).c_str(), r.steps,
          r.events, json_number(r.t_final).c_str(), r.repeats, r.status.c_str(),
          json_escape(r.message).c_str(), i + 1 < rows.size() ? "," : "");
    }
    std::printf("]\n");
  } else {
    std::printf("# %s\n", title.c_str());
    std::printf("# method param error_final cpu_seconds steps events t_final status\n");
    for (const Row& r : rows) {
      std::printf("%s %s %.3e %.3e %ld %ld %.12g %s\n", r.method.c_str(), r.param.c_str(), r.error,
                  r.cpu, r.steps, r.events, r.t_final, r.status.c_str());
      if (!r.message.empty())
        std::printf("#   %s: %s\n", r.method.c_str(), one_line(r.message).c_str());
    }
  }
}

}  // namespace peer_siconos
