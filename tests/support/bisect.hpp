// A root by bisection, for the tests' independent event times (a closed
// form's crossing, found without the simulator's own root finder).
#pragma once

namespace lcsim::test_support {

// The root of f on [a, b] (f(a), f(b) of opposite signs), halved until the
// midpoint is no longer strictly inside: to the last bit of t.
template <class F>
double bisect(F&& f, double a, double b) {
  const bool positive_at_a = f(a) > 0;
  for (int it = 0; it < 200 && b - a > 0; ++it) {
    const double m = 0.5 * (a + b);
    if (m <= a || m >= b) break;
    ((f(m) > 0) == positive_at_a ? a : b) = m;
  }
  return 0.5 * (a + b);
}

}  // namespace lcsim::test_support
