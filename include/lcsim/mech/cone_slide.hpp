// The polyhedral friction cone's error in closed form (issue 27;
// docs/friction.md, "The cone's error"): a point mass of mass m sliding on a
// horizontal floor (normal force m g) with initial speed s0 at the angle psi
// from the first tangent, its friction force on the cone of 2d edges at the
// angles pi i/d, of maximal dissipation over the polygon.
#pragma once

#include <lcsim/mech/mech.hpp>

namespace lcsim::mech {

// The motion, in the tangent plane (x along t, y along t2; m, s, rad).
//
// Let k be the edge direction nearest psi (k pi/d, |alpha0| <= pi/(2d) with
// alpha0 = psi - k pi/d), p0 = s0 cos(alpha0) the speed along it and
// r = s0 sin(alpha0) across. While the velocity's direction is strictly
// inside that edge's region (within pi/(2d) of it) the force is mu m g
// against the edge: p falls at mu g, r stays, so the heading turns away from
// the edge until it reaches the bisector, at p1 = |r| / tan(pi/(2d)) and
// t1 = (p0 - p1) / (mu g). Then the force lies on the face and the block
// slides straight along the bisector (heading k pi/d + sign(r) pi/(2d)),
// from speed s1 = |r| / sin(pi/(2d)), decelerating at mu g cos(pi/(2d)):
// t2 = s1 / (mu g cos(pi/(2d))). On an edge (r = 0) it stops straight at
// s0/(mu g) as on the circular cone; on a bisector (t1 = 0) it stops
// straight at s0/(mu g cos(pi/(2d))), the largest error. d = 1 (friction
// along t only) with r != 0 never stops: t_stop = distance = +inf.
struct ConeSlide {
  double t_turn = 0.0;      // t1: end of the turning phase (s)
  double t_stop = 0.0;      // t1 + t2 (s)
  double x = 0.0, y = 0.0;  // displacement at rest, along t and t2 (m)
  double path = 0.0;        // length of the path (m)
  double heading = 0.0;     // direction of the velocity as it comes to rest (rad)
  // The circular cone's straight-line stop: s0/(mu g), s0^2/(2 mu g), psi.
  double circular_t_stop = 0.0, circular_distance = 0.0;
};
// s0 > 0, mu > 0, g > 0, d >= 1 (std::invalid_argument otherwise).
ConeSlide cone_slide(double s0, double psi, double mu, double g, int d);

}  // namespace lcsim::mech
