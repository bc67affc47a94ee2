// The one status vocabulary of lcsim: LCP solves, LCS computations, impacts
// and runs all end with a Status and a message, and count their warnings
// per kind.
#pragma once

#include <cstddef>
#include <string>
#include <string_view>
#include <vector>

namespace lcsim {

enum class Status {
  kOk = 0,            // solved / computed / completed
  kInvalidInput,      // the caller's input is wrong; the message names field and value
  kNumericalFailure,  // singular matrix, non-finite values, a failed residual test
  kRayTermination,    // Lemke ended on a secondary ray (e.g. an infeasible LCP)
  kIterationLimit,    // an iteration or pivot cap was hit first
  kEventLimit,        // a run's cap on events, or events that make no progress
  kInterrupted,       // stopped by the caller (a progress callback, a signal)
  // The same value under the name each result uses for it.
  kSolved = kOk,
  kCompleted = kOk,
};

// `ok_word` for kOk (an LCP says "solved", a run "completed"), else
// "invalid input", "numerical failure", "ray termination", "iteration
// limit", "event limit", "interrupted".
inline std::string_view to_string(Status s, std::string_view ok_word = "ok") {
  switch (s) {
    case Status::kOk:
      return ok_word;
    case Status::kInvalidInput:
      return "invalid input";
    case Status::kNumericalFailure:
      return "numerical failure";
    case Status::kRayTermination:
      return "ray termination";
    case Status::kIterationLimit:
      return "iteration limit";
    case Status::kEventLimit:
      return "event limit";
    case Status::kInterrupted:
      return "interrupted";
  }
  return "unknown";
}

// Warnings of one kind ("pgs-not-converged", "restitution-ignored", ...):
// how many, when the first came, and its message.
struct WarningCount {
  std::string kind;
  long count = 0;
  double first_t = 0.0;  // time of the first (s); 0 for warnings before a run starts
  std::string message;   // the first one's text
};

// Counts a warning of `kind` in `counts` (one entry per kind, in order of
// first appearance), keeping the first message and time.
inline void count_warning(std::vector<WarningCount>& counts, std::string_view kind, double t,
                          std::string message) {
  for (auto& c : counts)
    if (c.kind == kind) {
      ++c.count;
      return;
    }
  counts.push_back({std::string(kind), 1, t, std::move(message)});
}

}  // namespace lcsim
