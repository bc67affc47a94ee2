// Event-driven integration: Algorithm 3.7.1 of the thesis.
//
// Step one/three (mode selection and re-initialisation): for mechanical
// models the impact law on the closed contacts (Moreau's LCP (3.69)-(3.70),
// with Newton restitution, §8.2.2), then the LDCP on the regular part
// (contact forces at acceleration level and, where those vanish, higher
// derivatives: Theorem 3.6.7). For general LCS the full LDCP_n including the
// impulsive levels, whose jump equals P_I x0 (eq. (3.10)).
// Step four: in mode I the dynamics are x' = (A + B_.I F_I) x, integrated
// exactly with the matrix exponential; output samples are exact too.
// Step five: the next event is the first time a free output y_i (i not in I)
// or an active multiplier u_i (i in I) turns negative: a root of a Bohl
// function, bracketed on a sampling grid fine enough for its frequencies and
// refined by Brent's method; grazing minima between samples are checked.
//
// Friction (issue 17): a closed frictional contact is in stick, slip+ or
// slip- (the thesis's relay systems, §4.6.2); its phase holds the sticking
// tangents at acceleration level and carries the slipping contacts' friction
// in their normal's force column (friction_phase.cpp); sliding velocities
// reaching zero and stick forces reaching the cone's edge are monitors like
// the others, and the next stick / slip modes come from the
// acceleration-level friction LCP (friction_modes.cpp). Events that change
// only those modes are kStick / kSlip.
//
// This file holds the main loop (EventDriven::run and its stages: phases,
// sampling, events) and the entry point; monitors.cpp the monitors' start
// and root finding; event_driven_detail.hpp lists the other parts.
#include <algorithm>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <sstream>

#include "sim/exact/event_driven_detail.hpp"
#include "sim/exact/sensitivity.hpp"

namespace lcsim::sim {

namespace detail {

namespace {

// A change of stick / slip modes with the normal mode unchanged: kStick if
// some contact starts to stick, else kSlip.
EventType friction_event_type(const std::vector<FrictionMode>& before,
                              const std::vector<FrictionMode>& after) {
  for (size_t f = 0; f < after.size(); ++f)
    if (after[f] == FrictionMode::kStick && (f >= before.size() || before[f] != after[f]))
      return EventType::kStick;
  return EventType::kSlip;
}

// Event::note of a stick / slip event: "'floor': slip+ -> stick", per
// contact whose mode changed.
std::string friction_note(const std::vector<FrictionMode>& before,
                          const std::vector<FrictionMode>& after, const std::vector<int>& contacts,
                          const std::vector<std::string>& names, const std::vector<int>& cone_d) {
  std::string note;
  for (size_t f = 0; f < after.size() && f < before.size(); ++f) {
    if (before[f] == after[f]) continue;
    const int d = f < cone_d.size() ? cone_d[f] : 1;
    note += (note.empty() ? "'" : "; '") + names[static_cast<size_t>(contacts[f])] +
            "': " + friction_mode_name(before[f], d) + " -> " + friction_mode_name(after[f], d);
  }
  return note;
}

// Ends the run with a numerical failure.
void fail(Trajectory& tr, const std::string& msg) {
  tr.status = RunStatus::kNumericalFailure;
  tr.message = msg;
}

// An event's LCP solves and warnings, counted into the run.
void count_event(Trajectory& tr, const EventResult& ev) {
  tr.lcp_solves += ev.lcp_solves;
  for (const auto& w : ev.warnings) tr.warn(w.kind, w.first_t, w.message);
}

// The run's next phase from make_phase's result: moved out of the memo when
// it is the memo's (no copy of its matrices and monitors). The memo keeps its
// arguments and monitors' start, which march_start reads, and no phase (an
// empty one: make_phase builds again if asked for the same).
template <class Memo>
void adopt_phase(std::optional<Memo>& memo, const Phase& built, Phase& phase) {
  if (memo && &memo->phase == &built) {
    phase = std::move(memo->phase);
    memo->phase = Phase{};
  } else {
    phase = built;
  }
}

}  // namespace

void EventDriven::check_feasible(double t, const VectorXd& xa, const VectorXd& y) const {
  if (!model_.is_mechanical() || k_ == 0 || !infeasible_.empty()) return;
  Eigen::Index r = 0;
  if (y.minCoeff(&r) >= -ldcp_.tol_abs) return;
  // The state's scale, not the row's own terms: a held contact's gap drifts
  // with the rounding of the whole state (reinitialisation.cpp).
  const double terms = sys_.C.row(r).cwiseAbs().sum() * xa.cwiseAbs().maxCoeff();
  // An event state lies within the event time's resolution of the crossing.
  const double rate = model_.mechanical->E.row(r).dot(xa.segment(N_, N_));
  // Not mech::event_gap_tolerance (mech/tolerances.hpp): sqrt(eps) of the state's scale.
  if (y(r) >= -(kSqrtEps * terms + ldcp_.tol_abs + time_resolution(t) * std::abs(rate))) return;
  infeasible_ = text("constraint '", model_.mechanical->constraints[static_cast<size_t>(r)],
                     "' is violated at t = ", t, " (gap = ", y(r),
                     "): the exact method missed a contact event; please report the model");
}

void EventDriven::record(Trajectory& tr, double t, const VectorXd& xa, const Phase& ph) const {
  if (k_ > 0) {
    // y = C x + D u: an LCS with a feedthrough (a diode in series with a
    // resistor) has C x < 0 where D u makes up the difference.
    VectorXd gaps = sys_.C * xa;
    if (!model_.is_mechanical()) gaps.noalias() += sys_.D * multipliers(ph, xa);
    tr.max_violation = std::min(tr.max_violation, std::min(0.0, gaps.minCoeff()));
    check_feasible(t, xa, gaps);
  }
  if (!opt_.record_samples) return;
  Sample s;
  s.t = t;
  s.x = user(xa);
  s.u = multipliers(ph, xa);
  s.y = sys_.C * xa + sys_.D * s.u;
  s.mode = ph.mode;
  s.configuration = config_;
  fill_friction(s, ph, xa);
  if (sens_ && opt_.sample_sink) {
    // Streamed: dx in the run's own storage, lent to the sink's view of s
    // (as Trajectory::record_sample hands it on) and taken back.
    sens_->fill_sample(t, s);
    opt_.sample_sink(s);
    sens_->take_back(s);
    return;
  }
  if (sens_) sens_->fill(t, s.dx, s.dx_exists);
  tr.record_sample(std::move(s), opt_);
}

// The run: the initial event, then phase by phase (next_phase: the phase's
// monitors started and armed, march_phase over its sampling intervals with
// their output samples) to the next event (take_event: zeno_guard,
// reinitialise, the livelock guard, classify_event), until the horizon
// (end_run).
Trajectory EventDriven::run(const VectorXd& x0_user) {
  RunState r;
  if (!start_run(r, x0_user)) return std::move(r.tr);
  LivelockGuard livelock(
      opt_.livelock_events, rho_A_,
      model_.is_mechanical() ? model_.mechanical->constraints : std::vector<std::string>{},
      friction_contacts_);
  while (r.t < *opt_.t_end) {
    ++r.tr.steps;
    if (opt_.progress) opt_.progress(r.t);
    if (!next_phase(r, livelock)) break;
  }
  end_run(r);
  return std::move(r.tr);
}

// Initial mode selection (and jump, if the initial state is not regular) and
// the first samples; false when the run ends there (r.tr says why).
bool EventDriven::start_run(RunState& r, const VectorXd& x0_user) {
  Trajectory& tr = r.tr;
  tr.method = "event";
  tr.t_end = *opt_.t_end;
  if (model_.is_mechanical()) tr.impact_law = impact_->name();
  r.xa = augment(x0_user);
  tr.energy_initial = energy(r.xa);
  r.t = 0.0;
  const EventResult ev = process_event(r.t, r.xa);
  count_event(tr, ev);
  if (!ev.ok()) {
    fail(tr, ev.message);
  } else {
    std::string err;
    const Phase& built = make_phase(ev.mode, ev.friction, ldcp_undetermined_, ev.x_plus, err);
    if (!err.empty())
      fail(tr, err);
    else
      adopt_phase(phase_memo_, built, r.phase);
  }
  if (tr.status != RunStatus::kCompleted) {
    tr.final_state = x0_user;
    tr.energy_final = tr.energy_initial;
    return false;
  }
  if (sens_) sens_->start(r.xa);
  if (ev.jumped) record_initial_jump(r, ev);
  if (sens_) sens_->after_event(ev, r.phase, r.t, ev.x_plus, {}, -1);
  r.xa = ev.x_plus;
  record(tr, r.t, r.xa, r.phase);
  return true;
}

// A jump at t = 0: the state before it (no contact force) and the impact.
void EventDriven::record_initial_jump(RunState& r, const EventResult& ev) const {
  Phase before = r.phase;
  before.mode.clear();
  before.F.resize(0, n_);
  std::fill(before.friction.begin(), before.friction.end(), FrictionMode::kOpen);
  before.Ft.setZero();
  record(r.tr, r.t, r.xa, before);
  Event e;
  e.t = r.t;
  e.type = EventType::kImpact;
  e.state_before = user(r.xa);
  e.state_after = user(ev.x_plus);
  e.mode_after = ev.mode;
  e.impulse = ev.impulse;
  set_friction(e, ev);
  if (sens_) sens_->fill_event(e);
  r.tr.events.push_back(std::move(e));
}

// The phase from r.t to its event (then take_event) or to the horizon;
// false when the run ends.
bool EventDriven::next_phase(RunState& r, LivelockGuard& livelock) {
  // The phase ends at the horizon or at the next scheduled event.
  const double t_end = std::min(*opt_.t_end, next_scheduled(r.t));
  // Sampling step: a quarter of the fastest time scale of the closed loop,
  // so a Bohl function changes the sign of its derivative at most once
  // between samples; first steps shorter where a monitor starts at zero.
  const double rho = r.phase.rho;
  double h_max = t_end - r.t;
  if (rho > 0.0) h_max = std::min(h_max, 0.5 / rho);
  h_max = std::min(h_max, (t_end - r.t) / 4.0 + 1e-300);
  const Phase& phase = r.phase;
  PhaseMarch pm(phase, r.t, r.xa, opt_.dt_out,
                [this, &phase]() -> StepExp& { return step_exp(phase, opt_.dt_out); });
  pm.start = march_start(phase, r.xa, pm.xstart, r.t, h_max);
  if (sens_) sens_->check_phase_start(phase, r.t, pm.start.m0, ldcp_undetermined_);
  const double h_first = std::max(pm.start.h_first, 1e-15 * std::max(1.0, std::abs(r.t)));
  arm_monitors(pm);
  march_phase(pm, h_first, h_max, t_end, r.tr);
  if (std::isfinite(pm.t_event)) return take_event(r, pm, livelock);
  if (t_end < *opt_.t_end) return take_scheduled(r, pm, t_end);
  // Reached the horizon.
  const VectorXd xend = pm.state_at(t_end);
  record(r.tr, t_end, xend, phase);
  r.xa = xend;
  r.t = t_end;
  return false;
}

// March over the samples of a phase, doubling the step up to h_max, until a
// monitor's root (pm.t_event) or the horizon; the output samples on the way.
void EventDriven::march_phase(PhaseMarch& pm, double h_first, double h_max, double t_stop,
                              Trajectory& tr) const {
  double ta = pm.t0;
  VectorXd xa_a = pm.xstart;
  MatrixXd Phi;
  double h_phi = -1.0;
  double h = h_first;
  while (ta < t_stop) {
    const double tb = std::min(ta + h, t_stop);
    VectorXd xa_b;
    // A nilpotent phase's action (nil - 1 products with a vector) costs less
    // than forming its exponential, even when the step repeats.
    if (!pm.phase.dense_exp() || pm.phase.nil > 0) {
      xa_b = pm.phase.expv(tb - ta, xa_a);
    } else {
      if (tb - ta != h_phi) {
        h_phi = tb - ta;
        Phi = pm.phase.expm(h_phi);
      }
      xa_b = Phi * xa_a;
    }
    first_root(pm, ta, tb, xa_a, xa_b);
    if (std::isfinite(pm.t_event)) return;
    // Exact output samples inside (ta, tb].
    while (pm.next_out <= tb && pm.next_out < t_stop) {
      record(tr, pm.next_out, pm.sampler.at(pm.next_out), pm.phase);
      pm.advance_out();
    }
    ta = tb;
    xa_a = xa_b;
    h = std::min(2.0 * h, h_max);
  }
}

// The event at pm.t_event: the samples before it, the state there, and the
// re-initialisation into the next phase; false when the run ends.
bool EventDriven::take_event(RunState& r, PhaseMarch& pm, LivelockGuard& livelock) {
  Trajectory& tr = r.tr;
  // Output samples before the event.
  while (pm.next_out < pm.t_event) {
    record(tr, pm.next_out, pm.sampler.at(pm.next_out), r.phase);
    pm.advance_out();
  }
  const VectorXd x_minus = pm.state_at(pm.t_event);
  const int trigger = pm.trigger;
  const long events_seen = static_cast<long>(tr.events.size()) + tr.events_not_recorded;
  const bool keep = static_cast<long>(tr.events.size()) < opt_.max_recorded_events;
  if (keep) record(tr, pm.t_event, x_minus, r.phase);
  r.t = pm.t_event;
  // pm refers to r.phase, which reinitialise replaces: not used below.
  const lcs::IndexSet old_mode = r.phase.mode;
  const std::vector<FrictionMode> old_friction = r.phase.friction;
  if (sens_) sens_->before_event(r.t, x_minus, pm.trigger_monitor);
  EventResult ev;
  if (zeno_guard(r, events_seen) || !reinitialise(r, x_minus, ev)) {
    r.xa = x_minus;
    return false;
  }
  if (const std::string why =
          livelock.after_event(r.t, x_minus, r.xa, old_mode, ev, old_friction, trigger);
      !why.empty()) {
    fail(tr, why);
    tr.status = RunStatus::kEventLimit;
    return false;
  }
  if (sens_) sens_->after_event(ev, r.phase, r.t, r.xa, old_mode, trigger);
  Event e;
  e.t = r.t;
  e.state_before = user(x_minus);
  e.state_after = user(r.xa);
  e.mode_after = ev.mode;
  e.impulse = ev.impulse;
  set_friction(e, ev);
  e.note = ev.note;
  if (sens_) sens_->fill_event(e);
  if (!classify_event(e, ev, old_mode, old_friction)) {
    if (sens_) sens_->graze(r.t, trigger);
    // A graze or a re-selection of the same mode: not a mode change.
    if (keep) record(tr, r.t, r.xa, r.phase);
    return true;
  }
  if (!keep) {
    if (tr.events_not_recorded++ == 0)
      tr.warn("events-not-recorded", r.t,
              "more than " + std::to_string(opt_.max_recorded_events) +
                  " events: later events and their samples are counted, not recorded");
    return true;
  }
  tr.events.push_back(std::move(e));
  record(tr, r.t, r.xa, r.phase);
  return true;
}

// Zeno guard: more than max_events_per_unit_time events within a unit of
// time, or max_events in all, end the run (true).
bool EventDriven::zeno_guard(RunState& r, long events_seen) const {
  if (r.t - r.window_start > 1.0) {
    r.window_start = r.t;
    r.events_in_window = 0;
  }
  if (++r.events_in_window > opt_.max_events_per_unit_time || events_seen >= opt_.max_events) {
    std::ostringstream msg;
    msg << "more than " << r.events_in_window << " events in less than unit time near t = " << r.t
        << ": the event times accumulate without a limit the simulator can take";
    fail(r.tr, msg.str());
    r.tr.status = RunStatus::kEventLimit;
    return true;
  }
  return false;
}

// Re-initialisation at r.t from x_minus (the impact law and mode selection:
// reinitialisation.cpp) and the next phase; an accumulation continues from
// its limit time. False (r.tr says why) on failure.
bool EventDriven::reinitialise(RunState& r, const VectorXd& x_minus, EventResult& ev) {
  ev = process_event(r.t, x_minus, r.phase.mode);
  count_event(r.tr, ev);
  if (!ev.ok()) {
    fail(r.tr, ev.message);
    return false;
  }
  std::string err;
  const Phase& built = make_phase(ev.mode, ev.friction, ldcp_undetermined_, ev.x_plus, err);
  if (!err.empty()) {
    fail(r.tr, err);
    return false;
  }
  adopt_phase(phase_memo_, built, r.phase);
  r.xa = ev.x_plus;
  if (ev.accumulation && ev.t_star > r.t) {
    // Continue from the accumulation time in the limit mode; the bounces
    // left out last ev.t_star - t seconds in all.
    r.xa = r.phase.exp_apply(ev.t_star - r.t, r.xa);
    r.t = ev.t_star;
  }
  return true;
}

// The event's type from what changed; false for a graze or a re-selection
// of the same modes (not an event).
bool EventDriven::classify_event(Event& e, const EventResult& ev, const lcs::IndexSet& old_mode,
                                 const std::vector<FrictionMode>& old_friction) const {
  if (ev.accumulation) {
    e.type = EventType::kAccumulation;
    return true;
  }
  if (ev.jumped) {
    e.type = EventType::kImpact;
    return true;
  }
  bool gained = false, lost = false;
  for (int r : ev.mode)
    if (std::find(old_mode.begin(), old_mode.end(), r) == old_mode.end()) gained = true;
  for (int r : old_mode)
    if (std::find(ev.mode.begin(), ev.mode.end(), r) == ev.mode.end()) lost = true;
  e.type = lost && !gained ? EventType::kRelease : EventType::kContact;
  if (!gained && !lost && ev.friction != old_friction) {
    e.type = friction_event_type(old_friction, ev.friction);
    e.note = friction_note(old_friction, ev.friction, friction_contacts_,
                           model_.mechanical->constraints, cone_d_);
  } else if (!gained && !lost) {
    return false;
  }
  return true;
}

// The final state, and the run's feasibility.
void EventDriven::end_run(RunState& r) const {
  if (k_ > 0) check_feasible(r.t, r.xa, sys_.C * r.xa);
  if (r.tr.status == RunStatus::kCompleted && !infeasible_.empty()) fail(r.tr, infeasible_);
  r.tr.final_state = user(r.xa);
  r.tr.energy_final = energy(r.xa);
  if (sens_) {
    r.tr.sensitivity_columns = sens_->column_names();
    sens_->fill(r.t, r.tr.dx_final, r.tr.dx_final_exists);
    r.tr.sensitivity_losses = sens_->losses();
  }
}

void EventDriven::init_sensitivity() {
  sens_ = std::make_shared<Sensitivity>(model_, sys_, parse_sensitivity(model_, opt_.sensitivity),
                                        impact_->name());
}

}  // namespace detail

// The method on input that Integrator::run has checked (simulate.cpp).
Trajectory integrate_event_driven(const mech::Model& model, const VectorXd& x0,
                                  const Options& opt) {
  detail::EventDriven ed(model, opt);
  return ed.run(x0);
}

}  // namespace lcsim::sim
