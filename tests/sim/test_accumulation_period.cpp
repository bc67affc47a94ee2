// Accumulations of inelastic impacts alternating between two coupled stops
// (issue 24, item 3): the limit must be taken from the resolved impacts,
// before the impacts turn into the rounding of the gaps. The reference t* is
// a closed-form geometric series derived here, not an lcsim run.
#include <gtest/gtest.h>

#include <cmath>
#include <lcsim/sim/sim.hpp>
#include <utility>

namespace lcsim {
namespace {

using Eigen::MatrixXd;
using Eigen::Vector2d;
using Eigen::Vector4d;
using ld = long double;

// A unit point mass in a corner at qc = (1, 1) or (0, 0) between two stops with unit
// normals nA = (1, 0) and nB = (c, s), c = nA.nB > 0 (the wedge is a little
// wider than a right angle), every impact inelastic, under the constant force
// f = -(nA + nB)/s, which presses the mass into either face and accelerates
// it towards the corner along either face at exactly 1 (f.tA = f.tB = -1 for
// the rays tA = (0, 1), tB = (s, -c)). Started at the corner moving along tA
// at w0, the mass slides out and back in 2 w0; at the corner face B is hit
// and Moreau's impact leaves it sliding out along tB at c w0 (the part of
// -w0 tA along tB), back after 2 c w0, and so on: impacts at
// T_k = 2 w0 (1 + c + ... + c^(k-1)), intervals shrinking by c per impact
// (c^2 per pair of the two stops), accumulating at t* = 2 w0 / (1 - c),
// after which the mass rests in the corner.
mech::Model corner_model(double c, double corner) {
  mech::MechanicalModel m;
  m.M = MatrixXd::Identity(2, 2).sparseView();
  const double s = std::sqrt(1.0 - c * c);
  MatrixXd E(2, 2);
  E << 1, 0, c, s;
  m.E = E.sparseView();
  m.g = -E * Vector2d(corner, corner);
  m.f = -Vector2d(1.0 + c, s) / s;
  m.restitution = Vector2d::Zero();
  return mech::model_of(m, "corner");
}

// With c = sqrt(1e-3) (intervals shrink by 1e-3 a pair) the impacts' gaps
// reach the rounding of q ~ 1 (excursions w^2/2 ~ 1e-16) by the sixth
// impact; the per-contact test needs a contact's fourth impact (the seventh
// in all), where the run used to find "impacts" in the noise, no longer
// shrinking, and extrapolate their tail with a ratio near 1.
// Tolerance 1e-10 s (the issue's) for c^2 = 1e-3 and c = 0.1: the limit is
// extrapolated from resolved impacts whose ratios are exactly c; their times
// carry the gaps' rounding over the approach rate (eps |q| / w: 1e-11 s
// at w ~ 1e-5), and a tail taken from the noise was 5.4e-9 s late (before
// the fix; 1.8e-7 s late with the corner at the origin, where the noise
// is relative to q -> 0). With c = 0.5 the tail falls below accumulation_tail only once
// the approach rates are ~1e-6, whose impact times carry ~1e-10 s of that
// rounding each: 5e-10.
TEST(AccumulationPeriod, AlternatingInelasticStopsTakeTheLimitFromResolvedImpacts) {
  for (const auto& [c, tol] : {std::pair{std::sqrt(1e-3), 1e-10}, {0.1, 1e-10}, {0.5, 5e-10}}) {
    for (const double w0 : {1.0, 0.3})
      for (const double qc : {1.0, 0.0}) {
        const mech::Model model = corner_model(c, qc);
        sim::Options opt;
        opt.t_end = 6.0;
        const auto tr = sim::simulate_event_driven(model, Vector4d(qc, qc, 0, w0), opt);
        ASSERT_EQ(tr.status, sim::RunStatus::kCompleted) << tr.message;
        const ld t_star = 2 * static_cast<ld>(w0) / (1 - static_cast<ld>(c));
        int accumulations = 0;
        for (const auto& e : tr.events) {
          if (e.type != sim::EventType::kAccumulation) continue;
          ++accumulations;
          EXPECT_NEAR(e.t, static_cast<double>(t_star), tol)
              << "c " << c << ", w0 " << w0 << ", qc " << qc << ": " << e.note;
        }
        EXPECT_EQ(accumulations, 1) << "c " << c << ", w0 " << w0 << ", qc " << qc;
        // Then at rest in the corner: exactly (qc, qc, 0, 0) up to the
        // rounding of the projection onto the two faces (a few ulp of q ~ 1).
        EXPECT_LE((tr.final_state - Vector4d(qc, qc, 0, 0)).cwiseAbs().maxCoeff(), 1e-12)
            << tr.final_state.transpose();
      }
  }
}

}  // namespace
}  // namespace lcsim
