// The signals of mech::Input (docs/inputs.md): each kind's value against its
// closed form written here, its exosystem e^(S tau) w(t0) against the value
// on every piece (the exactness the event-driven method relies on), and its
// breakpoints.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/mech/inputs.hpp>
#include <numbers>
#include <unsupported/Eigen/MatrixFunctions>

namespace lcsim::mech {
namespace {

Input pwl(std::vector<double> t, std::vector<double> v) {
  Input in;
  in.name = "u";
  in.kind = "pwl";
  in.times = std::move(t);
  in.values = std::move(v);
  return in;
}

// The exosystem's output at t, propagated from the start of t's piece
// (the last breakpoint at or before t, or 0).
double exo_value(const Input& in, double t0, double t) {
  const Eigen::VectorXd w = (in.exo_matrix() * (t - t0)).exp() * in.exo_state(t0);
  return in.exo_output() * w;
}

TEST(Input, PwlValuesAndExosystem) {
  const Input in = pwl({0.5, 1.5, 1.5, 3.0}, {1.0, 3.0, -2.0, 0.0});
  EXPECT_EQ(check_input(in), "");
  // By hand: 1 before 0.5; 1 + 2 (t - 0.5) on [0.5, 1.5); the jump to -2;
  // -2 + (2/1.5)(t - 1.5) on [1.5, 3); 0 after.
  EXPECT_EQ(in.value(0.2), 1.0);
  EXPECT_DOUBLE_EQ(in.value(1.0), 2.0);
  EXPECT_EQ(in.value(1.5), -2.0);  // the right limit at a jump
  EXPECT_DOUBLE_EQ(in.value(2.25), -1.0);
  EXPECT_EQ(in.value(7.0), 0.0);
  EXPECT_EQ(in.next_breakpoint(0.0), 0.5);
  EXPECT_EQ(in.next_breakpoint(0.5), 1.5);
  EXPECT_EQ(in.next_breakpoint(1.5), 3.0);
  EXPECT_TRUE(std::isinf(in.next_breakpoint(3.0)));
  // Exact on each piece: the exosystem from the piece's start (e^{S tau}
  // of a nilpotent S is exact to rounding; 1e-14 of values of order 1).
  const double starts[] = {0.0, 0.5, 1.5, 3.0};
  for (int p = 0; p < 4; ++p)
    for (double f : {0.0, 0.3, 0.9}) {
      const double t = starts[p] + f * (p < 3 ? starts[p + 1] - starts[p] : 1.0);
      EXPECT_NEAR(exo_value(in, starts[p], t), in.value(t), 1e-14) << t;
    }
}

TEST(Input, DampedSineValuesAndExosystem) {
  Input in;
  in.name = "s";
  in.kind = "damped_sine";
  in.sine = true;
  in.offset = 0.5, in.amplitude = 2.0, in.frequency = 3.0, in.damping = 1.5, in.phase = 0.7;
  in.origin = 0.25;
  EXPECT_EQ(check_input(in), "");
  const double w = 2.0 * std::numbers::pi * 3.0;
  for (double t : {0.3, 0.6, 1.1}) {
    const double tau = t - 0.25;
    const double want = 0.5 + 2.0 * std::exp(-1.5 * tau) * std::sin(w * tau + 0.7);
    EXPECT_NEAR(in.value(t), want, 1e-15);
    // One exponential of the 3-state oscillator over up to 0.85 s
    // (|S tau| ~ 16): rounding of a few ulp times that norm.
    EXPECT_NEAR(exo_value(in, 0.25, t), want, 1e-13) << t;
  }
  EXPECT_EQ(in.value(0.1), 0.5);  // the offset before the delay
  EXPECT_EQ(in.next_breakpoint(0.0), 0.25);
  EXPECT_TRUE(std::isinf(in.next_breakpoint(0.25)));
}

TEST(Input, PeriodicPulse) {
  Input in = pwl({0.0, 0.1, 0.4, 0.6}, {-1.0, 2.0, 2.0, -1.0});
  in.kind = "pulse";
  in.origin = 1.0;
  in.period = 1.0;
  EXPECT_EQ(check_input(in), "");
  EXPECT_EQ(in.value(0.5), -1.0);           // before the delay
  EXPECT_NEAR(in.value(3.05), 0.5, 1e-12);  // half way up the rise of the third period
  EXPECT_EQ(in.value(3.2), 2.0);            // the top
  EXPECT_NEAR(in.value(3.5), 0.5, 1e-12);   // half way down
  EXPECT_EQ(in.value(3.8), -1.0);           // the rest of the period
  EXPECT_NEAR(in.next_breakpoint(3.5), 3.6, 1e-15);
  EXPECT_NEAR(in.next_breakpoint(3.6), 4.0, 1e-15);
  EXPECT_NEAR(exo_value(in, 3.0, 3.07), in.value(3.07), 1e-14);
}

TEST(Input, RefusedSignals) {
  EXPECT_EQ(check_input(pwl({0.0, 2e-3, 1e-3}, {0, 1, 2})),
            "times decrease (0.001 s after 0.002 s)");
  EXPECT_NE(check_input(pwl({0.0}, {0, 1})).find("as many times as values"), std::string::npos);
  Input p = pwl({0.0, 0.5, 2.0}, {0, 1, 0});
  p.period = 1.0;
  EXPECT_NE(check_input(p).find("within one period"), std::string::npos);
  Input s;
  s.sine = true;
  s.frequency = -1.0;
  EXPECT_NE(check_input(s).find("frequency must be"), std::string::npos);
}

}  // namespace
}  // namespace lcsim::mech
