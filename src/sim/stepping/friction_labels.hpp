// Private to src/sim/stepping: the stick / slip label of a closed
// frictional contact after a time step, by Coulomb's law (issue 27), for
// Moreau–Jean's samples (moreau_jean.cpp); written for any time-stepping
// scheme that has a step's impulses and end velocity.
#pragma once

#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>

namespace lcsim::sim::detail {

// Whether a contact's friction impulse (p1, p2) along (t, t2) (N s) lies
// strictly inside its polygon of 2d edges of length mu_pn = mu p_N (N s):
// its gauge below 1 - 1e-9 (friction_labels.cpp says why).
bool strictly_inside_cone(double p1, double p2, double mu_pn, int d);

// The rounding band of a contact's sliding velocity (m/s) at the step's
// velocity scale V (m/s): kStickBand (|t|_1 + |t2|_1) V + |velocity|
// (friction_labels.cpp says why).
double stick_band(const mech::FrictionalContact& fc, double V);

// A closed contact's mode after a step (normal impulse p_n > 0, friction
// impulses p1, p2 along t, t2, end velocity v, V the step's velocity scale
// (m/s): the largest |v_free|, |v+| of the model): stick when the impulse
// is strictly inside the cone or the sliding velocity is within the
// rounding band 1e-9 (|t|_1 + |t2|_1) V; else kSlipPositive / kSlipNegative
// (planar) or kSlip (3-D; its facet from the velocity, impact::cone_facet).
FrictionMode friction_mode_after_step(const mech::FrictionalContact& fc, int d, double p_n,
                                      double p1, double p2, const VectorXd& v, double V);

}  // namespace lcsim::sim::detail
