// The Bullet layer: the same scene built in Bullet (double precision) for
// side-by-side runs, and Bullet's MLCP solvers as optional LCP back-ends.
//
// Public face of src/bullet. Bullet is linked in double precision
// (pkg-config bullet-float64, BT_USE_DOUBLE_PRECISION).
#pragma once

#include <string>

namespace lcsim::bullet {

// "Bullet <major>.<minor> (double precision)", from btGetVersion().
std::string version_string();

}  // namespace lcsim::bullet
