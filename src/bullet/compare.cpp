// Comparison of a run with the exact event-driven run: state deviation over
// time, final error, event-time shifts, energy drift, violation.
#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <limits>
#include <tuple>

#include "bullet/paired_samples.hpp"

namespace lcsim::bullet {

namespace {

struct Switch {
  double t;
  int constraint;
  bool activation;
};

// Constraint switches from the mode sets: the first sample's mode, then each
// event's mode_after.
std::vector<Switch> switches(const sim::Trajectory& tr) {
  std::vector<Switch> out;
  sim::IndexSet mode = tr.samples.empty() ? sim::IndexSet{} : tr.samples.front().mode;
  auto has = [](const sim::IndexSet& s, int i) {
    for (int j : s)
      if (j == i) return true;
    return false;
  };
  for (const auto& e : tr.events) {
    for (int i : e.mode_after)
      if (!has(mode, i)) out.push_back({e.t, i, true});
    for (int i : mode)
      if (!has(e.mode_after, i)) out.push_back({e.t, i, false});
    mode = e.mode_after;
  }
  return out;
}

// Event shifts: each exact switch, in time order, matched with the other
// run's switch of the same constraint and direction nearest in time and not
// before the previous match of that kind; the other's switches left over.
void match_events(const sim::Trajectory& exact, const sim::Trajectory& other, Comparison& c) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Switch> ex = switches(exact), ot = switches(other);
  std::vector<bool> used(ot.size(), false);
  std::vector<std::tuple<int, bool, double>> last;  // (constraint, activation, t of last match)
  for (const Switch& s : ex) {
    double floor_t = -std::numeric_limits<double>::infinity();
    for (const auto& [ci, act, t] : last)
      if (ci == s.constraint && act == s.activation) floor_t = t;
    int best = -1;
    for (size_t j = 0; j < ot.size(); ++j) {
      if (used[j] || ot[j].constraint != s.constraint || ot[j].activation != s.activation ||
          ot[j].t < floor_t)
        continue;
      if (best < 0 || std::abs(ot[j].t - s.t) < std::abs(ot[best].t - s.t))
        best = static_cast<int>(j);
    }
    EventShift sh;
    sh.constraint = s.constraint;
    sh.activation = s.activation;
    sh.t_exact = s.t;
    if (best >= 0) {
      used[best] = true;
      sh.t_other = ot[best].t;
      sh.shift = sh.t_other - sh.t_exact;
      bool found = false;
      for (auto& [ci, act, t] : last)
        if (ci == s.constraint && act == s.activation) {
          t = sh.t_other;
          found = true;
        }
      if (!found) last.emplace_back(s.constraint, s.activation, sh.t_other);
    } else {
      sh.t_other = nan;
      sh.shift = nan;
    }
    c.event_shifts.push_back(sh);
  }
  for (bool u : used)
    if (!u) ++c.unmatched_other;
}

}  // namespace

Comparison compare_trajectories(const sim::Trajectory& exact, const sim::Trajectory& other,
                                double time_tol) {
  Comparison c;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (exact.final_state.size() == other.final_state.size() && exact.final_state.size() > 0)
    c.error_final = (other.final_state - exact.final_state).cwiseAbs().maxCoeff();
  else
    c.error_final = nan;
  c.deviation_max = std::isnan(c.error_final) ? 0.0 : c.error_final;
  c.deviation_t = other.t_end;

  // Both sample lists are sorted by time; pair samples within time_tol.
  detail::deviation_over(
      exact.samples, other.samples, time_tol,
      [](const sim::Sample& s, const sim::Sample& x) {
        return x.x.size() == s.x.size() ? (s.x - x.x).cwiseAbs().maxCoeff()
                                        : std::numeric_limits<double>::infinity();
      },
      c.deviation_max, c.deviation_t, c.samples_compared);

  match_events(exact, other, c);

  c.energy_drift =
      (other.energy_final - other.energy_initial) - (exact.energy_final - exact.energy_initial);
  c.max_violation = other.max_violation;
  return c;
}

}  // namespace lcsim::bullet
