// Internal to src/bullet: the one step loop of Bullet's three scenes (the
// rigid bodies of world.cpp, the multibody of a URDF in multibody_world.cpp,
// the scene of bodies in bodies_world.cpp). A scene's world says how it forms
// a step's forces, steps and reads the step's impulses; the loop over the
// time-stepping grid, the progress callback, the rounding scale below which
// an impulse is no contact, and the recording are written once here.
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <utility>

#include "bullet/run_recorder.hpp"

namespace lcsim::bullet {

// A step just taken: from velocity v to v_next in h under the forces F.
struct StepTaken {
  const Eigen::VectorXd& v;
  const Eigen::VectorXd& v_next;
  const Eigen::VectorXd& F;
  double h = 0.0;
};

// `tr` as a run that failed with `message` (a numerical failure): what a
// scene returns when it cannot run.
sim::Trajectory failed_run(sim::Trajectory tr, const std::string& message);

// A run of `method` ("bullet ..."): its horizon, and x0 as its final state
// until it steps.
sim::Trajectory started_run(const std::string& method, const Eigen::VectorXd& x0,
                            const sim::Options& opt);

// Steps the world w, built and at x0, over opt's grid (sim::StepGrid: n
// steps of opt.h, the last shortened to end at t_end) and records every step
// in `tr` (RunRecorder; with `friction_outputs` the samples carry friction);
// `tr` then, or on a divergence a numerical failure saying so. The world's
// calls, found by argument-dependent lookup:
//   step_forces(w, q, v, F): the generalised forces F (size N) held through
//     the step from (q, v);
//   take_step(w, q, F, h, q_next, v_next): one Bullet step of length h under
//     F from q, and the state it reached;
//   step_impulses(w, taken, impulse, t1, t2): the step's constraint impulses
//     by row of E (N s, h u); true when t1, t2 hold each contact row's
//     friction impulse along its tangents for RunRecorder::friction.
template <class World>
sim::Trajectory run_steps(World& w, const mech::Model& model, const Eigen::VectorXd& x0,
                          const sim::Options& opt, sim::Trajectory tr, bool friction_outputs) {
  const mech::MechanicalModel& m = *model.mechanical;
  const int N = m.dofs(), k = m.num_constraints();
  Eigen::VectorXd q = x0.head(N), v = x0.tail(N);
  RunRecorder rec(model, opt, tr, q, v, friction_outputs);
  const sim::StepGrid grid = sim::StepGrid::of(*opt.t_end, opt.h);
  Eigen::VectorXd F(N), q_next(N), v_next(N), impulse(k), t1(k), t2(k);
  for (long j = 1; j <= grid.n; ++j) {
    const bool last = j == grid.n;
    if (opt.progress && j % sim::Options::kProgressSteps == 0) opt.progress(j * opt.h);
    const double h = last ? grid.h_last : grid.h;
    step_forces(w, q, v, F);
    take_step(w, q, F, h, q_next, v_next);
    if (step_impulses(w, StepTaken{v, v_next, F, h}, impulse, t1, t2)) rec.friction(t1, t2);
    // Round-off in an impulse (the momentum balance) is ~1e-16 of the
    // momentum; the impulses of real contacts are O(h).
    const double tiny =
        1e-10 * (1.0 + (m.M * v).cwiseAbs().maxCoeff() + h * F.cwiseAbs().maxCoeff());
    if (std::string why =
            rec.step(last ? *opt.t_end : j * opt.h, h, last, q_next, v_next, impulse, tiny);
        !why.empty())
      return failed_run(std::move(tr), "bullet: " + why);
    q = q_next;
    v = v_next;
  }
  rec.finish();
  return tr;
}

}  // namespace lcsim::bullet
