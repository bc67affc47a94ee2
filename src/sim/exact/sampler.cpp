// Output samples of the event-driven method on the dt_out grid: stepped from
// one sample to the next by a step exponential kept per mode (GridSampler,
// StepExp in event_driven_detail.hpp).
#include <algorithm>
#include <cmath>

#include "sim/exact/event_driven_detail.hpp"

namespace lcsim::sim::detail {

namespace {

// Estimated flops of e^{Ab dt} z by Phase::expv: ceil(||Ab dt||_1) substeps
// of ~20 products with Ab (its non-zeros when sparse); nil - 1 products for
// a nilpotent phase's finite series.
double action_flops(const Phase& ph, double dt) {
  const double n = static_cast<double>(ph.Ab.rows());
  const double nnz = ph.use_sparse ? static_cast<double>(ph.Ab_sparse.nonZeros()) : n * n;
  if (ph.nil > 0) return std::max(1.0, ph.nil - 1.0) * 2.0 * nnz;
  return std::max(1.0, std::ceil(ph.Ab_norm1 * dt)) * 20.0 * 2.0 * nnz;
}

// Estimated flops of forming e^{Ab dt} (Padé 13 with scaling and squaring:
// ~6 products for the approximant, a solve, and one per squaring; nil - 2
// products for a nilpotent phase's finite series).
double dense_flops(const Phase& ph, double dt) {
  const double n = static_cast<double>(ph.Ab.rows());
  if (ph.nil > 0) return std::max(1.0, ph.nil - 2.0) * 2.0 * n * n * n;
  const double squarings = std::max(0.0, std::ceil(std::log2(std::max(1.0, ph.Ab_norm1 * dt))));
  return (8.0 + squarings) * 2.0 * n * n * n;
}

}  // namespace

StepExp& EventDriven::step_exp(const Phase& phase, double dt) {
  StepExp& s = step_cache_[std::make_pair(phase.mode, phase.friction)];
  if (s.dt != dt || s.Ab.rows() != phase.Ab.rows() || s.Ab != phase.Ab) {
    s = StepExp{};
    s.Ab = phase.Ab;
    s.dt = dt;
  }
  return s;
}

VectorXd GridSampler::step(const VectorXd& z) {
  if (!step_) step_ = &fetch_();  // first step of this phase
  StepExp& step = *step_;
  if (step.E.size() == 0) {
    const double n = static_cast<double>(ph_.Ab.rows());
    const double action = action_flops(ph_, dt_);
    const bool form = ph_.dense_exp() ||
                      (action > 2.0 * n * n && step.action_flops + action >= dense_flops(ph_, dt_));
    if (!form) {
      step.action_flops += action;
      return ph_.expv(dt_, z);
    }
    step.E = ph_.expm(dt_);
  }
  return step.E * z;
}

VectorXd GridSampler::at(double t) {
  // The next grid point (k + 1) dt after k dt differs from t_ + dt by the
  // rounding of the two products: an ulp or two of t.
  const double ulps = 4.0 * kEps * std::max(std::abs(t), std::abs(dt_));
  const bool next = z_.size() != 0 && std::abs(t - t_ - dt_) <= ulps;
  z_ = next ? step(z_) : ph_.expv(t - t0_, z0_);
  t_ = t;
  return ph_.D.cwiseProduct(z_);
}

}  // namespace lcsim::sim::detail
