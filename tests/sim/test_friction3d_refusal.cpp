// Three-dimensional friction (issue 27) in the simulation methods: 'euler'
// (tests/sim/test_euler_friction.cpp), 'event'
// (tests/sim/test_event_friction3d.cpp) and 'moreau-jean'
// (tests/sim/test_mj_friction3d.cpp) integrate it. Bullet and MuJoCo take
// friction at a URDF scene's contacts only: a model of matrices with a
// two-tangent contact is refused in one line saying so. A method without 3-D
// friction would refuse it by one input-error line naming the entry and the
// three.
#include <gtest/gtest.h>

#include <lcsim/mech/mech.hpp>
#include <lcsim/sim/sim.hpp>
#include <string>

namespace lcsim {
namespace {

// A point mass (x, y, z) resting on the floor z >= 0 under gravity, sliding
// along x with mu = 0.3, d = 4.
mech::Model block3d() {
  mech::MechanicalModel m;
  m.M = Eigen::MatrixXd::Identity(3, 3).sparseView();
  m.E = Eigen::RowVector3d(0, 0, 1).sparseView();
  m.f = Eigen::Vector3d(0, 0, -9.81);
  mech::FrictionalContact c(0, Eigen::Vector3d(1, 0, 0), 0.3);
  c.tangent2 = Eigen::Vector3d(0, 1, 0).sparseView();
  m.friction.push_back(c);
  return mech::model_of(m, "block3d");
}

TEST(Friction3dRefusal, EveryMethodButEulerEventAndMoreauJeanRefusesAModelWithTwoTangents) {
  const mech::Model model = block3d();
  ASSERT_FALSE(mech::check_model(model));
  const Eigen::VectorXd x0 = (Eigen::VectorXd(6) << 0, 0, 0, 1, 0, 0).finished();
  sim::Options o;
  o.t_end = 0.1;
  int refused = 0;
  for (const std::string& name : sim::integrators().names()) {
    if (name == "moreau-jean" || name == "event" || name == "euler") continue;
    const auto integ = sim::make_integrator(name);
    const sim::Trajectory tr = integ->run(model, x0, o);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << name;
    ++refused;
    // The peers take friction at a URDF scene's contacts only, and say so.
    if (integ->options_used().friction_3d) {
      EXPECT_NE(tr.message.find("friction"), std::string::npos) << tr.message;
      EXPECT_NE(tr.message.find("scene"), std::string::npos) << tr.message;
      continue;
    }
    // Every other method, with friction or not: the 3-D refusal comes first.
    EXPECT_EQ(tr.message, "method '" + name +
                              "' does not yet handle 3-D friction (model 'block3d' has two "
                              "tangents at mechanical.friction[0]); method 'event', "
                              "'euler', 'moreau-jean' does");
  }
  EXPECT_GE(refused, 1);  // 'bullet' at least (registered in every test program)
}

// The exact method codes a cone's facets in its modes: d up to 27.
TEST(Friction3dRefusal, EventRefusesConesBeyondItsEdgeLimit) {
  mech::Model model = block3d();
  model.mechanical->friction[0].edges = 28;
  const Eigen::VectorXd x0 = (Eigen::VectorXd(6) << 0, 0, 0, 1, 0, 0).finished();
  sim::Options o;
  o.t_end = 0.1;
  const sim::Trajectory tr = sim::make_integrator("event")->run(model, x0, o);
  EXPECT_EQ(tr.status, Status::kInvalidInput);
  EXPECT_EQ(tr.message,
            "method 'event' takes cones of at most 27 edge pairs (d) (model 'block3d' has d = 28 "
            "at mechanical.friction[0])");
}

}  // namespace
}  // namespace lcsim
