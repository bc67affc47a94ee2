// The exact method's output samples (issue 24, item 2): the wall time of a
// run on the dt_out grid less that of the same run with events only
// (dt_out = 0), per extra sample, for each model file given (default: a
// 32-cart chain, 65 states, one 10 s phase). Samples go to a sink that drops
// them, so the figure is the integrator's, not a writer's. Usage:
//   build/bench/table_samples [model.yaml ...]
// e.g. a 32-joint Talos scene (talos_reduced.urdf of Gepetto's
// example-robot-data, not shipped: its licence forbids derivatives).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {

struct Run {
  double wall = 0.0;  // best of `repeats`, s
  long samples = 0;
  std::string status;
};

Run run(const lcsim::mech::Model& model, double t_end, double dt_out, int repeats) {
  lcsim::sim::Options opt;
  opt.t_end = t_end;
  opt.dt_out = dt_out;
  long samples = 0;
  opt.sample_sink = [&](const lcsim::sim::Sample&) { ++samples; };
  Run r;
  r.wall = 1e300;
  for (int i = 0; i < repeats; ++i) {
    samples = 0;
    const auto t0 = std::chrono::steady_clock::now();
    const auto tr = lcsim::sim::simulate_event_driven(model, model.initial, opt);
    const std::chrono::duration<double> d = std::chrono::steady_clock::now() - t0;
    r.wall = std::min(r.wall, d.count());
    r.samples = samples;
    r.status = tr.message.empty() ? "completed" : tr.message.substr(0, 60);
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::pair<std::string, lcsim::mech::Model>> models;
  if (argc < 2)
    models.emplace_back("chain of 32 carts", lcsim::mech::chain_model({32, false, false, true}));
  for (int i = 1; i < argc; ++i) try {
      models.emplace_back(argv[i], lcsim::scene::load_model(argv[i]));
    } catch (const std::exception& e) {  // a model the loader refuses: its one line
      std::fprintf(stderr, "table_samples: %s\n", e.what());
      return 2;
    }
  std::printf("%-28s %8s %10s %9s %12s %14s\n", "model", "dt_out", "samples", "wall s",
              "events-only s", "per sample us");
  for (const auto& [name, model] : models) {
    const double t_end = model.t_end;
    const Run base = run(model, t_end, 0.0, 3);
    for (const double dt : {t_end / 200.0, 1e-3, 1e-4}) {
      const Run r = run(model, t_end, dt, 3);
      const double per = (r.wall - base.wall) / static_cast<double>(r.samples - base.samples);
      std::printf("%-28s %8.2g %10ld %9.4f %12.4f %14.2f  %s\n", name.substr(0, 28).c_str(), dt,
                  r.samples, r.wall, base.wall, 1e6 * per, r.status.c_str());
    }
  }
  return 0;
}
