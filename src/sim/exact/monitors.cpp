// The monitors of a phase of the event-driven method (step five of
// Algorithm 3.7.1): how each starts (its noise level, its first nonzero
// derivative, whether it is armed) and the first root of the armed ones on a
// sampling interval, bracketed by the samples and refined by Brent's method
// (brent.hpp) on the interval's Taylor series; grazing minima between
// samples are checked.
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/exact/brent.hpp"
#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

// How each monitor of `phase` starts at t from xstart (balanced): its noise
// level, its first nonzero derivative, and the first sampling step (h_max,
// shorter where a monitor starts at zero).
EventDriven::MonitorStart EventDriven::monitor_start(const Phase& phase, const VectorXd& xstart,
                                                     double t, double h_max,
                                                     const std::vector<Monitor>* monitors) const {
  const std::vector<Monitor>& mons = monitors ? *monitors : phase.monitors;
  MonitorStart st;
  st.h_first = h_max;
  st.noise = monitor_noise(mons, xstart, t);
  first_derivatives(phase, mons, xstart, st);
  return st;
}

std::vector<double> EventDriven::monitor_noise(const std::vector<Monitor>& monitors,
                                               const VectorXd& xstart, double t) const {
  // Noise level of each monitor at the phase start: rounding of its terms
  // |w| |x| plus the time quantisation of the event time (ulp(t) times its
  // rate). Its own terms, not |w|_1 max|x|: balancing can scale a coordinate
  // the monitor does not involve far above the others (a clamped joint of
  // Talos at 2.7e5), and that band (2.5e-9) hid a gap of 1.2e-9 closing,
  // wider than re-initialisation's zero test (1e-9 of the gap's terms).
  std::vector<double> noise(monitors.size());
  for (size_t j = 0; j < monitors.size(); ++j) {
    const Monitor& mon = monitors[j];
    noise[j] = 64.0 * kEps * mon.w.cwiseAbs().dot(xstart.cwiseAbs()) +
               time_resolution(t) * std::abs(mon.wA.dot(xstart));
  }
  return noise;
}

// Per monitor: the order m0 of its first nonzero derivative at the phase
// start (0 = the value itself; -1 = none up to n) and that derivative d0;
// h_first shortened to a quarter of the time scale of its first two nonzero
// Taylor terms.
void EventDriven::first_derivatives(const Phase& phase, const std::vector<Monitor>& monitors,
                                    const VectorXd& xstart, MonitorStart& st) const {
  const std::vector<double>& noise = st.noise;
  double& h_first = st.h_first;
  std::vector<int>& m0 = st.m0;
  std::vector<double>& d0 = st.d0;
  // Derivatives of the monitors at the phase start: d_m = w Acl^m x.
  // A derivative is rounding noise when below the zero test of mode
  // selection applied to the magnitudes of its terms |w| |Acl|^m |x|.
  // Each monitor needs its first two nonzero derivatives only: the loop
  // stops once every monitor has them (usually m <= 3), instead of
  // always forming all n + 1 (O(n^3) per phase for large models).
  const size_t nm = monitors.size();
  m0.assign(nm, -1);
  d0.assign(nm, 0.0);
  st.small_opening.assign(nm, 0);
  std::vector<char> small(nm, 0);  // value within the LDCP's zero test
  std::vector<char> done(nm, 0);
  size_t remaining = nm;
  VectorXd Amx = xstart;
  VectorXd Amx_abs = xstart.cwiseAbs();
  VectorXd next(Amx.size());  // the products' destination, swapped in (no allocation per order)
  MatrixXd Acl_abs;
  bool finite = true;
  for (int m = 0; m <= n_ && remaining > 0; ++m) {
    if (m > 0) {
      if (m == 1) {
        Acl_abs = phase.Ab.cwiseAbs();
        finite = phase.Ab.allFinite();
      }
      // Once A^m x and |A|^m |x| are exactly zero (a free flight's or a
      // slide's state after its constant acceleration: m = 3), every later
      // derivative and its zero test are too (finite A): no monitor can
      // find its m0 or its next term there, so the orders up to n are not
      // formed. The result is the same, bit for bit.
      if (finite && ldcp_.tol_abs >= 0.0 && Amx.isZero(0.0) && Amx_abs.isZero(0.0)) break;
      if (phase.use_sparse)
        next.noalias() = phase.Ab_sparse * Amx;
      else
        next.noalias() = phase.Ab * Amx;
      Amx.swap(next);
      next.noalias() = Acl_abs * Amx_abs;
      Amx_abs.swap(next);
    }
    for (size_t j = 0; j < nm; ++j) {
      if (done[j]) continue;
      const Monitor& mon = monitors[j];
      const double dm = mon.w * Amx;
      const double zero =
          m == 0 ? noise[j] : ldcp_.tol_rel * mon.w.cwiseAbs().dot(Amx_abs) + ldcp_.tol_abs;
      if (m == 0)
        small[j] = std::abs(dm) <= ldcp_.tol_rel * mon.w.cwiseAbs().dot(Amx_abs) + ldcp_.tol_abs;
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
      // Within the zero test and opening by the next derivative: of either
      // sign (a general LCS's output held at -2.2e-16 through a jump and
      // released: mode selection took it for zero).
      st.small_opening[j] = m0[j] == 0 && small[j] && dm > 0.0;
      done[j] = 1;
      --remaining;
    }
  }
}

// A monitor is armed (watched for a sign change) when it starts positive, or
// when it starts at zero (within noise) and its first nonzero derivative is
// positive: it opens, however little (a lift-off of 1e-10 m and its landing
// are both seen). Such a monitor is followed as phi(t) - phi(t0), the start's
// rounding residue removed, so it leaves exactly zero and its return is a
// root. A monitor that starts at zero and is identically zero, or whose first
// nonzero derivative is negative (mode selection rules that out up to
// rounding), only counts once it leaves the noise band.
void EventDriven::arm_monitors(PhaseMarch& pm) const {
  const std::vector<Monitor>& monitors = pm.phase.monitors;
  pm.armed.assign(monitors.size(), 0);
  pm.opening.assign(monitors.size(), 0);  // armed by a positive derivative
  pm.offset.assign(monitors.size(), 0.0);
  for (size_t j = 0; j < monitors.size(); ++j) {
    const double value = monitors[j].w.dot(pm.xstart);
    if (pm.start.m0[j] == 0 && pm.start.small_opening[j]) {
      // Rounding left a few 1e-14 of a held gap (a clamp's diode held over
      // many periods) above the noise band, or a few 1e-16 below it (a
      // general LCS's output after its jump, released), but mode selection
      // took it for zero and opened it by its next derivative: followed
      // from the start, as an opening at zero is, so the rounding of the
      // states on the first, very short samples cannot read as its return
      // (below the band, as a spurious event that changes no mode).
      pm.armed[j] = true;
      pm.opening[j] = 1;
      pm.offset[j] = value;
    } else if (pm.start.m0[j] == 0) {
      pm.armed[j] = value > 0.0;
    } else if (pm.start.m0[j] > 0 && pm.start.d0[j] > 0.0) {
      pm.armed[j] = true;
      pm.opening[j] = 1;
      pm.offset[j] = value;
    }
  }
}

// Taylor terms A^k x_a / k! of a phase on the interval [ta, tb], built on
// first need: root refinement then evaluates polynomials instead of
// exponentials. Where the series does not reach rounding in 80 terms, the
// monitors are evaluated by the exponential.
class IntervalSeries {
 public:
  IntervalSeries(const Phase& phase, double ta, double tb, const VectorXd& xa_a)
      : phase_(phase), ta_(ta), tb_(tb), xa_a_(xa_a) {}
  // phi(tt) = w x(tt) and its derivative w Acl x(tt), tt in [ta, tb].
  double value(const RowVectorXd& w, double tt) {
    if (!built_) build();
    if (ok_) return series(w, tt - ta_, false);
    return w * phase_.expv(tt - ta_, xa_a_);
  }
  double derivative(const Monitor& mon, double tt) {
    if (!built_) build();
    if (ok_) return series(mon.w, tt - ta_, true);
    return mon.wA * phase_.expv(tt - ta_, xa_a_);
  }

 private:
  void build() {
    built_ = true;
    const double tau = tb_ - ta_;
    const double xnorm = xa_a_.cwiseAbs().maxCoeff();
    taylor_.push_back(xa_a_);
    double factor = 1.0;  // tau^k
    for (int k = 1; k <= 80; ++k) {
      taylor_.push_back(phase_.times(taylor_.back()) / static_cast<double>(k));
      factor *= tau;
      if (k >= 4 && taylor_.back().cwiseAbs().maxCoeff() * factor <= 1e-18 * xnorm &&
          taylor_[k - 1].cwiseAbs().maxCoeff() * factor / tau <= 1e-17 * xnorm) {
        ok_ = true;
        return;
      }
    }
  }
  double series(const RowVectorXd& w, double s, bool derivative) const {
    double acc = 0.0;
    if (!derivative) {
      for (int k = static_cast<int>(taylor_.size()) - 1; k >= 0; --k)
        acc = acc * s + w.dot(taylor_[k]);
    } else {
      for (int k = static_cast<int>(taylor_.size()) - 1; k >= 1; --k)
        acc = acc * s + k * w.dot(taylor_[k]);
    }
    return acc;
  }

  const Phase& phase_;
  double ta_, tb_;
  const VectorXd& xa_a_;
  std::vector<VectorXd> taylor_;
  bool ok_ = false, built_ = false;
};

// The first root of monitor j in [ta, tb] (states xa_a, xa_b, balanced), or
// infinity; arms the monitor when it leaves its noise band upwards.
double EventDriven::monitor_root(PhaseMarch& pm, size_t j, double ta, double tb,
                                 const VectorXd& xa_a, const VectorXd& xa_b,
                                 IntervalSeries& series) const {
  const Monitor& mon = pm.phase.monitors[j];
  const double offset = pm.offset[j];
  const double noise = pm.start.noise[j];
  const double fa = mon.w * xa_a - offset;
  const double fb = mon.w * xa_b - offset;
  const double tol_f = 1e-12 * mon.scale;
  auto phi = [&](double tt) -> double { return series.value(mon.w, tt) - offset; };
  auto dphi = [&](double tt) -> double { return series.derivative(mon, tt); };
  const double tol = opt_.event_time_tol;
  if (!pm.armed[j]) {
    // Started within rounding of zero: positive by mode selection, but
    // only a departure beyond the noise band counts as a sign.
    if (fb > noise) {
      pm.armed[j] = true;
    } else if (fb < -noise) {
      auto shifted = [&](double tt) { return phi(tt) + noise; };
      return brent_root(shifted, ta, tb, fa + noise, fb + noise, tol);
    }
    return std::numeric_limits<double>::infinity();
  }
  const double da = mon.wA * xa_a;
  const double db = mon.wA * xa_b;
  // A tangential touch (gap and rate both zero) leaves a minimum
  // within rounding of zero, of either sign: it is a graze, not an
  // impact with a spurious 1e-8 rate.
  const bool touch_shape = fa > 0.0 && da < 0.0 && db >= 0.0 && fb >= -tol_f;
  if (fb < 0.0 && !touch_shape && fa <= 0.0 && ta == pm.t0 && pm.opening[j]) {
    // Opened at the phase start and back below zero by tb: the
    // return lies after a positive stretch that starts at t. (Its
    // start may be exactly zero, a projected gap: offset 0.)
    return return_after_opening(phi, ta, tb, fb, tol);
  } else if (fb < 0.0 && !touch_shape) {
    return fa <= 0.0 ? ta : brent_root(phi, ta, tb, fa, fb, tol);
  } else if (fa > 0.0 && da < 0.0 && db > 0.0) {
    // Positive (or touching) at both ends, derivative from - to +.
    const double tm = brent_root(dphi, ta, tb, da, db, tol);
    const double fm = phi(tm);
    if (fm < -tol_f) return brent_root(phi, ta, tm, fa, fm, tol);
    if (fm <= tol_f) return tm;  // touches zero with zero rate
  }
  return std::numeric_limits<double>::infinity();
}

// The first root of any monitor in [ta, tb] into pm.t_event (and its
// constraint into pm.trigger); pm.t_event stays infinite when none.
void EventDriven::first_root(PhaseMarch& pm, double ta, double tb, const VectorXd& xa_a,
                             const VectorXd& xa_b) const {
  IntervalSeries series(pm.phase, ta, tb, xa_a);
  for (size_t j = 0; j < pm.phase.monitors.size(); ++j) {
    const double root = monitor_root(pm, j, ta, tb, xa_a, xa_b, series);
    if (root < pm.t_event) {
      pm.t_event = root;
      pm.trigger = pm.phase.monitors[j].constraint;
      pm.trigger_monitor = static_cast<int>(j);
    }
  }
}

}  // namespace lcsim::sim::detail
