// The reference law and run of a method (reference.hpp).
#include <lcsim/impact/impact.hpp>
#include <lcsim/sim/reference.hpp>

namespace lcsim::sim {

namespace {

bool has_restitution(const mech::Model& model) {
  return model.is_mechanical() && model.mechanical->restitution.size() > 0 &&
         model.mechanical->restitution.maxCoeff() > 0.0;
}

}  // namespace

std::string ReferenceLaw::label() const {
  if (lcs) return "exact (LCS)";
  // "inelastic" says e = 0 itself; another law run on the model with e = 0
  // says so after its name.
  return inelastic && law != "inelastic" ? law + ", e = 0" : law;
}

ReferenceLaw reference_law(const std::string& method, const std::string& impact,
                           const mech::Model& model) {
  ReferenceLaw r;
  if (!model.is_mechanical()) {
    r.law = impact;
    r.lcs = true;
    r.reason =
        "LCS model: the exact event-driven run (re-initialisation by projection, no "
        "impact law)";
    return r;
  }
  const bool e = has_restitution(model);
  const std::string inelastic_note =
      e ? "" : " (no restitution in this model: every law is inelastic here)";
  if (method == "event") {
    r.law = impact;
    r.reason = "the exact run itself (impact law " + impact + ")";
  } else if (method == "moreau-jean") {
    r.law = "moreau-restitution";
    r.reason = "Moreau-Jean's own law: restitution inside its step LCP";
    if (impact != r.law) r.reason += " (impact law " + impact + " does not apply to it)";
  } else if (method == "euler") {
    r.law = "inelastic";
    r.inelastic = e;
    r.reason =
        "backward Euler ignores restitution: nearest exact law is inelastic" + inelastic_note;
  } else if (method == "bullet") {
    r.law = "inelastic";
    r.inelastic = e;
    r.reason =
        "Bullet 3.24's limits do not bounce (rigid-body limits at stop ERP 0.2, multibody "
        "joint limits at all; docs/bullet-comparison.md): nearest exact law is inelastic" +
        inelastic_note;
  } else if (method == "mujoco") {
    r.law = "inelastic";
    r.inelastic = e;
    r.reason =
        "MuJoCo's contacts are critically damped springs (solref damping ratio 1): nearest "
        "exact law is inelastic" +
        inelastic_note;
  } else {
    r.law = impact;
    r.reason = "assumed: the run's impact law";
  }
  return r;
}

sim::Trajectory run_reference(const mech::Model& model, const Eigen::VectorXd& x0,
                              const ReferenceLaw& law, sim::Options opt) {
  const auto event = sim::make_integrator("event");
  opt = sim::keep_used(opt, event->options_used());
  opt.impact = law.law;
  if (!law.inelastic) return event->run(model, x0, opt);
  mech::Model m = model;
  m.mechanical->restitution.setZero();
  return event->run(m, x0, opt);
}

}  // namespace lcsim::sim
