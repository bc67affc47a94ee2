// The library checks a run's input at its entry (sim::check_run through
// Integrator::run), for every integrator the program links: bad input gives
// status kInvalidInput and a message naming the field and the value, never a
// run on garbage (these run under ASan and UBSan in CI).
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <limits>
#include <string>

namespace lcsim {
namespace {

using Eigen::VectorXd;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

mech::Model carts() {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/two_carts.yaml");
}

// Options a method accepts: the horizon, and the defaults of the rest.
sim::Options valid_options() {
  sim::Options o;
  o.t_end = 0.5;
  return o;
}

void expect_refused(const sim::Trajectory& tr, const std::string& needle) {
  EXPECT_EQ(tr.status, Status::kInvalidInput) << tr.method << ": " << tr.message;
  EXPECT_NE(tr.message.find(needle), std::string::npos)
      << tr.method << ": '" << tr.message << "' does not name '" << needle << "'";
  EXPECT_TRUE(tr.samples.empty() && tr.events.empty()) << tr.method << ": a refused run recorded";
}

class EveryMethod : public ::testing::TestWithParam<std::string> {};

TEST_P(EveryMethod, AValidRunCompletes) {
  const mech::Model m = carts();
  const auto integ = sim::make_integrator(GetParam());
  const sim::Trajectory tr = integ->run(m, m.initial, valid_options());
  EXPECT_EQ(tr.status, Status::kCompleted) << tr.message;
  EXPECT_DOUBLE_EQ(tr.t_end, 0.5);
  // The checked entry times the whole call, for every method alike.
  EXPECT_GT(tr.wall_time_s, 0.0);
}

TEST_P(EveryMethod, WrongSizeOrNonFiniteInitialState) {
  const mech::Model m = carts();
  const auto integ = sim::make_integrator(GetParam());
  expect_refused(integ->run(m, VectorXd::Zero(3), valid_options()), "expected 4 entries");
  expect_refused(integ->run(m, VectorXd(), valid_options()), "expected 4 entries");
  VectorXd x = m.initial;
  x(2) = kNaN;
  expect_refused(integ->run(m, x, valid_options()), "initial state[2]: not finite");
}

TEST_P(EveryMethod, BadHorizon) {
  const mech::Model m = carts();
  const auto integ = sim::make_integrator(GetParam());
  for (double T : {kNaN, -1.0, 0.0, kInf}) {
    sim::Options o = valid_options();
    o.t_end = T;
    expect_refused(integ->run(m, m.initial, o), "t_end must be a finite number > 0");
  }
}

TEST_P(EveryMethod, StepThetaAndNamesCheckedWhereReadRefusedWhereNot) {
  const mech::Model m = carts();
  const auto integ = sim::make_integrator(GetParam());
  const sim::OptionsUsed u = integ->options_used();
  auto with = [&](auto set) {
    sim::Options o = valid_options();
    set(o);
    return integ->run(m, m.initial, o);
  };
  for (double h : {0.0, -1e-3, kNaN, kInf}) {
    const sim::Trajectory tr = with([&](sim::Options& o) { o.h = h; });
    expect_refused(tr, u.h ? "step h must be a finite number > 0" : "does not use Options::h");
  }
  // A step longer than the horizon (0.5) is a typo, not a one-step run.
  expect_refused(with([](sim::Options& o) { o.h = 0.6; }),
                 u.h ? "step h = 0.6 exceeds t_end = 0.5" : "does not use Options::h");
  for (double theta : {0.0, -0.5, 1.5, kNaN}) {
    const sim::Trajectory tr = with([&](sim::Options& o) { o.theta = theta; });
    expect_refused(tr, u.theta ? "theta must lie in (0, 1]" : "does not use Options::theta");
  }
  const sim::Trajectory law = with([](sim::Options& o) { o.impact = "no-such-law"; });
  expect_refused(law,
                 u.impact ? "unknown impact law 'no-such-law'" : "does not use Options::impact");
  const sim::Trajectory lcp = with([](sim::Options& o) { o.lcp_solver = "no-such-solver"; });
  expect_refused(lcp, u.lcp_solver ? "unknown LCP solver 'no-such-solver'"
                                   : "does not use Options::lcp_solver");
}

TEST_P(EveryMethod, InfeasibleStartIsInput) {
  const mech::Model m = carts();
  VectorXd x = m.initial;
  x(0) = -0.5;  // E = [1 0], g = 0: cart 1 behind its stop
  expect_refused(sim::make_integrator(GetParam())->run(m, x, valid_options()),
                 "is violated at t = 0");
}

TEST_P(EveryMethod, OutputLimitRefusedBeforeTheRun) {
  const mech::Model m = carts();
  sim::Options o = valid_options();
  o.t_end = 3.0;
  o.dt_out = 1e-9;  // 3e9 samples of 9 numbers, about 6.75e11 bytes as CSV
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, o), "max_output_bytes");
  o.max_output_bytes = kNaN;
  o.dt_out = 0.1;
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, o),
                 "max_output_bytes must be > 0");
}

TEST_P(EveryMethod, ModelBuiltInCodeIsChecked) {
  mech::Model m = carts();
  m.mechanical->K.coeffRef(0, 0) = kNaN;
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, valid_options()),
                 "mechanical.K[0][0] = nan: not finite");
  m = carts();
  m.mechanical->M.coeffRef(1, 1) = -1.0;
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, valid_options()),
                 "mechanical.M: not positive definite");
  m = carts();
  m.mechanical->restitution(0) = 1.5;
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, valid_options()),
                 "mechanical.restitution[0]: outside [0, 1]");
  m = carts();
  m.mechanical->g.resize(3);
  expect_refused(sim::make_integrator(GetParam())->run(m, m.initial, valid_options()),
                 "mechanical.g: expected 1 entries");
}

INSTANTIATE_TEST_SUITE_P(CheckRun, EveryMethod, ::testing::ValuesIn(sim::integrator_names()),
                         [](const auto& info) {
                           std::string n = info.param;
                           for (char& c : n)
                             if (c == '-') c = '_';
                           return n;
                         });

// Every method the library has is registered without a call: "bullet" by
// linking lcsim::bullet (this test executable does).
// Moreau–Jean factors W = M + h theta D + h^2 theta^2 K by Cholesky, which
// reads one triangle: a gyroscopic D (skew part) would be dropped without a
// word. It refuses such a model naming the entry; the exact method runs it.
TEST(CheckRun, MoreauJeanRefusesANonSymmetricDamping) {
  mech::Model m = carts();
  m.mechanical->D.coeffRef(0, 1) += 0.5;
  m.mechanical->D.coeffRef(1, 0) -= 0.5;
  const sim::Trajectory mj =
      sim::make_integrator("moreau-jean")->run(m, m.initial, valid_options());
  expect_refused(mj, "needs symmetric D and K");
  expect_refused(mj, "D[0][1] = ");
  const sim::Trajectory ex = sim::make_integrator("event")->run(m, m.initial, valid_options());
  EXPECT_EQ(ex.status, Status::kCompleted) << ex.message;
  // K alike, and a difference at rounding (1e-15 of the largest entry, as a
  // scene's computed gravity stiffness may have) is symmetric.
  mech::Model k = carts();
  k.mechanical->K.coeffRef(0, 1) += 1e-15 * k.mechanical->K.coeffs().cwiseAbs().maxCoeff();
  EXPECT_EQ(sim::make_integrator("moreau-jean")->run(k, k.initial, valid_options()).status,
            Status::kCompleted);
  k.mechanical->K.coeffRef(0, 1) += 1.0;
  expect_refused(sim::make_integrator("moreau-jean")->run(k, k.initial, valid_options()),
                 "K[0][1] = ");
}

TEST(CheckRun, EveryMethodIsRegisteredByLinking) {
  const auto names = sim::integrator_names();
  for (const char* n : {"event", "euler", "moreau-jean", "bullet"})
    EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
}

TEST(CheckRun, UnknownMethodAndMissingInitialState) {
  const mech::Model m = carts();
  const sim::Trajectory tr = sim::simulate(m, m.initial, valid_options(), "no-such-method");
  expect_refused(tr, "unknown method 'no-such-method' (known: event, euler, moreau-jean");
  mech::Model bare = m;
  bare.initial.resize(0);
  expect_refused(sim::simulate(bare, valid_options()), "has no initial state");
}

// The model file's scenario is the default: two_carts.yaml says t_end: 3 and
// its initial state, so a run given neither ends at t = 3 (it used to stop
// at Options's old default t = 1). The state there is the §3.7 closed form
// (tests/sim/test_event_driven.cpp checks it to 1e-12; here only the horizon).
TEST(CheckRun, TheModelsScenarioIsTheDefault) {
  const mech::Model m = carts();
  ASSERT_DOUBLE_EQ(m.t_end, 3.0);
  const sim::Trajectory tr = sim::simulate(m);
  EXPECT_EQ(tr.status, Status::kCompleted) << tr.message;
  EXPECT_DOUBLE_EQ(tr.t_end, 3.0);
  mech::Model no_horizon = m;
  no_horizon.t_end = kNaN;
  expect_refused(sim::simulate(no_horizon), "no horizon");
}

// keep_used: one option set for several methods keeps for each what it reads.
TEST(CheckRun, KeepUsedResetsWhatAMethodDoesNotRead) {
  sim::Options o = valid_options();
  o.h = 1e-4;
  o.theta = 1.0;
  o.impact = "moreau";
  const auto event = sim::make_integrator("event");
  const sim::Options e = sim::keep_used(o, event->options_used());
  EXPECT_EQ(e.h, sim::Options{}.h);
  EXPECT_EQ(e.theta, sim::Options{}.theta);
  EXPECT_EQ(e.impact, "moreau");
  const sim::Options mj = sim::keep_used(o, sim::make_integrator("moreau-jean")->options_used());
  EXPECT_EQ(mj.h, 1e-4);
  EXPECT_EQ(mj.theta, 1.0);
  EXPECT_EQ(mj.impact, sim::Options{}.impact);
}

}  // namespace
}  // namespace lcsim
