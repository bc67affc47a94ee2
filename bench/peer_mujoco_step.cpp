// Moreau-Jean (lcsim) per step beside MuJoCo's mj_step on the same scene,
// side by side in one program (issue 26's target: Moreau-Jean at h = 1e-3
// no slower per step than MuJoCo's step on the legged robot).
//
// Moreau-Jean: the integrator run to T and to 2T (no samples), the per-step
// cost from the difference (its set-up cancels), the minimum over REPEAT
// pairs. MuJoCo: mujoco::mj_step_time (mj_step alone, over T / h steps),
// the minimum over REPEAT runs. Minima, since the machine is shared: a
// run's cost is its quietest repetition.
//
// Usage: peer_mujoco_step SCENE [h = 1e-3] [T = 1] [REPEAT = 7]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <lcsim/mujoco/mujoco.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <string>

namespace {

double wall_of(const lcsim::mech::Model& m, const std::string& method, double h, double T) {
  lcsim::sim::Options o;
  o.t_end = T;
  o.h = h;
  o.dt_out = 0.0;
  const auto integ = lcsim::sim::make_integrator(method);
  const auto t0 = std::chrono::steady_clock::now();
  const auto tr = integ->run(m, m.initial, lcsim::sim::keep_used(o, integ->options_used()));
  const double w = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (tr.status != lcsim::sim::RunStatus::kCompleted) {
    std::fprintf(stderr, "%s failed: %s\n", method.c_str(), tr.message.c_str());
    std::exit(3);
  }
  return w;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SCENE [h] [T] [REPEAT]\n", argv[0]);
    return 2;
  }
  const double h = argc > 2 ? std::atof(argv[2]) : 1e-3;
  const double T = argc > 3 ? std::atof(argv[3]) : 1.0;
  const int repeat = argc > 4 ? std::atoi(argv[4]) : 7;
  const lcsim::mech::Model m = lcsim::scene::load_model(argv[1]);
  const long steps = static_cast<long>(T / h + 0.5);
  double mj = std::numeric_limits<double>::infinity();
  double mu = std::numeric_limits<double>::infinity();
  for (int i = 0; i < repeat; ++i) {
    mj = std::min(mj, (wall_of(m, "moreau-jean", h, 2 * T) - wall_of(m, "moreau-jean", h, T)) /
                          static_cast<double>(steps));
    mu = std::min(mu, lcsim::mujoco::mj_step_time(m, m.initial, h, steps));
  }
  std::printf(
      "{\"scene\": \"%s\", \"h\": %g, \"steps\": %ld, \"moreau_jean_per_step_s\": %.6g, "
      "\"mj_step_per_step_s\": %.6g, \"ratio\": %.4g, \"mujoco\": \"%s\"}\n",
      m.name.c_str(), h, steps, mj, mu, mj / mu, lcsim::mujoco::version_string().c_str());
  return 0;
}
