// What every running command resolves the same way: the initial state (--x0
// or the model's `initial`) and the horizon (--t-end or the model's t_end).
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <string>

namespace lcsim::cli {

// io::InputError (one line) when absent or of the wrong size. `what` names
// the missing thing in the message ("initial state", "state").
Eigen::VectorXd resolve_initial_state(const mech::Model& model, const std::string& model_path,
                                      const std::string& x0_text,
                                      const std::string& what = "initial state");

// The horizon: --t-end if given (a given NaN is an error, not the model's),
// else the model's; io::InputError unless finite and > 0.
double resolve_horizon(const mech::Model& model, const std::string& model_path, bool t_end_given,
                       double t_end);

}  // namespace lcsim::cli
