// Time-stepping integrators: backward Euler for general LCS (Algorithm 7.3.1)
// and the Moreau–Jean theta-method for mechanical models.
//
// Both march on a fixed grid t_j = j h (the last step is shortened to land on
// t_end exactly when h does not divide it), solve one LCP per step (Moreau–Jean:
// only when some constraint is predicted to close) and report the same
// Trajectory as the event-driven method. Nothing throws inside the step loop:
// an LCP failure or a non-finite state ends the run with status kFailed and a
// message; the last good state is reported.
//
// Samples: every step when Options::dt_out = 0, otherwise the first step time
// at or after each multiple of dt_out (equal to it when dt_out is a multiple of
// h), always the initial and the final state. For time-stepping, Sample::u is
// the LCP multiplier as a force: backward Euler's u_{k+1} of (7.4), and the
// Moreau–Jean impulse divided by the step (the mean force over the step).
//
// This file registers them (make_euler_integrator, make_moreau_jean_integrator)
// and holds what they share; the schemes are in euler.cpp and moreau_jean.cpp.
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <string>

#include "sim/stepping/time_stepping_detail.hpp"

namespace lcsim::sim {

std::string detail::lcp_failure(const char* method, double t, const lcp::Result& r) {
  return std::string(method) + ": LCP failed at t = " + short_number(t) + " (" +
         std::string(lcp::to_string(r.status, "solved")) + ")" +
         (r.message.empty() ? "" : ": " + r.message);
}

namespace {

class EulerIntegrator : public Integrator {
 public:
  std::string name() const override { return "euler"; }
  OptionsUsed options_used() const override {
    OptionsUsed u;  // every impact inelastic: Options::impact is not read
    u.h = u.lcp_solver = u.force = u.dense_lcs = true;
    u.sensitivity = true;  // the discrete map's derivative (step_sensitivity.hpp)
    u.inputs = true;       // force inputs evaluated at each step's end (euler.cpp)
    u.friction = true;     // Moreau–Jean's friction LCP at theta = 1 (euler_friction.cpp)
    u.friction_3d = true;  // its cone in Stewart and Trinkle's form (the same)
    return u;
  }
  Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                       const Options& opt) const override {
    return detail::run_euler(model, x0, opt);
  }
};

class MoreauJeanIntegrator : public Integrator {
 public:
  std::string name() const override { return "moreau-jean"; }
  OptionsUsed options_used() const override {
    OptionsUsed u;  // its impact law is restitution inside the step LCP
    u.h = u.theta = u.lcp_solver = u.linear_algebra = u.needs_mechanical = true;
    u.friction = true;      // the friction LCP in every step (mj_friction.hpp)
    u.friction_3d = true;   // the cone's LCP in Stewart and Trinkle's form (the same)
    u.sensitivity = true;   // the discrete map's derivative, frictionless (step_sensitivity.hpp)
    u.symmetric_dk = true;  // W by Cholesky (step_kernels.hpp)
    u.inputs = true;        // force inputs theta-weighted over each step (step_kernels.hpp)
    return u;
  }
  Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                       const Options& opt) const override {
    return detail::run_moreau_jean(model, x0, opt);
  }
};

}  // namespace

std::unique_ptr<Integrator> make_euler_integrator() { return std::make_unique<EulerIntegrator>(); }
std::unique_ptr<Integrator> make_moreau_jean_integrator() {
  return std::make_unique<MoreauJeanIntegrator>();
}

}  // namespace lcsim::sim
