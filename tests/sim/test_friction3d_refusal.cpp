// Three-dimensional friction (issue 27) in the simulation methods: none
// integrates it yet (the impact laws do), so every method refuses a model
// with a two-tangent contact by one input-error line naming the entry, and
// the methods without friction keep their planar refusal.
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

TEST(Friction3dRefusal, EveryMethodRefusesAModelWithTwoTangents) {
  const mech::Model model = block3d();
  ASSERT_FALSE(mech::check_model(model));
  const Eigen::VectorXd x0 = (Eigen::VectorXd(6) << 0, 0, 0, 1, 0, 0).finished();
  sim::Options o;
  o.t_end = 0.1;
  int refused_3d = 0;
  for (const std::string& name : sim::integrators().names()) {
    const auto integ = sim::make_integrator(name);
    const sim::Trajectory tr = integ->run(model, x0, o);
    EXPECT_EQ(tr.status, Status::kInvalidInput) << name;
    EXPECT_EQ(tr.message.find('\n'), std::string::npos) << tr.message;
    if (!integ->options_used().friction) {  // the planar refusal comes first
      EXPECT_NE(tr.message.find("does not support friction"), std::string::npos) << tr.message;
      continue;
    }
    ++refused_3d;
    EXPECT_EQ(tr.message, "method '" + name +
                              "' does not yet handle 3-D friction (model 'block3d' has two "
                              "tangents at mechanical.friction[0]); no simulation method handles "
                              "it yet (the impact laws 'newton', 'inelastic' and "
                              "'moreau-restitution' do)");
  }
  EXPECT_EQ(refused_3d, 2);  // 'event' and 'moreau-jean'
}

}  // namespace
}  // namespace lcsim
