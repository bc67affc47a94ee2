// Deviation of a run from the exact run over paired samples, shared by
// compare_trajectories (compare.cpp) and compare_friction_box
// (friction_compare.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <vector>

namespace lcsim::bullet::detail {

// Both sample lists are sorted by time. Each sample s of `other` is paired
// with the exact samples within time_tol of s.t (at a jump the exact run has
// two samples: the nearer state counts, the smallest dist(s, x)); dist may
// return +infinity for a pair it cannot compare. Over the paired samples:
// the largest deviation and its time are raised into max / at, and the
// paired samples counted in `compared`.
template <class Other, class Dist>
void deviation_over(const std::vector<sim::Sample>& exact, const std::vector<Other>& other,
                    double time_tol, Dist dist, double& max, double& at, long& compared) {
  std::size_t e = 0;
  for (const Other& s : other) {
    while (e < exact.size() && exact[e].t < s.t - time_tol) ++e;
    double best = std::numeric_limits<double>::infinity();
    for (std::size_t j = e; j < exact.size() && exact[j].t <= s.t + time_tol; ++j)
      best = std::min(best, dist(s, exact[j]));
    if (!std::isfinite(best)) continue;
    ++compared;
    if (best > max) {
      max = best;
      at = s.t;
    }
  }
}

}  // namespace lcsim::bullet::detail
