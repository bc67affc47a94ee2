// The outcome of a computation that can fail: a Status and a message. Every
// result of lcsim (lcp::Result, lcs::ModeSelection, impact::ImpactResult,
// sim::Trajectory, the Bullet comparisons, ...) derives from Outcome, so
// `r.status`, `r.message` and `r.ok()` read the same on all of them, and a
// front end reports any of them through `const Outcome&`.
#pragma once

#include <lcsim/core/status.hpp>
#include <string>

namespace lcsim {

struct Outcome {
  Status status = Status::kOk;
  std::string message;  // why it failed; "" or a detail when ok
  bool ok() const { return status == Status::kOk; }
};

// An Outcome that starts as `initial` (a failure) until the computation sets
// kOk: a result built by default, or returned on an early path that forgot to
// set the status, is never taken for a success. LCP results start as
// kInvalidInput, the LCS computations and impacts as kNumericalFailure. The
// derived result stays an aggregate.
template <Status initial>
struct OutcomeStartingAs : Outcome {
  OutcomeStartingAs() : Outcome{initial, {}} {}
};

}  // namespace lcsim
