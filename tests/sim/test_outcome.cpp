// Every result struct reports through the one outcome type (issue #25, item
// 5) and keeps the status it had by default before it: a failing start for
// the results a computation must declare solved, kOk for the runs.
#include <gtest/gtest.h>

#include <lcsim/bullet/bullet.hpp>
#include <lcsim/core/outcome.hpp>
#include <lcsim/impact/impact.hpp>
#include <lcsim/lcp/lcp.hpp>
#include <lcsim/lcs/lcs.hpp>
#include <lcsim/sim/sim.hpp>
#include <type_traits>

namespace lcsim {
namespace {

template <class R>
Status default_status() {
  static_assert(std::is_base_of_v<Outcome, R> && std::is_aggregate_v<R>);
  const R r{};
  const Outcome& o = r;
  EXPECT_EQ(o.ok(), o.status == Status::kOk);
  EXPECT_EQ(o.message, "");
  return r.status;
}

TEST(Outcome, EveryResultKeepsItsDefaultStatus) {
  EXPECT_EQ(default_status<lcp::Result>(), Status::kInvalidInput);
  EXPECT_EQ(default_status<lcp::EnumerationResult>(), Status::kInvalidInput);
  EXPECT_EQ(default_status<lcs::Projection>(), Status::kNumericalFailure);
  EXPECT_EQ(default_status<lcs::ModeFeedback>(), Status::kNumericalFailure);
  EXPECT_EQ(default_status<lcs::ModeSelection>(), Status::kNumericalFailure);
  EXPECT_EQ(default_status<lcs::PassivityCertificateCheck>(), Status::kNumericalFailure);
  EXPECT_EQ(default_status<impact::ImpactResult>(), Status::kNumericalFailure);
  EXPECT_EQ(default_status<sim::Trajectory>(), sim::RunStatus::kCompleted);
  EXPECT_EQ(default_status<bullet::FrictionBlockOf>(), Status::kOk);
  EXPECT_EQ(default_status<bullet::FrictionBoxRun>(), Status::kOk);
  EXPECT_EQ(default_status<bullet::FrictionComparison>(), Status::kOk);
  // lcp::Result::ok() is "solved", the one word for kOk there.
  lcp::Result r;
  r.status = Status::kSolved;
  EXPECT_TRUE(r.ok());
}

}  // namespace
}  // namespace lcsim
