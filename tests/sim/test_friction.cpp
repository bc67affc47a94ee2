// Friction in the simulation methods (issue 17): Moreau–Jean against closed
// forms (a block sliding to a stop on a floor and on an incline, a
// mass–spring on a rough floor), and every other method refusing a model
// with friction instead of ignoring it.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/impact/impact.hpp>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <tuple>

namespace lcsim {
namespace {

using Eigen::VectorXd;

constexpr double kG = 9.81;

// A block of mass m on a plane inclined by alpha, coordinates (s, n) along
// and normal to the plane: f = m g (-sin alpha, -cos alpha), contact n >= 0,
// tangent along s, coefficient mu; a spring of stiffness k pulls s to 0.
mech::Model block(double m, double alpha, double mu, double k = 0.0) {
  mech::MechanicalModel mm;
  mm.M = (m * Eigen::MatrixXd::Identity(2, 2)).sparseView();
  Eigen::MatrixXd K = Eigen::MatrixXd::Zero(2, 2);
  K(0, 0) = k;
  mm.K = K.sparseView();
  mm.E = Eigen::RowVector2d(0, 1).sparseView();
  mm.f = Eigen::Vector2d(-m * kG * std::sin(alpha), -m * kG * std::cos(alpha));
  mech::fill_defaults(mm);
  mm.friction.push_back({0, Eigen::Vector2d(1, 0), mu});
  return mech::model_of(mm, "block");
}

sim::Trajectory run_mj(const mech::Model& model, const VectorXd& x0, double t_end, double h) {
  sim::Options o;
  o.t_end = t_end;
  o.h = h;
  return sim::make_integrator("moreau-jean")->run(model, x0, o);
}

// Zero to rounding: a stuck velocity is v_free + W^{-1} t lambda_T, a
// cancellation of terms of the size of the initial speed, exact to a few eps
// of it; 1e-12 of it is far below the last sliding velocity before a stick
// (a fraction of the decrement mu g h per step, 1e-4 and more here).
bool stuck(double v) { return std::abs(v) <= 1e-12 * 2.0; }

// The first sample time at which the sliding velocity is zero.
double stick_time(const sim::Trajectory& tr) {
  for (const sim::Sample& s : tr.samples)
    if (stuck(s.x(2))) return s.t;
  return NAN;
}

TEST(FrictionMoreauJean, BlockOnFloorSticksAtVOverMuG) {
  // v0 = 2 m/s, mu = 0.4: t* = v0 / (mu g) = 0.5097 s. Each step takes
  // mu g h off the velocity (normal impulse m g h, friction mu m g h) until
  // the step where less is left: there it sticks (exactly 0). So
  // t_stick = ceil(t* / h) h and |t_stick - t*| <= h: C = 1.
  const double v0 = 2.0, mu = 0.4, t_star = v0 / (mu * kG);
  for (const double h : {1e-2, 1e-3, 1e-4}) {
    const sim::Trajectory tr =
        run_mj(block(3.0, 0.0, mu), (VectorXd(4) << 0, 0, v0, 0).finished(), 1.0, h);
    ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
    const double ts = stick_time(tr);
    EXPECT_LE(std::abs(ts - t_star), h) << "h = " << h;
    // It stays stuck and on the floor: no velocity, and the position is the
    // one reached (distance v0 t* / 2 to O(h)).
    EXPECT_TRUE(stuck(tr.final_state(2))) << tr.final_state(2);
    EXPECT_NEAR(tr.final_state(0), v0 * t_star / 2, 2 * v0 * h);
    // Resting contact: a step whose normal rate came out +1e-17 leaves the
    // contact out of the next active set (predicted gap > 0), which then falls
    // for one step, by g h^2 / 2 at theta = 1/2 (the penetration bound of
    // src/sim/stepping/moreau_jean.cpp, frictionless alike): at most 2 g h^2 here.
    EXPECT_LE(std::abs(tr.final_state(1)), 2 * kG * h * h);
  }
}

TEST(FrictionMoreauJean, BlockOnInclineSticksAndStaysWhenMuAboveTanAlpha) {
  // alpha = 0.3 rad, mu = 0.5 > tan(0.3) = 0.309: sliding down at v0 = -1.5
  // m/s decelerates at g (mu cos alpha - sin alpha) and sticks at
  // t* = |v0| / (g (mu cos alpha - sin alpha)) = 0.8395 s, to within h as on
  // the floor; then it stays (velocity exactly 0 at every later sample).
  const double alpha = 0.3, mu = 0.5, v0 = -1.5;
  const double t_star = -v0 / (kG * (mu * std::cos(alpha) - std::sin(alpha)));
  const double h = 1e-3;
  const sim::Trajectory tr =
      run_mj(block(1.0, alpha, mu), (VectorXd(4) << 0, 0, v0, 0).finished(), 2.0, h);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  const double ts = stick_time(tr);
  EXPECT_LE(std::abs(ts - t_star), h);
  for (const sim::Sample& s : tr.samples)
    if (s.t >= ts) {
      EXPECT_TRUE(stuck(s.x(2))) << "t = " << s.t << ": " << s.x(2);
    }
  // mu < tan alpha: never sticks.
  const sim::Trajectory slide =
      run_mj(block(1.0, alpha, 0.25), (VectorXd(4) << 0, 0, v0, 0).finished(), 2.0, h);
  ASSERT_EQ(slide.status, Status::kCompleted) << slide.message;
  EXPECT_TRUE(std::isnan(stick_time(slide)));
}

TEST(FrictionMoreauJean, MassSpringOnRoughFloorStopsAfterNHalfCycles) {
  // m = 1, k = 4 (omega = 2), mu = 0.1: x_s = mu m g / k = 0.24525 m. From
  // x0 = 1 at rest: each half-cycle the amplitude about the far side's
  // offset shrinks by 2 x_s; N = ceil((x0 - x_s) / (2 x_s)) = 2 half-cycles,
  // final position (-1)^N (x0 - 2 N x_s) = 0.019 m, at rest from
  // T = N pi / omega = pi s. First order in h: the final position to a few
  // h times the speed scale x0 omega (C = 4 leaves room for the stick step).
  const double m = 1, k = 4, mu = 0.1, x0 = 1.0, omega = 2.0;
  const double xs = mu * m * kG / k;
  const int N = static_cast<int>(std::ceil((x0 - xs) / (2 * xs)));
  ASSERT_EQ(N, 2);
  const double x_final = (N % 2 ? -1.0 : 1.0) * (x0 - 2 * N * xs);
  const double h = 1e-4;
  const sim::Trajectory tr =
      run_mj(block(m, 0.0, mu, k), (VectorXd(4) << x0, 0, 0, 0).finished(), 5.0, h);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  EXPECT_NEAR(tr.final_state(0), x_final, 4 * h * x0 * omega);
  EXPECT_TRUE(stuck(tr.final_state(2))) << tr.final_state(2);
  // At rest from T = N pi / omega on (to within a few steps).
  double t_rest = NAN;
  for (const sim::Sample& s : tr.samples)
    if (!stuck(s.x(2)))
      t_rest = NAN;
    else if (std::isnan(t_rest))
      t_rest = s.t;
  EXPECT_NEAR(t_rest, N * M_PI / omega, 4 * h);
}

mech::Model shipped(const std::string& name) {
  return scene::load_model(std::string(LCSIM_SOURCE_DIR) + "/robots/" + name);
}

// robots/*friction*.yaml against the closed forms in their headers, at the
// tolerances of the tests above (stick within h, positions within 2 v0 h).
TEST(FrictionShippedModels, MatchTheirClosedForms) {
  const double h = 1e-3;
  for (const auto& [file, t_star, x_star] :
       {std::tuple{"block_on_floor_friction.yaml", 0.509684, 0.509684},
        std::tuple{"incline_friction.yaml", 0.839456, -0.629592}}) {
    SCOPED_TRACE(file);
    const mech::Model m = shipped(file);
    const sim::Trajectory tr = run_mj(m, m.initial, m.t_end, h);
    ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
    // 1e-6: the closed forms in the files are rounded to 6 digits.
    EXPECT_LE(std::abs(stick_time(tr) - t_star), h + 1e-6);
    EXPECT_NEAR(tr.final_state(0), x_star, 2 * std::abs(m.initial(2)) * h + 1e-6);
    EXPECT_TRUE(stuck(tr.final_state(2))) << tr.final_state(2);
  }
  const mech::Model ms = shipped("mass_spring_friction.yaml");
  const sim::Trajectory tr = run_mj(ms, ms.initial, ms.t_end, 1e-4);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  EXPECT_NEAR(tr.final_state(0), 0.019, 4 * 1e-4 * 2.0);  // as in the test above
  // The disk: its initial state is the impact; v+ = (-1/3, 1.5, 2/3) exactly
  // (a 3 x 3 LCP and a diagonal M: 1e-12 is a few hundred ulps).
  const mech::Model d = shipped("spinning_disk_friction.yaml");
  impact::ImpactInput in;
  in.model = &*d.mechanical;
  in.q = d.initial.head(3);
  in.v = d.initial.tail(3);
  in.closed = {0};
  const impact::ImpactResult r =
      impact::make_impact_law("moreau")->apply(in, *lcp::make_solver("pivot"));
  ASSERT_TRUE(r.ok()) << r.message;
  EXPECT_NEAR((r.v_after - Eigen::Vector3d(-1.0 / 3, 1.5, 2.0 / 3)).cwiseAbs().maxCoeff(), 0.0,
              1e-12);
  EXPECT_NEAR(r.friction_impulse(0), -8.0 / 3, 1e-12);
  EXPECT_EQ(r.outcome[0], impact::ContactOutcome::kStick);
}

// robots/belt_friction.yaml: a mass-spring riding a belt at v_b = 0.2 m/s.
// Released at rest, it slides back on the belt until its velocity reaches
// v_b at t1 = asin(v_b / (x_s omega)) / omega, sticks (v = v_b) until the
// spring force reaches mu m g at x = x_s (t2), then slips with
// v = v_b cos(omega (t - t2)) (the file's header).
TEST(FrictionMoreauJean, BeltSticksAtT1AndSlipsAtT2) {
  const mech::Model m = shipped("belt_friction.yaml");
  const double vb = 0.2, omega = 2.0, xs = 0.1 * kG / 4.0;
  const double t1 = std::asin(vb / (xs * omega)) / omega;
  const double x1 = xs * (1 - std::cos(omega * t1)), t2 = t1 + (xs - x1) / vb;
  const double h = 1e-4;
  const sim::Trajectory tr = run_mj(m, m.initial, m.t_end, h);
  ASSERT_EQ(tr.status, Status::kCompleted) << tr.message;
  // Stuck to the belt: v - v_b zero to rounding (as `stuck` above).
  double t_stick = NAN, t_slip = NAN;
  for (const sim::Sample& s : tr.samples) {
    const bool on_belt = stuck(s.x(2) - vb);
    if (std::isnan(t_stick) && on_belt) t_stick = s.t;
    if (!std::isnan(t_stick) && std::isnan(t_slip) && !on_belt) t_slip = s.t;
  }
  // First order, as the block's stick time: within h of t1. The slip starts
  // when the spring force exceeds mu m g; the sliding velocity then grows
  // like v_b omega^2 tau^2 / 2 and passes the rounding level after a few
  // steps: within 3 h of t2.
  EXPECT_LE(std::abs(t_stick - t1), h) << t_stick;
  EXPECT_LE(std::abs(t_slip - t2), 3 * h) << t_slip;
  // After the slip, v = v_b cos(omega (t - t2)) to first order (C = 4 as
  // the mass-spring above, speed scale v_b).
  EXPECT_NEAR(tr.final_state(2), vb * std::cos(omega * (m.t_end - t2)), 4 * h * vb * omega);
  // The samples' friction modes: sliding backwards on the belt (slip-)
  // before t1 and after t2, stuck in between (away from the switching steps
  // by the bounds above).
  int checked = 0;
  for (const sim::Sample& s : tr.samples) {
    ASSERT_EQ(s.friction_mode.size(), 1u);
    const sim::FrictionMode want = s.t > t1 + h && s.t < t2 - 3 * h ? sim::FrictionMode::kStick
                                   : s.t > 0 && (s.t < t1 - h || s.t > t2 + 3 * h)
                                       ? sim::FrictionMode::kSlipNegative
                                       : s.friction_mode[0];  // near a switch: either
    EXPECT_EQ(s.friction_mode[0], want) << "t = " << s.t;
    checked += s.t > 0;
  }
  EXPECT_GT(checked, 100);
}

TEST(FrictionRefusal, MethodsWithoutFrictionRefuseIt) {
  const mech::Model model = block(1.0, 0.0, 0.3);
  const VectorXd x0 = (VectorXd(4) << 0, 0, 1, 0).finished();
  sim::Options o;
  o.t_end = 0.1;
  for (const std::string& name : sim::integrators().names()) {
    const auto integ = sim::make_integrator(name);
    if (integ->options_used().friction) continue;
    const sim::Trajectory tr = integ->run(model, x0, o);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << name;
    EXPECT_EQ(tr.message, "method '" + name +
                              "' does not support friction (model 'block' has 1 frictional "
                              "contact in mechanical.friction); use method 'event', 'euler', "
                              "'moreau-jean'");
  }
}

}  // namespace
}  // namespace lcsim
