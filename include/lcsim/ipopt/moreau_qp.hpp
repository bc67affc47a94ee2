// The component lcsim::ipopt: Moreau's impact rule as a minimisation, solved
// by Ipopt. Linking lcsim::ipopt adds "moreau-qp" to impact::laws(); nothing
// else in lcsim needs Ipopt.
#pragma once

#include <lcsim/impact/impact.hpp>

namespace lcsim::impact {

// "moreau-qp": the same rule with lambda from the minimisation 3.8.1,
// min ½(w - v)'M(w - v) s.t. E_J w >= 0, solved by Ipopt (TNLP); lambda are
// Ipopt's constraint multipliers with the sign flipped (Ipopt's Lagrangian is
// f + lambda' g, so a lower-bounded active constraint has lambda <= 0).
ImpactResult moreau_qp(const ImpactInput& in);

// Adds "moreau-qp" to laws(). Called by the registration source that CMake
// compiles into every program linking lcsim::ipopt (src/ipopt/autoregister/);
// calling it again is harmless.
void register_moreau_qp();

}  // namespace lcsim::impact
