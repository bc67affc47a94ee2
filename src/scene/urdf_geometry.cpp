// URDF text without the elements urdfdom must not see: <visual>,
// <collision> and <material>; and the <collision> elements as the text has
// them, for a scene's contacts (collision_elements: only those a scene
// names are checked, in contact_geometry.cpp). urdfdom refuses a whole
// robot for an error in one of them: Bullet's own geometry types (capsule,
// plane, cdf), a mesh scale of four numbers, two materials of one name. Public robot files have all
// of these.
//
// A small scanner, not an XML parser: it copies the text, drops every such
// element (from its start tag to its end tag, or a self-closing tag) and
// keeps comments, CDATA sections and processing instructions verbatim, so
// that a tag inside them is not taken for an element. Anything it does not
// recognise is copied unchanged and left to urdfdom.
#include <array>
#include <cctype>
#include <cstring>
#include <lcsim/io/text.hpp>
#include <map>
#include <regex>
#include <string>

#include "scene/detail.hpp"

namespace lcsim::scene {

using io::format_number;
using io::one_line;

namespace {

constexpr std::array<const char*, 3> kIgnored{"visual", "collision", "material"};

// Does `xml` at `pos` start the tag `<name` (followed by a space, '>' or
// '/', so that <visual_frame> is not <visual>)?
bool starts_tag(const std::string& xml, std::size_t pos, const std::string& name) {
  if (xml.compare(pos, name.size() + 1, "<" + name) != 0) return false;
  const std::size_t after = pos + name.size() + 1;
  if (after >= xml.size()) return false;
  const char c = xml[after];
  return c == '>' || c == '/' || c == ' ' || c == '\t' || c == '\n' || c == '\r';
}

// End (one past '>') of the tag starting at `pos`, skipping quoted
// attribute values; npos if it never closes.
std::size_t tag_end(const std::string& xml, std::size_t pos) {
  char quote = 0;
  for (std::size_t i = pos; i < xml.size(); ++i) {
    const char c = xml[i];
    if (quote) {
      if (c == quote) quote = 0;
    } else if (c == '"' || c == '\'') {
      quote = c;
    } else if (c == '>') {
      return i + 1;
    }
  }
  return std::string::npos;
}

// End of the element `name` whose start tag begins at `pos` (one past its
// end tag, or past a self-closing start tag); npos if it never closes.
// URDF never nests these elements in themselves.
std::size_t element_end(const std::string& xml, std::size_t pos, const std::string& name) {
  const std::size_t open = tag_end(xml, pos);
  if (open == std::string::npos) return open;
  if (xml[open - 2] == '/') return open;
  std::size_t close = xml.find("</" + name, open);
  if (close == std::string::npos) return close;
  return tag_end(xml, close);
}

// Text kept verbatim from `pos`: a comment, CDATA or processing instruction
// ends at its terminator (npos: not one of them).
std::size_t verbatim_end(const std::string& xml, std::size_t pos) {
  for (const auto& [open, close] :
       {std::pair<const char*, const char*>{"<!--", "-->"}, {"<![CDATA[", "]]>"}, {"<?", "?>"}}) {
    if (xml.compare(pos, std::strlen(open), open) != 0) continue;
    const std::size_t e = xml.find(close, pos + std::strlen(open));
    return e == std::string::npos ? xml.size() : e + std::strlen(close);
  }
  return std::string::npos;
}

// The value of attribute `name` in the start tag `tag` ("" if absent), and
// whether it is there at all.
bool has_attribute(const std::string& tag, const std::string& name, std::string* value = nullptr) {
  const std::regex re("[\\s]" + name + "\\s*=\\s*(\"([^\"]*)\"|'([^']*)')");
  std::smatch m;
  if (!std::regex_search(tag, m, re)) return false;
  if (value) *value = m[2].matched ? m[2].str() : m[3].str();
  return true;
}

// Calls visit(pos, tag) for every tag of the URDF text in order (start, end
// or self-closing; `tag` its text from '<' to '>'), skipping comments, CDATA
// and processing instructions; stops at an unclosed tag (urdfdom reports it).
template <class Visit>
void for_each_tag(const std::string& xml, Visit visit) {
  std::size_t pos = 0;
  while ((pos = xml.find('<', pos)) != std::string::npos) {
    if (const std::size_t v = verbatim_end(xml, pos); v != std::string::npos) {
      pos = v;
      continue;
    }
    const std::size_t e = tag_end(xml, pos);
    if (e == std::string::npos) break;
    visit(pos, xml.substr(pos, e - pos));
    pos = e;
  }
}

}  // namespace

std::map<std::string, std::string> limits_without_bounds(const std::string& xml) {
  std::map<std::string, std::string> out;
  std::string joint;  // the <joint> element the scan is in ("" outside)
  for_each_tag(xml, [&](std::size_t pos, const std::string& tag) {
    if (starts_tag(xml, pos, "joint")) {
      joint.clear();
      if (tag[tag.size() - 2] != '/') has_attribute(tag, "name", &joint);
    } else if (tag.compare(0, 7, "</joint") == 0) {
      joint.clear();
    } else if (!joint.empty() && starts_tag(xml, pos, "limit")) {
      const bool lower = has_attribute(tag, "lower"), upper = has_attribute(tag, "upper");
      if (!lower || !upper)
        out[joint] = !lower && !upper ? "lower and upper" : !lower ? "lower" : "upper";
    }
  });
  return out;
}

namespace {

// The scan's place in the URDF text: the link and the collision element it
// is in (for collision_elements).
struct CollisionScan {
  std::string link;                  // "" outside a <link>
  std::map<std::string, int> count;  // <collision> elements seen per link
  bool in_collision = false, in_geometry = false;
  std::vector<CollisionElement> out;

  // One tag of the text (start, end or self-closing), `tag` its text.
  void see(const std::string& xml, std::size_t pos, const std::string& tag) {
    const bool closes = tag.size() >= 2 && tag[tag.size() - 2] == '/';
    if (starts_tag(xml, pos, "link")) {
      link.clear();
      if (!closes) has_attribute(tag, "name", &link);
    } else if (tag.compare(0, 6, "</link") == 0) {
      link.clear();
    } else if (!link.empty() && starts_tag(xml, pos, "collision")) {
      CollisionElement c;
      c.link = link;
      c.index = static_cast<std::size_t>(count[link]++);
      out.push_back(c);
      in_collision = !closes;
    } else if (tag.compare(0, 11, "</collision") == 0) {
      in_collision = in_geometry = false;
    } else if (in_collision) {
      see_inside(xml, pos, tag, closes);
    }
  }

  void see_inside(const std::string& xml, std::size_t pos, const std::string& tag, bool closes) {
    CollisionElement& c = out.back();
    if (!in_geometry && starts_tag(xml, pos, "origin")) {
      has_attribute(tag, "xyz", &c.xyz);
      has_attribute(tag, "rpy", &c.rpy);
    } else if (starts_tag(xml, pos, "geometry")) {
      in_geometry = !closes;
    } else if (tag.compare(0, 10, "</geometry") == 0) {
      in_geometry = false;
    } else if (in_geometry && c.shape.empty() && tag.size() > 1 && tag[1] != '/') {
      std::size_t e = 1;
      while (e < tag.size() && (std::isalnum(static_cast<unsigned char>(tag[e])) || tag[e] == '_'))
        ++e;
      c.shape = tag.substr(1, e - 1);
      for (const char* a : {"size", "radius", "length"}) {
        std::string v;
        if (has_attribute(tag, a, &v)) c.attributes[a] = v;
      }
    }
  }
};

}  // namespace

std::vector<CollisionElement> collision_elements(const std::string& xml) {
  CollisionScan scan;
  for_each_tag(xml, [&](std::size_t pos, const std::string& tag) { scan.see(xml, pos, tag); });
  return std::move(scan.out);
}

std::string without_geometry(const std::string& xml) {
  std::string out;
  out.reserve(xml.size());
  std::size_t pos = 0;
  while (pos < xml.size()) {
    const std::size_t lt = xml.find('<', pos);
    if (lt == std::string::npos) break;
    out.append(xml, pos, lt - pos);
    pos = lt;
    if (const std::size_t v = verbatim_end(xml, pos); v != std::string::npos) {
      out.append(xml, pos, v - pos);
      pos = v;
      continue;
    }
    bool dropped = false;
    for (const char* name : kIgnored) {
      if (!starts_tag(xml, pos, name)) continue;
      const std::size_t e = element_end(xml, pos, name);
      if (e == std::string::npos) break;  // unclosed: urdfdom reports it
      pos = e;
      dropped = true;
      break;
    }
    if (!dropped) out += xml[pos++];
  }
  out.append(xml, pos, std::string::npos);
  return out;
}

}  // namespace lcsim::scene
