// A model file's inputs (docs/inputs.md): the `inputs:` list and the
// mechanical keys that say where they enter (force_inputs, gap_inputs).
#include <algorithm>
#include <lcsim/core/format.hpp>
#include <lcsim/io/yaml.hpp>
#include <set>

namespace lcsim::io::yaml {

namespace {

// The optional number at `name` (fallback when absent).
double optional(const Keys& keys, const std::string& name, double fallback,
                const std::string& source, const std::string& key) {
  const auto it = keys.find(name);
  return it == keys.end() ? fallback : number(it->second, source, key + "." + name);
}

double required(const Keys& keys, const std::string& name, const std::string& source,
                const std::string& key) {
  const auto it = keys.find(name);
  if (it == keys.end()) fail(source, key + "." + name, "missing");
  return number(it->second, source, key + "." + name);
}

// The points of a pwl: a list of [t, value] pairs.
void pwl_points(const YAML::Node& n, const std::string& source, const std::string& key,
                mech::Input& in) {
  const Eigen::MatrixXd p = matrix(n, source, key, 2);
  if (p.cols() != 2 || p.rows() == 0)
    fail(source, key, "expected a list of [time, value] pairs (got " + dims(p) + ")");
  for (Eigen::Index i = 0; i < p.rows(); ++i) {
    in.times.push_back(p(i, 0));
    in.values.push_back(p(i, 1));
  }
}

// SPICE's PULSE(v1 v2 delay rise fall width period): one period's points
// from `delay`, repeated when period > 0.
void pulse_points(const Keys& keys, const std::string& source, const std::string& key,
                  mech::Input& in) {
  const double v1 = required(keys, "v1", source, key), v2 = required(keys, "v2", source, key);
  const double rise = optional(keys, "rise", 0.0, source, key);
  const double fall = optional(keys, "fall", 0.0, source, key);
  const double width = required(keys, "width", source, key);
  for (const auto& [name, x] : {std::pair{"rise", rise}, {"fall", fall}, {"width", width}})
    if (x < 0.0) fail(source, key + "." + name, "must be >= 0 (got " + format_number(x) + ")");
  in.origin = optional(keys, "delay", 0.0, source, key);
  in.period = optional(keys, "period", 0.0, source, key);
  in.times = {0.0, rise, rise + width, rise + width + fall};
  in.values = {v1, v2, v2, v1};
  if (in.period > 0.0 && in.times.back() > in.period)
    fail(source, key + ".period",
         "a pulse longer than its period (rise + width + fall = " + format_number(in.times.back()) +
             " s > " + format_number(in.period) + " s)");
}

// The signal of one entry by its kind; the keys each kind reads.
void signal(const Keys& keys, const std::string& kind, const std::string& source,
            const std::string& key, mech::Input& in) {
  const auto opt = [&](const char* name, double fallback) {
    return optional(keys, name, fallback, source, key);
  };
  const auto req = [&](const char* name) { return required(keys, name, source, key); };
  if (kind == "constant") {
    in.times = {0.0};
    in.values = {req("value")};
  } else if (kind == "step") {
    const double t = req("time");
    in.times = {t, t};
    in.values = {opt("initial", 0.0), req("final")};
  } else if (kind == "ramp") {
    in.times = {opt("time", 0.0)};
    in.values = {opt("offset", 0.0)};
    in.tail_slope = req("slope");
  } else if (kind == "sine" || kind == "damped_sine") {
    in.sine = true;
    in.offset = opt("offset", 0.0);
    in.amplitude = req("amplitude");
    in.frequency = req("frequency");
    in.phase = opt("phase", 0.0);
    in.damping = kind == "damped_sine" ? req("damping") : 0.0;
    in.origin = opt("delay", 0.0);
  } else if (kind == "pulse") {
    pulse_points(keys, source, key, in);
  } else if (kind == "pwl") {
    if (!keys.count("points")) fail(source, key + ".points", "missing");
    pwl_points(keys.at("points"), source, key + ".points", in);
  } else {
    fail(
        source, key + ".kind",
        "unknown kind '" + kind + "' (known: constant, step, ramp, sine, damped_sine, pulse, pwl)");
  }
}

}  // namespace

std::vector<mech::Input> inputs(const YAML::Node& n, const std::string& source) {
  if (!n.IsSequence())
    fail(source, "inputs", "expected a list of {name, kind, ...} (got " + describe(n) + ")");
  std::vector<mech::Input> out;
  std::set<std::string> seen;
  for (std::size_t j = 0; j < n.size(); ++j) {
    const std::string key = "inputs[" + std::to_string(j) + "]";
    const Keys keys =
        mapping(n[j], source, key,
                {"name",   "kind",      "value",     "time",  "initial", "final", "slope",
                 "offset", "amplitude", "frequency", "phase", "damping", "delay", "v1",
                 "v2",     "rise",      "fall",      "width", "period",  "points"});
    for (const char* k : {"name", "kind"})
      if (!keys.count(k) || !keys.at(k).IsScalar() || keys.at(k).Scalar().empty())
        fail(source, key + "." + k, "missing (every input has a name and a kind)");
    mech::Input in;
    in.name = keys.at("name").Scalar();
    in.kind = keys.at("kind").Scalar();
    if (!seen.insert(in.name).second)
      fail(source, key + ".name", "input '" + in.name + "' is named twice");
    signal(keys, in.kind, source, key, in);
    if (std::string why = mech::check_input(in); !why.empty())
      fail(source, key, "input '" + in.name + "': " + why);
    out.push_back(std::move(in));
  }
  return out;
}

std::vector<mech::InputUse> input_uses(const YAML::Node& n, const std::vector<mech::Input>& inputs,
                                       Eigen::Index size, const std::string& source,
                                       const std::string& key, const std::string& why) {
  if (!n.IsSequence())
    fail(source, key, "expected a list of {input, gain} (got " + describe(n) + ")");
  std::vector<mech::InputUse> out;
  for (std::size_t i = 0; i < n.size(); ++i) {
    const std::string ikey = key + "[" + std::to_string(i) + "]";
    const Keys keys = mapping(n[i], source, ikey, {"input", "gain"});
    for (const char* k : {"input", "gain"})
      if (!keys.count(k)) fail(source, ikey + "." + k, "missing");
    const YAML::Node& name = keys.at("input");
    std::vector<std::string> names;
    for (const mech::Input& in : inputs) names.push_back(in.name);
    const auto it = std::find(names.begin(), names.end(), name.IsScalar() ? name.Scalar() : "");
    if (it == names.end())
      fail(source, ikey + ".input",
           "no input named " + describe(name) +
               (names.empty() ? " (the model has no `inputs:`)"
                              : " (the inputs: " + join(names) + ")"));
    mech::InputUse use;
    use.input = static_cast<int>(it - names.begin());
    use.gain = vector(keys.at("gain"), source, ikey + ".gain");
    expect_size(use.gain, size, source, ikey + ".gain", why);
    out.push_back(std::move(use));
  }
  return out;
}

}  // namespace lcsim::io::yaml
