#include <sstream>
#include <stdexcept>

#include "sim/sim.hpp"

namespace lcsim::sim {

std::string_view to_string(EventType t) {
  switch (t) {
    case EventType::kImpact:
      return "impact";
    case EventType::kRelease:
      return "release";
    case EventType::kContact:
      return "contact";
    case EventType::kAccumulation:
      return "accumulation";
    case EventType::kStart:
      return "start";
  }
  return "unknown";
}

namespace {

class EventDrivenIntegrator : public Integrator {
 public:
  std::string name() const override { return "event"; }
  Trajectory run(const mech::Model& model, const VectorXd& x0, const Options& opt) const override {
    return simulate_event_driven(model, x0, opt);
  }
};

}  // namespace

// Time-stepping schemes (src/sim/time_stepping.cpp): backward Euler
// (Algorithm 7.3.1) and the Moreau–Jean theta-method.
std::unique_ptr<Integrator> make_euler_integrator();
std::unique_ptr<Integrator> make_moreau_jean_integrator();

std::vector<std::string> integrator_names() { return {"event", "euler", "moreau-jean"}; }

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  if (name == "event") return std::make_unique<EventDrivenIntegrator>();
  if (name == "euler") return make_euler_integrator();
  if (name == "moreau-jean") return make_moreau_jean_integrator();
  std::ostringstream msg;
  msg << "unknown method '" << name << "' (known:";
  for (const auto& n : integrator_names()) msg << " " << n;
  msg << ")";
  throw std::invalid_argument(msg.str());
}

}  // namespace lcsim::sim
