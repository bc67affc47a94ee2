#include "bullet/run_recorder.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <utility>

namespace lcsim::bullet {

using Eigen::VectorXd;

namespace {

using Eigen::MatrixXd;

VectorXd join(const VectorXd& q, const VectorXd& v) {
  VectorXd x(q.size() + v.size());
  x << q, v;
  return x;
}

// The largest eigenvalue of M^{-1} D (1/s), real and >= 0 for M symmetric
// positive definite and D symmetric positive semi-definite: of the pencil
// D x = lambda M x. Dense up to kDenseMax coordinates (a URDF scene, a small
// matrix model); above, rb6's diagonal M (world.cpp) with Gershgorin's bound
// on M^{-1} D, which can only lower the h stated (`exact` false).
double damping_rate(const mech::MechanicalModel& m, bool& exact) {
  constexpr int kDenseMax = 200;
  exact = m.dofs() <= kDenseMax;
  if (exact) {
    const Eigen::GeneralizedSelfAdjointEigenSolver<MatrixXd> es(MatrixXd(m.D), MatrixXd(m.M),
                                                                Eigen::EigenvaluesOnly);
    return es.info() == Eigen::Success ? std::max(0.0, es.eigenvalues().maxCoeff()) : 0.0;
  }
  double rate = 0.0;
  for (int j = 0; j < m.dofs(); ++j) {
    double row = 0.0;
    for (mech::SparseMatrix::InnerIterator it(m.D, j); it; ++it) row += std::abs(it.value());
    rate = std::max(rate, row / m.M.coeff(j, j));  // D symmetric: column sums = row sums
  }
  return rate;
}

}  // namespace

void warn_explicit_damping(sim::Trajectory& tr, const mech::MechanicalModel& m, double h,
                           const char* what) {
  if (m.D.norm() == 0.0) return;
  bool exact = true;
  const double rate = damping_rate(m, exact);
  if (!(rate > 0.0)) return;
  const double h_max = 2.0 / rate;
  tr.warn("bullet-explicit-damping", 0.0,
          std::string("bullet: dampers are explicit ") + what +
              " -D v, stable only for h <= 2 / lambda_max(M^-1 D) = " + sim::short_number(h_max) +
              " s" + (exact ? "" : " or more (Gershgorin)") +
              " (lambda_max = " + sim::short_number(rate) +
              " 1/s from the model's M and D); h = " + sim::short_number(h) +
              (h > h_max ? " is above it: expect divergence, or reduce h" : " is within it"));
}

RunRecorder::RunRecorder(const mech::Model& model, const sim::Options& opt, sim::Trajectory& tr,
                         const VectorXd& q0, const VectorXd& v0, bool friction_outputs)
    : m_(*model.mechanical),
      opt_(opt),
      tr_(tr),
      sampler_(opt.dt_out),
      guard_(model, join(q0, v0), *opt.t_end),
      q_(q0),
      v_(v0) {
  tr_.energy_initial = mech::total_energy(m_, q_, v_);
  y_ = m_.E * q_ + m_.g;
  if (m_.num_constraints() > 0) tr_.max_violation = std::min(0.0, y_.minCoeff());
  if (friction_outputs) ft1_ = ft2_ = VectorXd::Zero(m_.num_constraints());
  record(0.0, VectorXd::Zero(m_.num_constraints()));
}

void RunRecorder::friction(const VectorXd& t1, const VectorXd& t2) {
  ft1_ = t1;
  ft2_ = t2;
}

void RunRecorder::record(double t, const VectorXd& u, double h) {
  if (!opt_.record_samples) return;
  sim::Sample smp;
  smp.t = t;
  smp.x.resize(2 * m_.dofs());
  smp.x << q_, v_;
  smp.u = u;
  smp.y = y_;
  smp.mode = mode_;
  if (ft1_.size() > 0 && !m_.friction.empty()) {  // friction(): each entry's, by its row
    const auto nf = static_cast<Eigen::Index>(m_.friction.size());
    smp.u_t = VectorXd::Zero(nf);
    if (m_.has_friction_3d()) smp.u_t2 = VectorXd::Zero(nf);
    for (Eigen::Index e = 0; e < nf && h > 0.0; ++e) {
      const int row = m_.friction[static_cast<std::size_t>(e)].contact;
      smp.u_t(e) = ft1_(row) / h;
      if (smp.u_t2.size() > 0) smp.u_t2(e) = ft2_(row) / h;
    }
  }
  tr_.record_sample(std::move(smp), opt_);
}

std::string RunRecorder::step(double t, double h, bool last, const VectorXd& q, const VectorXd& v,
                              const VectorXd& impulse, double tiny) {
  if (std::string why = guard_.check(t, q, v, last); !why.empty()) {
    finish();
    tr_.t_end = t_;
    return why;
  }
  const int N = m_.dofs(), k = m_.num_constraints();
  sim::IndexSet mode;
  for (int i = 0; i < k; ++i)
    if (impulse(i) > tiny) mode.push_back(i);
  if (mode != mode_) {
    sim::Event e;
    e.t = t;
    e.state_before.resize(2 * N);
    e.state_before << q_, v_;
    e.state_after.resize(2 * N);
    e.state_after << q, v;
    e.mode_after = mode;
    e.impulse = impulse;
    bool gained = false, lost = false, approaching = false;
    for (int i : mode)
      if (std::find(mode_.begin(), mode_.end(), i) == mode_.end()) {
        gained = true;
        if (m_.E.row(i).dot(v_) < 0.0) approaching = true;
      }
    for (int i : mode_)
      if (std::find(mode.begin(), mode.end(), i) == mode.end()) lost = true;
    e.type = approaching       ? sim::EventType::kImpact
             : lost && !gained ? sim::EventType::kRelease
                               : sim::EventType::kContact;
    tr_.events.push_back(std::move(e));
    mode_ = std::move(mode);
  }
  q_ = q;
  v_ = v;
  t_ = t;
  ++tr_.steps;
  if (k > 0) ++tr_.lcp_solves;  // the constraint solver runs every step
  y_ = m_.E * q_ + m_.g;
  if (k > 0) tr_.max_violation = std::min(tr_.max_violation, std::min(0.0, y_.minCoeff()));
  if (sampler_.want(t, opt_.h, last)) record(t, k > 0 ? VectorXd(impulse / h) : VectorXd(), h);
  return "";
}

void RunRecorder::finish() {
  tr_.final_state.resize(2 * m_.dofs());
  tr_.final_state << q_, v_;
  tr_.energy_final = mech::total_energy(m_, q_, v_);
}

}  // namespace lcsim::bullet
