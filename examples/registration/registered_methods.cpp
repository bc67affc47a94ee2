// Linking the optional components lcsim::bullet and lcsim::ipopt (and
// lcsim::mujoco) is all it takes to use their methods: no registration call.
// Lists the methods of each registry and makes the optional ones by name
// (make_* throws std::invalid_argument naming the known ones when a name is
// unknown); "mujoco" too when it is registered.
//
// CMake: target_link_libraries(app lcsim::bullet lcsim::ipopt [lcsim::mujoco])
// pkg-config: g++ -std=c++20 registered_methods.cpp
//                 $(pkg-config --cflags --libs lcsim-bullet lcsim-ipopt [lcsim-mujoco])
#include <algorithm>
#include <cstdio>
#include <exception>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace {
void print(const char* what, const std::vector<std::string>& names) {
  std::printf("%s:", what);
  for (const std::string& n : names) std::printf(" %s", n.c_str());
  std::printf("\n");
}
}  // namespace

int main() {
  print("integrators", lcsim::sim::integrator_names());
  print("impact laws", lcsim::impact::impact_law_names());
  print("LCP solvers", lcsim::lcp::solver_names());
  try {
    std::printf("made %s, %s and %s\n", lcsim::sim::make_integrator("bullet")->name().c_str(),
                lcsim::impact::make_impact_law("moreau-qp")->name().c_str(),
                lcsim::lcp::make_solver("bullet-dantzig")->name().c_str());
    const std::vector<std::string> integrators = lcsim::sim::integrator_names();
    if (std::find(integrators.begin(), integrators.end(), "mujoco") != integrators.end())
      std::printf("made %s\n", lcsim::sim::make_integrator("mujoco")->name().c_str());
    return 0;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "%s\n", e.what());
    return 1;
  }
}
