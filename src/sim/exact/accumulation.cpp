// Accumulations of impacts in the event-driven method (Remark 3.4.11): when
// a contact's impact intervals shrink geometrically, the time of the limit
// and the limit state (the contacts taking part closed and at rest).
#include <algorithm>
#include <cmath>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// Impacts whose intervals shrink geometrically, whatever the restitution
// (inelastic impacts accumulate too when they alternate between coupled
// contacts): the ratios d_i / d_{i-p} of the last two intervals to those a
// period p before agree to kRatioAgreement and are below 1; the remaining
// impacts then take rho/(1 - rho) times the last period's intervals. When
// that tail is below accumulation_tail max(1, t) s, the limit is taken.
// A ball's ratios agree exactly; impacts that alternate through a coupling
// reach a constant ratio only as their intervals shrink (the rest of the
// system drifts between impacts: 0.061, 0.060, 0.056 on the NAO legs' knee
// and ankle), and they must be caught before the rounding of the gaps drives
// them (there below 1e-8 s). 10 % agreement with a tail below 1e-6 s: the
// limit then misses only motion within the tail, in which every contact
// involved stays within its bounce amplitude of the limit.
constexpr double kRatioAgreement = 0.1;

// An interval is evidence of a sequence only when it exceeds this many times
// the resolution of its two impact times: below, the "impacts" are the
// rounding of the gaps (issue 24: two coupled stops alternating 3e-9 s apart
// with ratio 0.99 after intervals that had shrunk by 1e-3 a pair).
constexpr double kNoiseFactor = 16.0;
constexpr int kMaxPeriod = 3;
constexpr size_t kKeep = 2 * kMaxPeriod + 2;  // impacts kept per sequence

bool resolved(const ImpactTime& a, const ImpactTime& b) {
  return b.t - a.t > kNoiseFactor * (a.noise + b.noise);
}

// The geometric tail of seq (its last entry the impact now) with the
// smallest period p <= kMaxPeriod whose last two ratios agree, over
// intervals all resolved; t_star < 0 if none.
GeometricTail geometric_tail(const std::vector<ImpactTime>& seq) {
  GeometricTail out;
  const int m = static_cast<int>(seq.size()) - 1;  // intervals 1..m
  auto d = [&](int i) { return seq[i].t - seq[i - 1].t; };
  for (int p = 1; p <= kMaxPeriod && m >= p + 2; ++p) {
    bool ok = true;
    for (int i = m - p - 1; i <= m && ok; ++i) ok = resolved(seq[i - 1], seq[i]);
    if (!ok) return out;  // longer periods reach further back: not resolved either
    const double ratio = d(m) / d(m - p), ratio0 = d(m - 1) / d(m - 1 - p);
    if (!(ratio < 1.0) || std::abs(ratio - ratio0) > kRatioAgreement * ratio) continue;
    // Extrapolated from the impact now, or from the one before with the
    // ratio before: whichever is resolved better. The latest impact's time is
    // the least resolved (its rate the smallest); the earlier anchor carries
    // the ratios' drift over a longer tail instead.
    auto estimate = [&](int j, double rho, double drift, double* error) {
      double last = 0.0;
      for (int i = j - p + 1; i <= j; ++i) last += d(i);
      const double tail = last * rho / (1.0 - rho);
      const double rel = drift + 2.0 * (seq[j].noise + seq[j - 1].noise) / d(j);
      *error = seq[j].noise + tail * rel / (1.0 - rho);
      return seq[j].t + tail;
    };
    double err_now = 0.0, err_before = 0.0;
    const double now = estimate(m, ratio, 0.0, &err_now);
    const double before = estimate(m - 1, ratio0, std::abs(ratio - ratio0) / ratio0, &err_before);
    out.t_star = err_before < err_now ? before : now;
    out.ratio = err_before < err_now ? ratio0 : ratio;
    out.period = p;
    out.since = seq[m - p - 2].t;
    return out;
  }
  return out;
}

void keep_last(std::vector<ImpactTime>& h, const ImpactTime& now) {
  h.push_back(now);
  if (h.size() > kKeep) h.erase(h.begin());
}

}  // namespace

GeometricTail EventDriven::accumulation_time(int r, double t, double noise) const {
  GeometricTail none;
  const auto& h = impact_times_[r];
  // A further round of the impact law at the same event is not an impact of
  // a sequence (it repairs a jump that left a contact approaching).
  if (h.empty() || h.back().t >= t) return none;
  const ImpactTime now{t, noise};
  // Two impacts of r closer than accumulation_dt, or than their times
  // resolve: the limit is reached, without a ratio to extrapolate
  // (accumulation_dt = 0 turns both off, as the livelock guard's test does).
  if (t - h.back().t < opt_.accumulation_dt ||
      (opt_.accumulation_dt > 0.0 && !resolved(h.back(), now)))
    return GeometricTail{t, 0.0, 1, h.back().t};
  const double tail_max = opt_.accumulation_tail * std::max(1.0, std::abs(t));
  auto within = [&](const GeometricTail& g) { return g.t_star >= t && g.t_star - t < tail_max; };
  // Every contact's impacts first: impacts alternating between coupled
  // contacts show their ratio after one period, r's own only after three.
  std::vector<ImpactTime> seq = impact_seq_;
  if (seq.empty() || seq.back().t < t) keep_last(seq, now);
  if (const GeometricTail g = geometric_tail(seq); within(g)) return g;
  std::vector<ImpactTime> own = h;
  keep_last(own, now);
  if (const GeometricTail g = geometric_tail(own); within(g)) return g;
  return none;
}

void EventDriven::record_impacts(const std::vector<int>& contacts, const VectorXd& impulse,
                                 double t, const VectorXd& noise) {
  for (int r : contacts) {
    if (!(impulse(r) > 0.0)) continue;
    const ImpactTime now{t, noise(r)};
    auto& h = impact_times_[r];
    if (h.empty() || h.back().t != t) keep_last(h, now);
    if (impact_seq_.empty() || impact_seq_.back().t != t)
      keep_last(impact_seq_, now);
    else
      impact_seq_.back().noise = std::max(impact_seq_.back().noise, now.noise);
  }
}

// The M-orthogonal projection onto E_J q + g_J = 0 (positions) or E_J v = 0
// (velocities): the smallest change in the kinetic metric, as in Moreau's
// rule; a least-squares solve copes with dependent rows. Used only for
// corrections at rounding level.
void EventDriven::project_onto(const std::vector<int>& rows, VectorXd& xa, bool positions) const {
  if (rows.empty()) return;
  const mech::MechanicalModel& m = *model_.mechanical;
  VectorXd r(rows.size());
  for (size_t i = 0; i < rows.size(); ++i)
    r(i) = positions ? m.E.row(rows[i]).dot(xa.head(N_)) + m.g(rows[i])
                     : m.E.row(rows[i]).dot(xa.segment(N_, N_));
  if (moving_stops()) {  // the stops' own position or rate (schedule.cpp)
    const VectorXd own = positions ? stop_offset(xa) : stop_rate(xa);
    for (size_t i = 0; i < rows.size(); ++i) r(static_cast<Eigen::Index>(i)) += own(rows[i]);
  }
  if (!projection_ || projection_->rows != rows) {  // E_J's factors, once per set J
    MatrixXd EJ(rows.size(), N_);
    for (size_t i = 0; i < rows.size(); ++i) EJ.row(i) = m.E.row(rows[i]);
    if (!M_llt_) M_llt_.emplace(m.M);  // M is the run's: factorised once
    MatrixXd MinvEt = M_llt_->solve(EJ.transpose());
    Eigen::CompleteOrthogonalDecomposition<MatrixXd> cod =
        (EJ * MinvEt).completeOrthogonalDecomposition();
    projection_ = ProjectionFactors{rows, std::move(MinvEt), std::move(cod)};
  }
  const MatrixXd& MinvEt = projection_->MinvEt;
  const VectorXd lambda = projection_->cod.solve(r);
  if (positions)
    xa.head(N_) -= MinvEt * lambda;
  else
    xa.segment(N_, N_) -= MinvEt * lambda;
}

// The limit of an accumulation at contact r. The contacts that take part
// are r and those with an impact since the first impact of the evidence
// (tail.since) that are open by at most 1e-6 of their gap's scale plus
// tol_abs (a closed gap of 1e-27 at a corner through q = 0 is its own
// scale: left out, the partner kept bouncing) plus twice what their rate
// covers in the remaining tail t_star - t: with impacts alternating in a
// corner the partner is open by its bounce amplitude, ~ tail |rate| (3.2e-6
// with a tail of 9e-7 s and |rate| 3.9 on golden seed 318: left open, the
// projection of r alone sent it towards its stop at -3.5 m/s, to be hit
// again 1e-8 s later with restitution and impulses of 400). In the limit their gaps and
// rates vanish (each impact shrinks the rates by the ratio), so the state is
// projected, in the kinetic metric, onto E_J q + g_J = 0 and E_J v = 0: the
// nearest limit state, which never gains kinetic energy. Mode selection then
// decides their forces. Returns how the limit was taken (Event::note).
std::string EventDriven::take_accumulation_limit(int r, double t, const GeometricTail& tail,
                                                 const VectorXd& gap, const VectorXd& gap_scale,
                                                 const VectorXd& rate, VectorXd& xa,
                                                 lcs::IndexSet& joined) const {
  const double since = tail.since, ratio = tail.ratio, t_star = tail.t_star;
  joined.clear();
  std::string names;
  for (int s = 0; s < k_; ++s) {
    const auto& h = impact_times_[s];
    const bool took_part = s == r || (!h.empty() && h.back().t >= since);
    // Plus what the event time's resolution leaves in the gap, as in the
    // closed test of re-initialisation (an event_time_tol of 1e-6 s left r
    // itself open by 1e-10 and out of its own limit: it bounced on).
    const double bounce =
        std::abs(rate(s)) * (2.0 * std::max(0.0, t_star - t) + time_resolution(t));
    // Not mech::zero_tolerance (mech/tolerances.hpp): 1e-6 relative, wider (see above).
    if (!took_part || gap(s) > 1e-6 * gap_scale(s) + ldcp_.tol_abs + bounce) continue;
    names += (names.empty() ? "'" : ", '") + model_.mechanical->constraints[s] + "'";
    joined.push_back(s);
  }
  const VectorXd x_before = xa;
  project_onto(joined, xa, true);
  project_onto(joined, xa, false);
  const VectorXd dq = xa.head(N_) - x_before.head(N_);
  const VectorXd dv = xa.segment(N_, N_) - x_before.segment(N_, N_);
  const double moved = std::sqrt(dq.dot(model_.mechanical->M * dq));
  const double slowed = std::sqrt(dv.dot(model_.mechanical->M * dv));
  std::string note = "impacts at " + names + " accumulate: ";
  if (ratio > 0.0)
    note +=
        text("their intervals shrink by the ratio ", ratio,
             (tail.period > 1 ? " every " + std::to_string(tail.period) + " impacts" : ""),
             ", so the remaining impacts take ", (t_star - t), " s (geometric tail d r/(1 - r))");
  else
    note += text("two impacts of '", model_.mechanical->constraints[r], "' ", (t - since),
                 " s apart, below accumulation_dt or the resolution of their times");
  return note + text("; limit taken at t = ", t,
                     ": their gaps and rates set to zero (positions moved by ", moved,
                     ", velocities by ", slowed,
                     " in the kinetic metric), then the limit mode up to t* = ", t_star);
}

}  // namespace lcsim::sim::detail
