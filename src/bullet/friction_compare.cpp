// `lcsim compare` on a block on a floor (issue 17's Bullet side by side):
// Bullet's box beside the exact run, along the floor.
#include <algorithm>
#include <cmath>
#include <lcsim/bullet/bullet.hpp>
#include <limits>

#include "bullet/paired_samples.hpp"

namespace lcsim::bullet {

namespace {

// The stop of the exact run's samples, read as slide_stop reads Bullet's.
SlideStop exact_stop(const sim::Trajectory& exact, int it, double v_tol) {
  const Eigen::Index n = exact.samples.empty() ? 0 : exact.samples.front().x.size() / 2;
  std::vector<double> t, x, v;
  for (const sim::Sample& s : exact.samples) {
    t.push_back(s.t);
    x.push_back(s.x(it));
    v.push_back(s.x(n + it));
  }
  return slide_stop(t, x, v, v_tol);
}

// Deviation along the floor over Bullet's samples paired in time with the
// exact run's (detail::deviation_over), and at t_end.
void deviation(const sim::Trajectory& exact, const FrictionBoxRun& run, int it, double time_tol,
               FrictionComparison& c) {
  const Eigen::Index n = exact.samples.front().x.size() / 2;
  detail::deviation_over(
      exact.samples, run.samples, time_tol,
      [&](const FrictionBoxSample& b, const sim::Sample& x) {
        return std::max(std::abs(b.x - x.x(it)), std::abs(b.v - x.x(n + it)));
      },
      c.deviation_max, c.deviation_t, c.samples_compared);
  const Eigen::VectorXd& xf = exact.final_state;
  const FrictionBoxSample& bf = run.samples.back();
  c.error_final = std::max(std::abs(bf.x - xf(it)), std::abs(bf.v - xf(n + it)));
}

}  // namespace

FrictionComparison compare_friction_box(const mech::Model& model, const Eigen::VectorXd& x0,
                                        const sim::Trajectory& exact, const FrictionBoxSettings& s,
                                        double time_tol) {
  FrictionComparison c;
  FrictionBlockOf of = friction_block_of(model, x0);
  if (of.status != Status::kOk) {
    c.status = of.status;
    c.message = of.message;
    return c;
  }
  c.block = of.block;
  if (exact.samples.empty() || exact.final_state.size() != 4 || !(exact.t_end > 0.0)) {
    c.status = Status::kInvalidInput;
    c.message = "bullet friction box: the exact run has no samples of the block's 4-entry state";
    return c;
  }
  c.block.t_end = exact.t_end;
  const FrictionBoxRun run = simulate_friction_box(c.block, s);
  if (run.status != Status::kOk) {
    c.status = run.status;
    c.message = run.message;
    return c;
  }
  const int it = c.block.tangent_coordinate;
  if (std::isfinite(c.block.stop_time()) && c.block.stop_time() < c.block.t_end) {
    c.closed_form.time = c.block.stop_time();
    c.closed_form.distance = c.block.slide_distance();
  }
  c.exact = exact_stop(exact, it, s.stop_velocity);
  c.bullet = run.stop;
  deviation(exact, run, it, time_tol, c);
  c.steps = static_cast<long>(run.samples.size()) - 1;
  c.min_contact_points = std::numeric_limits<int>::max();
  for (std::size_t j = 0; j < run.samples.size(); ++j) {
    c.max_tilt = std::max(c.max_tilt, std::abs(run.samples[j].tilt));
    if (j > 0) c.min_contact_points = std::min(c.min_contact_points, run.samples[j].contact_points);
  }
  if (c.steps == 0) c.min_contact_points = 0;
  return c;
}

}  // namespace lcsim::bullet
