// The exact run a method is measured against: the reference of the sweep
// (`lcsim sweep`), of compare and of a study's errors (issue 13).
#pragma once

#include <Eigen/Dense>
#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim::sim {

// The exact law a method is measured against.
//   event        the run's own law (Options::impact): it is the reference;
//   moreau-jean  "moreau-restitution": restitution inside its step LCP is that
//                law (src/sim/time_stepping.cpp), whatever Options::impact says;
//   euler        "inelastic" (every restitution zero): backward Euler
//                ignores restitution (every impact inelastic), so the nearest
//                exact law is the inelastic one;
//   bullet       the same inelastic law: Bullet 3.24 applies a limit's bounce
//                only near stop ERP 1 and lcsim's scene uses 0.2, where nothing
//                rebounds (docs/bullet-comparison.md);
//   mujoco       inelastic too: its soft contacts are critically damped
//                springs that do not bounce (docs/contacts.md);
//   other names  Options::impact, said to be assumed.
// On a model without restitution (every e = 0) the inelastic flag is dropped:
// the laws coincide. LCS models have no impact law; the reference is the
// event-driven run with Options::impact (unused there).
struct ReferenceLaw {
  std::string law;         // impact law name of the exact run (src/impact)
  bool inelastic = false;  // the exact run uses a copy of the model with e = 0
  std::string reason;      // one sentence: why this law
  bool lcs = false;        // an LCS model: no impact law, the label is "exact (LCS)"
  // The law's name ("moreau-restitution", "inelastic"), or "<law>, e = 0" when
  // another law runs on the model with e = 0: the row's label.
  std::string label() const;
  bool operator==(const ReferenceLaw& o) const { return law == o.law && inelastic == o.inelastic; }
};
ReferenceLaw reference_law(const std::string& method, const std::string& impact,
                           const mech::Model& model);

// The exact event-driven run of `law` on `model` from x0: the model's
// restitution set to zero when law.inelastic, Options::impact = law.law.
Trajectory run_reference(const mech::Model& model, const Eigen::VectorXd& x0,
                         const ReferenceLaw& law, Options opt);

}  // namespace lcsim::sim
