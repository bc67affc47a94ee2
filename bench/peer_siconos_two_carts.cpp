// Two carts with a stop (thesis §3.2, run S1 of §3.7) simulated in Siconos 4.4, the peer
// with the same algorithms as lcsim: event-driven (LsodarOSI + EventDriven) at several
// integrator tolerances and Moreau–Jean time-stepping (theta = 0.5 and 1, LCP by Lemke) at
// several steps h. Each run prints one row: the max-abs error of the final state (q, v)
// against the exact solution of §3.7, the CPU time of the simulation loop alone and the
// number of steps.
//
// Model (eq. (3.1)): masses 1, K = [[2,-1],[-1,1]], stop y = x1 >= 0, inelastic (e = 0);
// x0 = e^{-A} (0,-1,-1,0), T = 3. Exact solution (§3.7, with the misprints listed in
// DESIGN.md corrected): free flight to the impact at t = 1, where (0,-1,-1,0) jumps to
// (0,-1,0,0); constrained phase x2 = -cos(t-1), u = cos(t-1); release at t = 1 + π/2 at
// (0,0,0,1); free flight afterwards, x(t) = e^{A(t-1-π/2)} (0,0,0,1).
//
// Usage: peer_siconos_two_carts [--json] [--no-fix] [--hout H] [--max-nstep N] [--repeats N]
//            [--trace]
//   --json         print the rows as one JSON list instead of whitespace-separated text
//   --no-fix       also run the event-driven scheme as shipped (without the computeRhs call
//                  before processEvents, see shared notes/siconos.md) to show its failure
//   --hout H       event-driven output step (time-discretisation events, at which Lsodar
//                  stops); default: two sets of runs, H = T and H = 1e-2
//   --max-nstep N  Lsodar's maximum number of steps per call (default: Siconos's, 500)
//   --repeats N    repeats of each short run (< 0.5 s); the median CPU time is reported
//                  (default 5)
//   --trace        print every event of the event-driven runs (time, type, state) to stderr
//
// Output (text): one row per run,
//   method param error_final cpu_seconds steps events t_final status
// method: ed_lsodar (with the fix), ed_lsodar_asshipped, mj_theta0.5, mj_theta1; param:
// tol=..,hout=.. or h=..; steps: Lsodar steps (NST summed over restarts) or time steps;
// events: non-smooth events Siconos processed (the exact solution has two: impact, release);
// status: ok, failed (then a comment line '#   method: message' follows), short.
// Siconos's own diagnostics go to stderr, so stdout holds only the rows.
//
// Siconos exceptions are caught per run and reported in the row, never allowed to end the
// program. Build note: Boost.uBLAS 1.74, used by the Siconos headers, calls
// std::allocator<T>::construct, which C++20 removed; compile this file as C++17.

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
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <iostream>
#include <string>
#include <unsupported/Eigen/MatrixFunctions>
#include <vector>

namespace {

constexpr double kT = 3.0;  // final time (s)

using Vec4 = Eigen::Matrix<double, 4, 1>;
using Mat4 = Eigen::Matrix<double, 4, 4>;

// State matrix of eq. (3.1) in free motion, x = (x1, x2, x3, x4) = (q, v).
Mat4 free_matrix() {
  Mat4 a;
  a << 0, 0, 1, 0,  //
      0, 0, 0, 1,   //
      -2, 1, 0, 0,  //
      1, -1, 0, 0;
  return a;
}

Vec4 initial_state() {
  const Vec4 z(0, -1, -1, 0);
  return (Mat4(-free_matrix())).exp() * z;
}

// Exact solution of §3.7 at time t in [0, T]; right-continuous at the impact t = 1.
Vec4 exact_state(double t) {
  const double release = 1.0 + M_PI / 2.0;
  if (t < 1.0) return (Mat4(free_matrix() * (t - 1.0))).exp() * Vec4(0, -1, -1, 0);
  if (t < release) return Vec4(0, -std::cos(t - 1.0), 0, std::sin(t - 1.0));
  return (Mat4(free_matrix() * (t - release))).exp() * Vec4(0, 0, 0, 1);
}

double process_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// One row of output.
struct Row {
  std::string method;    // "ed_lsodar", "ed_lsodar_asshipped", "mj_theta0.5", "mj_theta1"
  std::string param;     // "tol=1e-08" or "h=1e-03"
  double error = NAN;    // max-abs error of (q, v) at the final time
  double cpu = NAN;      // CPU seconds of the simulation loop (median over repeats)
  long steps = 0;        // Lsodar steps (event-driven) or time steps (Moreau–Jean)
  long events = 0;       // non-smooth events processed (event-driven); 0 for Moreau–Jean
  double t_final = NAN;  // time the simulation stopped at (should be T)
  int repeats = 0;
  std::string status = "ok";
  std::string message;
};

double g_hout = 0;     // --hout: the only output step of the event-driven runs
bool g_trace = false;  // --trace: print every event of the event-driven runs to stderr

// The Siconos model of the two carts: one LagrangianLinearTIDS and one Interaction.
struct Scene {
  SP::NonSmoothDynamicalSystem nsds;
  SP::LagrangianLinearTIDS carts;
  SP::Interaction stop;
};

Scene build_scene() {
  const Vec4 x0 = initial_state();
  SP::SiconosVector q0(new SiconosVector(2));
  SP::SiconosVector v0(new SiconosVector(2));
  (*q0)(0) = x0(0);
  (*q0)(1) = x0(1);
  (*v0)(0) = x0(2);
  (*v0)(1) = x0(3);
  SP::SimpleMatrix mass(new SimpleMatrix(2, 2));
  mass->eye();
  SP::SimpleMatrix stiffness(new SimpleMatrix(2, 2));
  (*stiffness)(0, 0) = 2.0;
  (*stiffness)(0, 1) = -1.0;
  (*stiffness)(1, 0) = -1.0;
  (*stiffness)(1, 1) = 1.0;
  SP::SimpleMatrix damping(new SimpleMatrix(2, 2));
  damping->zero();

  Scene scene;
  scene.carts.reset(new LagrangianLinearTIDS(q0, v0, mass, stiffness, damping));
  SP::SimpleMatrix h_stop(new SimpleMatrix(1, 2));
  (*h_stop)(0, 0) = 1.0;  // y = x1
  (*h_stop)(0, 1) = 0.0;
  SP::NonSmoothLaw law(new NewtonImpactNSL(0.0));  // inelastic stop, e = 0
  SP::Relation relation(new LagrangianLinearTIR(h_stop));
  scene.stop.reset(new Interaction(law, relation));
  scene.nsds.reset(new NonSmoothDynamicalSystem(0.0, kT));
  scene.nsds->insertDynamicalSystem(scene.carts);
  scene.nsds->link(scene.stop, scene.carts);
  return scene;
}

Vec4 final_state(const Scene& scene) {
  const SiconosVector& q = *scene.carts->q();
  const SiconosVector& v = *scene.carts->velocity();
  return Vec4(q(0), q(1), v(0), v(1));
}

// Result of one simulation: everything but the timing statistics.
struct Outcome {
  Vec4 x = Vec4::Constant(NAN);
  double t_final = NAN;
  long steps = 0;
  long events = 0;
  double cpu = NAN;
};

// Event-driven: LsodarOSI at rtol = atol = tol, impact LCP and acceleration LCP. With
// `fix`, the integrator's right-hand side (acceleration) is recomputed at the event time
// before the events are processed (shared notes/siconos.md); without it, the scheme runs
// as shipped.
Outcome run_event_driven(double tol, double h_out, bool fix, long max_nstep) {
  Scene scene = build_scene();
  SP::LsodarOSI osi(new LsodarOSI());
  osi->setTol(1, tol, tol);
  // One time-discretisation event at T only: Lsodar runs freely between the non-smooth
  // events and is stopped exactly at the final time.
  SP::TimeDiscretisation td(new TimeDiscretisation(0.0, h_out));
  SP::EventDriven sim(new EventDriven(scene.nsds, td));
  sim->insertIntegrator(osi);
  SP::OneStepNSProblem impact(new LCP());
  SP::OneStepNSProblem acceleration(new LCP());
  sim->insertNonSmoothProblem(impact, SICONOS_OSNSP_ED_IMPACT);
  sim->insertNonSmoothProblem(acceleration, SICONOS_OSNSP_ED_SMOOTH_ACC);
  sim->initialize();
  if (max_nstep > 0) osi->setMaxNstep(max_nstep);  // Lsodar's work arrays exist only now
  SP::EventsManager events = sim->eventsManager();

  Outcome out;
  // Lsodar's step counter iwork[10] (NST) counts from the last (re)start of the integrator,
  // and EventDriven restarts it after every non-smooth event; sum it over the restarts.
  long nst_last = 0;
  const double c0 = process_cpu_seconds();
  // EventsManager::hasNextEvent() only says that an event is scheduled: the
  // time-discretisation event after T is scheduled too, so stop at T explicitly.
  while (sim->hasNextEvent() && sim->startingTime() < kT - 1e-12) {
    sim->advanceToEvent();
    const long nst = osi->getIwork()[10];
    out.steps += nst >= nst_last ? nst - nst_last : nst;
    nst_last = nst;
    if (events->nextEvent()->getType() == NS_EVENT) {
      ++out.events;
      if (fix) osi->computeRhs(sim->nextTime());
    }
    if (g_trace) {
      const Vec4 x = final_state(scene);
      std::fprintf(stderr, "trace tol=%.0e t=%.15g type=%d nst=%ld x=(%.10g %.10g %.10g %.10g)\n",
                   tol, sim->nextTime(), events->nextEvent()->getType(), nst, x(0), x(1), x(2),
                   x(3));
    }
    const bool restart = events->nextEvent()->getType() == NS_EVENT;
    sim->processEvents();
    if (restart) nst_last = 0;
  }
  out.cpu = process_cpu_seconds() - c0;
  out.t_final = sim->startingTime();
  out.x = final_state(scene);
  return out;
}

// Moreau–Jean time-stepping with parameter theta at step h; LCP solved by Lemke.
Outcome run_moreau_jean(double theta, double h) {
  Scene scene = build_scene();
  SP::MoreauJeanOSI osi(new MoreauJeanOSI(theta));
  SP::TimeDiscretisation td(new TimeDiscretisation(0.0, h));
  SP::OneStepNSProblem lcp(new LCP(SICONOS_LCP_LEMKE));
  SP::TimeStepping sim(new TimeStepping(scene.nsds, td, osi, lcp));
  sim->initialize();

  Outcome out;
  const double c0 = process_cpu_seconds();
  while (sim->hasNextEvent()) {
    sim->computeOneStep();
    sim->nextStep();
    ++out.steps;
  }
  out.cpu = process_cpu_seconds() - c0;
  out.t_final = sim->startingTime();
  out.x = final_state(scene);
  return out;
}

// The message of the exception being handled: for a Siconos exception, where it was thrown
// and its message (kept as boost::error_info, not in what()); else what().
std::string failure_message() {
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

// Runs `once` (repeated while short) and turns it into a row; a Siconos failure becomes a
// row with status "failed" and the exception's message.
Row measure(const std::string& method, const std::string& param, int repeats,
            const std::function<Outcome()>& once) {
  Row row;
  row.method = method;
  row.param = param;
  try {
    std::vector<double> cpus;
    Outcome first = once();
    cpus.push_back(first.cpu);
    if (first.cpu < 0.5)
      for (int i = 1; i < repeats; ++i) cpus.push_back(once().cpu);
    std::sort(cpus.begin(), cpus.end());
    row.cpu = cpus[cpus.size() / 2];
    row.repeats = static_cast<int>(cpus.size());
    row.steps = first.steps;
    row.events = first.events;
    row.t_final = first.t_final;
    row.error = (first.x - exact_state(first.t_final)).cwiseAbs().maxCoeff();
    if (std::abs(first.t_final - kT) > 1e-9) {
      row.status = "short";
      row.message = "stopped before T";
    }
  } catch (...) {
    row.status = "failed";
    row.message = failure_message();
  }
  return row;
}

std::string one_line(std::string s) {
  std::replace(s.begin(), s.end(), '\n', ' ');
  std::replace(s.begin(), s.end(), '\t', ' ');
  return s;
}

std::string json_escape(const std::string& s) {
  std::string out;
  for (char c : one_line(s)) {
    if (c == '"' || c == '\\') out += '\\';
    out += c;
  }
  return out;
}

std::string json_number(double x) {
  if (!std::isfinite(x)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6e", x);
  return buf;
}

std::string format_param(const char* name, double value) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%s=%.0e", name, value);
  return buf;
}

}  // namespace

int main(int argc, char** argv) {
  bool json = false;
  bool also_as_shipped = false;
  int repeats = 5;
  long max_nstep = 0;  // 0: Lsodar's default (MXSTEP = 500 steps per call)
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--json") == 0) {
      json = true;
    } else if (std::strcmp(argv[i], "--no-fix") == 0) {
      also_as_shipped = true;
    } else if (std::strcmp(argv[i], "--hout") == 0 && i + 1 < argc) {
      g_hout = std::atof(argv[++i]);
    } else if (std::strcmp(argv[i], "--trace") == 0) {
      g_trace = true;
    } else if (std::strcmp(argv[i], "--max-nstep") == 0 && i + 1 < argc) {
      max_nstep = std::max(0L, std::atol(argv[++i]));
    } else if (std::strcmp(argv[i], "--repeats") == 0 && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else {
      std::fprintf(stderr, "usage: %s [--json] [--no-fix] [--max-nstep N] [--repeats N]\n",
                   argv[0]);
      return 2;
    }
  }

  // Siconos prints diagnostics on stdout; send them to stderr while simulating so that
  // stdout holds only the rows (parseable with --json).
  std::fflush(stdout);
  const int saved_stdout = dup(STDOUT_FILENO);
  dup2(STDERR_FILENO, STDOUT_FILENO);

  std::vector<Row> rows;
  // Event-driven: each tolerance with Lsodar free between events (output step = T) and
  // with output every 1e-2 (the restarts at output times change where the release is found).
  const double tols[] = {1e-6, 1e-8, 1e-10, 1e-12};
  std::vector<double> houts = {kT, 1e-2};
  if (g_hout > 0) houts = {g_hout};
  for (int pass = 0; pass < (also_as_shipped ? 2 : 1); ++pass) {
    const bool fix = pass == 0;
    for (double hout : houts)
      for (double tol : tols) {
        char param[64];
        std::snprintf(param, sizeof param, "tol=%.0e,hout=%g", tol, hout);
        rows.push_back(measure(
            fix ? "ed_lsodar" : "ed_lsodar_asshipped", param, repeats,
            [tol, hout, fix, max_nstep] { return run_event_driven(tol, hout, fix, max_nstep); }));
      }
  }
  const double thetas[] = {0.5, 1.0};
  const double steps[] = {1e-2, 1e-3, 1e-4, 1e-5};
  for (double theta : thetas)
    for (double h : steps)
      rows.push_back(measure(theta == 0.5 ? "mj_theta0.5" : "mj_theta1", format_param("h", h),
                             repeats, [theta, h] { return run_moreau_jean(theta, h); }));

  std::cout.flush();
  std::fflush(stdout);
  dup2(saved_stdout, STDOUT_FILENO);
  close(saved_stdout);

  if (json) {
    std::printf("[\n");
    for (std::size_t i = 0; i < rows.size(); ++i) {
      const Row& r = rows[i];
      std::printf(
          "  {\"peer\": \"siconos\", \"scene\": \"two_carts_S1\", \"method\": \"%s\", "
          "\"param\": \"%s\", \"error_final\": %s, \"cpu_seconds\": %s, \"steps\": %ld, "
          "\"events\": %ld, \"t_final\": %s, \"repeats\": %d, \"status\": \"%s\", "
          "\"message\": \"%s\"}%s\n",
          r.method.c_str(), r.param.c_str(), json_number(r.error).c_str(),
          json_number(r.cpu).c_str(), r.steps, r.events, json_number(r.t_final).c_str(), r.repeats,
          r.status.c_str(), json_escape(r.message).c_str(), i + 1 < rows.size() ? "," : "");
    }
    std::printf("]\n");
  } else {
    std::printf("# two carts S1 (thesis §3.7), Siconos %s (Debian), T = %g\n", "4.4", kT);
    std::printf("# method param error_final cpu_seconds steps events t_final status\n");
    for (const Row& r : rows) {
      std::printf("%s %s %.3e %.3e %ld %ld %.12g %s\n", r.method.c_str(), r.param.c_str(), r.error,
                  r.cpu, r.steps, r.events, r.t_final, r.status.c_str());
      if (!r.message.empty())
        std::printf("#   %s: %s\n", r.method.c_str(), one_line(r.message).c_str());
    }
  }
  return 0;
}
