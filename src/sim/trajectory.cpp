#include <cmath>
#include <functional>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <stdexcept>
#include <utility>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim {

std::string_view to_string(EventType t) {
  switch (t) {
    case EventType::kImpact:
      return "impact";
    case EventType::kRelease:
      return "release";
    case EventType::kContact:
      return "contact";
    case EventType::kAccumulation:
      return "accumulation";
    case EventType::kStart:
      return "start";
    case EventType::kStick:
      return "stick";
    case EventType::kSlip:
      return "slip";
    case EventType::kSchedule:
      return "schedule";
  }
  return "unknown";
}

std::string_view to_string(FrictionMode m) {
  switch (m) {
    case FrictionMode::kOpen:
      return "open";
    case FrictionMode::kStick:
      return "stick";
    case FrictionMode::kSlipPositive:
      return "slip+";
    case FrictionMode::kSlipNegative:
      return "slip-";
    case FrictionMode::kSlip:
      return "slip";
  }
  return "unknown";
}

std::string friction_mode_text(FrictionMode m, impact::ConeFacet facet) {
  if (m == FrictionMode::kSlip && facet.edge >= 0)
    return impact::cone_mode_text(impact::ContactOutcome::kSlip, facet);
  return std::string(to_string(m));
}

void Trajectory::record_sample(Sample s, const Options& opt) {
  if (opt.sample_sink)
    opt.sample_sink(s);
  else
    samples.push_back(std::move(s));
}

void Trajectory::warn(std::string_view kind, double t, std::string message) {
  count_warning(warnings, kind, t, std::move(message));
}

long Trajectory::warning_count() const {
  long n = 0;
  for (const auto& w : warnings) n += w.count;
  return n;
}

long Trajectory::warning_count(std::string_view kind) const {
  for (const auto& w : warnings)
    if (w.kind == kind) return w.count;
  return 0;
}

std::string Trajectory::first_warning() const {
  return warnings.empty() ? std::string() : warnings.front().message;
}

StepGrid StepGrid::of(double t_end, double h) {
  StepGrid g;
  g.h = h;
  const double r = t_end / h;
  const double rn = std::round(r);
  if (rn >= 1.0 && std::abs(r - rn) <= 1e-9 * rn) {
    g.n = static_cast<long>(rn);
    g.h_last = h;
  } else {
    const double nf = std::floor(r);
    g.n = static_cast<long>(nf) + 1;
    g.h_last = t_end - nf * h;
  }
  return g;
}

// The next output time is kept as a multiple of dt_out (one rounding), not a
// sum of dt_out's: the sum drifted by ~1e-15 after 155 outputs, past the
// 1e-9 h tolerance at h = 1e-6, and the samples from t = 1.55 on landed one
// step late (t = 1.550001; found by the golden comparison). The tolerance
// also covers a few ulp of t, the rounding of both sides.
bool OutputSampler::want(double t, double h, bool last) {
  if (last || dt_out_ <= 0.0) return true;
  const double tol = 1e-9 * h + 8.0 * std::numeric_limits<double>::epsilon() * std::abs(t);
  if (t < next_ - tol) return false;
  while (next_ <= t + tol) next_ = (std::round(next_ / dt_out_) + 1.0) * dt_out_;
  return true;
}

// The methods themselves, on checked input (event_driven.cpp, time_stepping.cpp).
Trajectory integrate_event_driven(const mech::Model& model, const VectorXd& x0, const Options& opt);

namespace {

class EventDrivenIntegrator : public Integrator {
 public:
  std::string name() const override { return "event"; }
  OptionsUsed options_used() const override {
    OptionsUsed u;
    u.impact = u.lcp_solver = u.event_search = u.dense_lcs = true;
    u.friction = true;     // stick / slip modes (friction_phase.cpp, friction_modes.cpp)
    u.friction_3d = true;  // stick / edge / face slip on the cone (cone_phase.cpp, cone_modes.cpp)
    u.sensitivity = true;  // forward sensitivities (sensitivity.cpp)
    u.inputs = true;       // exosystems and scheduled events (exact/schedule.cpp)
    return u;
  }

 protected:
  // A cone's modes are coded in a FrictionMode (detail::kMaxEventConeEdges).
  std::string refusal(const mech::Model& model) const override {
    if (!model.is_mechanical()) return "";
    const mech::MechanicalModel& m = *model.mechanical;
    for (size_t f = 0; f < m.friction.size(); ++f)
      if (m.edges_of(m.friction[f]) > detail::kMaxEventConeEdges)
        return text("method 'event' takes cones of at most ", detail::kMaxEventConeEdges,
                    " edge pairs (d) (model '", model.name, "' has d = ", m.edges_of(m.friction[f]),
                    " at mechanical.friction[", f, "])");
    return "";
  }

 public:
  Trajectory integrate(const mech::Model& model, const VectorXd& x0,
                       const Options& opt) const override {
    return integrate_event_driven(model, x0, opt);
  }
};

}  // namespace

// Time-stepping schemes (src/sim/stepping/time_stepping.cpp): backward Euler
// (Algorithm 7.3.1) and the Moreau–Jean theta-method.
std::unique_ptr<Integrator> make_euler_integrator();
std::unique_ptr<Integrator> make_moreau_jean_integrator();

Registry<Integrator>& integrators() {
  return Registry<Integrator>::instance("method", [](Registry<Integrator>& reg) {
    reg.add("event", [] { return std::make_unique<EventDrivenIntegrator>(); });
    reg.add("euler", [] { return make_euler_integrator(); });
    reg.add("moreau-jean", [] { return make_moreau_jean_integrator(); });
  });
}

Trajectory simulate_event_driven(const mech::Model& model, const VectorXd& x0, const Options& opt) {
  return EventDrivenIntegrator().run(model, x0, opt);
}

std::vector<std::string> integrator_names() { return integrators().names(); }

std::unique_ptr<Integrator> make_integrator(std::string_view name) {
  return integrators().make_or_throw(
      name, name == "bullet" ? "bullet is in the component lcsim::bullet; link it" : "");
}

}  // namespace lcsim::sim
