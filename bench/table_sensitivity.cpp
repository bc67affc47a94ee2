// The cost of forward sensitivities (docs/sensitivities.md) against the
// plain exact run, for issue 28's targets: dx(T)/dx0 at most 3x the plain
// run, dx(T)/dp for one parameter (f[0]) at most 1.5x. Each model is run as
// `lcsim simulate MODEL --json` runs it (app::run_model: a scene records its
// samples for the linearisation check), plain, with `--sensitivity x0` and
// with `--sensitivity f[0]`, alternately (plain, x0, f[0], plain, ...) REPS
// times in one process, so the three see the same load; the figure is the
// best `wall_time_s` of each (the run alone, not the loading), beside the
// median ratio of the rounds. The load average is printed before and after.
//   build/bench/table_sensitivity REPS NAME=MODEL[@T_END] ...
// bench/run_sensitivity_bench.sh runs it on the NAO legs and the chain of 100.
#include <algorithm>
#include <cstdio>
#include <exception>
#include <fstream>
#include <lcsim/app/run.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>
#include <vector>

namespace {

std::string load_average() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

// One run's wall time (s), or a negative value when it did not complete.
double run_once(const lcsim::scene::LoadedModel& loaded, double t_end,
                const std::vector<std::string>& sensitivity) {
  lcsim::app::RunRequest req;
  req.method = "event";
  req.options.t_end = t_end;
  req.options.sensitivity = sensitivity;
  const lcsim::app::ModelRun run = lcsim::app::run_model(loaded, req);
  const auto& tr = run.trajectory;
  return tr.status == lcsim::sim::RunStatus::kCompleted ? tr.wall_time_s : -1.0;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

const char* verdict(double ratio, double target) { return ratio <= target ? "met" : "MISSED"; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::fprintf(stderr, "usage: table_sensitivity REPS NAME=MODEL[@T_END] ...\n");
    return 2;
  }
  const int reps = std::max(1, std::atoi(argv[1]));
  std::printf("load average before: %s\n", load_average().c_str());
  std::printf("%-20s %11s %11s %7s %7s %-6s %11s %7s %7s %-6s\n", "model", "plain_s", "x0_s",
              "ratio", "median", "(<=3)", "f[0]_s", "ratio", "median", "(<=1.5)");
  for (int i = 2; i < argc; ++i) {
    const std::string spec = argv[i];
    const size_t eq = spec.find('='), at = spec.find('@', eq);
    const std::string name = spec.substr(0, eq);
    const std::string path = spec.substr(eq + 1, at == std::string::npos ? at : at - eq - 1);
    lcsim::scene::LoadedModel loaded;
    try {
      loaded = lcsim::scene::load_model_and_scene(path);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "table_sensitivity: %s\n", e.what());
      return 2;
    }
    const double t_end =
        at == std::string::npos ? loaded.model.t_end : std::stod(spec.substr(at + 1));
    const std::vector<std::vector<std::string>> asks = {{}, {"x0"}, {"f[0]"}};
    std::vector<double> best(3, 1e300);
    std::vector<double> rx, rf;
    for (int r = 0; r < reps; ++r) {
      double w[3];
      for (int k = 0; k < 3; ++k) {
        w[k] = run_once(loaded, t_end, asks[static_cast<size_t>(k)]);
        if (w[k] < 0.0) {
          std::fprintf(stderr, "table_sensitivity: %s did not complete\n", name.c_str());
          return 3;
        }
        best[static_cast<size_t>(k)] = std::min(best[static_cast<size_t>(k)], w[k]);
      }
      rx.push_back(w[1] / w[0]);
      rf.push_back(w[2] / w[0]);
    }
    const double x = best[1] / best[0], f = best[2] / best[0];
    std::printf("%-20s %11.6f %11.6f %7.2f %7.2f %-6s %11.6f %7.2f %7.2f %-6s\n", name.c_str(),
                best[0], best[1], x, median(rx), verdict(x, 3.0), best[2], f, median(rf),
                verdict(f, 1.5));
    std::fflush(stdout);
  }
  std::printf("load average after: %s\n", load_average().c_str());
  return 0;
}
