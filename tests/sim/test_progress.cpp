// Options::progress: every integrator reports the time it has reached, in
// order, inside [0, t_end], and as often as documented (time stepping every
// Options::kProgressSteps steps; the event-driven method once per step of its
// event search). The two carts of §3.7 from the impact state (0, -1, -1, 0)
// to T = 3: impact, constrained phase, release at pi/2, free motion.
#include <gtest/gtest.h>

#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <vector>

namespace lcsim::sim {
namespace {

std::vector<double> reported(const std::string& method, double h) {
  const mech::Model model = mech::two_carts_model(false);
  Options opt;
  opt.t_end = 3.0;
  opt.h = h;
  opt.record_samples = false;
  std::vector<double> ts;
  opt.progress = [&ts](double t) { ts.push_back(t); };
  const Trajectory tr = make_integrator(method)->run(model, Eigen::Vector4d(0, -1, -1, 0), opt);
  EXPECT_EQ(tr.status, RunStatus::kCompleted) << method << ": " << tr.message;
  return ts;
}

void expect_ordered_in_range(const std::vector<double>& ts, const std::string& method) {
  for (std::size_t i = 0; i < ts.size(); ++i) {
    EXPECT_GE(ts[i], 0.0) << method;
    EXPECT_LE(ts[i], 3.0) << method;
    if (i > 0) {
      EXPECT_GE(ts[i], ts[i - 1]) << method;
    }
  }
}

// 3 / 1e-4 = 30000 steps: a report every 1024 steps is floor(30000 / 1024) =
// 29 reports, the k-th at t = 1024 k h (exact multiples: 1024 k * 1e-4 is
// computed as j * h, as the integrators do).
TEST(Progress, TimeSteppingReportsEveryKProgressSteps) {
  const double h = 1e-4;
  for (const std::string method : {"moreau-jean", "euler"}) {
    const std::vector<double> ts = reported(method, h);
    ASSERT_EQ(ts.size(), 30000u / Options::kProgressSteps) << method;
    for (std::size_t i = 0; i < ts.size(); ++i)
      EXPECT_EQ(ts[i], static_cast<double>((i + 1) * Options::kProgressSteps) * h) << method;
    expect_ordered_in_range(ts, method);
  }
}

// The exact method: at least one report per phase (two phases on [0, 3]),
// the first at t = 0.
TEST(Progress, EventDrivenReportsEachStepOfItsSearch) {
  const std::vector<double> ts = reported("event", 1e-3);
  EXPECT_GE(ts.size(), 2u);
  expect_ordered_in_range(ts, "event");
  EXPECT_EQ(ts.front(), 0.0);
}

}  // namespace
}  // namespace lcsim::sim
