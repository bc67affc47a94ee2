// Scheduled events of the exact method (issue 29; docs/inputs.md): the
// breakpoints of a model's inputs (a step, a pulse's edges, a PWL's points).
// Between them each input is the output of its exosystem, appended to the
// state (mech::to_lcs), so a phase is still one matrix exponential; at a
// breakpoint the phase ends, the exosystem's state is re-initialised to the
// next piece (mech::exosystem_states) and the mode is selected again, as at
// any event (the new force may open a closed contact). The state q, v is
// continuous there: a bounded force jump gives no impulse.
#include <cmath>
#include <lcsim/core/format.hpp>

#include "sim/exact/event_driven_detail.hpp"
#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim::detail {

// A mechanical model's inputs, or an `lcs:` model's (a circuit's PULSE and
// PWL sources, mech::Model::inputs): either way their exosystems are the last
// states of the LCS, so one mechanism serves both.
// A switched circuit's switch times (mech::Model::switch_times) are
// scheduled events too.
double EventDriven::next_scheduled(double t) const {
  const std::vector<mech::Input>& inputs = model_.scheduled_inputs();
  double next = std::numeric_limits<double>::infinity();
  if (!inputs.empty()) next = mech::next_breakpoint(inputs, t);
  const std::size_t i = model_.interval_at(t);
  if (i < model_.switch_times.size()) next = std::min(next, model_.switch_times[i]);
  return next;
}

// The state is the same in every configuration (a switch is a resistor of
// RON or ROFF: no state jumps), so swapping the matrices is all; the mode is
// selected again after (take_scheduled), on the new matrices.
std::string EventDriven::swap_configuration(double t0, double t_b) {
  const std::size_t i = model_.interval_at(t0);
  if (i >= model_.switch_times.size() || model_.switch_times[i] != t_b) return "";
  if (config_caches_.empty()) config_caches_.resize(model_.configurations.size());
  ConfigCaches& before = config_caches_[static_cast<std::size_t>(config_)];
  swap_caches(before);  // the old configuration's caches, kept
  before.built = true;
  config_ = model_.switch_config[i + 1];
  sys_ = model_.configurations[static_cast<std::size_t>(config_)].lcs;
  ConfigCaches& after = config_caches_[static_cast<std::size_t>(config_)];
  if (after.built) {
    swap_caches(after);
    after.built = false;
  } else {
    feedback_cache_.clear();
    rho_cache_.clear();
    step_cache_.clear();
    ldcp_data_ = lcs::ldcp_data(sys_);
    rho_A_ = spectral_radius_bound(sys_.A);
  }
  return model_.switch_notes[i];
}

void EventDriven::swap_caches(ConfigCaches& c) {
  std::swap(c.ldcp, ldcp_data_);  // ldcp_.data points at ldcp_data_, which stays
  std::swap(c.rho_A, rho_A_);
  std::swap(c.feedback, feedback_cache_);
  std::swap(c.rho, rho_cache_);
  std::swap(c.step, step_cache_);
}

// The event at the breakpoint t_b that ended the phase pm: the state there,
// the exosystem re-initialised, the mode selected; false when the run ends.
// Not counted by the Zeno or livelock guards: breakpoints are the user's,
// finitely many in any interval, and need no guard against accumulating.
bool EventDriven::take_scheduled(RunState& r, PhaseMarch& pm, double t_b) {
  Trajectory& tr = r.tr;
  const std::vector<mech::Input>& inputs = model_.scheduled_inputs();
  const VectorXd x_minus = pm.state_at(t_b);
  const bool keep = static_cast<long>(tr.events.size()) < opt_.max_recorded_events;
  if (keep) record(tr, t_b, x_minus, r.phase);  // before a swap: the old configuration's
  std::string names;
  for (const mech::Input& in : inputs)
    if (in.next_breakpoint(pm.t0) == t_b) names += (names.empty() ? "'" : ", '") + in.name + "'";
  const std::string switched = swap_configuration(pm.t0, t_b);
  r.t = t_b;
  // Sensitivities: a fixed time (dt_b/dtheta = 0), q and v continuous, w a
  // function of t alone (docs/sensitivities.md).
  VectorXd x_b = x_minus;
  const VectorXd w = mech::exosystem_states(inputs, t_b);
  x_b.tail(w.size()) = w;
  if (sens_) {
    sens_->before_event(t_b, x_minus, -1);
    sens_->reset_exosystem(static_cast<int>(w.size()));
  }
  // pm refers to r.phase, which reinitialise replaces: not used below.
  EventResult ev;
  const lcs::IndexSet old_mode = r.phase.mode;
  if (!reinitialise(r, x_b, ev)) {
    r.xa = x_b;
    return false;
  }
  if (sens_) sens_->after_event(ev, r.phase, r.t, r.xa, old_mode, -1);
  if (!keep) {
    if (tr.events_not_recorded++ == 0)
      tr.warn("events-not-recorded", r.t,
              "more than " + std::to_string(opt_.max_recorded_events) +
                  " events: later events and their samples are counted, not recorded");
    return true;
  }
  Event e;
  e.t = r.t;
  e.type = EventType::kSchedule;
  e.state_before = user(x_minus);
  e.state_after = user(r.xa);
  e.mode_after = ev.mode;
  e.impulse = ev.impulse;
  set_friction(e, ev);
  if (!names.empty()) e.note = "breakpoint of input " + names;
  if (!switched.empty()) e.note += (names.empty() ? "switch: " : "; switch: ") + switched;
  if (sens_) sens_->fill_event(e);
  tr.events.push_back(std::move(e));
  record(tr, r.t, r.xa, r.phase);
  return true;
}

// The exosystem block: its states are the last e of the augmented state,
// after (q, v, 1) (mech::to_lcs).
VectorXd EventDriven::stop_offset(const VectorXd& xa) const {
  const int e = n_ - 2 * N_ - 1;
  return sys_.C.rightCols(e) * xa.tail(e);
}

VectorXd EventDriven::stop_rate(const VectorXd& xa) const {
  const int e = n_ - 2 * N_ - 1;
  return sys_.C.rightCols(e) * (sys_.A.bottomRightCorner(e, e) * xa.tail(e));
}

// delta = M^{-1} E_J' (E_J M^{-1} E_J')^+ gdot_J: the M-smallest velocity
// whose rates on J are the stops' own (a least-squares solve copes with
// dependent rows, as project_onto). Zero when no closed stop moves.
VectorXd EventDriven::stop_shift(const std::vector<int>& closed, const VectorXd& xa) const {
  VectorXd delta = VectorXd::Zero(N_);
  if (closed.empty()) return delta;
  const mech::MechanicalModel& m = *model_.mechanical;
  const VectorXd rate = stop_rate(xa);
  MatrixXd EJ(closed.size(), N_);
  VectorXd r(closed.size());
  for (size_t i = 0; i < closed.size(); ++i) {
    EJ.row(static_cast<Eigen::Index>(i)) = m.E.row(closed[i]);
    r(static_cast<Eigen::Index>(i)) = rate(closed[i]);
  }
  if (r.isZero(0.0)) return delta;
  const MatrixXd MinvEt = Eigen::LLT<MatrixXd>(m.M).solve(EJ.transpose());
  return MinvEt * (EJ * MinvEt).completeOrthogonalDecomposition().solve(r);
}

}  // namespace lcsim::sim::detail
