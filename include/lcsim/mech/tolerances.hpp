// When is a gap (E q + g)_i zero, and when is it violated: every such test of
// lcsim, with its tolerance and the reason for it, in one place.
//
// A gap is formed from terms of magnitude scale_i = |E_i| |q| + |g_i| (see
// gap_scale), so rounding leaves an error of a few eps * scale_i in it: a
// tolerance is relative to that scale, plus an absolute floor where a gap
// whose terms all vanish must still count as zero.
#pragma once

#include <Eigen/Dense>
#include <cmath>
#include <lcsim/lcs/lcs.hpp>

namespace lcsim::mech {

// |E| |q| + |g| row by row: the magnitude of the terms each gap is formed
// from (E dense or sparse).
template <class EMatrix>
Eigen::VectorXd gap_scale(const EMatrix& E, const Eigen::VectorXd& q, const Eigen::VectorXd& g) {
  return E.cwiseAbs() * q.cwiseAbs() + g.cwiseAbs();
}

// The zero test of mode selection, the one test for "is this coefficient
// zero" (lcs::LdcpOptions: tol_rel = 1e-9, tol_abs = 1e-13): |value| <=
// zero_tolerance(scale). 1e-9 relative (about 4.5e6 eps) leaves room for
// the rounding a solve or a matrix exponential carries into a gap, and still
// tells a contact 1 nm from its stop at a length scale of 1 m; 1e-13
// absolute makes zero a gap whose terms all vanish (a contact through q = 0).
inline double zero_tolerance(double scale, const lcs::LdcpOptions& zero = {}) {
  return zero.tol_rel * scale + zero.tol_abs;
}

// Whether a gap at a state the user gives is closed: the closed contacts of
// an impact (app::closed_constraints), the coactive sets (a least-squares
// residual of E_J q = -g_J, room for its SVD's rounding included), and the
// start's feasibility (sim::infeasible_start, a gap below -zero_tolerance).
// The same test as the exact method's, so a state that passes here is read
// the same way by the run that follows.
inline bool gap_is_zero(double gap, double scale) { return std::abs(gap) <= zero_tolerance(scale); }

// The exact method's zero test of a gap at an event time t: the zero test
// with its options (`zero`, Options of the run), widened by what the time's
// resolution leaves in a gap that moves at `rate` (an event time is known to
// `time_resolution`, a few ulp of t plus event_time_tol, so the gap is known
// to time_resolution * |rate|).
inline double event_gap_tolerance(double scale, double rate, double time_resolution,
                                  const lcs::LdcpOptions& zero) {
  return zero_tolerance(scale, zero) + time_resolution * std::abs(rate);
}

// A gap project_feasible still has to correct: below -1e-12 * scale. Tighter
// than the zero test and without its absolute floor, because the projection
// is what makes a state feasible: the state it returns must pass every
// feasibility test afterwards with room to spare (a gap the LCP leaves at
// -1e-12 relative is the rounding of the solve, not a violation).
constexpr double kProjectedGapRel = 1e-12;
inline bool projection_violates(double gap, double scale) {
  return gap < -kProjectedGapRel * scale;
}

}  // namespace lcsim::mech
