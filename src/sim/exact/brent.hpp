// Private to src/sim: roots of the event-driven method's monitored functions
// (event_driven.cpp): Brent's method on a bracket, and the return to zero of
// a function that has just left zero upwards.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

namespace lcsim::sim::detail {

// Brent's method (Dekker–Brent zeroin) for a root of f in [a, b] with
// f(a) f(b) <= 0. Returns the bracket end at which |f| is smallest once the
// bracket is shorter than tol.
template <class F>
double brent_root(F&& f, double a, double b, double fa, double fb, double tol) {
  if (fa == 0.0) return a;
  if (fb == 0.0) return b;
  double c = a, fc = fa, d = b - a, e = d;
  for (int iter = 0; iter < 200; ++iter) {
    if ((fb > 0) == (fc > 0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::abs(fc) < std::abs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol1 = 2.0 * std::numeric_limits<double>::epsilon() * std::abs(b) + 0.5 * tol;
    const double xm = 0.5 * (c - b);
    if (std::abs(xm) <= tol1 || fb == 0.0) return b;
    if (std::abs(e) >= tol1 && std::abs(fa) > std::abs(fb)) {
      double p, q, r;
      const double s = fb / fa;
      if (a == c) {
        p = 2.0 * xm * s;
        q = 1.0 - s;
      } else {
        q = fa / fc;
        r = fb / fc;
        p = s * (2.0 * xm * q * (q - r) - (b - a) * (r - 1.0));
        q = (q - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0) q = -q;
      p = std::abs(p);
      if (2.0 * p < std::min(3.0 * xm * q - std::abs(tol1 * q), std::abs(e * q))) {
        e = d;
        d = p / q;
      } else {
        d = xm;
        e = d;
      }
    } else {
      d = xm;
      e = d;
    }
    a = b;
    fa = fb;
    b += std::abs(d) > tol1 ? d : (xm > 0 ? tol1 : -tol1);
    fb = f(b);
  }
  return b;
}

// The return to zero of phi on (a, b] when phi leaves zero upwards at a and
// phi(b) = fb < 0: a positive point is searched for by halving towards a,
// then the root is bracketed between it and b. If none is found down to
// 2^-60 of the interval the opening is below resolution and a is returned.
template <class F>
double return_after_opening(F&& phi, double a, double b, double fb, double tol) {
  for (int k = 1; k <= 60; ++k) {
    const double tp = a + std::ldexp(b - a, -k);
    if (!(tp > a)) break;
    const double fp = phi(tp);
    if (fp > 0.0) return brent_root(phi, tp, b, fp, fb, tol);
  }
  return a;
}

}  // namespace lcsim::sim::detail
