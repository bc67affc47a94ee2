// Where a scene's linear model holds (src/scene/linearisation.cpp): the exact
// mass matrix and forces of the URDF against the linear model, at visited
// states and along each coordinate; and the linear model written as YAML.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <lcsim/io/io.hpp>
#include <lcsim/scene/linearisation.hpp>
#include <lcsim/scene/scene.hpp>
#include <lcsim/sim/sim.hpp>
#include <random>

#include "scene/scene_files.hpp"
#include "support/same_model.hpp"

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::VectorXd;

const std::string kRobots = std::string(LCSIM_SOURCE_DIR) + "/robots/";

// A pendulum: mass 2 kg at l = 0.5 m below a pivot about y, iyy = 0.01,
// hanging at q0 = 0. M = 0.01 + 2 * 0.25 = 0.51 for every angle, the exact
// force is F = -m G l sin(th), the linear one L = -m G l th (K_g = m G l,
// f = 0), so e_M = 0 and
//   e_F(th) = |th - sin th| / |th|   (~ th^2 / 6).
const char* kPendulum =
    "<robot name='p'><link name='pivot'/><link name='bob'><inertial><origin xyz='0 0 -0.5'/>"
    "<mass value='2'/><inertia ixx='0.01' ixy='0' ixz='0' iyy='0.01' iyz='0' izz='0.01'/>"
    "</inertial></link><joint name='swing' type='revolute'><parent link='pivot'/>"
    "<child link='bob'/><axis xyz='0 1 0'/>"
    "<limit lower='-1.5' upper='1.5' effort='1' velocity='1'/></joint></robot>";

double e_pendulum(double th) { return std::abs(th - std::sin(th)) / std::abs(th); }

class Linearisation : public test_support::SceneFiles {
 protected:
  void SetUp() override {
    SceneFiles::SetUp();
    write("p.urdf", kPendulum);
    scene_ = *scene::load_scene_details(
        write("s.yaml", "urdf: p.urdf\njoints: [{name: swing, stops: []}]\n"));
  }
  scene::Scene scene_;
};

// Tolerance: K_g comes from central differences, relative error ~1e-11
// (docs/model-format.md), which moves e_F by about as much; M(q) is exact to
// rounding (~1e-16). 1e-9 leaves a factor 100.
constexpr double kTolE = 1e-9;

TEST_F(Linearisation, PendulumErrorIsTheClosedForm) {
  for (const double th : {0.05, -0.3, 1.0}) {
    const scene::LinearisationCheck c =
        scene::check_linearisation(scene_, {VectorXd::Constant(1, th)});
    EXPECT_NEAR(c.force_error, e_pendulum(th), kTolE) << th;
    EXPECT_LE(c.mass_error, 1e-15) << th;
    EXPECT_NEAR(c.error, e_pendulum(th), kTolE) << th;
    EXPECT_EQ(c.worst_q(0), th);
    EXPECT_EQ(c.states, 1u);
  }
}

// Runs of the linear model from rest at th0 swing within [-th0, th0] (no
// stops, no damping), and e_F grows with |th|, so the worst sampled state is
// the first, th0 itself: the error is e_pendulum(th0). 0.05 rad: 4.2e-4,
// below the default 1 %; 1 rad: 0.159, above it, with a warning.
TEST_F(Linearisation, PendulumRunsAtSmallAndLargeAmplitude) {
  for (const double th0 : {0.05, 1.0}) {
    sim::Options opt;
    opt.t_end = 3.0;
    opt.dt_out = 0.01;
    const VectorXd x0 = (VectorXd(2) << th0, 0.0).finished();
    const sim::Trajectory tr = sim::simulate_event_driven(scene_.model, x0, opt);
    ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
    std::vector<VectorXd> states;
    for (const auto& s : tr.samples) states.push_back(s.x);
    ASSERT_GT(states.size(), scene::kLinearisationStates);  // 301 samples: subsampled
    const scene::LinearisationCheck c = scene::check_linearisation(scene_, states);
    EXPECT_EQ(c.states, scene::kLinearisationStates);
    EXPECT_NEAR(c.error, e_pendulum(th0), kTolE) << th0;
    const std::string w = scene::linearisation_warning(c, scene::kLinearisationThreshold);
    if (th0 < 0.1) {
      EXPECT_LT(c.error, 1e-3);
      EXPECT_EQ(w, "");
    } else {
      EXPECT_GT(c.error, 0.15);
      EXPECT_NE(w.find("the linear model is off by 15.9 %"), std::string::npos) << w;
    }
  }
}

// The range where e <= 1 %: |th| <= th* with (th* - sin th*) / th* = 0.01,
// solved here by Newton's method on the closed form (th* ~ 0.2451).
TEST_F(Linearisation, PendulumRangeIsWhereTheClosedFormCrossesTheThreshold) {
  double t = 0.25;
  for (int k = 0; k < 50; ++k) {
    const double g = (t - std::sin(t)) / t - 0.01;
    const double dg = (1 - std::cos(t)) / t - (t - std::sin(t)) / (t * t);
    t -= g / dg;
  }
  const std::vector<scene::LinearRange> r = scene::linear_ranges(scene_, 0.01);
  ASSERT_EQ(r.size(), 1u);
  EXPECT_EQ(r[0].joint, "swing");
  EXPECT_EQ(r[0].unit, "rad");
  // e is moved by ~1e-11 (K_g) and de/dth ~ th/3 ~ 0.08 there: th* to ~1e-10.
  EXPECT_NEAR(r[0].upper, t, 1e-8);
  EXPECT_NEAR(r[0].lower, -t, 1e-8);
  EXPECT_EQ(r[0].upper_end, "threshold");
  EXPECT_EQ(r[0].lower_end, "threshold");
  // A threshold the whole limit range satisfies: e(1.5) = 0.335 < 0.5.
  const std::vector<scene::LinearRange> all = scene::linear_ranges(scene_, 0.5);
  EXPECT_EQ(all[0].upper, 1.5);
  EXPECT_EQ(all[0].lower, -1.5);
  EXPECT_EQ(all[0].upper_end, "limit");
  EXPECT_EQ(all[0].lower_end, "limit");
}

// The double pendulum's mass matrix changes with the elbow angle:
// M(th2) from the hand derivation of test_scene.cpp, e_M = ||M(th2) -
// M(0)||_F / ||M(0)||_F. Only M11 and M12 depend on th2:
// dM11 = 2 m2 l1 c2 (cos th2 - 1), dM12 = m2 l1 c2 (cos th2 - 1), and
// M(0) = [[1.26, 0.29], [0.29, 0.09]].
TEST(LinearisationDoublePendulum, MassErrorIsTheClosedForm) {
  const auto scene = scene::load_scene_details(kRobots + "double_pendulum_scene.yaml");
  ASSERT_TRUE(scene);
  const double th2 = 0.7, k = 0.5 * 1 * 0.4 * (std::cos(th2) - 1);
  const double num = std::sqrt(4 * k * k + 2 * k * k);
  const double den = std::sqrt(1.26 * 1.26 + 2 * 0.29 * 0.29 + 0.09 * 0.09);
  const scene::LinearisationCheck c =
      scene::check_linearisation(*scene, {(VectorXd(4) << 0.0, th2, 0.3, 0.0).finished()});
  // M by the CRBA to ~1e-16 relative; the ratio to 1e-14.
  EXPECT_NEAR(c.mass_error, num / den, 1e-14);
}

// Prismatic carts on a horizontal rail: M constant, no gravity along the
// rail, springs linear: the linear model is exact.
TEST(LinearisationCarts, ExactModelHasNoError) {
  const auto scene = scene::load_scene_details(kRobots + "two_carts_scene.yaml");
  ASSERT_TRUE(scene);
  const scene::LinearisationCheck c = scene::check_linearisation(
      *scene, {(VectorXd(2) << 0.7, -2.0).finished(), (VectorXd(2) << -3.0, 5.0).finished()});
  EXPECT_EQ(c.mass_error, 0.0);
  EXPECT_EQ(c.force_error, 0.0);
  EXPECT_FALSE(scene::load_scene_details(kRobots + "two_carts.yaml").has_value());
}

TEST_F(Linearisation, ThresholdMustBePositiveAndFinite) {
  const scene::LinearisationCheck c =
      scene::check_linearisation(scene_, {VectorXd::Constant(1, 0.1)});
  for (const double t : {0.0, -0.01, std::nan(""), HUGE_VAL}) {
    EXPECT_THROW(scene::linearisation_warning(c, t), io::InputError) << t;
    EXPECT_THROW(scene::linear_ranges(scene_, t), io::InputError) << t;
  }
  EXPECT_THROW(scene::check_linearisation(scene_, {VectorXd()}), std::invalid_argument);
}

// analyze --model-out: the linear model of every shipped scene written as
// YAML (io::model_yaml) reads back with the same matrices, bit for bit.
TEST(ModelOut, ScenesRoundTripExactly) {
  for (const char* f :
       {"two_carts_scene.yaml", "two_carts_hook_scene.yaml", "double_pendulum_scene.yaml",
        "arm_gripper_scene.yaml", "kuka_iiwa_scene.yaml", "panda_gripper_scene.yaml",
        "box_drop_scene.yaml", "box_tip_scene.yaml", "quadruped_drop_scene.yaml",
        "gripper_box_scene.yaml", "vision60_drop_scene.yaml"}) {
    const mech::Model a = scene::load_model(kRobots + f);
    const mech::Model b = scene::parse_model(io::model_yaml(a, "header"), "written.yaml");
    SCOPED_TRACE(f);
    test_support::expect_same_matrices(*a.mechanical, *b.mechanical);
    EXPECT_EQ(a.mechanical->coordinates, b.mechanical->coordinates);
    EXPECT_EQ(a.mechanical->constraints, b.mechanical->constraints);
    EXPECT_EQ(a.initial, b.initial);
    EXPECT_EQ(a.t_end, b.t_end);
    EXPECT_EQ(a.name, b.name);
  }
}

// A scene's 3-D friction rows are a world frame mapped to coordinates, not
// Euclidean-orthogonal there (the tipped box's corners: cosine ~5e-3); the
// written model says so (`frame: world`) and reads back as the same contacts,
// so it loads and runs as the scene does, bit for bit.
TEST(ModelOut, SceneFrictionRoundTripsWithItsFrame) {
  std::ifstream in(kRobots + "box_tip_scene.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string plain = "- {link: box, plane: floor}";
  ASSERT_NE(text.find(plain), std::string::npos);
  text.replace(text.find(plain), plain.size(), "- {link: box, plane: floor, friction: 0.5, d: 4}");
  const mech::Model a = scene::parse_model(text, kRobots + "box_tip_friction.yaml");
  const std::string written = io::model_yaml(a, "header");
  EXPECT_NE(written.find("frame: world"), std::string::npos);
  const mech::Model b = scene::parse_model(written, "written.yaml");
  test_support::expect_same_matrices(*a.mechanical, *b.mechanical);
  ASSERT_EQ(a.mechanical->friction.size(), b.mechanical->friction.size());
  for (size_t i = 0; i < a.mechanical->friction.size(); ++i) {
    const mech::FrictionalContact &fa = a.mechanical->friction[i], &fb = b.mechanical->friction[i];
    EXPECT_TRUE(fa.world_frame && fb.world_frame) << i;
    EXPECT_EQ(VectorXd(fa.tangent), VectorXd(fb.tangent)) << i;
    EXPECT_EQ(VectorXd(fa.tangent2), VectorXd(fb.tangent2)) << i;
    EXPECT_EQ(fa.mu, fb.mu) << i;
    EXPECT_EQ(fa.edges, fb.edges) << i;
  }
  const sim::Trajectory ta = sim::simulate(a, sim::Options{}),
                        tb = sim::simulate(b, sim::Options{});
  ASSERT_EQ(ta.status, sim::RunStatus::kCompleted) << ta.message;
  ASSERT_EQ(tb.status, sim::RunStatus::kCompleted) << tb.message;
  EXPECT_EQ(ta.samples.back().x, tb.samples.back().x);
}

TEST(ModelOut, FrictionFrameIsWorldOrModel) {
  const std::string model =
      "mechanical:\n  M: [[1, 0], [0, 1]]\n  E: [[1, 0]]\n  g: [0]\n"
      "  friction:\n    - {contact: 0, tangents: [[0, 1], [0, 1]], mu: 0.1, frame: ";
  try {
    scene::parse_model(model + "earth}\n", "bad.yaml");
    ADD_FAILURE() << "frame: earth accepted";
  } catch (const io::InputError& e) {
    EXPECT_EQ(std::string(e.what()),
              "bad.yaml: mechanical.friction[0].frame: must be 'world' or 'model' (got 'earth')");
  }
}

}  // namespace
}  // namespace lcsim
