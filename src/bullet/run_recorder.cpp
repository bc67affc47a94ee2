#include "bullet/run_recorder.hpp"

#include <algorithm>
#include <utility>

namespace lcsim::bullet {

using Eigen::VectorXd;

RunRecorder::RunRecorder(const mech::MechanicalModel& m, const sim::Options& opt,
                         sim::Trajectory& tr, const VectorXd& q0, const VectorXd& v0)
    : m_(m), opt_(opt), tr_(tr), sampler_(opt.dt_out), q_(q0), v_(v0) {
  tr_.energy_initial = mech::total_energy(m_, q_, v_);
  y_ = m_.E * q_ + m_.g;
  if (m_.num_constraints() > 0) tr_.max_violation = std::min(0.0, y_.minCoeff());
  record(0.0, VectorXd::Zero(m_.num_constraints()));
}

void RunRecorder::record(double t, const VectorXd& u) {
  if (!opt_.record_samples) return;
  sim::Sample smp;
  smp.t = t;
  smp.x.resize(2 * m_.dofs());
  smp.x << q_, v_;
  smp.u = u;
  smp.y = y_;
  smp.mode = mode_;
  tr_.record_sample(std::move(smp), opt_);
}

void RunRecorder::step(double t, double h, bool last, const VectorXd& q, const VectorXd& v,
                       const VectorXd& impulse, double tiny) {
  const int N = m_.dofs(), k = m_.num_constraints();
  sim::IndexSet mode;
  for (int i = 0; i < k; ++i)
    if (impulse(i) > tiny) mode.push_back(i);
  if (mode != mode_) {
    sim::Event e;
    e.t = t;
    e.state_before.resize(2 * N);
    e.state_before << q_, v_;
    e.state_after.resize(2 * N);
    e.state_after << q, v;
    e.mode_after = mode;
    e.impulse = impulse;
    bool gained = false, lost = false, approaching = false;
    for (int i : mode)
      if (std::find(mode_.begin(), mode_.end(), i) == mode_.end()) {
        gained = true;
        if (m_.E.row(i).dot(v_) < 0.0) approaching = true;
      }
    for (int i : mode_)
      if (std::find(mode.begin(), mode.end(), i) == mode.end()) lost = true;
    e.type = approaching       ? sim::EventType::kImpact
             : lost && !gained ? sim::EventType::kRelease
                               : sim::EventType::kContact;
    tr_.events.push_back(std::move(e));
    mode_ = std::move(mode);
  }
  q_ = q;
  v_ = v;
  ++tr_.steps;
  if (k > 0) ++tr_.lcp_solves;  // the constraint solver runs every step
  y_ = m_.E * q_ + m_.g;
  if (k > 0) tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y_.minCoeff()));
  if (sampler_.want(t, opt_.h, last)) record(t, k > 0 ? VectorXd(impulse / h) : VectorXd());
}

void RunRecorder::finish() {
  tr_.final_state.resize(2 * m_.dofs());
  tr_.final_state << q_, v_;
  tr_.energy_final = mech::total_energy(m_, q_, v_);
}

}  // namespace lcsim::bullet
