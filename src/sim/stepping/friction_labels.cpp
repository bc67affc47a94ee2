// The stick / slip labels of the time-stepping schemes (friction_labels.hpp).
#include "sim/stepping/friction_labels.hpp"

#include <algorithm>
#include <cmath>

namespace lcsim::sim::detail {

namespace {
// Whether a contact's friction impulse (p1, p2) along (t, t2) (N s) lies
// strictly inside its polygon of 2d edges of length mu p_N: its gauge (the
// polygon's norm, 1 on the boundary) below 1 - kInsideCone. A sliding
// contact's impulse is on the boundary to the solver's precision: the dense
// cone and planar LCPs hold mu p_N - sum(beta) = 0 complementary to the
// sliding speed to rounding (solved by pivoting, accepted at 1e-12 relative
// to the problem), and the sweeps' local solves (cone_gs.cpp,
// friction_gs.cpp) put it on its facet to rounding (~1e-16 relative). 1e-9
// is far above both; a sticking impulse that close to the boundary is at
// the threshold of slip, where the sliding velocity decides
// (friction_mode_after_step). mu p_N = 0 (no friction) has no interior.
constexpr double kInsideCone = 1e-9;
}  // namespace

bool strictly_inside_cone(double p1, double p2, double mu_pn, int d) {
  if (!(mu_pn > 0.0)) return false;
  const double f1 = p1 / mu_pn, f2 = p2 / mu_pn, limit = 1.0 - kInsideCone;
  if (d == 1) return std::abs(f1) < limit && std::abs(f2) <= kInsideCone;  // the segment [-t, t]
  const double r = std::hypot(f1, f2);
  const double pi = std::acos(-1.0), half = pi / (2 * d), apothem = std::cos(half);
  if (r < limit * apothem) return true;  // inside the inscribed circle
  if (r >= limit) return false;          // at or beyond a vertex's radius
  // The face whose sector holds the heading phi: the gauge is r cos(phi -
  // bisector) / cos(pi/(2d)), bisector (2i + 1) pi/(2d) of face i.
  const double phi = std::atan2(f2, f1);
  const double face = std::floor(phi / (2 * half));
  return r * std::cos(phi - (2 * face + 1) * half) < limit * apothem;
}

// A closed frictional contact's mode after a step (Coulomb's law, issue 27):
// stick when its friction impulse (p1, p2) (N s) is strictly inside the
// cone (strictly_inside_cone) or its sliding velocity is zero to the step's
// rounding band; else slip (on the boundary, sliding above the band): along
// the sliding velocity's sign for a planar contact, kSlip (its facet from
// the velocity, slip_facets) for a 3-D one.
// The band is scaled by the model's velocities, not the contact's own: a
// sticking contact's velocity v+ = v_free + W^-1 G' lambda is the
// cancellation of terms of the size of the step's velocities (|v_free|, and
// the impulses' |W^-1 G' lambda| ~ |v_free - v+|), which the sweeps solve to
// a natural residual of 1e-13 (1 + |b|_inf) (b the rates G v_free), so the
// contact's sliding velocity t.v+ is zero to ~1e-13 (|t|_1 + |t2|_1) V with
// V = max(|v_free|_inf, |v+|_inf) (m/s); a contact at rest among moving
// ones, or a chain at rest under springs, has a tiny velocity of its own
// and a relative test on it reads rounding as sliding. kStickBand = 1e-9 is
// 10^4 times that residual and ~10^7 eps; sliding that slow moves a contact
// by 1e-9 V h per step.
constexpr double kStickBand = 1e-9;
double stick_band(const mech::FrictionalContact& fc, double V) {
  double t_size = 0.0;
  for (Eigen::SparseVector<double>::InnerIterator it(fc.tangent); it; ++it)
    t_size += std::abs(it.value());
  for (Eigen::SparseVector<double>::InnerIterator it(fc.tangent2); it; ++it)
    t_size += std::abs(it.value());
  return kStickBand * (t_size * V + std::abs(fc.velocity));
}

FrictionMode friction_mode_after_step(const mech::FrictionalContact& fc, int d, double p_n,
                                      double p1, double p2, const VectorXd& v, double V) {
  const double s = fc.sliding(v);
  const double s2 = fc.is_3d() ? fc.tangent2.dot(v) : 0.0;
  const double band = stick_band(fc, V);
  // A 3-D contact with d = 1 has a flat polygon (the segment [-t, t]): no
  // friction along t2, so it sticks only if it does not slide along t2.
  const bool inside = strictly_inside_cone(p1, p2, fc.mu * p_n, d) &&
                      (d > 1 || !fc.is_3d() || std::abs(s2) <= band);
  if (inside || std::max(std::abs(s), std::abs(s2)) <= band) return FrictionMode::kStick;
  if (fc.is_3d()) return FrictionMode::kSlip;
  return s > 0.0 ? FrictionMode::kSlipPositive : FrictionMode::kSlipNegative;
}

void slip_facets(const mech::MechanicalModel& m, const std::vector<FrictionMode>& mode,
                 const VectorXd& v, std::vector<impact::ConeFacet>& facet) {
  for (size_t fi = 0; fi < facet.size(); ++fi) {
    const mech::FrictionalContact& fc = m.friction[fi];
    facet[fi] = mode[fi] == FrictionMode::kSlip
                    ? impact::cone_facet(fc.sliding(v), fc.tangent2.dot(v), m.edges_of(fc))
                    : impact::ConeFacet{};
  }
}

}  // namespace lcsim::sim::detail
