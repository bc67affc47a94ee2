// Internal to src/bullet: what both Bullet scenes (the rigid bodies of
// world.cpp, the multibody of multibody_world.cpp) report after each step,
// so that both fill the same sim::Trajectory in the same way.
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::bullet {

// Samples (every step, or on the opt.dt_out grid), u = constraint impulse / h,
// mode = constraints with an impulse above `tiny` in the step, an event at
// every mode change (an impact when a gained constraint was approached, a
// release when constraints were only lost, else a contact), max_violation,
// steps, lcp_solves, energies (of the model at Bullet's states).

class RunRecorder {
 public:
  // Records the sample at t = 0.
  RunRecorder(const mech::MechanicalModel& m, const sim::Options& opt, sim::Trajectory& tr,
              const Eigen::VectorXd& q0, const Eigen::VectorXd& v0);
  // One step of length h ending at t (the last one when `last`), from the
  // state held to (q, v), with constraint impulses `impulse` (h u, size k).
  void step(double t, double h, bool last, const Eigen::VectorXd& q, const Eigen::VectorXd& v,
            const Eigen::VectorXd& impulse, double tiny);
  // Final state and energy.
  void finish();

 private:
  void record(double t, const Eigen::VectorXd& u);
  const mech::MechanicalModel& m_;
  const sim::Options& opt_;
  sim::Trajectory& tr_;
  sim::OutputSampler sampler_;
  Eigen::VectorXd q_, v_, y_;
  sim::IndexSet mode_;
};

}  // namespace lcsim::bullet
