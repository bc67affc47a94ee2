// Reading a study file (docs/study.md): the models, the defaults and the
// axes, every error one line naming the file, the key and the value.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/io/text.hpp>
#include <lcsim/io/yaml.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/study/study.hpp>

#include "study/detail.hpp"

namespace lcsim::study {

namespace {

namespace y = io::yaml;

const std::vector<std::string> kTopKeys = {"name",   "model",  "models",    "t_end",
                                           "seed",   "method", "h",         "theta",
                                           "impact", "lcp",    "reference", "axes"};

int index_of(const std::vector<std::string>& names, const std::string& name) {
  const auto it = std::find(names.begin(), names.end(), name);
  return it == names.end() ? -1 : static_cast<int>(it - names.begin());
}

// The index of `name` in the names each model gives (coordinates or
// constraints): it must be the same in every model.
int named_index(const Study& s, const std::string& key, const std::string& name, bool constraint) {
  int found = -2;
  for (const auto& m : s.models) {
    if (!m.is_mechanical())
      y::fail(s.source, key,
              "model '" + m.name + "' is an LCS model: it has no named " +
                  (constraint ? "constraints" : "coordinates"));
    const auto& names = constraint ? m.mechanical->constraints : m.mechanical->coordinates;
    const int i = index_of(names, name);
    if (i < 0)
      y::fail(s.source, key,
              "no " + std::string(constraint ? "constraint" : "coordinate") + " '" +
                  io::one_line(name, 80) + "' in model '" + m.name + "' (it has " + y::join(names) +
                  ")");
    if (found != -2 && found != i)
      y::fail(s.source, key, "'" + name + "' is not at the same index in every model");
    found = i;
  }
  return found;
}

// A mu.<constraint> quantity: every model has a mechanical.friction entry on
// that constraint.
void check_frictional(const Study& s, const std::string& key, const std::string& name, int row) {
  for (const auto& m : s.models) {
    const auto& fr = m.mechanical->friction;
    if (std::none_of(fr.begin(), fr.end(),
                     [row](const mech::FrictionalContact& c) { return c.contact == row; }))
      y::fail(s.source, key,
              "constraint '" + io::one_line(name, 80) + "' of model '" + m.name +
                  "' has no friction (no mechanical.friction entry, no scene contact's "
                  "friction:)");
  }
}

std::vector<std::string> split_dots(const std::string& key) { return io::split(key, '.'); }

// where: the key as placed in the file ("axes[1].scale.K"), for messages.
Quantity parse_scale(const Study& s, const std::string& key, const std::string& where,
                     const std::vector<std::string>& p) {
  Quantity q;
  q.kind = Quantity::Kind::kScale;
  q.key = key;
  const std::vector<std::string> mats = {"M", "D", "K", "f", "g"};
  if (p.size() < 2 || index_of(mats, p[1]) < 0)
    y::fail(s.source, where, "expected scale.<M|D|K|f|g>[.<name>...] (got '" + key + "')");
  q.matrix = p[1];
  const bool square = q.matrix == "M" || q.matrix == "D" || q.matrix == "K";
  if (p.size() == 2) return q;
  if (square && p.size() == 4) {
    q.row = named_index(s, where, p[2], false);
    q.col = named_index(s, where, p[3], false);
    return q;
  }
  if (!square && p.size() == 3) {
    q.row = named_index(s, where, p[2], q.matrix == "g");
    return q;
  }
  y::fail(s.source, where,
          square ? "expected scale." + q.matrix + " or scale." + q.matrix + ".<coord>.<coord>"
                 : "expected scale." + q.matrix + " or scale." + q.matrix + ".<" +
                       (q.matrix == "g" ? "constraint" : "coordinate") + ">");
}

Quantity parse_quantity(const Study& s, const std::string& key, const std::string& where) {
  Quantity q;
  q.key = key;
  const std::vector<std::string> p = split_dots(key);
  using K = Quantity::Kind;
  if (p.size() == 1) {
    const std::vector<std::pair<std::string, K>> plain = {
        {"model", K::kModel}, {"method", K::kMethod}, {"impact", K::kImpact},
        {"h", K::kH},         {"theta", K::kTheta},   {"t_end", K::kTEnd}};
    for (const auto& [name, kind] : plain)
      if (key == name) {
        q.kind = kind;
        return q;
      }
  } else if (p[0] == "scale") {
    return parse_scale(s, key, where, p);
  } else if (p.size() == 2 && (p[0] == "x0" || p[0] == "v0" || p[0] == "restitution")) {
    q.kind = p[0] == "x0" ? K::kX0 : p[0] == "v0" ? K::kV0 : K::kRestitution;
    q.row = named_index(s, where, p[1], q.kind == K::kRestitution);
    return q;
  } else if (p.size() == 2 && p[0] == "mu") {
    q.kind = K::kMu;
    q.row = named_index(s, where, p[1], true);
    check_frictional(s, where, p[1], q.row);
    return q;
  }
  y::fail(s.source, where,
          "unknown quantity (expected method, impact, h, theta, t_end, x0.<coord>, v0.<coord>, "
          "restitution.<constraint>, mu.<constraint> or scale.<M|D|K|f|g>...)");
}

void check_name(const Study& s, const std::string& key, const Quantity& q, const std::string& v) {
  try {
    if (q.kind == Quantity::Kind::kMethod)
      (void)sim::make_integrator(v);
    else
      (void)impact::make_impact_law(v);
  } catch (const std::invalid_argument& e) {
    y::fail(s.source, key, io::one_line(e.what()));
  }
}

std::size_t count_of(const Study& s, const YAML::Node& n, const std::string& key) {
  const double c = y::number(n, s.source, key);
  if (!(c >= 1.0) || c != std::floor(c) || c > 1e12)
    y::fail(s.source, key, "expected a whole number >= 1 (got " + y::describe(n) + ")");
  return static_cast<std::size_t>(c);
}

std::vector<Value> numbers(const std::vector<double>& v) {
  std::vector<Value> out;
  for (double x : v) out.push_back({"", x});
  return out;
}

// {linspace|logspace: [a, b, count]} or a distribution {uniform|normal|loguniform: [a, b]}.
void parse_range(const Study& s, const YAML::Node& n, const std::string& key, Axis& axis) {
  const y::Keys k =
      y::mapping(n, s.source, key, {"linspace", "logspace", "uniform", "normal", "loguniform"});
  if (k.size() != 1)
    y::fail(s.source, key, "expected one of linspace, logspace, uniform, normal, loguniform");
  const auto& [name, spec] = *k.begin();
  const std::string sub = key + "." + name;
  const Eigen::VectorXd v = y::vector(spec, s.source, sub);
  const bool range = name == "linspace" || name == "logspace";
  if (v.size() != (range ? 3 : 2))
    y::fail(s.source, sub,
            range ? "expected [first, last, count] (got " + y::describe(spec) + ")"
                  : "expected two numbers (got " + y::describe(spec) + ")");
  if (range) {
    const double c = v(2);
    if (!(c >= 1.0) || c != std::floor(c) || c > 1e9)
      y::fail(s.source, sub,
              "count must be a whole number >= 1 (got " + io::format_number(c) + ")");
    if (name == "logspace" && !(v(0) > 0.0 && v(1) > 0.0))
      y::fail(s.source, sub,
              "ends must be > 0 (got " + io::format_number(v(0)) + ", " + io::format_number(v(1)) +
                  ")");
    const auto n_values = static_cast<std::size_t>(c);
    axis.values.push_back(numbers(name == "linspace" ? linspace(v(0), v(1), n_values)
                                                     : logspace(v(0), v(1), n_values)));
    axis.random.push_back({});
    return;
  }
  Distribution d{Distribution::Kind::kUniform, v(0), v(1)};
  if (name == "normal") d.kind = Distribution::Kind::kNormal;
  if (name == "loguniform") d.kind = Distribution::Kind::kLogUniform;
  if (d.kind == Distribution::Kind::kNormal ? !(v(1) >= 0.0) : !(v(0) <= v(1)))
    y::fail(s.source, sub,
            d.kind == Distribution::Kind::kNormal
                ? "the standard deviation must be >= 0 (got " + io::format_number(v(1)) + ")"
                : "expected low <= high (got " + io::format_number(v(0)) + ", " +
                      io::format_number(v(1)) + ")");
  if (d.kind == Distribution::Kind::kLogUniform && !(v(0) > 0.0))
    y::fail(s.source, sub, "low must be > 0 (got " + io::format_number(v(0)) + ")");
  axis.values.push_back({});
  axis.random.push_back(d);
}

void parse_values(const Study& s, const YAML::Node& n, const std::string& key, Axis& axis) {
  const Quantity& q = axis.quantities.back();
  if (n.IsMap()) {
    if (q.text() || q.kind == Quantity::Kind::kModel)
      y::fail(s.source, key, "expected a list of names (got a mapping)");
    return parse_range(s, n, key, axis);
  }
  std::vector<Value> vals;
  const auto one = [&](const YAML::Node& e, const std::string& k) {
    if (q.text()) {
      if (!e.IsScalar()) y::fail(s.source, k, "expected a name (got " + y::describe(e) + ")");
      check_name(s, k, q, e.Scalar());
      vals.push_back({e.Scalar(), 0.0});
    } else {
      vals.push_back({"", y::number(e, s.source, k)});
    }
  };
  if (n.IsSequence()) {
    if (n.size() == 0) y::fail(s.source, key, "empty list");
    for (std::size_t i = 0; i < n.size(); ++i) one(n[i], key + "[" + std::to_string(i) + "]");
  } else {
    one(n, key);
  }
  axis.values.push_back(std::move(vals));
  axis.random.push_back({});
}

Axis parse_axis(const Study& s, const YAML::Node& n, const std::string& key) {
  (void)y::mapping(n, s.source, key, {});  // a mapping without duplicate keys
  Axis axis;
  bool has_count = false;
  for (const auto& kv : n) {  // in the file's order: the table's columns follow it
    const std::string name = kv.first.Scalar();
    const YAML::Node& node = kv.second;
    const std::string sub = key + "." + name;
    if (name == "count") {
      axis.count = count_of(s, node, sub);
      has_count = true;
      continue;
    }
    axis.quantities.push_back(parse_quantity(s, name, sub));
    if (axis.quantities.back().kind == Quantity::Kind::kModel)
      y::fail(s.source, sub, "the model axis comes from the top-level `models:` list");
    parse_values(s, node, sub, axis);
  }
  if (axis.quantities.empty()) y::fail(s.source, key, "an axis sets no quantity");
  for (std::size_t i = 0; i < axis.quantities.size(); ++i) {
    const std::string sub = key + "." + axis.quantities[i].key;
    if (axis.random[i].kind != Distribution::Kind::kNone) {
      if (!has_count) y::fail(s.source, sub, "a random draw needs `count:` in its axis");
      continue;
    }
    const std::size_t c = axis.values[i].size();
    if (axis.count == 0) axis.count = c;
    if (c != axis.count)
      y::fail(s.source, sub,
              "has " + std::to_string(c) + " values, the axis " + std::to_string(axis.count) +
                  " (the quantities of one axis vary together)");
  }
  return axis;
}

void check_unique_keys(const Study& s) {
  std::vector<std::string> seen;
  for (std::size_t a = 0; a < s.axes.size(); ++a)
    for (const auto& q : s.axes[a].quantities) {
      if (index_of(seen, q.key) >= 0)
        y::fail(s.source, "axes[" + std::to_string(a) + "]." + q.key,
                "set by two axes (each quantity is set by one)");
      seen.push_back(q.key);
    }
}

void parse_models(Study& s, const y::Keys& k, std::string& text) {
  const std::filesystem::path dir = std::filesystem::path(s.source).parent_path();
  const bool one = k.count("model"), many = k.count("models");
  if (one == many) y::fail(s.source, "model", "give either `model:` or `models:` (a list)");
  const YAML::Node list = one ? k.at("model") : k.at("models");
  const std::string key = one ? "model" : "models";
  std::vector<YAML::Node> entries;
  if (one) {
    entries.push_back(list);
  } else {
    if (!list.IsSequence() || list.size() == 0)
      y::fail(s.source, key, "expected a list of model files (got " + y::describe(list) + ")");
    for (const auto& e : list) entries.push_back(e);
  }
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const std::string sub = one ? key : key + "[" + std::to_string(i) + "]";
    if (!entries[i].IsScalar())
      y::fail(s.source, sub, "expected a model file path (got " + y::describe(entries[i]) + ")");
    const std::filesystem::path p = dir / entries[i].Scalar();
    try {
      text += io::read_file(p);
      s.models.push_back(scene::load_model(p));
    } catch (const io::InputError& e) {
      y::fail(s.source, sub, e.what());
    }
    s.model_paths.push_back(entries[i].Scalar());
  }
  if (many) {
    Axis axis;
    Quantity q;
    q.kind = Quantity::Kind::kModel;
    q.key = "model";
    axis.quantities.push_back(q);
    std::vector<Value> vals;
    for (std::size_t i = 0; i < s.model_paths.size(); ++i)
      vals.push_back({s.model_paths[i], static_cast<double>(i)});
    axis.values.push_back(vals);
    axis.random.push_back({});
    axis.count = vals.size();
    s.axes.push_back(axis);
  }
}

std::string text_of(const Study& s, const y::Keys& k, const std::string& key) {
  const YAML::Node& n = k.at(key);
  if (!n.IsScalar()) y::fail(s.source, key, "expected a name (got " + y::describe(n) + ")");
  return n.Scalar();
}

void parse_defaults(Study& s, const y::Keys& k) {
  if (k.count("name")) s.name = text_of(s, k, "name");
  if (k.count("t_end")) s.base.t_end = y::number(k.at("t_end"), s.source, "t_end");
  if (k.count("h")) s.base.h = y::number(k.at("h"), s.source, "h");
  if (k.count("theta")) s.base.theta = y::number(k.at("theta"), s.source, "theta");
  if (k.count("seed")) {
    const double seed = y::number(k.at("seed"), s.source, "seed");
    if (!(seed >= 0.0) || seed != std::floor(seed) || seed >= 9007199254740992.0)
      y::fail(s.source, "seed",
              "expected a whole number in [0, 2^53) (got " + y::describe(k.at("seed")) + ")");
    s.seed = static_cast<std::uint64_t>(seed);
  }
  Quantity q;
  if (k.count("method")) {
    q.kind = Quantity::Kind::kMethod;
    s.method = text_of(s, k, "method");
    check_name(s, "method", q, s.method);
  }
  if (k.count("impact")) {
    q.kind = Quantity::Kind::kImpact;
    s.base.impact = text_of(s, k, "impact");
    check_name(s, "impact", q, s.base.impact);
  }
  if (k.count("lcp")) {
    s.base.lcp_solver = text_of(s, k, "lcp");
    try {
      (void)lcp::make_solver(s.base.lcp_solver);
    } catch (const std::invalid_argument& e) {
      y::fail(s.source, "lcp", io::one_line(e.what()));
    }
  }
  if (k.count("reference")) {
    s.reference = text_of(s, k, "reference");
    if (s.reference != "event" && s.reference != "none")
      y::fail(s.source, "reference",
              "expected event or none (got '" + io::one_line(s.reference, 80) + "')");
  }
}

}  // namespace

Study parse_study(const std::string& yaml_text, const std::string& source) {
  Study s;
  s.source = source;
  const YAML::Node root = y::load(yaml_text, source);
  if (!root.IsMap())
    y::fail(source, "top level", "expected a mapping (got " + y::describe(root) + ")");
  const y::Keys k = y::mapping(root, source, "", kTopKeys);
  std::string text = yaml_text;
  parse_models(s, k, text);
  parse_defaults(s, k);
  if (k.count("axes")) {
    const YAML::Node& axes = k.at("axes");
    if (!axes.IsSequence())
      y::fail(source, "axes", "expected a list of axes (got " + y::describe(axes) + ")");
    for (std::size_t i = 0; i < axes.size(); ++i)
      s.axes.push_back(parse_axis(s, axes[i], "axes[" + std::to_string(i) + "]"));
  }
  check_unique_keys(s);
  if (run_count(s) > (std::size_t{1} << 40))
    y::fail(source, "axes", "more than 2^40 runs (got " + std::to_string(run_count(s)) + ")");
  s.fingerprint = fingerprint(text);
  return s;
}

Study load_study(const std::filesystem::path& path) {
  return parse_study(io::read_file(path), path.string());
}

}  // namespace lcsim::study
