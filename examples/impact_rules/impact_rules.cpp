// Every impact rule lcsim knows, applied to the two carts with a stop and a
// hook (thesis Example 3.8.3, robots/two_carts_hook.yaml): at the model's
// initial state both gaps are closed and both are closing, so the rules
// disagree. Prints each rule's post-impact velocity and kinetic energy.
//
//   usage: impact_rules <path to robots/two_carts_hook.yaml>
#include <cstdio>
#include <exception>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/scene/scene.hpp>
#include <string>

namespace {
std::string text(const Eigen::VectorXd& v) {  // "(a, b)"
  std::string s = "(";
  for (int i = 0; i < v.size(); ++i) s += (i ? ", " : "") + std::to_string(v[i]);
  return s + ")";
}
}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s robots/two_carts_hook.yaml\n", argv[0]);
    return 2;
  }
  try {
    const lcsim::mech::Model model = lcsim::scene::load_model(argv[1]);
    if (!model.is_mechanical()) {  // an `lcs:` file has no masses or contacts
      std::fprintf(stderr, "%s: not a mechanical model\n", argv[1]);
      return 2;
    }
    const lcsim::mech::MechanicalModel& m = *model.mechanical;
    const int n = m.dofs();
    // The pre-impact state: the model's initial one, q then v.
    lcsim::impact::ImpactInput in;
    in.model = &m;
    in.q = model.initial.head(n);
    in.v = model.initial.tail(n);
    // The closed contacts are those with zero gap E q + g (here exactly 0).
    const Eigen::VectorXd gap = lcsim::mech::gaps(m, in.q);
    for (int i = 0; i < m.num_constraints(); ++i)
      if (gap[i] == 0.0) in.closed.push_back(i);
    std::printf("before: v = %s m/s, kinetic energy %.6f J, %zu closed contacts\n",
                text(in.v).c_str(), lcsim::mech::kinetic_energy(m, in.v), in.closed.size());
    auto solver = lcsim::lcp::make_solver("pivot");  // for the rules that solve an LCP
    std::printf("%-20s %-24s %-12s %s\n", "rule", "v+ (m/s)", "energy (J)", "admissible");
    for (const std::string& name : lcsim::impact::impact_law_names()) {
      const lcsim::impact::ImpactResult r =
          lcsim::impact::make_impact_law(name)->apply(in, *solver);
      if (!r.ok()) {
        std::printf("%-20s failed: %s\n", name.c_str(), r.message.c_str());
        continue;
      }
      std::printf("%-20s %-24s %-12.6f ", name.c_str(), text(r.v_after).c_str(), r.energy_after);
      std::printf("%s\n", r.admissible ? "yes" : "no (a negative impulse or E_J v+ < 0)");
    }
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 2;
  }
}
