// Re-initialisation at an event of the event-driven method (steps one and
// three of Algorithm 3.7.1): for mechanical models the impact law on the
// closed contacts, repeated while a contact approaches (and an accumulation's
// limit when impacts accumulate), then mode selection on the regular part;
// for general LCS the LDCP with its impulsive levels (jump P_I x0).
//
// process_mechanical is the driver of its stages: scan_contacts (which
// contacts are closed, resting, approaching, accumulating), then either the
// accumulation's limit or impact_round (the impact law), and once no contact
// approaches, select_regular_mode.
#include <algorithm>
#include <cmath>
#include <lcsim/core/format.hpp>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

EventDriven::ContactScan EventDriven::scan_contacts(double t, const VectorXd& xa,
                                                    const lcs::IndexSet& held, bool limit_taken,
                                                    VectorXd& time_noise) const {
  const mech::MechanicalModel& m = *model_.mechanical;
  ContactScan s;
  const VectorXd q = xa.head(N_), v = xa.segment(N_, N_);
  s.gap = m.E * q + m.g;
  s.gap_scale = m.E.cwiseAbs() * q.cwiseAbs() + m.g.cwiseAbs();
  s.rate = m.E * v;
  VectorXd rate_scale = m.E.cwiseAbs() * v.cwiseAbs();
  if (moving_stops()) {  // the stops' own motion (schedule.cpp)
    const VectorXd offset = stop_offset(xa), rate = stop_rate(xa);
    s.gap += offset;
    s.gap_scale += offset.cwiseAbs();
    s.rate += rate;
    rate_scale += rate.cwiseAbs();
  }
  s.in.model = &m;
  s.in.q = q;
  s.in.v = v;
  for (int r = 0; r < k_; ++r) {
    // Zero within rounding, or within what the event time's resolution
    // leaves in the gap (mech/tolerances.hpp).
    double gap_tol =
        mech::event_gap_tolerance(s.gap_scale(r), s.rate(r), time_resolution(t), ldcp_);
    // A constraint the ending phase held closed has a zero gap by
    // construction; what it shows is the phase's drift, the rounding of
    // the whole state carried through the coupling (its own entries may be
    // tiny: a light finger on a heavy arm, gap 4e-13 at q ~ 1). Closed
    // within sqrt(eps) of the state's scale, so that the impact law sees
    // it: left open, an impact elsewhere can drive it into its stop.
    if (std::find(held.begin(), held.end(), r) != held.end())
      gap_tol +=
          kSqrtEps * (m.E.row(r).cwiseAbs().sum() * q.cwiseAbs().maxCoeff() + std::abs(m.g(r)));
    if (s.gap(r) < -gap_tol) {
      s.violation =
          text("constraint '", m.constraints[r], "' is violated at t = ", t, " (gap = ", s.gap(r),
               "): the state is infeasible, E q + g >= 0 must hold (thesis §3.8)");
      return s;
    }
    if (s.gap(r) > gap_tol) continue;
    s.in.closed.push_back(r);
    // A rate is zero within rounding of its terms, or within what rounding
    // of the state leaves in it: eps times the velocities and positions
    // times the fastest frequency (a stiff spring grazing its stop).
    const double rate_noise = 64.0 * kEps * m.E.row(r).cwiseAbs().sum() *
                              (v.cwiseAbs().maxCoeff() + rho_A_ * q.cwiseAbs().maxCoeff());
    const double rate_tol = mech::zero_tolerance(rate_scale(r), ldcp_) + rate_noise;
    if (std::abs(s.rate(r)) <= rate_tol) s.resting.push_back(r);
    if (s.rate(r) < -rate_tol) {
      s.approaching = true;
      // The resolution of this impact's time: the gap's rounding over the
      // approach rate, and the event time's few ulp.
      time_noise(r) =
          64.0 * kEps * (m.E.row(r).cwiseAbs().dot(q.cwiseAbs()) + std::abs(m.g(r))) / -s.rate(r) +
          time_resolution(t);
      const GeometricTail g =
          limit_taken ? GeometricTail{} : accumulation_time(r, t, time_noise(r));
      if (g.t_star >= t && g.t_star >= s.tail.t_star) {
        s.accumulating = r;
        s.tail = g;
      }
    }
  }
  return s;
}

// One application of the impact law to the approaching contacts: xa takes
// the velocities after, out the impulses; false (out.message) on failure.
bool EventDriven::impact_round(double t, ContactScan& scan, bool limit_taken,
                               const VectorXd& time_noise, VectorXd& xa, EventResult& out) {
  impact::ImpactInput& in = scan.in;
  in.restitution = limit_taken ? VectorXd::Zero(k_) : VectorXd(restitution_);
  // Moving stops: the law acts on the velocities relative to the stops.
  const VectorXd shift = moving_stops() ? stop_shift(in.closed, xa) : VectorXd();
  if (moving_stops()) in.v += shift;
  const impact::ImpactResult ir = impact_->apply(in, *solver_);
  out.lcp_solves += ir.lcp_solves;
  if (!ir.ok()) {
    out.message = "impact at t = " + std::to_string(t) + ": " + ir.message;
    return false;
  }
  if (!ir.admissible)
    count_warning(out.warnings, "impact-not-admissible", t,
                  "impact law '" + impact_->name() + "' at t = " + std::to_string(t) +
                      " gave a non-admissible jump (negative impulse or E_J v+ < 0)" +
                      (ir.message.empty() ? "" : ": " + ir.message));
  if (ir.energy_gain) count_warning(out.warnings, "impact-energy-gain", t, ir.message);
  // The last round's stick / slip / no-impulse per contact: stick leaves a
  // sliding velocity zero to the law's tolerance (friction_modes.cpp).
  if (!ir.outcome.empty()) outcome_ = ir.outcome;
  xa.segment(N_, N_) = ir.v_after;
  if (moving_stops()) xa.segment(N_, N_) -= shift;
  out.impulse += ir.impulse;
  if (ir.friction_impulse.size() == k_)
    for (size_t f = 0; f < friction_contacts_.size(); ++f)
      out.friction_impulse(static_cast<Eigen::Index>(f)) +=
          ir.friction_impulse(friction_contacts_[f]);
  if (ir.friction_impulse2.size() == k_ &&
      out.friction_impulse2.size() == out.friction_impulse.size())
    for (size_t f = 0; f < friction_contacts_.size(); ++f)
      out.friction_impulse2(static_cast<Eigen::Index>(f)) +=
          ir.friction_impulse2(friction_contacts_[f]);
  out.jumped = true;
  if (sens_) out.rounds.push_back({in.closed, in.v, ir.impulse, in.restitution, ir.outcome});
  record_impacts(in.closed, ir.impulse, t, time_noise);
  return true;
}

// The regular state's mode: the closed gaps and resting rates put at exactly
// zero, mode selection at acceleration level and above, and the friction
// modes; false (out.message) on failure.
bool EventDriven::select_regular_mode(double t, const ContactScan& scan, const lcs::IndexSet& held,
                                      VectorXd& xa, EventResult& out) {
  // Put the closed gaps and the resting rates at exactly zero: they are zero
  // up to the state's rounding, and mode selection must see them so.
  project_onto(scan.in.closed, xa, true);
  project_onto(scan.resting, xa, false);
  const lcs::ModeSelection& sel = select_regular_ldcp(xa);
  out.lcp_solves += sel.lcp_solves;
  if (!sel.ok()) {
    out.message = "mode selection at t = " + std::to_string(t) + ": " + sel.message;
    return false;
  }
  out.mode = sel.mode;
  lcs::IndexSet undetermined = sel.undetermined;
  if (model_.mechanical->has_friction()) {
    if (std::string why = select_friction_and_normals(t, sel, held, xa, out, undetermined);
        !why.empty()) {
      out.message = why;
      return false;
    }
  }
  ldcp_undetermined_ = undetermined;
  return true;
}

bool EventDriven::ldcp_free_response(const VectorXd& xa, std::vector<VectorXd>& response) const {
  // The products of the LDCP's FreeResponse::reach, in its order, so that
  // equal responses here are equal responses there.
  const MatrixXd Aabs = sys_.A.cwiseAbs(), Cabs = sys_.C.cwiseAbs();
  VectorXd Amx = xa, Amx_abs = xa.cwiseAbs();
  response.clear();
  for (int m = 0; m <= n_; ++m) {
    if (Amx.isZero(0.0) && Amx_abs.isZero(0.0)) return true;
    response.push_back(sys_.C * Amx);
    response.push_back(Cabs * Amx_abs);
    if (!response[response.size() - 2].allFinite() || !response.back().allFinite()) return false;
    Amx = sys_.A * Amx;
    Amx_abs = Aabs * Amx_abs;
  }
  return false;
}

// The LDCP reads x only through C A^m x and |C| |A|^m |x| (their values: a
// zero of either sign enters a level's coefficient as +0 + (+-0) = +0) and
// whether A^m x and |A|^m |x| are zero vectors; the response here ends at the
// first order where both are (every later order is then zero too), so its
// length says where. With |A| nilpotent (no path of n edges in A's pattern:
// the free dynamics of bodies without springs, x' = v, v' = const) the
// response ends by order n, and the retry in scaled time never changes the
// first result (its growth per order, log2_growth, is -inf). So a state whose
// response equals the memo's, order by order, gets the memo's selection: the
// very computation it would repeat. At the events of a box sliding on a floor
// (only the sliding direction changes) it is the same, event after event.
const lcs::ModeSelection& EventDriven::select_regular_ldcp(const VectorXd& xa) {
  lcs::LdcpOptions o = ldcp_;
  o.regular_only = true;  // the state is now regular: contact forces and higher
  if (ldcp_nilpotent_config_ != config_) {
    ldcp_nilpotent_config_ = config_;
    ldcp_nilpotent_ = no_path_of(sys_.A, n_);
    ldcp_memo_.reset();
  }
  std::vector<VectorXd> response;
  const bool ends = ldcp_nilpotent_ && ldcp_free_response(xa, response);
  if (ends && ldcp_memo_ && ldcp_memo_->config == config_ &&
      ldcp_memo_->response.size() == response.size() &&
      std::equal(response.begin(), response.end(), ldcp_memo_->response.begin(),
                 [](const VectorXd& a, const VectorXd& b) {
                   return a.size() == b.size() && (a.array() == b.array()).all();
                 }))
    return ldcp_memo_->sel;
  lcs::ModeSelection sel = lcs::select_mode(sys_, xa, o);
  if (!ends) {
    ldcp_memo_.reset();
    return ldcp_scratch_ = std::move(sel);
  }
  ldcp_memo_ = LdcpMemo{config_, std::move(response), std::move(sel)};
  return ldcp_memo_->sel;
}

EventResult EventDriven::process_mechanical(double t, const VectorXd& xa0,
                                            const lcs::IndexSet& held) {
  EventResult out;
  out.impulse = VectorXd::Zero(k_);
  out.friction_impulse = VectorXd::Zero(static_cast<Eigen::Index>(friction_contacts_.size()));
  if (has_cone_) out.friction_impulse2 = out.friction_impulse;
  VectorXd xa = xa0;
  ContactScan scan;
  VectorXd time_noise = VectorXd::Zero(k_);  // per approaching contact
  bool limit_taken = false;                  // an accumulation's limit is being taken
  std::fill(outcome_.begin(), outcome_.end(), impact::ContactOutcome::kNone);
  for (int iter = 0; iter < 100; ++iter) {
    scan = scan_contacts(t, xa, held, limit_taken, time_noise);
    if (!scan.violation.empty()) {
      out.message = scan.violation;
      return out;
    }
    if (scan.accumulating >= 0) {
      // Right-accumulation of impacts (Remark 3.4.11): the limit state has
      // every contact that takes part in the accumulation closed (with
      // alternating impacts the others are open by a gap of the order of the
      // tail), and the remaining impacts are inelastic in the limit. Close
      // those contacts (M-orthogonal projection of q), then apply the
      // inelastic impact; the run continues from t_star in the limit mode.
      limit_taken = true;
      out.accumulation = true;
      out.t_star = scan.tail.t_star;
      out.limit_round = out.rounds.size();
      out.limit_x = xa;
      out.note = take_accumulation_limit(scan.accumulating, t, scan.tail, scan.gap, scan.gap_scale,
                                         scan.rate, xa, out.limit_rows);
      continue;
    }
    if (!scan.approaching) break;
    if (!impact_round(t, scan, limit_taken, time_noise, xa, out)) return out;
    if (iter == 99) {
      out.message =
          "impacts at t = " + std::to_string(t) + " did not end after 100 rounds of the impact law";
      return out;
    }
  }
  if (!select_regular_mode(t, scan, held, xa, out)) return out;
  out.x_plus = xa;
  out.status = Status::kOk;
  return out;
}

EventResult EventDriven::process_lcs(double t, const VectorXd& xa0) {
  EventResult out;
  out.impulse = VectorXd::Zero(k_);
  VectorXd xa = xa0;
  // Theorem 3.6.3: with P-matrix leading coefficients at most one jump occurs;
  // a few more rounds are allowed and then reported.
  for (int iter = 0; iter < 4; ++iter) {
    const lcs::ModeSelection sel = lcs::select_mode(sys_, xa, ldcp_);
    out.lcp_solves += sel.lcp_solves;
    if (!sel.ok()) {
      // The levels assume a P-matrix script M; a circuit's is not (free
      // pairs, free_pairs.cpp): every mode is then tried at this state.
      std::string why;
      if (select_by_enumeration(t, xa, out, why)) return out;
      out.message = "mode selection at t = " + short_number(t) + " s: " +
                    (why.empty() ? sel.message + pair_sets(sel.mode, sel.undetermined) : why);
      return out;
    }
    bool impulsive = false;
    for (const auto& imp : sel.impulse)
      if (!imp.isZero(0.0)) impulsive = true;
    if (!impulsive) {
      out.mode = sel.mode;
      out.x_plus = xa;
      out.status = Status::kOk;
      ldcp_undetermined_ = sel.undetermined;
      normalise_free(out.mode, ldcp_undetermined_);  // a no-op unless a pair is free
      return out;
    }
    out.impulse += sel.impulse[0];
    out.jumped = true;
    if (sens_) out.lcs_jumps.push_back({sel.mode, xa});
    xa = sel.x_plus;
  }
  out.message = "re-initialisation did not reach a regular state after 4 jumps";
  return out;
}

EventResult EventDriven::process_event(double t, const VectorXd& xa, const lcs::IndexSet& held) {
  return model_.is_mechanical() ? process_mechanical(t, xa, held) : process_lcs(t, xa);
}

}  // namespace lcsim::sim::detail
