// Contacts between two bodies of a scene (docs/contacts.md, "Body against
// body"): a contact entry's `link:` and `against:` name links of two
// bodies ("<body>/<link>"); the points of the first touch the spheres,
// boxes, capsules and cylinders of the second.
#include <urdf_model/model.h>

#include <algorithm>
#include <lcsim/io/yaml.hpp>
#include <lcsim/scene/bodies.hpp>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::yaml::fail;
using io::yaml::join;

LinkRef find_link(const std::vector<ContactBody>& bodies, const YAML::Node& n,
                  const std::string& source, const std::string& key) {
  LinkRef ref;
  ref.label = name_of(n, source, key);
  if (bodies.size() == 1 && bodies[0].name.empty()) {  // a one-URDF scene: the link alone
    if (!bodies[0].urdf->model->getLink(ref.label))
      fail(source, key, "no link '" + ref.label + "' in " + bodies[0].urdf->path);
    ref.link = ref.label;
    return ref;
  }
  std::vector<std::string> names;
  for (const ContactBody& b : bodies) names.push_back(b.name);
  const auto slash = ref.label.find('/');
  if (slash == std::string::npos)
    fail(source, key,
         "expected <body>/<link> (got '" + ref.label + "'; the bodies are " + join(names) + ")");
  const std::string body = ref.label.substr(0, slash);
  ref.link = ref.label.substr(slash + 1);
  const auto it = std::find(names.begin(), names.end(), body);
  if (it == names.end())
    fail(source, key, "no body '" + body + "' (the bodies are " + join(names) + ")");
  ref.body = static_cast<std::size_t>(it - names.begin());
  if (!bodies[ref.body].urdf->model->getLink(ref.link))
    fail(source, key,
         "no link '" + ref.link + "' in body '" + body + "' (" + bodies[ref.body].urdf->path + ")");
  return ref;
}

std::vector<BodyShape> body_shapes(const std::vector<ContactBody>& bodies, const LinkRef& ref,
                                   const std::string& source, const std::string& key) {
  const SceneUrdf& u = *bodies[ref.body].urdf;
  const std::vector<CollisionShape> shapes = collision_shapes(u.collisions, ref.link, u.path);
  if (shapes.empty())
    fail(source, key,
         "link '" + ref.label + "' has no <collision> sphere, box, capsule or cylinder in " +
             u.path + " (another body's points touch those)");
  std::vector<BodyShape> out;
  for (const CollisionShape& c : shapes) {
    BodyShape s;
    s.name = ref.label + (shapes.size() > 1 ? "." + c.kind + std::to_string(c.index) : "");
    s.body = ref.body;
    s.link = ref.link;
    s.kind = c.kind;
    s.local = c.origin;
    s.radius = c.radius;
    s.half = c.half;
    out.push_back(s);
  }
  return out;
}

std::vector<ContactFrame> against_frames(const std::vector<ContactBody>& bodies, const LinkRef& ref,
                                         const YAML::Node& against, const std::string& source,
                                         const std::string& key,
                                         const std::vector<ContactPoint>& points, const Bodies& dyn,
                                         const VectorXd& q0) {
  const LinkRef other = find_link(bodies, against, source, key + ".against");
  if (other.body == ref.body)
    fail(source, key + ".against",
         "'" + ref.label + "' and '" + other.label +
             "' are links of one body: lcsim models contacts between two bodies (or a body and "
             "a plane), not within one");
  const std::vector<BodyShape> shapes = body_shapes(bodies, other, source, key + ".against");
  std::vector<ContactFrame> out;
  std::map<std::string, int> count;  // k per kind, as the URDF's elements are counted
  for (const BodyShape& shape : shapes) {
    const std::string suffix = "_" + shape.kind + std::to_string(count[shape.kind]++);
    for (ContactPoint p : points) {
      if (shapes.size() > 1) p.name += suffix;
      try {
        out.push_back(contact_frame(dyn, p, shape, q0));
      } catch (const InputError& e) {  // a point at a sphere's centre: no normal
        fail(source, key, e.what());
      }
    }
  }
  return out;
}

}  // namespace lcsim::scene
