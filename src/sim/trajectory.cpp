#include <functional>
#include <sstream>
#include <utility>
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

namespace {
using Factory = std::function<std::unique_ptr<Integrator>()>;
// Integrators registered by later layers (register_integrator), in order.
std::vector<std::pair<std::string, Factory>>& extra_integrators() {
  static std::vector<std::pair<std::string, Factory>> registry;
  return registry;
}
}  // namespace

void register_integrator(std::string name, std::function<std::unique_ptr<Integrator>()> factory) {
  for (auto& [n, f] : extra_integrators())
    if (n == name) {
      f = std::move(factory);
      return;
    }
  extra_integrators().emplace_back(std::move(name), std::move(factory));
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names = {"event", "euler", "moreau-jean"};
  for (const auto& [n, f] : extra_integrators()) names.push_back(n);
  return names;
}

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  if (name == "event") return std::make_unique<EventDrivenIntegrator>();
  if (name == "euler") return make_euler_integrator();
  if (name == "moreau-jean") return make_moreau_jean_integrator();
  for (const auto& [n, f] : extra_integrators())
    if (name == n) return f();
  std::ostringstream msg;
  msg << "unknown method '" << name << "' (known:";
  for (const auto& n : integrator_names()) msg << " " << n;
  msg << ")";
  throw std::invalid_argument(msg.str());
}

}  // namespace lcsim::sim
