#include <LinearMath/btScalar.h>

#include <lcsim/bullet/bullet.hpp>

namespace lcsim::bullet {

std::string version_string() {
  static_assert(sizeof(btScalar) == sizeof(double), "lcsim links Bullet in double precision");
  const int v = btGetVersion();
  return "Bullet " + std::to_string(v / 100) + "." + std::to_string(v % 100) +
         " (double precision)";
}

}  // namespace lcsim::bullet
