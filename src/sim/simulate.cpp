// The checked entry points of a run: Integrator::run and sim::simulate.
#include <lcsim/sim/sim.hpp>
#include <stdexcept>

namespace lcsim::sim {

namespace {
Trajectory refused(std::string method, std::string message) {
  Trajectory tr;
  tr.method = std::move(method);
  tr.status = RunStatus::kInvalidInput;
  tr.message = std::move(message);
  return tr;
}
}  // namespace

Trajectory Integrator::run(const mech::Model& model, const VectorXd& x0, const Options& opt) const {
  Options resolved = opt;
  if (!resolved.t_end && std::isfinite(model.t_end)) resolved.t_end = model.t_end;
  const OptionsUsed used = options_used();
  if (std::string why = check_run(model, x0, resolved, name(), used); !why.empty())
    return refused(name(), std::move(why));
  return integrate(model, x0, resolved);
}

Trajectory simulate(const mech::Model& model, const VectorXd& x0, const Options& opt,
                    std::string_view method) {
  if (!integrators().contains(method))
    return refused(std::string(method), integrators().unknown_message(method));
  return make_integrator(method)->run(model, x0, opt);
}

Trajectory simulate(const mech::Model& model, const Options& opt, std::string_view method) {
  if (model.initial.size() == 0)
    return refused(std::string(method), "model '" + model.name +
                                            "' has no initial state: give one, or set "
                                            "`initial` in the model");
  return simulate(model, model.initial, opt, method);
}

}  // namespace lcsim::sim
