// Axes: ranges, random draws and the expansion of a run index into its point
// (study.hpp).
#include <cmath>
#include <lcsim/study/study.hpp>
#include <limits>

namespace lcsim::study {

std::uint64_t splitmix64(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

std::uint64_t draw_seed(std::uint64_t seed, std::size_t axis, std::size_t quantity,
                        std::size_t draw) {
  std::uint64_t state = seed;
  for (const std::uint64_t part :
       {std::uint64_t(axis), std::uint64_t(quantity), std::uint64_t(draw)})
    state = splitmix64(state) ^ part;
  return splitmix64(state);
}

double uniform01(std::uint64_t& state) {
  return static_cast<double>(splitmix64(state) >> 11) * 0x1.0p-53;
}

double draw(const Distribution& d, std::uint64_t& state) {
  switch (d.kind) {
    case Distribution::Kind::kUniform:
      return d.a + (d.b - d.a) * uniform01(state);
    case Distribution::Kind::kLogUniform:
      return std::exp(std::log(d.a) + (std::log(d.b) - std::log(d.a)) * uniform01(state));
    case Distribution::Kind::kNormal: {
      const double u1 = 1.0 - uniform01(state);  // (0, 1]: the log is finite
      const double u2 = uniform01(state);
      return d.a + d.b * std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
    }
    case Distribution::Kind::kNone:
      break;
  }
  return std::numeric_limits<double>::quiet_NaN();
}

std::vector<double> linspace(double a, double b, std::size_t count) {
  std::vector<double> v(count);
  for (std::size_t i = 0; i < count; ++i)
    v[i] = count == 1 ? a : a + static_cast<double>(i) * (b - a) / static_cast<double>(count - 1);
  if (count > 1) v.back() = b;
  return v;
}

std::vector<double> logspace(double a, double b, std::size_t count) {
  std::vector<double> v = linspace(std::log(a), std::log(b), count);
  for (double& x : v) x = std::exp(x);
  v.front() = a;
  if (count > 1) v.back() = b;
  return v;
}

std::size_t run_count(const Study& s) {
  std::size_t n = 1;
  for (const auto& a : s.axes) {
    if (a.count != 0 && n > std::numeric_limits<std::size_t>::max() / a.count)
      return std::numeric_limits<std::size_t>::max();
    n *= a.count;
  }
  return n;
}

RunPoint expand(const Study& s, std::size_t index) {
  RunPoint p;
  p.index = index;
  p.axis_index.assign(s.axes.size(), 0);
  // The last axis varies fastest.
  std::size_t rest = index;
  for (std::size_t a = s.axes.size(); a-- > 0;) {
    p.axis_index[a] = rest % s.axes[a].count;
    rest /= s.axes[a].count;
  }
  for (std::size_t a = 0; a < s.axes.size(); ++a) {
    const Axis& axis = s.axes[a];
    const std::size_t j = p.axis_index[a];
    for (std::size_t q = 0; q < axis.quantities.size(); ++q) {
      if (axis.random[q].kind == Distribution::Kind::kNone) {
        p.values.push_back(axis.values[q][j]);
        continue;
      }
      std::uint64_t state = draw_seed(s.seed, a, q, j);
      p.values.push_back({"", draw(axis.random[q], state)});
    }
  }
  return p;
}

std::vector<std::string> quantity_keys(const Study& s) {
  std::vector<std::string> keys;
  for (const auto& a : s.axes)
    for (const auto& q : a.quantities) keys.push_back(q.key);
  return keys;
}

}  // namespace lcsim::study
