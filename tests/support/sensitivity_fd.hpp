// Central differences of the exact method's runs, for the sensitivity tests
// (tests/sim/test_sensitivity_*.cpp): each column of a run's dx(T) and of
// its events' dt against (outcome(theta + h) - outcome(theta - h)) / 2h.
//
// Tolerance: 4 |D(h) - D(h/2)| (Richardson's estimate of D(h/2)'s
// truncation, margin 12) plus 64e-13 max(1, |outcome|) / h (the run's
// rounding, ~1e-13 of the state over a few hundred events, over the step
// h, margin 32), at h = 1e-4 max(1, |theta|).
#pragma once

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <functional>
#include <lcsim/sim/sim.hpp>
#include <string>
#include <vector>

namespace lcsim::test_support {

// A column: its name as the run gives it, the value it perturbs (the step's
// scale) and how to move it by d in copies of the model and the start.
struct FdColumn {
  std::string column;
  double theta;
  std::function<void(mech::Model&, Eigen::VectorXd&, double)> apply;
};

// A run's outcome: x(T) then the event times t_1, t_2, ...
inline Eigen::VectorXd run_outcome(const sim::Trajectory& tr) {
  Eigen::VectorXd out(tr.final_state.size() + static_cast<Eigen::Index>(tr.events.size()));
  out.head(tr.final_state.size()) = tr.final_state;
  for (size_t k = 0; k < tr.events.size(); ++k)
    out(tr.final_state.size() + static_cast<Eigen::Index>(k)) = tr.events[k].t;
  return out;
}

// The exact run of m from x0 to T without sensitivities.
inline sim::Trajectory plain_run(const mech::Model& m, const Eigen::VectorXd& x0, double T) {
  sim::Options opt;
  opt.t_end = T;
  return sim::simulate(m, x0, opt, "event");
}

// Each column c of `tr` (the run with sensitivities, its columns in the
// order of `cols`) against central differences: a present column entry by
// entry (x(T), then each event's dt), an absent one must carry no number.
// Returns the number of entries compared.
inline int expect_columns_match_fd(const mech::Model& m, const Eigen::VectorXd& x0, double T,
                                   const sim::Trajectory& tr, const std::vector<FdColumn>& cols) {
  using Eigen::VectorXd;
  const VectorXd base = run_outcome(tr);
  const double xs = std::max(1.0, base.cwiseAbs().maxCoeff());
  const Eigen::Index n = tr.final_state.size();
  int compared = 0;
  for (size_t c = 0; c < cols.size(); ++c) {
    const auto col = static_cast<Eigen::Index>(c);
    EXPECT_EQ(tr.sensitivity_columns[c], cols[c].column);
    if (!tr.dx_final_exists[c]) {  // absent (a loss): no number
      EXPECT_EQ(tr.dx_final.col(col).cwiseAbs().maxCoeff(), 0.0) << cols[c].column;
      continue;
    }
    auto fd = [&](double h) {
      VectorXd out[2];
      for (int s = 0; s < 2; ++s) {
        mech::Model mm = m;
        VectorXd xx = x0;
        cols[c].apply(mm, xx, s == 0 ? h : -h);
        const sim::Trajectory t2 = plain_run(mm, xx, T);
        EXPECT_TRUE(t2.ok()) << t2.message;
        EXPECT_EQ(t2.events.size(), tr.events.size()) << cols[c].column << ": events differ";
        if (t2.events.size() != tr.events.size()) return VectorXd(VectorXd::Zero(base.size()));
        out[s] = run_outcome(t2);
      }
      return VectorXd((out[0] - out[1]) / (2 * h));
    };
    const double h = 1e-4 * std::max(1.0, std::abs(cols[c].theta));
    const VectorXd d1 = fd(h), d2 = fd(h / 2);
    for (Eigen::Index i = 0; i < d2.size(); ++i) {
      const double tol = 4 * std::abs(d1(i) - d2(i)) + 64e-13 * xs / h;
      if (i < n) {
        EXPECT_NEAR(tr.dx_final(i, col), d2(i), tol) << "dx[" << i << "]/d" << cols[c].column;
      } else {
        const sim::Event& e = tr.events[static_cast<size_t>(i - n)];
        EXPECT_TRUE(e.dt_exists[c]);
        EXPECT_NEAR(e.dt(col), d2(i), tol)
            << "dt of event " << i - n << " (" << sim::to_string(e.type) << " at " << e.t << ")/d"
            << cols[c].column;
      }
      ++compared;
    }
  }
  return compared;
}

}  // namespace lcsim::test_support
