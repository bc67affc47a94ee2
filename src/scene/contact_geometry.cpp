// The contact points of a link's URDF <collision> primitives (docs/contacts.md,
// "Contact points"): a box's eight corners, a sphere's centre with its
// radius, a capsule's two cap centres with its radius, a cylinder's points on
// its two rims; a mesh (or any other shape) is refused unless the scene gives
// the link's points itself.
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>
#include <sstream>

#include "scene/detail.hpp"

namespace lcsim::scene {

using Eigen::Vector3d;

namespace {

[[noreturn]] void refuse(const std::string& urdf, const CollisionElement& c,
                         const std::string& what) {
  throw InputError(urdf + ": link '" + c.link + "': <collision> " + std::to_string(c.index) + ": " +
                   what);
}

// `n` finite numbers from an attribute's text ("" when absent: `fallback`).
std::vector<double> numbers(const std::string& text, std::size_t n, const std::string& urdf,
                            const CollisionElement& c, const std::string& what,
                            const std::vector<double>& fallback = {}) {
  if (text.empty() && !fallback.empty()) return fallback;
  std::istringstream in(text);
  std::vector<double> v;
  std::string word;
  while (in >> word) {
    char* end = nullptr;
    const double x = std::strtod(word.c_str(), &end);
    if (*end != '\0' || !std::isfinite(x))
      refuse(urdf, c, what + ": not a finite number (got '" + word + "')");
    v.push_back(x);
  }
  if (v.size() != n)
    refuse(urdf, c, what + ": expected " + std::to_string(n) + " numbers (got '" + text + "')");
  return v;
}

// A positive length (m) from an attribute of the shape.
double length(const CollisionElement& c, const std::string& attribute, const std::string& urdf) {
  const auto it = c.attributes.find(attribute);
  const std::string what = "<" + c.shape + " " + attribute + ">";
  if (it == c.attributes.end()) refuse(urdf, c, what + ": missing");
  const double x = numbers(it->second, 1, urdf, c, what)[0];
  if (!(x > 0.0)) refuse(urdf, c, what + ": must be > 0 (got " + format_number(x) + ")");
  return x;
}

// The collision element's <origin> in the link frame (URDF rpy: R = Rz(yaw)
// Ry(pitch) Rx(roll)).
Eigen::Isometry3d origin(const CollisionElement& c, const std::string& urdf) {
  const auto xyz = numbers(c.xyz, 3, urdf, c, "<origin xyz>", {0.0, 0.0, 0.0});
  const auto rpy = numbers(c.rpy, 3, urdf, c, "<origin rpy>", {0.0, 0.0, 0.0});
  Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
  X.linear() =
      (Eigen::AngleAxisd(rpy[2], Vector3d::UnitZ()) * Eigen::AngleAxisd(rpy[1], Vector3d::UnitY()) *
       Eigen::AngleAxisd(rpy[0], Vector3d::UnitX()))
          .toRotationMatrix();
  X.translation() = Vector3d(xyz[0], xyz[1], xyz[2]);
  return X;
}

// Names <link>.<kind><k>, k counted per kind over the link's elements.
struct Namer {
  std::map<std::string, int> count;
  std::string operator()(const std::string& prefix, const std::string& kind) {
    return prefix + "." + kind + std::to_string(count[kind]++);
  }
};

void add_points(const CollisionElement& c, const std::string& urdf, const std::string& prefix,
                Namer& name, std::vector<ContactPoint>& out) {
  const Eigen::Isometry3d X = origin(c, urdf);
  const auto add = [&](const std::string& kind, const Vector3d& p, double r) {
    out.push_back({name(prefix, kind), c.link, X * p, r, 0});
  };
  if (c.shape == "box") {
    const auto it = c.attributes.find("size");
    if (it == c.attributes.end()) refuse(urdf, c, "<box size>: missing");
    const auto s = numbers(it->second, 3, urdf, c, "<box size>");
    for (double x : s)
      if (!(x > 0.0)) refuse(urdf, c, "<box size>: must be > 0 (got '" + it->second + "')");
    for (int k = 0; k < 8; ++k)  // corner k: bit 0 the sign of x, bit 1 of y, bit 2 of z
      add("corner",
          Vector3d((k & 1 ? 0.5 : -0.5) * s[0], (k & 2 ? 0.5 : -0.5) * s[1],
                   (k & 4 ? 0.5 : -0.5) * s[2]),
          0.0);
  } else if (c.shape == "sphere") {
    add("sphere", Vector3d::Zero(), length(c, "radius", urdf));
  } else if (c.shape == "capsule") {  // Bullet's extension: two half spheres on a cylinder along z
    const double r = length(c, "radius", urdf), l = length(c, "length", urdf);
    add("cap", Vector3d(0, 0, -0.5 * l), r);
    add("cap", Vector3d(0, 0, 0.5 * l), r);
  } else if (c.shape == "cylinder") {  // along z; 8 points on each end's rim
    const double r = length(c, "radius", urdf), l = length(c, "length", urdf);
    for (int k = 0; k < 16; ++k) {
      const double a = 2.0 * M_PI * (k % 8) / 8.0;
      add("rim", Vector3d(r * std::cos(a), r * std::sin(a), (k < 8 ? -0.5 : 0.5) * l), 0.0);
    }
  } else {
    refuse(urdf, c,
           "<" + (c.shape.empty() ? std::string("geometry") : c.shape) +
               ">: lcsim has no contact points for it (only box, sphere, cylinder and capsule); "
               "give the link's contact points in the scene (contacts[]: points)");
  }
}

}  // namespace

std::vector<ContactPoint> collision_points(const std::vector<CollisionElement>& elements,
                                           const std::string& link, const std::string& prefix,
                                           const std::string& urdf) {
  std::vector<ContactPoint> out;
  Namer name;
  for (const CollisionElement& c : elements)
    if (c.link == link) add_points(c, urdf, prefix, name, out);
  return out;
}

std::vector<CollisionShape> collision_shapes(const std::vector<CollisionElement>& elements,
                                             const std::string& link, const std::string& urdf) {
  std::vector<CollisionShape> out;
  std::map<std::string, int> count;
  for (const CollisionElement& c : elements) {
    if (c.link != link) continue;
    CollisionShape s;
    s.kind = c.shape;
    s.origin = origin(c, urdf);
    if (c.shape == "sphere") {
      s.radius = length(c, "radius", urdf);
    } else if (c.shape == "box") {
      const auto it = c.attributes.find("size");
      if (it == c.attributes.end()) refuse(urdf, c, "<box size>: missing");
      const auto v = numbers(it->second, 3, urdf, c, "<box size>");
      for (double x : v)
        if (!(x > 0.0)) refuse(urdf, c, "<box size>: must be > 0 (got '" + it->second + "')");
      s.half = 0.5 * Vector3d(v[0], v[1], v[2]);
    } else if (c.shape == "capsule" || c.shape == "cylinder") {  // along z
      s.radius = length(c, "radius", urdf);
      s.half = Vector3d(0.0, 0.0, 0.5 * length(c, "length", urdf));
    } else {
      refuse(urdf, c,
             "<" + (c.shape.empty() ? std::string("geometry") : c.shape) +
                 ">: another body's points can touch a sphere, a box, a capsule or a cylinder "
                 "only (a mesh: give this link's points in the scene and let them touch the "
                 "other body's primitives)");
    }
    s.index = static_cast<std::size_t>(count[s.kind]++);
    out.push_back(s);
  }
  return out;
}

}  // namespace lcsim::scene
