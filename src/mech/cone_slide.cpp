// The sliding block on a polyhedral friction cone in closed form (see
// include/lcsim/mech/cone_slide.hpp for the derivation).
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/mech/cone_slide.hpp>
#include <limits>
#include <stdexcept>

namespace lcsim::mech {

namespace {

// Integral of sqrt(p^2 + r^2) dp: the path length while p falls at unit rate.
double path_integral(double p, double r) {
  if (r == 0.0) return 0.5 * p * std::abs(p);
  return 0.5 * (p * std::hypot(p, r) + r * r * std::asinh(p / std::abs(r)));
}

}  // namespace

ConeSlide cone_slide(double s0, double psi, double mu, double g, int d) {
  if (!(s0 > 0.0 && std::isfinite(s0) && mu > 0.0 && std::isfinite(mu) && g > 0.0 &&
        std::isfinite(g) && std::isfinite(psi) && d >= 1))
    throw std::invalid_argument(text("cone_slide: needs s0 > 0, mu > 0, g > 0, finite psi and ",
                                     "d >= 1 (got s0 ", s0, ", mu ", mu, ", g ", g, ", psi ", psi,
                                     ", d ", d, ")"));
  const double pi = std::acos(-1.0), delta = pi / d, a = mu * g;
  const double k = std::round(psi / delta), alpha0 = psi - k * delta;
  const double p0 = s0 * std::cos(alpha0), r = s0 * std::sin(alpha0);
  const double ek = k * delta;
  ConeSlide out;
  out.circular_t_stop = s0 / a;
  out.circular_distance = s0 * s0 / (2 * a);
  // Phase 1: along the edge direction e_k the speed p falls at mu g.
  const double half = delta / 2, c = std::cos(half);
  const double p1 = r == 0.0 ? 0.0 : (d == 1 ? 0.0 : std::min(p0, std::abs(r) / std::tan(half)));
  out.t_turn = (p0 - p1) / a;
  const double along = (p0 * p0 - p1 * p1) / (2 * a), across = r * out.t_turn;
  out.path = (path_integral(p0, r) - path_integral(p1, r)) / a;
  double x = along * std::cos(ek) - across * std::sin(ek);
  double y = along * std::sin(ek) + across * std::cos(ek);
  if (r == 0.0) {  // on an edge: straight, as the circular cone
    out.t_stop = out.t_turn;
    out.heading = ek;
  } else if (d == 1) {  // across the only edge pair: no friction, never stops
    out.t_stop = out.path = std::numeric_limits<double>::infinity();
    out.heading = ek + std::copysign(half, r);
    x = y = std::numeric_limits<double>::infinity();
  } else {  // phase 2: along the bisector at mu g cos(pi/(2d))
    out.heading = ek + std::copysign(half, r);
    const double s1 = std::hypot(p1, r), a2 = a * c;
    out.t_stop = out.t_turn + s1 / a2;
    const double dist = s1 * s1 / (2 * a2);
    out.path += dist;
    x += dist * std::cos(out.heading);
    y += dist * std::sin(out.heading);
  }
  out.x = x;
  out.y = y;
  return out;
}

}  // namespace lcsim::mech
