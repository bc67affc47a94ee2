// Compiled into every program that links lcsim::ipopt (an INTERFACE source
// of that target): adds "moreau-qp" to impact::laws() before main runs, so
// no caller has to. A static library alone could not do this, since the
// linker drops an object file nothing refers to.
#include <lcsim/ipopt/moreau_qp.hpp>

namespace {
const bool kRegistered = (lcsim::impact::register_moreau_qp(), true);
}  // namespace
