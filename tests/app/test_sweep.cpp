// The work-precision sweep (src/app/sweep.cpp): each method measured against
// the exact run of its own impact law or the nearest exact law, rows carrying
// their warnings, and first-order convergence of Moreau–Jean against its law.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <lcsim/app/sweep.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/reference.hpp>
#include <lcsim/sim/sim.hpp>
#include <memory>
#include <string>
#include <vector>

namespace lcsim::app {
namespace {

using io::InputError;
using scene::load_model;
using scene::parse_model;
using sim::reference_law;
using sim::run_reference;

// A run of `method` with the sweep's shared options, keeping what the method
// reads (the library refuses an option a method would ignore, e.g. the
// impact law for Moreau–Jean, whose law is inside its LCP).
sim::Trajectory run_keeping_used(const char* method, const mech::Model& m, const sim::Options& o) {
  const auto integ = sim::make_integrator(method);
  return integ->run(m, m.initial, sim::keep_used(o, integ->options_used()));
}

// Two coupled coordinates (M = [2 1; 1 2]) with stops q1 >= 0 and
// q2 >= -0.5, e = 0.9 and 0.1, started on both stops approaching them at
// (-1, -2) m/s: a simultaneous impact at t = 0 where Newton's (1+e) lambda
// ("moreau") and Moreau–Jean's law ("moreau-restitution") part, since the
// coefficients differ (with equal ones the two LCPs are scalings of each
// other and the laws agree). Newton's jump here is not even admissible. A
// force -1 N on q1 and a spring 4 N/m on q2 keep it moving for 2 s.
const char* const kCoupled =
    "name: coupled_stops\nmechanical:\n  M: [[2, 1], [1, 2]]\n  K: [[0, 0], [0, 4]]\n"
    "  E: [[1, 0], [0, 1]]\n  g: [0, 0.5]\n  f: [-1, 0]\n  restitution: [0.9, 0.1]\n"
    "  constraints: [stop1, stop2]\ninitial: [0, -0.5, -1, -2]\nt_end: 2\n";

mech::Model coupled() { return parse_model(kCoupled, "coupled.yaml"); }

TEST(ReferenceLaw, EachMethodIsMeasuredAgainstItsOwnOrTheNearestLaw) {
  const mech::Model m = coupled();
  EXPECT_EQ(reference_law("event", "moreau", m).label(), "moreau");
  EXPECT_EQ(reference_law("event", "sequential", m).label(), "sequential");
  EXPECT_EQ(reference_law("moreau-jean", "moreau", m).label(), "moreau-restitution");
  EXPECT_EQ(reference_law("euler", "moreau-restitution", m).label(), "inelastic");
  EXPECT_EQ(reference_law("bullet", "moreau-restitution", m).label(), "inelastic");
  // Without restitution every law is inelastic: no copy with e = 0 needed.
  const mech::Model carts =
      parse_model("name: c\nmechanical:\n  M: [[1]]\n  E: [[1]]\n  restitution: [0]\n", "c.yaml");
  EXPECT_EQ(reference_law("euler", "moreau", carts).label(), "inelastic");
  EXPECT_FALSE(reference_law("euler", "moreau", carts).inelastic);
}

// Final-state errors of one method's rows, in the order of `hs`.
std::vector<double> errors(const SweepResult& s, const std::string& method) {
  std::vector<double> out;
  for (const auto& r : s.rows)
    if (r.method == method) out.push_back(r.error_final);
  return out;
}

double max_abs_diff(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return (a - b).cwiseAbs().maxCoeff();
}

// Like with like: Moreau–Jean against moreau-restitution and backward Euler
// against the inelastic law both fall by at least 5x per decade of h (first
// order would be 10x: event times and the impact step are O(h); 5x leaves
// room for where a step falls against the impact). Against the unlike law
// ("moreau", the old single reference) Moreau–Jean's error stays O(1): that
// run is computed here directly, not through the sweep.
TEST(Sweep, MoreauJeanConvergesAtFirstOrderAgainstItsOwnLaw) {
  const mech::Model m = coupled();
  SweepOptions o;
  o.methods = {"moreau-jean", "euler"};
  o.hs = {1e-2, 1e-3, 1e-4};
  o.repeat = 1;
  o.base.t_end = 2.0;
  o.base.impact = "moreau";
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_FALSE(s.reference_failed());
  for (const std::string method : {"moreau-jean", "euler"}) {
    const std::vector<double> e = errors(s, method);
    ASSERT_EQ(e.size(), 3u);
    EXPECT_GE(e[0] / e[1], 5.0) << method << ": " << e[0] << " -> " << e[1];
    EXPECT_GE(e[1] / e[2], 5.0) << method << ": " << e[1] << " -> " << e[2];
  }
  sim::Options ev = o.base;
  const sim::Trajectory newton = sim::make_integrator("event")->run(m, m.initial, ev);
  ev.impact = "moreau-restitution";
  const sim::Trajectory mj_law = sim::make_integrator("event")->run(m, m.initial, ev);
  sim::Options step = o.base;
  step.h = 1e-4;
  const sim::Trajectory mj = run_keeping_used("moreau-jean", m, step);
  EXPECT_GT(max_abs_diff(mj.final_state, newton.final_state), 0.5);
  EXPECT_DOUBLE_EQ(errors(s, "moreau-jean")[2], max_abs_diff(mj.final_state, mj_law.final_state));
  // Newton's jump at t = 0 is not admissible: its run warns once.
  EXPECT_EQ(newton.warning_count("impact-not-admissible"), 1);
}

// Issue 13's target on a KUKA-like scene: three revolute joints of
// robots/arm_gripper.urdf (shoulder, elbow, wrist), both limits of each
// (six rows, E of rank 3), restitution different per limit, started on the
// shoulder's upper and the elbow's lower limit, both approached: a
// simultaneous impact where Newton's law and Moreau–Jean's part. Measured
// (lcsim sweep, final-state errors): 47, 1.57, 0.18, 0.015 at h = 1e-2 ..
// 1e-5 against moreau-restitution, while at h = 1e-5 the distance to the
// Newton run stays 0.28. Asserted: >= 5x per decade over the last two
// decades (the first decade, h = 1e-2 against a 0.8 s wrist period
// under-resolved, falls 30x), and the Newton distance above 0.1.
TEST(Sweep, MoreauJeanConvergesOnAKukaLikeScene) {
  const std::string scene =
      "name: arm3_limits\nurdf: " + std::string(LCSIM_SOURCE_DIR) +
      "/robots/arm_gripper.urdf\njoints: [shoulder, elbow, wrist]\n"
      "q0: {shoulder: 0.2, elbow: 0.5, wrist: 0.4, finger_left: 0.02, finger_right: 0.02}\n"
      "springs:\n"
      "  - {name: s1, joint: shoulder, stiffness: 200, damping: 0, rest: 0.2}\n"
      "  - {name: s2, joint: elbow, stiffness: 80, damping: 0, rest: 0.5}\n"
      "  - {name: s3, joint: wrist, stiffness: 20, damping: 0, rest: 0.4}\n"
      "restitution: {shoulder_lower: 0.5, shoulder_upper: 0.8, elbow_lower: 0.2, "
      "elbow_upper: 0.5, wrist_lower: 0.7, wrist_upper: 0.3}\n"
      "initial:\n  q: {shoulder: 1.5, elbow: -2, wrist: 0.4}\n"
      "  v: {shoulder: 1, elbow: -3, wrist: 0}\nt_end: 2\n";
  const mech::Model m = parse_model(scene, std::string(LCSIM_SOURCE_DIR) + "/robots/arm3.yaml");
  SweepOptions o;
  o.methods = {"moreau-jean"};
  o.hs = {1e-3, 1e-4, 1e-5};
  o.repeat = 1;
  o.base.t_end = 2.0;
  o.base.impact = "moreau";
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_FALSE(s.reference_failed());
  const std::vector<double> e = errors(s, "moreau-jean");
  ASSERT_EQ(e.size(), 3u);
  EXPECT_GE(e[0] / e[1], 5.0) << e[0] << " -> " << e[1];
  EXPECT_GE(e[1] / e[2], 5.0) << e[1] << " -> " << e[2];
  sim::Options ev = o.base;
  const sim::Trajectory newton = sim::make_integrator("event")->run(m, m.initial, ev);
  sim::Options step = o.base;
  step.h = 1e-5;
  const sim::Trajectory mj = run_keeping_used("moreau-jean", m, step);
  EXPECT_GT(max_abs_diff(mj.final_state, newton.final_state), 0.1);
}

// Backward Euler's reference is the exact run of the model with e = 0: its
// row's error is that distance (recomputed here from two direct runs), the
// row carries Euler's one warning and the reference's none.
TEST(Sweep, EulerIsMeasuredAgainstTheInelasticRunAndCarriesItsWarning) {
  const mech::Model m = coupled();
  SweepOptions o;
  o.methods = {"euler"};
  o.hs = {1e-3};
  o.repeat = 1;
  o.base.t_end = 2.0;
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 1u);
  const SweepRow& r = s.rows[0];
  mech::Model inelastic = m;
  inelastic.mechanical->restitution.setZero();
  sim::Options ev = o.base;
  ev.impact = "moreau";
  const sim::Trajectory ref = sim::make_integrator("event")->run(inelastic, m.initial, ev);
  sim::Options step = o.base;
  step.h = 1e-3;
  const sim::Trajectory eu = run_keeping_used("euler", m, step);
  EXPECT_DOUBLE_EQ(r.error_final, max_abs_diff(eu.final_state, ref.final_state));
  EXPECT_EQ(r.reference.label(), "inelastic");
  EXPECT_EQ(r.warnings, 1);
  EXPECT_EQ(r.first_warning, "backward Euler ignores restitution: every impact is inelastic");
  EXPECT_EQ(r.reference_warnings, 0);
  EXPECT_EQ(r.reference_first_warning, "");
}

// A refused run is a row with its status, not an exception: backward Euler
// on the triple integrator (rho = 3, Example 7.3.3) without force.
TEST(Sweep, RefusedRunIsARow) {
  const mech::Model m =
      load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/triple_integrator.yaml");
  SweepOptions o;
  o.methods = {"euler"};
  o.hs = {1e-2};
  o.repeat = 1;
  o.base.t_end = m.t_end;
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 1u);
  EXPECT_EQ(s.rows[0].status.rfind("refused: euler: refused:", 0), 0u) << s.rows[0].status;
  EXPECT_TRUE(std::isinf(s.rows[0].error_final));
  EXPECT_TRUE(sweep_json(s)["rows"][0]["error_final"].is_null());
}

TEST(Sweep, BadOptionsNameTheOption) {
  const mech::Model m = coupled();
  SweepOptions o;
  o.methods = {"euler"};
  o.hs = {1e-2};
  o.base.t_end = 2.0;
  o.base.impact = "bounce";
  try {
    run_sweep(m, m.initial, o);
    ADD_FAILURE() << "accepted impact law bounce";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("impact: unknown impact law 'bounce'", 0), 0u)
        << e.what();
  }
  o.base.impact = "moreau";
  o.hs = {3.0};
  EXPECT_THROW(run_sweep(m, m.initial, o), InputError);
}

// ---- Issue 24 ----------------------------------------------------------------

// Moreau-Jean under another name, recording the options of every run the
// sweep makes with it.
struct SeenRun {
  bool record_samples = false, sink = false;
  double dt_out = 0.0;
};
std::vector<SeenRun>& seen_runs() {
  static std::vector<SeenRun> runs;
  return runs;
}
class ProbeIntegrator : public sim::Integrator {
 public:
  std::string name() const override { return "probe-mj"; }
  sim::OptionsUsed options_used() const override {
    return sim::make_integrator("moreau-jean")->options_used();
  }

 protected:
  sim::Trajectory integrate(const mech::Model& model, const Eigen::VectorXd& x0,
                            const sim::Options& opt) const override {
    seen_runs().push_back({opt.record_samples, static_cast<bool>(opt.sample_sink), opt.dt_out});
    return sim::make_integrator("moreau-jean")->run(model, x0, opt);
  }
};

// Item 2: a row's wall time is of runs made as a user makes them, with their
// samples (on the comparison grid): a sweep showed 0.09 s for a run whose
// samples took 16 s, since its timing runs recorded nothing. Here: the one
// compared run (every step through the comparison sink) and `repeat` timing
// runs, each recording its samples on the grid dt_cmp = h = 0.01 (t_end / h
// = 200 points, under the ~2000 cap).
TEST(Sweep, RowsAreTimedWithTheirOutput) {
  if (!sim::integrators().contains("probe-mj"))
    sim::integrators().add("probe-mj", [] { return std::make_unique<ProbeIntegrator>(); });
  seen_runs().clear();
  const mech::Model m = coupled();
  SweepOptions o;
  o.methods = {"probe-mj"};
  o.hs = {1e-2};
  o.repeat = 3;
  o.base.t_end = 2.0;
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 1u);
  ASSERT_EQ(s.rows[0].status, "completed");
  ASSERT_EQ(seen_runs().size(), 4u);
  EXPECT_TRUE(seen_runs()[0].sink);  // the compared run
  for (std::size_t i = 1; i < 4; ++i) {
    EXPECT_TRUE(seen_runs()[i].record_samples) << i;
    EXPECT_FALSE(seen_runs()[i].sink) << i;
    EXPECT_DOUBLE_EQ(seen_runs()[i].dt_out, 1e-2) << i;
  }
  EXPECT_GT(s.rows[0].wall_time_s, 0.0);
}

// Item 9: the error at the exact run's events. The ball of robots/ball.yaml
// (e = 0.5, 3 s: impacts at 0.45 s, 1.35 s, ... accumulating at 1.35 s + 0.9 s)
// at h = 1e-4: the comparison grid is 1.5e-3 (2000 points), coarser than the
// steps, so the error where the impacts happen is measured apart: at each
// exact event, the run's state at the end of the step holding it against
// the exact state before or after (the nearer). Recomputed here from two
// direct runs: the exact run of Moreau-Jean's law and Moreau-Jean sampled at
// every step.
TEST(Sweep, ErrorAtTheExactEventsIsPartOfTheErrorOverTheRun) {
  const mech::Model m = load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/ball.yaml");
  SweepOptions o;
  o.methods = {"moreau-jean"};
  o.hs = {1e-4};
  o.repeat = 1;
  o.base.t_end = m.t_end;
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 1u);
  const SweepRow& r = s.rows[0];
  ASSERT_EQ(r.status, "completed");
  sim::Options ev = o.base;
  ev.impact = "moreau-restitution";
  const sim::Trajectory exact = sim::make_integrator("event")->run(m, m.initial, ev);
  sim::Options step = o.base;
  step.h = 1e-4;
  const sim::Trajectory mj = run_keeping_used("moreau-jean", m, step);
  ASSERT_GT(exact.events.size(), 1u);
  double at_events = 0.0;
  std::size_t i = 0;
  for (const sim::Event& e : exact.events) {
    while (mj.samples[i].t < e.t) ++i;
    at_events = std::max(at_events, std::min(max_abs_diff(mj.samples[i].x, e.state_before),
                                             max_abs_diff(mj.samples[i].x, e.state_after)));
  }
  EXPECT_DOUBLE_EQ(r.error_events, at_events);
  EXPECT_GT(r.error_events, 0.0);
  EXPECT_GE(r.error_max, r.error_events);
  EXPECT_GE(r.error_max, r.error_final);
  const auto j = sweep_json(s);
  EXPECT_EQ(j["rows"][0]["error_events"].get<double>(), r.error_events);
  EXPECT_EQ(j["error_measures"].get<std::string>(), kErrorMeasures);
}

}  // namespace
}  // namespace lcsim::app

namespace lcsim::app {
namespace {

// Asked for sensitivities, each row also measures error_gradient: the
// max-abs difference of its dx(T)/dtheta to the exact run's, which is what
// the two runs give directly (the same runs: equal to rounding, 0 here since
// the sweep runs them with the same options), falling at first order for
// Moreau-Jean with theta = 1 on the two carts before their impact (t = 1;
// tests/sim/test_sensitivity_stepping.cpp measures ratio 2.000). Not asked,
// the JSON has no such field (today's outputs unchanged). A method that
// refuses a column (Moreau-Jean, g[c]) is a refused row.
TEST(Sweep, GradientErrorOnlyWhenAsked) {
  const mech::Model m = load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/two_carts.yaml");
  SweepOptions o;
  o.methods = {"event", "moreau-jean"};
  o.hs = {1e-2, 5e-3};
  o.repeat = 1;
  o.base.t_end = 0.9;
  o.base.theta = 1.0;
  const nlohmann::json plain = sweep_json(run_sweep(m, m.initial, o));
  EXPECT_FALSE(plain.contains("sensitivity"));
  for (const auto& row : plain["rows"]) EXPECT_FALSE(row.contains("error_gradient"));
  o.base.sensitivity = {"x0", "f[1]"};
  const SweepResult s = run_sweep(m, m.initial, o);
  ASSERT_EQ(s.rows.size(), 3u);
  EXPECT_EQ(s.rows[0].error_gradient, 0.0);  // the event row is the reference
  sim::Options so;
  so.t_end = 0.9;
  so.sensitivity = o.base.sensitivity;
  const sim::Trajectory exact = sim::simulate(m, m.initial, so, "event");
  for (int r = 1; r <= 2; ++r) {
    so.h = s.rows[static_cast<size_t>(r)].h;
    so.theta = 1.0;
    const sim::Trajectory mj = sim::simulate(m, m.initial, so, "moreau-jean");
    so.theta = 0.5;
    ASSERT_TRUE(mj.ok()) << mj.message;
    EXPECT_EQ(s.rows[static_cast<size_t>(r)].error_gradient,
              (mj.dx_final - exact.dx_final).cwiseAbs().maxCoeff());
  }
  const double ratio = s.rows[1].error_gradient / s.rows[2].error_gradient;
  EXPECT_GT(ratio, 1.8);  // first order: 2 within 10%
  EXPECT_LT(ratio, 2.2);
  const nlohmann::json j = sweep_json(s);
  EXPECT_EQ(j["sensitivity"], nlohmann::json({"x0", "f[1]"}));
  EXPECT_EQ(j["rows"][1]["error_gradient"].get<double>(), s.rows[1].error_gradient);
  o.base.sensitivity = {"g[stop]"};
  const SweepResult g = run_sweep(m, m.initial, o);
  EXPECT_EQ(g.rows[1].status.rfind("refused: ", 0), 0u) << g.rows[1].status;
  EXPECT_TRUE(std::isinf(g.rows[1].error_gradient));
}

}  // namespace
}  // namespace lcsim::app
