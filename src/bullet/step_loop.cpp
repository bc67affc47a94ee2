// The step loop of Bullet's scenes (step_loop.hpp): how a run starts and
// fails.
#include "bullet/step_loop.hpp"

namespace lcsim::bullet {

sim::Trajectory failed_run(sim::Trajectory tr, const std::string& message) {
  tr.status = sim::RunStatus::kNumericalFailure;
  tr.message = message;
  return tr;
}

sim::Trajectory started_run(const std::string& method, const Eigen::VectorXd& x0,
                            const sim::Options& opt) {
  sim::Trajectory tr;
  tr.method = method;
  tr.t_end = *opt.t_end;
  tr.final_state = x0;
  return tr;
}

}  // namespace lcsim::bullet
