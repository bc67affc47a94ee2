// Internal to src/bullet: what the Bullet scenes (the rigid bodies of
// world.cpp, the multibody of multibody_world.cpp, the scene of bodies of
// bodies_world.cpp) report after each step, through their one step loop
// (step_loop.hpp), so that all fill the same sim::Trajectory in the same way.
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

// Bullet applies dampers as explicit forces (-D v before the step, then
// v+ = v + h M^{-1} F: btRigidBody::integrateVelocities, and for the
// multibody btMultiBody::computeAccelerationsArticulatedBodyAlgorithmMultiDof
// then applyDeltaVeeMultiDof), so the damping term alone multiplies v by
// I - h M^{-1} D each step: stable only for h <= 2 / lambda_max(M^{-1} D).
// Counts the warning "bullet-explicit-damping" when D != 0, stating that
// bound from the model's own M and D (`what`: "forces" or "joint torques")
// and whether opt.h is above it.
void warn_explicit_damping(sim::Trajectory& tr, const mech::MechanicalModel& m, double h,
                           const char* what);

class RunRecorder {
 public:
  // Records the sample at t = 0 (with `friction_outputs`, the run gives
  // friction(): its u_t, u_t2 zero).
  RunRecorder(const mech::Model& model, const sim::Options& opt, sim::Trajectory& tr,
              const Eigen::VectorXd& q0, const Eigen::VectorXd& v0, bool friction_outputs = false);
  // One step of length h ending at t (the last one when `last`), from the
  // state held to (q, v), with constraint impulses `impulse` (h u, size k).
  // "" when recorded; else the state diverged (sim::DivergenceGuard): nothing
  // more is recorded, the run is finished at the last sane step (its final
  // state, and t_end the time it reached) and the message says what.
  std::string step(double t, double h, bool last, const Eigen::VectorXd& q,
                   const Eigen::VectorXd& v, const Eigen::VectorXd& impulse, double tiny);
  // Final state and energy.
  void finish();
  // The next step's friction impulses on each contact row's point along its
  // tangents t1, t2 (N s, by row of E): that step's sample gives each
  // friction entry's (mech::MechanicalModel::friction) u_t and, for 3-D
  // friction, u_t2 (the impulse / h). Without it a sample has none.
  void friction(const Eigen::VectorXd& t1, const Eigen::VectorXd& t2);

 private:
  void record(double t, const Eigen::VectorXd& u, double h = 0.0);
  const mech::MechanicalModel& m_;
  const sim::Options& opt_;
  sim::Trajectory& tr_;
  sim::OutputSampler sampler_;
  sim::DivergenceGuard guard_;
  Eigen::VectorXd q_, v_, y_;
  double t_ = 0.0;  // time of (q_, v_), the last step recorded (s)
  sim::IndexSet mode_;
  Eigen::VectorXd ft1_, ft2_;  // friction(): the step's tangential impulses by row
};

}  // namespace lcsim::bullet
