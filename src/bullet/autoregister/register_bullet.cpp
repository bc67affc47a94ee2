// Compiled into every program that links lcsim::bullet (an INTERFACE source
// of that target): adds the "bullet" integrator and the LCP back-ends
// bullet-dantzig, bullet-lemke and bullet-pgs before main runs, so no caller
// has to. A static library alone could not do this, since the linker drops
// an object file nothing refers to.
#include <lcsim/bullet/bullet.hpp>

namespace {
const bool kRegistered = (lcsim::bullet::register_backends(), true);
}  // namespace
