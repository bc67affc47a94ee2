// The event-driven method's guard against livelock: events that follow each
// other faster than the fastest time scale and change the state by less than
// rounding end the run with a message naming the contacts involved.
#include <algorithm>
#include <cmath>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

std::string LivelockGuard::after_event(double t, const VectorXd& x_minus, const VectorXd& x_plus,
                                       const lcs::IndexSet& old_mode, const EventResult& ev,
                                       const std::vector<FrictionMode>& old_friction, int trigger) {
  const double dt = t - last_t_;
  last_t_ = t;
  const double quick = rho_ > 0.0 ? 1e-4 / rho_ : 1e-4 * std::max(1.0, std::abs(t));
  const double jump = (x_plus - x_minus).cwiseAbs().maxCoeff();
  const bool idle = dt <= quick && jump <= kIdleJump * x_minus.cwiseAbs().maxCoeff();
  if (!idle) {
    streak_ = 0;
    involved_.clear();
    return "";
  }
  if (streak_++ == 0) since_ = t;
  // The contact whose monitor stopped the phase: an event that selects the
  // same mode again without an impulse involves no other.
  if (trigger >= 0) involved_.insert(trigger);
  for (int r : ev.mode)
    if (std::find(old_mode.begin(), old_mode.end(), r) == old_mode.end()) involved_.insert(r);
  for (int r : old_mode)
    if (std::find(ev.mode.begin(), ev.mode.end(), r) == ev.mode.end()) involved_.insert(r);
  for (size_t f = 0; f < ev.friction.size() && f < friction_contacts_.size(); ++f)
    if (f >= old_friction.size() || ev.friction[f] != old_friction[f])
      involved_.insert(friction_contacts_[f]);  // a stick / slip change
  for (int r = 0; r < static_cast<int>(ev.impulse.size()); ++r)
    if (ev.impulse(r) != 0.0) involved_.insert(r);
  if (streak_ < limit_) return "";
  std::string msg = text("no progress at t = ", t, ": ", streak_, " events in ", (t - since_),
                         " s each changed the state by less than rounding, at contacts ");
  bool first = true;
  for (int r : involved_) {
    msg += first ? "" : ", ";
    msg += r < static_cast<int>(names_.size()) ? "'" + names_[r] + "'" : std::to_string(r);
    first = false;
  }
  if (involved_.empty()) msg += "(none)";
  return msg +
         " (their modes alternate with impulses below rounding): the event-driven method "
         "cannot resolve this contact configuration; a time-stepping method (Moreau–Jean) can";
}

}  // namespace lcsim::sim::detail
