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

#include <cstdlib>
#include <cstring>

#include "peer_siconos_common.hpp"

namespace {

using namespace peer_siconos;

constexpr double kT = 3.0;  // final time (s)

double g_hout = 0;     // --hout: the only output step of the event-driven runs
bool g_trace = false;  // --trace: print every event of the event-driven runs to stderr

// Event-driven: LsodarOSI at rtol = atol = tol, impact LCP and acceleration LCP. With
// `fix`, the integrator's right-hand side (acceleration) is recomputed at the event time
// before the events are processed (shared notes/siconos.md); without it, the scheme runs
// as shipped.
Outcome run_event_driven(double tol, double h_out, bool fix, long max_nstep) {
  SiconosModel scene = build_model(two_carts_spec(), kT);
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
  const double w0 = wall_seconds();
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
      const Eigen::VectorXd x = scene.state();
      std::fprintf(stderr, "trace tol=%.0e t=%.15g type=%d nst=%ld x=(%.10g %.10g %.10g %.10g)\n",
                   tol, sim->nextTime(), events->nextEvent()->getType(), nst, x(0), x(1), x(2),
                   x(3));
    }
    const bool restart = events->nextEvent()->getType() == NS_EVENT;
    sim->processEvents();
    if (restart) nst_last = 0;
  }
  out.cpu = process_cpu_seconds() - c0;
  out.wall = wall_seconds() - w0;
  out.t_final = sim->startingTime();
  out.x = scene.state();
  return out;
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

  std::vector<Row> rows;
  {
    const StdoutToStderr quiet;  // Siconos's diagnostics go to stderr
    // Event-driven: each tolerance with Lsodar free between events (output step = T) and
    // with output every 1e-2 (the restarts at output times change where the release is
    // found).
    const double tols[] = {1e-6, 1e-8, 1e-10, 1e-12};
    std::vector<double> houts = {kT, 1e-2};
    if (g_hout > 0) houts = {g_hout};
    for (int pass = 0; pass < (also_as_shipped ? 2 : 1); ++pass) {
      const bool fix = pass == 0;
      for (double hout : houts)
        for (double tol : tols) {
          char param[64];
          std::snprintf(param, sizeof param, "tol=%.0e,hout=%g", tol, hout);
          Row row;
          row.method = fix ? "ed_lsodar" : "ed_lsodar_asshipped";
          row.param = param;
          rows.push_back(measure(row, repeats, kT, two_carts_exact, [tol, hout, fix, max_nstep] {
            return run_event_driven(tol, hout, fix, max_nstep);
          }));
        }
    }
    // Moreau–Jean, LCP by Lemke (peer_siconos_wp runs every scene, theta and solver).
    const MechSpec spec = two_carts_spec();
    const double thetas[] = {0.5, 1.0};
    const double steps[] = {1e-2, 1e-3, 1e-4, 1e-5};
    for (double theta : thetas)
      for (double h : steps) {
        Row row;
        row.method = theta == 0.5 ? "mj_theta0.5" : "mj_theta1";
        row.param = format_param("h", h);
        row.theta = theta;
        row.solver = "lemke";
        row.h = h;
        rows.push_back(measure(row, repeats, kT, two_carts_exact, [&spec, theta, h] {
          return run_moreau_jean(spec, kT, theta, h, SICONOS_LCP_LEMKE);
        }));
      }
  }
  char title[128];
  std::snprintf(title, sizeof title, "two carts S1 (thesis §3.7), Siconos %s (Debian), T = %g",
                "4.4", kT);
  print_rows(rows, json, "two_carts_S1", title);
  return 0;
}
