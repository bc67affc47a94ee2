// The two carts with a stop of thesis §3.7 (robots/two_carts.yaml), simulated
// with lcsim as a library: load the model file, run the exact event-driven
// method to the model's own horizon (t_end: 3 s in the file), then print the
// events and the final state.
//
//   usage: two_carts <path to robots/two_carts.yaml>
#include <cstdio>
#include <exception>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s robots/two_carts.yaml\n", argv[0]);
    return 2;
  }
  try {
    // Throws lcsim::io::InputError naming the file, key and value on bad input.
    const lcsim::mech::Model model = lcsim::scene::load_model(argv[1]);
    if (!model.is_mechanical()) {  // an `lcs:` file has no masses or contacts
      std::fprintf(stderr, "%s: not a mechanical model\n", argv[1]);
      return 2;
    }
    lcsim::sim::Options opt;                             // defaults, but the horizon:
    opt.t_end = model.t_end;                             // the model's own (3 s in the file)
    auto method = lcsim::sim::make_integrator("event");  // the exact method
    // The model's initial state (q then v), as the file gives it.
    const lcsim::sim::Trajectory traj = method->run(model, model.initial, opt);
    if (traj.status != lcsim::Status::kCompleted) {
      std::fprintf(stderr, "run failed at t = %g: %s\n", traj.t_end, traj.message.c_str());
      return 3;
    }
    for (const lcsim::sim::Event& e : traj.events)
      std::printf("event at t = %.9f: %s\n", e.t,
                  std::string(lcsim::sim::to_string(e.type)).c_str());
    // The state is q then v; the coordinate names come from the file.
    const auto& names = model.mechanical->coordinates;
    const int n = model.mechanical->dofs();
    std::printf("final state at t = %g:\n", traj.t_end);
    for (int i = 0; i < n; ++i)
      std::printf("  %s = %+.9f m, %s' = %+.9f m/s\n", names[i].c_str(), traj.final_state[i],
                  names[i].c_str(), traj.final_state[n + i]);
    std::printf("energy: %.9f J -> %.9f J\n", traj.energy_initial, traj.energy_final);
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
