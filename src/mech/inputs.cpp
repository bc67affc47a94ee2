// Inputs that vary in time: their closed forms, exosystems and breakpoints
// (include/lcsim/mech/inputs.hpp, docs/inputs.md).
#include <cmath>
#include <lcsim/core/format.hpp>
#include <lcsim/mech/inputs.hpp>
#include <numbers>

namespace lcsim::mech {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// The piece of a piecewise linear input holding t: it starts at point i at
// time `start`; i = -1 before the first point.
struct Piece {
  int i = -1;
  double start = -kInf;
};

// Point i's time in repetition k: one formula, so that a breakpoint found by
// next_breakpoint is the start that locate finds at that time, to the bit.
double point_time(const Input& in, long k, std::size_t i) {
  const double base = in.period > 0.0 ? in.origin + static_cast<double>(k) * in.period : in.origin;
  return base + in.times[i];
}

// Whether point i starts a piece: in a periodic input a point at the
// period's end is the next repetition's start, not a piece of its own.
bool starts_piece(const Input& in, std::size_t i) {
  return in.period <= 0.0 || in.times[i] < in.period;
}

// Calls f(k, i, time) for every breakpoint near t, in increasing (k, i).
template <class F>
void near_points(const Input& in, double t, F&& f) {
  long k0 = 0, k1 = 0;
  if (in.period > 0.0) {
    const double kk = std::floor((t - in.origin) / in.period);
    k0 = std::max(0L, static_cast<long>(kk) - 1);
    k1 = std::max(0L, static_cast<long>(kk) + 2);
  }
  for (long k = k0; k <= k1; ++k)
    for (std::size_t i = 0; i < in.times.size(); ++i)
      if (starts_piece(in, i)) f(k, i, point_time(in, k, i));
}

Piece locate(const Input& in, double t) {
  Piece p;
  near_points(in, t, [&](long, std::size_t i, double b) {
    if (b <= t && b >= p.start) p = {static_cast<int>(i), b};
  });
  return p;
}

// The slope (unit/s) of the piece starting at point i.
double slope(const Input& in, int i) {
  const auto j = static_cast<std::size_t>(i);
  if (j + 1 < in.times.size()) {
    const double dt = in.times[j + 1] - in.times[j];
    return dt > 0.0 ? (in.values[j + 1] - in.values[j]) / dt : 0.0;
  }
  return in.period > 0.0 ? 0.0 : in.tail_slope;
}

}  // namespace

double Input::value(double t) const {
  if (sine) {
    const double tau = t - origin;
    if (tau < 0.0) return offset;
    return offset + amplitude * std::exp(-damping * tau) *
                        std::sin(2.0 * std::numbers::pi * frequency * tau + phase);
  }
  const Piece p = locate(*this, t);
  if (p.i < 0) return values.front();
  return values[static_cast<std::size_t>(p.i)] + slope(*this, p.i) * (t - p.start);
}

Eigen::MatrixXd Input::exo_matrix() const {
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(exo_size(), exo_size());
  if (sine) {
    const double w = 2.0 * std::numbers::pi * frequency;
    S(1, 1) = -damping, S(1, 2) = w, S(2, 1) = -w, S(2, 2) = -damping;
  } else {
    S(0, 1) = 1.0;
  }
  return S;
}

Eigen::RowVectorXd Input::exo_output() const {
  Eigen::RowVectorXd l = Eigen::RowVectorXd::Zero(exo_size());
  l(0) = 1.0;
  if (sine) l(1) = amplitude;
  return l;
}

Eigen::VectorXd Input::exo_state(double t) const {
  Eigen::VectorXd w = Eigen::VectorXd::Zero(exo_size());
  if (sine) {
    w(0) = offset;
    const double tau = t - origin;
    if (tau >= 0.0) {
      const double e = std::exp(-damping * tau),
                   a = 2.0 * std::numbers::pi * frequency * tau + phase;
      w(1) = e * std::sin(a);
      w(2) = e * std::cos(a);
    }
    return w;
  }
  const Piece p = locate(*this, t);
  if (p.i < 0) {
    w(0) = values.front();
    return w;
  }
  w(1) = slope(*this, p.i);
  w(0) = values[static_cast<std::size_t>(p.i)] + w(1) * (t - p.start);
  return w;
}

double Input::next_breakpoint(double t) const {
  if (sine) return origin > t && origin > 0.0 ? origin : kInf;
  double next = kInf;
  near_points(*this, t, [&](long, std::size_t, double b) {
    if (b > t && b < next) next = b;
  });
  return next;
}

std::string check_input(const Input& in) {
  const auto finite = [](double x) { return std::isfinite(x); };
  if (!finite(in.origin) || in.origin < 0.0)
    return text("delay must be a finite number >= 0 (got ", format_number(in.origin), ")");
  if (in.sine) {
    if (!finite(in.offset) || !finite(in.amplitude) || !finite(in.damping) || !finite(in.phase))
      return "offset, amplitude, damping and phase must be finite";
    if (!finite(in.frequency) || in.frequency < 0.0)
      return text("frequency must be a finite number >= 0 (got ", format_number(in.frequency), ")");
    return "";
  }
  if (in.times.empty() || in.times.size() != in.values.size())
    return text("expected as many times as values, at least one (got ", in.times.size(), " and ",
                in.values.size(), ")");
  for (std::size_t i = 0; i < in.times.size(); ++i) {
    if (!finite(in.times[i]) || !finite(in.values[i]))
      return text("point ", i, " is not finite (", format_number(in.times[i]), ", ",
                  format_number(in.values[i]), ")");
    if (i > 0 && in.times[i] < in.times[i - 1])
      return text("times decrease (", format_number(in.times[i]), " s after ",
                  format_number(in.times[i - 1]), " s)");
  }
  if (!finite(in.tail_slope)) return "slope must be finite";
  if (!finite(in.period) || in.period < 0.0)
    return text("period must be a finite number >= 0 (got ", format_number(in.period), ")");
  if (in.period > 0.0 && (in.times.front() < 0.0 || in.times.back() > in.period))
    return text("the points must lie within one period [0, ", format_number(in.period), "] s (got ",
                format_number(in.times.front()), " .. ", format_number(in.times.back()), " s)");
  return "";
}

}  // namespace lcsim::mech
