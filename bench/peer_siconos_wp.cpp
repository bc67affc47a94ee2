// Work-precision of Siconos 4.4's Moreau–Jean time-stepping on one scene, the peer rows of
// bench/run_work_precision.sh: MoreauJeanOSI(theta) for theta = 0.5 and 1, each with the
// LCP solvers SICONOS_LCP_LEMKE and SICONOS_LCP_PGS, at steps h = 1e-2 ... 1e-5. Each run
// prints one row: the max-abs error of the final state (q, v) at T against the exact final
// state, the CPU time of the simulation loop alone and the number of steps.
//
// Scenes (masses, stiffness, constraints as in robots/*.yaml):
//   two_carts  thesis §3.2, run S1 of §3.7: M = I, K = [[2,-1],[-1,1]], stop x1 >= 0,
//              e = 0, x0 = e^{-A} (0,-1,-1,0); exact final state in closed form (§3.7).
//   hook       Example 3.8.3: the same carts with E = [[1,0],[1,-1]] (stop and hook),
//              e = 0, x0 = (0,0,-1,2); the exact final state must be given with --exact
//              (bench/run_work_precision.sh takes it from lcsim's event-driven run).
//   ball0      ball of mass 1 under gravity 9.81, q = height >= 0, from q = 1 at rest,
//              NewtonImpactNSL(0): at rest on the ground after t1 = sqrt(2/g) ≈ 0.4515,
//              exact final state (0, 0).
//   ball05     the same with NewtonImpactNSL(0.5): the impacts accumulate at
//              3 t1 ≈ 1.3546 < T, then at rest: exact final state (0, 0).
//
// Usage: peer_siconos_wp SCENE [--json] [--h-list H1,H2,...] [--solvers lemke,pgs]
//            [--thetas 0.5,1] [--exact A,B,...] [--t-end T] [--repeats N] [--print-exact]
//   --h-list       steps (default 1e-2,1e-3,1e-4,1e-5)
//   --solvers      Siconos LCP solvers, lemke and/or pgs (default both)
//   --thetas       MoreauJeanOSI thetas (default 0.5,1)
//   --exact        the exact final state at T (q then v); overrides the closed form
//   --t-end        horizon T (default 3; the closed forms hold for any T >= 1.36)
//   --repeats      runs of each short case (< 0.5 s CPU); median times (default 5)
//   --print-exact  print the closed-form exact final state (comma-separated) and exit
//
// Output: the rows of peer_siconos_common.hpp (print_rows): text
//   method param error_final cpu_seconds steps events t_final status
// with method mj_theta<theta>_<solver> and param h=<h>, or with --json one list of objects
// (peer, scene, method, param, theta, solver, h, error_final, cpu_seconds, wall_seconds,
// cpu_per_step, steps, events, t_final, repeats, status, message).
// Siconos's own diagnostics go to stderr. Compile as C++17 (see the common header).

#include <cstdlib>
#include <cstring>
#include <sstream>

#include "peer_siconos_common.hpp"

namespace {

using namespace peer_siconos;

constexpr double kGravity = 9.81;

std::vector<double> parse_list(const std::string& s) {
  std::vector<double> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (item.empty()) continue;
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !std::isfinite(v))
      throw std::runtime_error("not a number: '" + item + "'");
    out.push_back(v);
  }
  return out;
}

std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

MechSpec hook_spec() {
  MechSpec s = two_carts_spec();
  s.name = "hook";
  s.E.resize(2, 2);
  s.E << 1, 0, 1, -1;
  s.e = Eigen::VectorXd::Zero(2);
  s.x0 = Vec4(0, 0, -1, 2);
  return s;
}

MechSpec ball_spec(double restitution) {
  MechSpec s;
  s.name = restitution == 0.0 ? "ball0" : "ball05";
  s.M = Eigen::MatrixXd::Identity(1, 1);
  s.K = Eigen::MatrixXd::Zero(1, 1);
  s.f = Eigen::VectorXd::Constant(1, -kGravity);
  s.E = Eigen::MatrixXd::Identity(1, 1);
  s.e = Eigen::VectorXd::Constant(1, restitution);
  s.x0 = Eigen::Vector2d(1.0, 0.0);
  return s;
}

// The closed-form exact final state at T, if the scene has one (empty otherwise).
Eigen::VectorXd closed_form_final(const std::string& scene, double t_end) {
  if (scene == "two_carts") return two_carts_exact(t_end);
  const double t1 = std::sqrt(2.0 / kGravity);  // first impact of the balls
  if (scene == "ball0" && t_end >= t1) return Eigen::Vector2d(0.0, 0.0);
  if (scene == "ball05" && t_end >= 3.0 * t1) return Eigen::Vector2d(0.0, 0.0);
  return {};
}

int usage(const char* argv0) {
  std::fprintf(stderr,
               "usage: %s two_carts|hook|ball0|ball05 [--json] [--h-list H,...] "
               "[--solvers lemke,pgs] [--thetas 0.5,1] [--exact A,B,...] [--t-end T] "
               "[--repeats N] [--print-exact]\n",
               argv0);
  return 2;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene;
  bool json = false;
  bool print_exact = false;
  int repeats = 5;
  double t_end = 3.0;
  std::vector<double> hs = {1e-2, 1e-3, 1e-4, 1e-5};
  std::vector<double> thetas = {0.5, 1.0};
  std::vector<std::string> solvers = {"lemke", "pgs"};
  std::vector<double> exact_given;
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string arg = argv[i];
      const bool has_value = i + 1 < argc;
      if (arg == "--json") {
        json = true;
      } else if (arg == "--print-exact") {
        print_exact = true;
      } else if (arg == "--h-list" && has_value) {
        hs = parse_list(argv[++i]);
      } else if (arg == "--thetas" && has_value) {
        thetas = parse_list(argv[++i]);
      } else if (arg == "--solvers" && has_value) {
        solvers = split(argv[++i]);
      } else if (arg == "--exact" && has_value) {
        exact_given = parse_list(argv[++i]);
      } else if (arg == "--t-end" && has_value) {
        t_end = std::atof(argv[++i]);
      } else if (arg == "--repeats" && has_value) {
        repeats = std::max(1, std::atoi(argv[++i]));
      } else if (!arg.empty() && arg[0] != '-' && scene.empty()) {
        scene = arg;
      } else {
        return usage(argv[0]);
      }
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "peer_siconos_wp: %s\n", e.what());
    return 2;
  }

  MechSpec spec;
  if (scene == "two_carts") {
    spec = two_carts_spec();
  } else if (scene == "hook") {
    spec = hook_spec();
  } else if (scene == "ball0") {
    spec = ball_spec(0.0);
  } else if (scene == "ball05") {
    spec = ball_spec(0.5);
  } else {
    return usage(argv[0]);
  }
  if (!(t_end > 0.0) || !std::isfinite(t_end)) {
    std::fprintf(stderr, "peer_siconos_wp: --t-end must be a finite number > 0\n");
    return 2;
  }
  for (double h : hs)
    if (!(h > 0.0) || h > t_end) {
      std::fprintf(stderr, "peer_siconos_wp: --h-list: every step must lie in (0, T]\n");
      return 2;
    }
  for (double th : thetas)
    if (!(th >= 0.0 && th <= 1.0)) {
      std::fprintf(stderr, "peer_siconos_wp: --thetas: every theta must lie in [0, 1]\n");
      return 2;
    }
  for (const std::string& s : solvers)
    if (s != "lemke" && s != "pgs") {
      std::fprintf(stderr, "peer_siconos_wp: --solvers: lemke or pgs, not '%s'\n", s.c_str());
      return 2;
    }

  Eigen::VectorXd exact = closed_form_final(scene, t_end);
  if (print_exact) {
    if (exact.size() == 0) {
      std::fprintf(stderr, "peer_siconos_wp: %s has no closed-form final state\n", scene.c_str());
      return 1;
    }
    for (int i = 0; i < exact.size(); ++i) std::printf("%s%.17g", i ? "," : "", exact(i));
    std::printf("\n");
    return 0;
  }
  if (!exact_given.empty()) {
    if (static_cast<long>(exact_given.size()) != spec.x0.size()) {
      std::fprintf(stderr, "peer_siconos_wp: --exact: %zu entries, the state has %ld\n",
                   exact_given.size(), static_cast<long>(spec.x0.size()));
      return 2;
    }
    exact = Eigen::Map<const Eigen::VectorXd>(exact_given.data(), spec.x0.size());
  }
  if (exact.size() == 0) {
    std::fprintf(stderr, "peer_siconos_wp: %s: give the exact final state with --exact\n",
                 scene.c_str());
    return 2;
  }

  std::vector<Row> rows;
  {
    const StdoutToStderr quiet;  // Siconos's diagnostics go to stderr
    // The error is taken at T only; a run that stops early is flagged "short".
    const auto exact_at = [&exact](double) { return exact; };
    for (double theta : thetas)
      for (const std::string& solver : solvers)
        for (double h : hs) {
          Row row;
          char method[64];
          std::snprintf(method, sizeof method, "mj_theta%g_%s", theta, solver.c_str());
          row.method = method;
          row.param = format_param("h", h);
          row.theta = theta;
          row.solver = solver;
          row.h = h;
          const int id = solver == "lemke" ? SICONOS_LCP_LEMKE : SICONOS_LCP_PGS;
          rows.push_back(measure(row, repeats, t_end, exact_at, [&spec, t_end, theta, h, id] {
            return run_moreau_jean(spec, t_end, theta, h, id);
          }));
        }
  }
  char title[160];
  std::snprintf(title, sizeof title, "%s, Siconos 4.4 (Debian) Moreau–Jean, T = %g", scene.c_str(),
                t_end);
  print_rows(rows, json, scene, title);
  return 0;
}
