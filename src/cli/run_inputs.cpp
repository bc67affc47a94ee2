#include "cli/run_inputs.hpp"

#include <cmath>
#include <lcsim/io/io.hpp>

namespace lcsim::cli {

Eigen::VectorXd resolve_initial_state(const mech::Model& model, const std::string& model_path,
                                      const std::string& x0_text, const std::string& what) {
  Eigen::VectorXd x0 = model.initial;
  if (!x0_text.empty()) x0 = io::parse_vector(x0_text, "--x0");
  if (x0.size() == 0)
    throw io::InputError(model_path + ": no " + what + ": give --x0 or `initial` in the model");
  x0 = model.full_state(x0);  // an exosystem's states (a circuit's sources) are the model's
  if (x0.size() != model.state_size())
    throw io::InputError("--x0: has " + std::to_string(x0.size()) + " entries, the model '" +
                         model.name + "' has a state of size " +
                         std::to_string(model.state_size()) +
                         (model.is_mechanical() ? " (q then v)" : ""));
  return x0;
}

double resolve_horizon(const mech::Model& model, const std::string& model_path, bool t_end_given,
                       double t_end) {
  const double T = t_end_given ? t_end : model.t_end;
  if (!t_end_given && std::isnan(T))
    throw io::InputError(model_path + ": no horizon: give --t-end or `t_end` in the model");
  if (!(T > 0.0) || !std::isfinite(T))
    throw io::InputError("--t-end: must be a finite number > 0 (got " + std::to_string(T) + ")");
  return T;
}

}  // namespace lcsim::cli
