// Private to src/sim: what the two time-stepping integrators share
// (time_stepping.cpp registers them; euler.cpp and moreau_jean.cpp run them).
#pragma once

#include <lcsim/lcp/lcp.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::sim::detail {

// The message of a step whose LCP failed, for both schemes.
std::string lcp_failure(const char* method, double t, const lcp::Result& r);

// Backward Euler (euler.cpp) and the Moreau–Jean theta-method (moreau_jean.cpp)
// on input that Integrator::run has checked.
Trajectory run_euler(const mech::Model& model, const VectorXd& x0_user, const Options& opt);
// Backward Euler on a mechanical model with friction (euler_friction.cpp):
// the step of Moreau–Jean's friction LCP at theta = 1 with the normal rows at
// the position level; run_euler takes it where the model has friction.
Trajectory run_euler_friction(const mech::Model& model, const VectorXd& x0, const Options& opt);
Trajectory run_moreau_jean(const mech::Model& model, const VectorXd& x0, const Options& opt);

}  // namespace lcsim::sim::detail
