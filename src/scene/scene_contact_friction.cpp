// Friction at a scene's contacts (issue 27): `friction:` (mu) and `d:` per
// entry of `contacts:`, or in `contact_options:` as every contact's default,
// make each contact row a 3-D frictional contact whose two tangent rows are
// its ContactFrame's (the world frame's tangents mapped by the point's
// Jacobian at q0), on the polyhedral cone of 2d edges (docs/friction.md,
// docs/contacts.md).
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::fail;
using io::yaml::number;

namespace {

constexpr double kMaxConeEdges = 1024;  // as a matrix model's `d` (src/io/model_yaml.cpp)

}  // namespace

ContactFriction read_contact_friction(const Keys& ck, const std::string& source,
                                      const std::string& k, const ContactFriction& dflt) {
  ContactFriction c = dflt;
  if (ck.count("friction")) {
    c.mu = number(ck.at("friction"), source, k + ".friction");
    if (!(c.mu >= 0.0) || !std::isfinite(c.mu))
      fail(source, k + ".friction",
           "must be a coefficient mu >= 0 (got " + format_number(c.mu) + ")");
  }
  if (ck.count("d")) {
    const double x = number(ck.at("d"), source, k + ".d");
    if (!(x >= 1.0 && x == std::floor(x) && x <= kMaxConeEdges))
      fail(source, k + ".d",
           "must be a whole number >= 1 and <= " + format_number(kMaxConeEdges) + " (got '" +
               ck.at("d").Scalar() + "')");
    if (c.mu < 0.0) fail(source, k + ".d", "applies to a contact with friction: (give its mu)");
    c.d = static_cast<int>(x);
  }
  return c;
}

void add_contact_friction(const SceneContacts& sc, mech::MechanicalModel& m) {
  for (std::size_t i = 0; i < sc.frames.size(); ++i) {
    const ContactFriction& c = sc.friction[i];
    if (c.mu < 0.0) continue;
    const ContactFrame& f = sc.frames[i];
    mech::FrictionalContact fc(static_cast<int>(f.row), f.tangent1_row, c.mu);
    fc.tangent2 = f.tangent2_row.sparseView(0.0);
    fc.edges = c.d;
    fc.world_frame = true;
    m.friction.push_back(fc);
  }
}

}  // namespace lcsim::scene
