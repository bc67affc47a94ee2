// The checked entry points of a run: Integrator::run and sim::simulate.
#include <chrono>
#include <cmath>
#include <lcsim/sim/sim.hpp>

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

std::optional<Trajectory> refuse_invalid_run(const mech::Model& model, const VectorXd& x0,
                                             Options& opt, std::string_view method,
                                             const OptionsUsed& used) {
  if (!opt.t_end && std::isfinite(model.t_end)) opt.t_end = model.t_end;
  if (std::string why = check_run(model, x0, opt, method, used); !why.empty())
    return refused(std::string(method), std::move(why));
  return std::nullopt;
}

std::optional<Trajectory> Integrator::refuse_resolved(const mech::Model& model, const VectorXd& x0,
                                                      Options& opt) const {
  if (auto refused_run = refuse_invalid_run(model, x0, opt, name(), options_used()))
    return refused_run;
  if (std::string why = refusal(model); !why.empty()) return refused(name(), std::move(why));
  return std::nullopt;
}

std::optional<Trajectory> Integrator::refuse(const mech::Model& model, const VectorXd& x0,
                                             const Options& opt) const {
  Options resolved = opt;
  return refuse_resolved(model, x0, resolved);
}

Trajectory Integrator::run(const mech::Model& model, const VectorXd& x0, const Options& opt) const {
  Options resolved = opt;
  if (auto refused_run = refuse_resolved(model, x0, resolved)) return std::move(*refused_run);
  const auto wall0 = std::chrono::steady_clock::now();
  Trajectory tr = integrate(model, x0, resolved);
  check_diverged(model, x0, tr);
  tr.wall_time_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  return tr;
}

void check_diverged(const mech::Model& model, const VectorXd& x0, Trajectory& tr) {
  if (tr.status != RunStatus::kCompleted) return;
  DivergenceGuard guard(model, x0, tr.t_end);
  std::string why = guard.check(tr.t_end, tr.final_state, true);
  if (why.empty()) why = guard.check_worst_gap(tr.max_violation);
  if (why.empty()) return;
  tr.status = RunStatus::kNumericalFailure;
  tr.message = tr.method + ": " + why;
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
