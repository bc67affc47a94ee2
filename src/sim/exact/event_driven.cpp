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
// This file holds the main loop (EventDriven::run: phases, sampling, root
// finding, events) and the entry point; event_driven_detail.hpp lists the
// other parts.
#include <algorithm>
#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <sstream>
#include <unsupported/Eigen/MatrixFunctions>

#include "sim/exact/brent.hpp"
#include "sim/exact/event_driven_detail.hpp"

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
                          const std::vector<std::string>& names) {
  std::string note;
  for (size_t f = 0; f < after.size() && f < before.size(); ++f) {
    if (before[f] == after[f]) continue;
    note += (note.empty() ? "'" : "; '") + names[static_cast<size_t>(contacts[f])] +
            "': " + std::string(to_string(before[f])) + " -> " + std::string(to_string(after[f]));
  }
  return note;
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
  if (y(r) >= -(kSqrtEps * terms + ldcp_.tol_abs + time_resolution(t) * std::abs(rate))) return;
  std::ostringstream msg;
  msg.precision(6);
  msg << "constraint '" << model_.mechanical->constraints[static_cast<size_t>(r)]
      << "' is violated at t = " << t << " (gap = " << y(r)
      << "): the exact method missed a contact event; please report the model";
  infeasible_ = msg.str();
}

void EventDriven::record(Trajectory& tr, double t, const VectorXd& xa, const Phase& ph) const {
  if (k_ > 0) {
    const VectorXd gaps = sys_.C * xa;  // D u is zero for mechanical models
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
  fill_friction(s, ph, xa);
  tr.record_sample(std::move(s), opt_);
}

// How each monitor of `phase` starts at t from xstart (balanced): its noise
// level, its first nonzero derivative, and the first sampling step (h_max,
// shorter where a monitor starts at zero).
EventDriven::MonitorStart EventDriven::monitor_start(const Phase& phase, const VectorXd& xstart,
                                                     double t, double h_max) const {
  MonitorStart st;
  double& h_first = st.h_first;
  h_first = h_max;
  // Noise level of each monitor at the phase start: rounding of its terms
  // |w| |x| plus the time quantisation of the event time (ulp(t) times its
  // rate). Its own terms, not |w|_1 max|x|: balancing can scale a coordinate
  // the monitor does not involve far above the others (a clamped joint of
  // Talos at 2.7e5), and that band (2.5e-9) hid a gap of 1.2e-9 closing,
  // wider than re-initialisation's zero test (1e-9 of the gap's terms).
  std::vector<double>& noise = st.noise;
  noise.resize(phase.monitors.size());
  for (size_t j = 0; j < phase.monitors.size(); ++j) {
    const Monitor& mon = phase.monitors[j];
    noise[j] = 64.0 * kEps * mon.w.cwiseAbs().dot(xstart.cwiseAbs()) +
               time_resolution(t) * std::abs(mon.wA.dot(xstart));
  }
  // Per monitor: the order m0 of its first nonzero derivative at the phase
  // start (0 = the value itself; -1 = none up to n) and that derivative d0.
  std::vector<int>& m0 = st.m0;
  std::vector<double>& d0 = st.d0;
  {
    // Derivatives of the monitors at the phase start: d_m = w Acl^m x.
    // A derivative is rounding noise when below the zero test of mode
    // selection applied to the magnitudes of its terms |w| |Acl|^m |x|.
    // Each monitor needs its first two nonzero derivatives only: the loop
    // stops once every monitor has them (usually m <= 3), instead of
    // always forming all n + 1 (O(n^3) per phase for large models).
    const size_t nm = phase.monitors.size();
    m0.assign(nm, -1);
    d0.assign(nm, 0.0);
    std::vector<char> done(nm, 0);
    size_t remaining = nm;
    VectorXd Amx = xstart;
    VectorXd Amx_abs = xstart.cwiseAbs();
    MatrixXd Acl_abs;
    for (int m = 0; m <= n_ && remaining > 0; ++m) {
      if (m > 0) {
        if (m == 1) Acl_abs = phase.Ab.cwiseAbs();
        Amx = phase.times(Amx);
        Amx_abs = Acl_abs * Amx_abs;
      }
      for (size_t j = 0; j < nm; ++j) {
        if (done[j]) continue;
        const Monitor& mon = phase.monitors[j];
        const double dm = mon.w * Amx;
        const double zero =
            m == 0 ? noise[j] : ldcp_.tol_rel * mon.w.cwiseAbs().dot(Amx_abs) + ldcp_.tol_abs;
        if (std::abs(dm) <= zero) continue;
        if (m0[j] < 0) {
          m0[j] = m;
          d0[j] = dm;
          continue;
        }
        // Time scale of the first two nonzero Taylor terms:
        // |d_m0| t^m0/m0! = |d_m| t^m/m!  ->  t = (|d_m0| m!/(m0! |d_m|))^(1/(m-m0))
        const double ratio = std::abs(d0[j]) / std::abs(dm);
        double f = 1.0;
        for (int i = m0[j] + 1; i <= m; ++i) f *= i;
        const double tau = std::pow(ratio * f, 1.0 / (m - m0[j]));
        h_first = std::min(h_first, 0.25 * tau);
        done[j] = 1;
        --remaining;
      }
    }
  }
  return st;
}

Trajectory EventDriven::run(const VectorXd& x0_user) {
  Trajectory tr;
  tr.method = "event";
  tr.t_end = *opt_.t_end;
  if (model_.is_mechanical()) tr.impact_law = impact_->name();
  auto fail = [&](const std::string& msg) {
    tr.status = RunStatus::kNumericalFailure;
    tr.message = msg;
  };
  VectorXd xa = augment(x0_user);
  tr.energy_initial = energy(xa);
  double t = 0.0;

  // Initial mode selection (and jump, if the initial state is not regular).
  EventResult ev = process_event(t, xa);
  tr.lcp_solves += ev.lcp_solves;
  for (const auto& w : ev.warnings) tr.warn(w.kind, w.first_t, w.message);
  std::string err;
  Phase phase;
  if (!ev.ok()) {
    fail(ev.message);
  } else {
    phase = make_phase(ev.mode, ev.friction, ldcp_undetermined_, ev.x_plus, err);
    if (!err.empty()) fail(err);
  }
  if (tr.status != RunStatus::kCompleted) {
    tr.final_state = x0_user;
    tr.energy_final = tr.energy_initial;
    return tr;
  }
  if (ev.jumped) {
    Phase before = phase;
    before.mode.clear();
    before.F.resize(0, n_);
    std::fill(before.friction.begin(), before.friction.end(), FrictionMode::kOpen);
    before.Ft.setZero();
    record(tr, t, xa, before);
    Event e;
    e.t = t;
    e.type = EventType::kImpact;
    e.state_before = user(xa);
    e.state_after = user(ev.x_plus);
    e.mode_after = ev.mode;
    e.impulse = ev.impulse;
    set_friction(e, ev);
    tr.events.push_back(std::move(e));
  }
  xa = ev.x_plus;
  record(tr, t, xa, phase);

  const double t_end = *opt_.t_end;
  LivelockGuard livelock(
      opt_.livelock_events, rho_A_,
      model_.is_mechanical() ? model_.mechanical->constraints : std::vector<std::string>{},
      friction_contacts_);
  long events_in_window = 0;
  double window_start = 0.0;
  while (t < t_end) {
    ++tr.steps;
    if (opt_.progress) opt_.progress(t);
    // Sampling step: a quarter of the fastest time scale of the closed loop,
    // so a Bohl function changes the sign of its derivative at most once
    // between samples; first steps shorter where a monitor starts at zero.
    const double rho = phase.rho;
    double h_max = t_end - t;
    if (rho > 0.0) h_max = std::min(h_max, 0.5 / rho);
    h_max = std::min(h_max, (t_end - t) / 4.0 + 1e-300);
    const VectorXd xstart = xa.cwiseQuotient(phase.D);  // balanced
    const MonitorStart start = monitor_start(phase, xstart, t, h_max);
    const std::vector<double>& noise = start.noise;
    const std::vector<int>& m0 = start.m0;
    const std::vector<double>& d0 = start.d0;
    double h_first = start.h_first;
    h_first = std::max(h_first, 1e-15 * std::max(1.0, std::abs(t)));

    // March over the samples of this phase. A monitor is armed (watched for
    // a sign change) when it starts positive, or when it starts at zero
    // (within noise) and its first nonzero derivative is positive: it opens,
    // however little (a lift-off of 1e-10 m and its landing are both seen).
    // Such a monitor is followed as phi(t) - phi(t0), the start's rounding
    // residue removed, so it leaves exactly zero and its return is a root.
    // A monitor that starts at zero and is identically zero, or whose first
    // nonzero derivative is negative (mode selection rules that out up to
    // rounding), only counts once it leaves the noise band.
    std::vector<char> armed(phase.monitors.size());
    std::vector<char> opening(phase.monitors.size(), 0);  // armed by a positive derivative
    std::vector<double> offset(phase.monitors.size(), 0.0);
    for (size_t j = 0; j < phase.monitors.size(); ++j) {
      const double value = phase.monitors[j].w.dot(xstart);
      if (m0[j] == 0) {
        armed[j] = value > 0.0;
      } else if (m0[j] > 0 && d0[j] > 0.0) {
        armed[j] = true;
        opening[j] = 1;
        offset[j] = value;
      }
    }
    double ta = t;
    VectorXd xa_a = xstart;
    MatrixXd Phi;
    double h_phi = -1.0;
    double h = h_first;
    double t_event = std::numeric_limits<double>::infinity();
    int trigger = -1;  // the constraint whose monitor gave t_event
    bool event_found = false;
    // Output grid k dt_out (not a running sum, whose rounding accumulates).
    double k_out = opt_.dt_out > 0 ? std::floor(t / opt_.dt_out + 1e-9) + 1 : 0.0;
    double next_out =
        opt_.dt_out > 0 ? k_out * opt_.dt_out : std::numeric_limits<double>::infinity();
    auto advance_out = [&] { next_out = ++k_out * opt_.dt_out; };
    GridSampler sampler(phase, t, xstart, opt_.dt_out,
                        [&]() -> StepExp& { return step_exp(phase, opt_.dt_out); });
    auto state_at = [&](double tt) -> VectorXd {
      return phase.D.cwiseProduct(phase.expv(tt - t, xstart));
    };
    while (ta < t_end && !event_found) {
      const double tb = std::min(ta + h, t_end);
      VectorXd xa_b;
      if (!phase.dense_exp()) {
        xa_b = phase.expv(tb - ta, xa_a);
      } else {
        if (tb - ta != h_phi) {
          h_phi = tb - ta;
          Phi = (phase.Ab * h_phi).exp();
        }
        xa_b = Phi * xa_a;
      }
      // Taylor terms A^k x_a / k! on this interval, built on first need:
      // root refinement then evaluates polynomials instead of exponentials.
      std::vector<VectorXd> taylor;
      bool taylor_ok = false, taylor_built = false;
      auto build_taylor = [&] {
        taylor_built = true;
        const double tau = tb - ta;
        const double xnorm = xa_a.cwiseAbs().maxCoeff();
        taylor.push_back(xa_a);
        double factor = 1.0;  // tau^k
        for (int k = 1; k <= 80; ++k) {
          taylor.push_back(phase.times(taylor.back()) / static_cast<double>(k));
          factor *= tau;
          if (k >= 4 && taylor.back().cwiseAbs().maxCoeff() * factor <= 1e-18 * xnorm &&
              taylor[k - 1].cwiseAbs().maxCoeff() * factor / tau <= 1e-17 * xnorm) {
            taylor_ok = true;
            return;
          }
        }
      };
      auto series = [&](const Eigen::RowVectorXd& w, double s, bool derivative) {
        double acc = 0.0;
        if (!derivative) {
          for (int k = static_cast<int>(taylor.size()) - 1; k >= 0; --k)
            acc = acc * s + w.dot(taylor[k]);
        } else {
          for (int k = static_cast<int>(taylor.size()) - 1; k >= 1; --k)
            acc = acc * s + k * w.dot(taylor[k]);
        }
        return acc;
      };
      for (size_t j = 0; j < phase.monitors.size(); ++j) {
        const Monitor& mon = phase.monitors[j];
        const double fa = mon.w * xa_a - offset[j];
        const double fb = mon.w * xa_b - offset[j];
        const double tol_f = 1e-12 * mon.scale;
        auto phi = [&](double tt) -> double {
          if (!taylor_built) build_taylor();
          if (taylor_ok) return series(mon.w, tt - ta, false) - offset[j];
          return mon.w * phase.expv(tt - ta, xa_a) - offset[j];
        };
        auto dphi = [&](double tt) -> double {
          if (!taylor_built) build_taylor();
          if (taylor_ok) return series(mon.w, tt - ta, true);
          return mon.wA * phase.expv(tt - ta, xa_a);
        };
        double root = std::numeric_limits<double>::infinity();
        if (!armed[j]) {
          // Started within rounding of zero: positive by mode selection, but
          // only a departure beyond the noise band counts as a sign.
          if (fb > noise[j]) {
            armed[j] = true;
          } else if (fb < -noise[j]) {
            auto shifted = [&](double tt) { return phi(tt) + noise[j]; };
            root = brent_root(shifted, ta, tb, fa + noise[j], fb + noise[j], opt_.event_time_tol);
          }
        } else {
          const double da = mon.wA * xa_a;
          const double db = mon.wA * xa_b;
          // A tangential touch (gap and rate both zero) leaves a minimum
          // within rounding of zero, of either sign: it is a graze, not an
          // impact with a spurious 1e-8 rate.
          const bool touch_shape = fa > 0.0 && da < 0.0 && db >= 0.0 && fb >= -tol_f;
          if (fb < 0.0 && !touch_shape && fa <= 0.0 && ta == t && opening[j]) {
            // Opened at the phase start and back below zero by tb: the
            // return lies after a positive stretch that starts at t. (Its
            // start may be exactly zero, a projected gap: offset 0.)
            root = return_after_opening(phi, ta, tb, fb, opt_.event_time_tol);
          } else if (fb < 0.0 && !touch_shape) {
            root = fa <= 0.0 ? ta : brent_root(phi, ta, tb, fa, fb, opt_.event_time_tol);
          } else if (fa > 0.0 && da < 0.0 && db > 0.0) {
            // Positive (or touching) at both ends, derivative from - to +.
            const double tm = brent_root(dphi, ta, tb, da, db, opt_.event_time_tol);
            const double fm = phi(tm);
            if (fm < -tol_f) {
              root = brent_root(phi, ta, tm, fa, fm, opt_.event_time_tol);
            } else if (fm <= tol_f) {
              root = tm;  // touches zero with zero rate
            }
          }
        }
        if (root < t_event) {
          t_event = root;
          trigger = mon.constraint;
        }
      }
      if (std::isfinite(t_event)) {
        event_found = true;
      } else {
        // Exact output samples inside (ta, tb].
        while (next_out <= tb && next_out < t_end) {
          record(tr, next_out, sampler.at(next_out), phase);
          advance_out();
        }
        ta = tb;
        xa_a = xa_b;
        h = std::min(2.0 * h, h_max);
      }
    }
    if (!event_found) {
      // Reached the horizon.
      const VectorXd xend = state_at(t_end);
      record(tr, t_end, xend, phase);
      xa = xend;
      t = t_end;
      break;
    }
    // Output samples before the event.
    while (next_out < t_event) {
      record(tr, next_out, sampler.at(next_out), phase);
      advance_out();
    }
    const VectorXd x_minus = state_at(t_event);
    const long events_seen = static_cast<long>(tr.events.size()) + tr.events_not_recorded;
    const bool keep = static_cast<long>(tr.events.size()) < opt_.max_recorded_events;
    if (keep) record(tr, t_event, x_minus, phase);
    t = t_event;
    // Zeno guard.
    if (t - window_start > 1.0) {
      window_start = t;
      events_in_window = 0;
    }
    if (++events_in_window > opt_.max_events_per_unit_time || events_seen >= opt_.max_events) {
      std::ostringstream msg;
      msg << "more than " << events_in_window << " events in less than unit time near t = " << t
          << ": the event times accumulate without a limit the simulator can take";
      fail(msg.str());
      tr.status = RunStatus::kEventLimit;
      xa = x_minus;
      break;
    }
    ev = process_event(t, x_minus, phase.mode);
    tr.lcp_solves += ev.lcp_solves;
    for (const auto& w : ev.warnings) tr.warn(w.kind, w.first_t, w.message);
    if (!ev.ok()) {
      fail(ev.message);
      xa = x_minus;
      break;
    }
    const lcs::IndexSet old_mode = phase.mode;
    const std::vector<FrictionMode> old_friction = phase.friction;
    phase = make_phase(ev.mode, ev.friction, ldcp_undetermined_, ev.x_plus, err);
    if (!err.empty()) {
      fail(err);
      xa = x_minus;
      break;
    }
    xa = ev.x_plus;
    if (ev.accumulation && ev.t_star > t) {
      // Continue from the accumulation time in the limit mode; the bounces
      // left out last ev.t_star - t seconds in all.
      xa = phase.exp_apply(ev.t_star - t, xa);
      t = ev.t_star;
    }
    if (const std::string why =
            livelock.after_event(t, x_minus, xa, old_mode, ev, old_friction, trigger);
        !why.empty()) {
      fail(why);
      tr.status = RunStatus::kEventLimit;
      break;
    }
    Event e;
    e.t = t;
    e.state_before = user(x_minus);
    e.state_after = user(xa);
    e.mode_after = ev.mode;
    e.impulse = ev.impulse;
    set_friction(e, ev);
    e.note = ev.note;
    if (ev.accumulation) {
      e.type = EventType::kAccumulation;
    } else if (ev.jumped) {
      e.type = EventType::kImpact;
    } else {
      bool gained = false, lost = false;
      for (int r : ev.mode)
        if (std::find(old_mode.begin(), old_mode.end(), r) == old_mode.end()) gained = true;
      for (int r : old_mode)
        if (std::find(ev.mode.begin(), ev.mode.end(), r) == ev.mode.end()) lost = true;
      e.type = lost && !gained ? EventType::kRelease : EventType::kContact;
      if (!gained && !lost && ev.friction != old_friction) {
        e.type = friction_event_type(old_friction, ev.friction);
        e.note = friction_note(old_friction, ev.friction, friction_contacts_,
                               model_.mechanical->constraints);
      } else if (!gained && !lost) {
        // A graze or a re-selection of the same mode: not a mode change.
        if (keep) record(tr, t, xa, phase);
        continue;
      }
    }
    if (!keep) {
      if (tr.events_not_recorded++ == 0)
        tr.warn("events-not-recorded", t,
                "more than " + std::to_string(opt_.max_recorded_events) +
                    " events: later events and their samples are counted, not recorded");
      continue;
    }
    tr.events.push_back(std::move(e));
    record(tr, t, xa, phase);
  }
  if (k_ > 0) check_feasible(t, xa, sys_.C * xa);
  if (tr.status == RunStatus::kCompleted && !infeasible_.empty()) fail(infeasible_);
  tr.final_state = user(xa);
  tr.energy_final = energy(xa);
  return tr;
}

}  // namespace detail

// The method on input that Integrator::run has checked (simulate.cpp).
Trajectory integrate_event_driven(const mech::Model& model, const VectorXd& x0,
                                  const Options& opt) {
  detail::EventDriven ed(model, opt);
  return ed.run(x0);
}

}  // namespace lcsim::sim
