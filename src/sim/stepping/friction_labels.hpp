// Private to src/sim/stepping: the stick / slip label of a closed
// frictional contact after a time step, by Coulomb's law (issue 27), and a
// sliding 3-D contact's facet, for Moreau–Jean's and backward Euler's
// samples (moreau_jean.cpp, euler_friction.cpp); written for any
// time-stepping scheme that has a step's impulses and end velocity.
#pragma once

#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <vector>

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

// The closed contacts of a step (mode kStick: every contact with a normal
// impulse) labelled by friction_mode_after_step; the open ones stay. p_n(c)
// is contact c's normal impulse (N s), lambda_T / lambda_T2 the friction
// impulses along t / t2 per contact (lambda_T2 nullptr without 3-D
// friction), v the step's end velocity and V its velocity scale (m/s).
// Shared by Moreau–Jean's and backward Euler's samples.
template <class NormalImpulse>
void label_closed_contacts(const mech::MechanicalModel& m, NormalImpulse p_n,
                           const VectorXd& lambda_T, const VectorXd* lambda_T2, const VectorXd& v,
                           double V, std::vector<FrictionMode>& mode) {
  for (size_t fi = 0; fi < mode.size(); ++fi) {
    if (mode[fi] != FrictionMode::kStick) continue;  // open (closed ones are kStick here)
    const mech::FrictionalContact& fc = m.friction[fi];
    const double p2 = lambda_T2 ? (*lambda_T2)(fc.contact) : 0.0;
    mode[fi] = friction_mode_after_step(fc, m.edges_of(fc), p_n(fc.contact), lambda_T(fc.contact),
                                        p2, v, V);
  }
}

// Each contact sliding in 3-D (mode kSlip) given the cone facet holding its
// friction at the end velocity v (Sample::friction_facet: the facet of
// maximal dissipation for its sliding velocity, impact::cone_facet, as the
// impact names it), the others none; one
// entry of `facet` per mechanical.friction entry (empty for planar models).
void slip_facets(const mech::MechanicalModel& m, const std::vector<FrictionMode>& mode,
                 const VectorXd& v, std::vector<impact::ConeFacet>& facet);

}  // namespace lcsim::sim::detail
