// Inputs that vary in time (issue 29; docs/inputs.md): the signals a model's
// force f and gaps g may follow, each exactly the output of a small linear
// exosystem w' = S w, value = l' w, whose state is re-initialised at the
// signal's breakpoints (the scheduled events of the exact method). Between
// breakpoints each phase of the exact method stays one matrix exponential.
#pragma once

#include <Eigen/Dense>
#include <limits>
#include <optional>
#include <string>
#include <vector>

namespace lcsim::mech {

// One named signal u(t) (the unit is that of what it drives: N, m).
// Two families:
// - piecewise linear (kinds constant, step, ramp, pwl, pulse): the points
//   (times[i], values[i]) with times non-decreasing (two equal times are a
//   jump: the value from there is the later point's), values[0] before the
//   first point, values.back() + tail_slope (t - times.back()) after the
//   last. With period > 0 the points (times in [0, period]) repeat every
//   period from `origin` (values[0] before it). Exosystem (p, r): p' = r,
//   r' = 0, value p; re-initialised to (u, u') at each point.
// - sine (kinds sine and damped sine): offset + amplitude e^(-damping tau)
//   sin(2 pi frequency tau + phase) with tau = t - origin >= 0, offset before.
//   Exosystem (o, s, c): o' = 0, s' = -damping s + omega c,
//   c' = -omega s - damping c, value o + amplitude s; re-initialised at
//   t = origin > 0 (the delay).
struct Input {
  std::string name;
  std::string kind;  // as the model file names it (messages)
  bool sine = false;
  // Piecewise linear.
  std::vector<double> times, values;  // s, and the unit of the input
  double tail_slope = 0.0;            // unit/s after the last point (a ramp)
  double period = 0.0;                // s; 0: not periodic
  double origin = 0.0;                // s: where the period or the sine starts (a delay)
  // Sine.
  double offset = 0.0, amplitude = 0.0;
  double frequency = 0.0;  // Hz
  double damping = 0.0;    // 1/s
  double phase = 0.0;      // rad

  // The value at t (the right limit at a jump), by its closed form.
  double value(double t) const;
  // The exosystem: its size, S and l (value = l' w).
  int exo_size() const { return sine ? 3 : 2; }
  Eigen::MatrixXd exo_matrix() const;
  Eigen::RowVectorXd exo_output() const;
  // The exosystem state at t on the piece that starts at or holds t.
  Eigen::VectorXd exo_state(double t) const;
  // The first breakpoint after t (strictly), +inf if none.
  double next_breakpoint(double t) const;
};

// Where an input enters a mechanical model: `gain` times its value added to
// f (N entries) or to g (k entries).
struct InputUse {
  int input = 0;  // index into MechanicalModel::inputs
  Eigen::VectorXd gain;
};

// What is wrong with an input ("" when usable): finite numbers, times that
// never decrease (named as "times decrease (1 s after 2 s)"), points inside a
// period, frequency and period >= 0.
std::string check_input(const Input& in);

}  // namespace lcsim::mech
